//! Figure 1: a scene's world as primitives, and the camera and light
//! that show it. Each ragdoll is drawn from its skeleton pose (so a
//! simplified ragdoll's spine bodies, which the rod replaces in the world,
//! are drawn where the rod puts them), every body a capsule in the
//! ragdoll's own colour; the static colliders are grey, the ground a
//! checker of 0.5 m squares. The camera looks down at 50 degrees from
//! 30 degrees off the +Z axis, at the middle of everything bounded, from
//! far enough that all of it is in view; walls (upright static boxes
//! taller than thick) on the camera's side of the middle (the pit's two
//! near walls) are cut down to 10 cm, so they show where they stand
//! without hiding the pile.

use glam::{Quat, Vec3};
use vertebra_collide::ColliderShape;
use vertebra_ragdoll::{Pose, RagdollDesc, SpineMapping};
use vertebra_scenes::SceneWorld;
use vertebra_world::Shape;

use super::colour::{linear_rgb, ragdoll_colour};
use super::{Camera, Image, Light, Object, Paint, Primitive, Scene, render};

/// The image's size (pixels).
const WIDTH: u32 = 1200;
const HEIGHT: u32 = 800;
/// The vertical field of view (degrees).
const FOV_Y: f32 = 40.0;
/// The camera's elevation above the horizon and turn from +Z towards +X
/// (degrees).
const ELEVATION: f32 = 50.0;
const AZIMUTH: f32 = 30.0;
/// How tall a cut-away wall is left (m).
const CUT_HEIGHT: f32 = 0.1;
/// Colours (8-bit sRGB): the static colliders and the ground's squares.
const STATIC: [u8; 3] = [150, 150, 150];
const GROUND: [[u8; 3]; 2] = [[222, 222, 218], [196, 196, 192]];

/// Figure 1 of `scene`'s world as it stands.
pub fn figure_1(scene: &SceneWorld) -> Result<Image, String> {
    let mut objects = ragdolls(scene)?;
    let statics = statics(scene)?;
    let (target, eye) = view(objects.iter().chain(&statics));
    let away = (eye - target).with_y(0.0).normalize_or_zero();
    objects.extend(statics.into_iter().map(|o| cut_away(o, target, away)));
    let camera = Camera::look_at(eye, target, FOV_Y, WIDTH, HEIGHT)?;
    let light = Light::new(Vec3::new(-0.6, 1.0, 0.25), 0.8, 0.25)?;
    Ok(render(&Scene::new(objects)?, &light, &camera))
}

/// Every ragdoll's bodies as capsules, ragdoll `k` in
/// [`ragdoll_colour`]`(k)`.
fn ragdolls(scene: &SceneWorld) -> Result<Vec<Object>, String> {
    let mut objects = Vec::new();
    for (k, ragdoll) in scene.ragdolls.iter().enumerate() {
        let pose = ragdoll
            .skeleton_pose(&scene.world, SpineMapping::Arc)
            .map_err(|e| e.to_string())?;
        let paint = Paint::Plain(linear_rgb(ragdoll_colour(k)));
        for ([a, b], radius) in capsules(ragdoll.description(), &pose) {
            objects.push(Object {
                primitive: Primitive::Capsule { a, b, radius },
                paint,
            });
        }
    }
    Ok(objects)
}

/// Each body of `desc` at `pose` as its capsule: the core segment's ends
/// (m, world) and the radius (m).
pub fn capsules<'a>(
    desc: &'a RagdollDesc,
    pose: &'a Pose,
) -> impl Iterator<Item = ([Vec3; 2], f32)> + 'a {
    desc.bodies.iter().zip(&pose.bones).map(|(body, &(p, q))| {
        (
            body.segment.map(|s| p + q * (s - body.centre())),
            body.radius,
        )
    })
}

/// The colliders on bodies of no ragdoll (the ground, walls, boxes).
fn statics(scene: &SceneWorld) -> Result<Vec<Object>, String> {
    let Some(collisions) = &scene.collisions else {
        return Ok(Vec::new());
    };
    let ragdoll_bodies: std::collections::HashSet<_> = scene
        .ragdolls
        .iter()
        .flat_map(|r| r.bodies.iter().flatten())
        .collect();
    let mut objects = Vec::new();
    for collider in collisions.colliders() {
        if ragdoll_bodies.contains(&collider.body) {
            continue;
        }
        let state = scene.world.body(collider.body).map_err(|e| e.to_string())?;
        let (p, q) = (state.position, state.orientation);
        let grey = Paint::Plain(linear_rgb(STATIC));
        let (primitive, paint) = match collider.shape {
            ColliderShape::Plane(n) => {
                let normal = q * n;
                let [a, b] = GROUND.map(linear_rgb);
                let offset = normal.dot(p);
                (
                    Primitive::Plane { normal, offset },
                    Paint::Checker { a, b, size: 0.5 },
                )
            }
            ColliderShape::Solid(shape) => (solid(shape, p, q), grey),
        };
        objects.push(Object { primitive, paint });
    }
    Ok(objects)
}

/// A body shape at pose `(p, q)` (m, world).
fn solid(shape: Shape, p: Vec3, q: Quat) -> Primitive {
    match shape {
        Shape::Sphere { radius } => Primitive::Sphere { centre: p, radius },
        Shape::Box { half_extents } => Primitive::Box {
            centre: p,
            rotation: q,
            half_extents,
        },
        Shape::Capsule {
            half_segment,
            radius,
        } => Primitive::Capsule {
            a: p - q * half_segment,
            b: p + q * half_segment,
            radius,
        },
    }
}

