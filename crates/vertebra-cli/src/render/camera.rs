//! The pinhole camera: an eye, a view direction, the world's +Y kept up,
//! a vertical field of view and an image of `width x height` pixels.
//! Pixel coordinates run from the image's top-left corner, x right and y
//! down; pixel `(i, j)` covers `[i, i + 1) x [j, j + 1)`.

use glam::Vec3;

use super::primitive::Ray;

/// The largest image side (pixels) the renderer makes.
pub const MAX_SIDE: u32 = 8192;

#[derive(Clone, Copy, Debug)]
pub struct Camera {
    eye: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    /// The image plane's distance from the eye, in pixels.
    focal: f32,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// A camera at `eye` (m, world) looking at `target`, +Y up, seeing
    /// `fov_y_degrees` from the image's top edge to its bottom edge.
    /// Refused, by name, for a non-finite point, a target at the eye or
    /// straight above or below it, a field of view outside (0, 180)
    /// degrees, or a side of 0 or above [`MAX_SIDE`] pixels.
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        fov_y_degrees: f32,
        width: u32,
        height: u32,
    ) -> Result<Self, String> {
        if !(eye.is_finite() && target.is_finite()) {
            return Err(format!(
                "camera: eye {eye} or target {target} is not finite"
            ));
        }
        if !(fov_y_degrees > 0.0 && fov_y_degrees < 180.0) {
            return Err(format!(
                "camera: field of view {fov_y_degrees} degrees is not within (0, 180)"
            ));
        }
        if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
            return Err(format!(
                "camera: image {width} x {height} is not within 1 to {MAX_SIDE} pixels a side"
            ));
        }
        let forward = (target - eye).normalize_or_zero();
        let right = forward.cross(Vec3::Y).normalize_or_zero();
        if right == Vec3::ZERO || !right.is_finite() {
            return Err(format!(
                "camera: target {target} is at the eye {eye} or straight above or below it"
            ));
        }
        let focal = 0.5 * height as f32 / (0.5 * fov_y_degrees.to_radians()).tan();
        Ok(Self {
            eye,
            forward,
            right,
            up: right.cross(forward),
            focal,
            width,
            height,
        })
    }

    /// The ray from the eye through the image point `(x, y)` (pixels).
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let (cx, cy) = (0.5 * self.width as f32, 0.5 * self.height as f32);
        let dir = self.forward * self.focal + self.right * (x - cx) + self.up * (cy - y);
        Ray {
            origin: self.eye,
            dir: dir.normalize(),
        }
    }
}
