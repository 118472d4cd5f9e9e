//! Shading: Lambert's law under one directional light plus a constant
//! ambient term, the light cut off by a shadow ray, on whichever side of
//! a surface the ray sees.

use glam::Vec3;

use super::primitive::Ray;
use super::scene::Scene;

/// Linear RGB where a ray meets nothing.
pub const BACKGROUND: Vec3 = Vec3::new(0.80, 0.84, 0.90);

/// How far a shadow ray starts off its surface (m): far above the
/// rounding of a point a few metres from the origin, far below any
/// feature of a ragdoll.
const SHADOW_OFFSET: f32 = 1e-4;

/// A directional light (the sun) and the ambient light.
#[derive(Clone, Copy, Debug)]
pub struct Light {
    /// Unit vector from a surface towards the light (world).
    towards: Vec3,
    /// The light's strength on a surface facing it (0 to 1 of white).
    sun: f32,
    /// The ambient light on every surface (0 to 1 of white).
    ambient: f32,
}

impl Light {
    /// A light from direction `towards` (any length above 0; world) of
    /// strength `sun`, with `ambient`; refused, by name, for non-finite or
    /// negative values or a zero direction.
    pub fn new(towards: Vec3, sun: f32, ambient: f32) -> Result<Self, String> {
        let unit = towards.normalize_or_zero();
        let fine = |x: f32| x.is_finite() && x >= 0.0;
        if unit == Vec3::ZERO || !unit.is_finite() || !fine(sun) || !fine(ambient) {
            return Err(format!(
                "light: direction {towards}, sun {sun} and ambient {ambient} must be finite, not negative, the direction not zero"
            ));
        }
        Ok(Self {
            towards: unit,
            sun,
            ambient,
        })
    }
}

/// What one ray sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Linear RGB.
    pub colour: Vec3,
    /// The object hit ([`Scene::closest`]'s index), or `None`: the
    /// background.
    pub object: Option<usize>,
}

/// What `ray` sees: the background, or the nearest surface's paint times
/// `ambient + sun max(n . l, 0)`, the sun term dropped where a shadow ray
/// towards the light is blocked (`n` the unit normal on the side facing
/// the ray, `l` the light's direction).
pub fn sample(scene: &Scene, light: &Light, ray: &Ray) -> Sample {
    let Some((hit, k)) = scene.closest(ray, 0.0, f32::INFINITY) else {
        return Sample {
            colour: BACKGROUND,
            object: None,
        };
    };
    let point = ray.at(hit.t);
    let normal = if hit.normal.dot(ray.dir) > 0.0 {
        -hit.normal
    } else {
        hit.normal
    };
    let facing = normal.dot(light.towards).max(0.0);
    let lit = facing > 0.0 && {
        let shadow = Ray {
            origin: point + normal * SHADOW_OFFSET,
            dir: light.towards,
        };
        !scene.blocked(&shadow, 0.0, f32::INFINITY)
    };
    let sun = if lit { light.sun * facing } else { 0.0 };
    Sample {
        colour: scene.object(k).paint.at(point) * (light.ambient + sun),
        object: Some(k),
    }
}