/// The camera's target (the middle of everything bounded, a fifth of the
/// way up) and eye (at
/// [`ELEVATION`] and [`AZIMUTH`], far enough that a ball holding
/// everything bounded fits the field of view).
fn view<'a>(objects: impl Iterator<Item = &'a Object>) -> (Vec3, Vec3) {
    let (min, max) = objects
        .filter_map(|o| o.primitive.bounds())
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), (a, b)| {
            (lo.min(a), hi.max(b))
        });
    if !(min.is_finite() && max.is_finite()) {
        // Nothing bounded: the origin, from above and in front.
        return (Vec3::ZERO, Vec3::new(0.0, 2.0, 4.0));
    }
    // Aimed a fifth of the way up: the near side, closer to the eye, is
    // drawn larger, and would otherwise leave the image's lower edge.
    let reach = (max - min).length() * 0.5;
    let target = ((min + max) * 0.5).with_y(min.y + 0.2 * (max.y - min.y));
    let (el, az) = (ELEVATION.to_radians(), AZIMUTH.to_radians());
    let towards_eye = Vec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos());
    let distance = 0.95 * reach / (0.5 * FOV_Y.to_radians()).sin();
    (target, target + towards_eye * distance)
}

/// `object` cut down to [`CUT_HEIGHT`] if it is a wall (an upright box
/// taller than it is thick) standing on the camera's side of `target`
/// (horizontal unit direction `away`); otherwise as it is.
fn cut_away(object: Object, target: Vec3, away: Vec3) -> Object {
    let Primitive::Box {
        centre,
        rotation,
        half_extents,
    } = object.primitive
    else {
        return object;
    };
    let upright = (rotation * Vec3::Y).y > 0.999;
    let wall = half_extents.y > half_extents.x.min(half_extents.z);
    let near = (centre - target).with_y(0.0).dot(away) > 0.0;
    if !(upright && wall && near && half_extents.y > 0.5 * CUT_HEIGHT) {
        return object;
    }
    let bottom = centre.y - half_extents.y;
    Object {
        primitive: Primitive::Box {
            centre: centre.with_y(bottom + 0.5 * CUT_HEIGHT),
            rotation,
            half_extents: half_extents.with_y(0.5 * CUT_HEIGHT),
        },
        ..object
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};
    use vertebra_ragdoll::SpineMode;
    use vertebra_scenes::{Scene as Scenes, SceneConfig, build};

    use super::{FOV_Y, HEIGHT, WIDTH, cut_away, ragdolls, statics, view};
    use crate::render::{Object, Paint, Primitive};

    fn wall(centre: Vec3, half_extents: Vec3, rotation: Quat) -> Object {
        Object {
            primitive: Primitive::Box {
                centre,
                rotation,
                half_extents,
            },
            paint: Paint::Plain(Vec3::splat(0.5)),
        }
    }

    #[test]
    fn only_walls_on_the_cameras_side_are_cut_down_to_their_foot() {
        let (along_z, thin) = (Vec3::new(1.6, 0.5, 0.05), Vec3::new(0.3, 0.15, 0.3));
        let near = wall(Vec3::new(0.0, 0.5, 1.55), along_z, Quat::IDENTITY);
        let cut = cut_away(near, Vec3::ZERO, Vec3::Z);
        assert_eq!(
            cut.primitive,
            Primitive::Box {
                centre: Vec3::new(0.0, 0.05, 1.55),
                rotation: Quat::IDENTITY,
                half_extents: Vec3::new(1.6, 0.05, 0.05),
            }
        );
        let kept = [
            wall(Vec3::new(0.0, 0.5, -1.55), along_z, Quat::IDENTITY),
            wall(Vec3::new(0.6, 0.15, 0.6), thin, Quat::IDENTITY),
            wall(
                Vec3::new(0.0, 0.5, 1.55),
                along_z,
                Quat::from_rotation_x(0.5),
            ),
        ];
        for object in kept {
            assert_eq!(cut_away(object, Vec3::ZERO, Vec3::Z), object);
        }
    }

    #[test]
    fn the_drop_is_drawn_whole_and_all_in_view() {
        let mut config = SceneConfig::new(Scenes::RagdollDrop, SpineMode::Rod);
        config.ragdolls = 3;
        let scene = build(&config).unwrap();
        let bodies = ragdolls(&scene).unwrap();
        // Every described body, the rod's spine bodies too.
        let desc = scene.ragdolls[0].description();
        assert_eq!(bodies.len(), 3 * desc.bodies.len());
        // The ground, four walls and three boxes.
        let statics = statics(&scene).unwrap();
        assert_eq!(statics.len(), 8);
        // Every bounding box's corners project inside the image: on the
        // image plane at the focal length f (pixels), within half the
        // width and height of the centre.
        let (target, eye) = view(bodies.iter().chain(&statics));
        let forward = (target - eye).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let focal = 0.5 * HEIGHT as f32 / (0.5 * FOV_Y).to_radians().tan();
        for (lo, hi) in bodies
            .iter()
            .chain(&statics)
            .filter_map(|o| o.primitive.bounds())
        {
            for k in 0..8 {
                let corner =
                    Vec3::select(glam::BVec3::new(k & 1 > 0, k & 2 > 0, k & 4 > 0), hi, lo);
                let v = corner - eye;
                let (x, y) = (
                    focal * v.dot(right) / v.dot(forward),
                    focal * v.dot(up) / v.dot(forward),
                );
                assert!(
                    x.abs() < 0.5 * WIDTH as f32 && y.abs() < 0.5 * HEIGHT as f32,
                    "{corner} is at ({x}, {y}) px from the centre"
                );
            }
        }
    }
}
