//! A small ray caster, no GPU: figure 1 (the pile of ragdolls at rest).
//!
//! **Camera** (`camera.rs`): a pinhole at the eye looking at a target,
//! +Y up, with a vertical field of view; each pixel is sampled at four
//! points of a 2 x 2 grid (offsets 1/4 and 3/4 of a pixel), each by one
//! ray from the eye, and the four linear colours averaged (antialiasing).
//!
//! **Primitives** (`primitive.rs`): sphere, capsule, oriented box and
//! plane, each intersected exactly (closed-form roots, slabs; no
//! tessellation), the nearest hit giving its distance and the outward
//! normal. The bounded ones sit under a bounding volume hierarchy
//! (`bvh.rs`); planes are tested by every ray.
//!
//! **Shading** (`shade.rs`): Lambert's law under one directional light
//! plus a constant ambient term, `paint (ambient + sun max(n . l, 0))`,
//! the sun term dropped where a shadow ray from the point towards the
//! light hits anything (hard shadows). Colours are linear RGB, written as
//! 8-bit sRGB (`colour.rs`).
//!
//! **Figure 1** (`figure.rs`): a scene's world turned into primitives
//! (each ragdoll's capsules in its own colour, the static colliders grey,
//! the ground a checker) and the camera and light that show the pit.
//!
//! Each pixel is computed on its own from the scene, the camera and the
//! light, so the image is the same bytes whatever the number of threads
//! rendering its rows.

mod bvh;
mod camera;
pub mod colour;
mod figure;
mod primitive;
mod scene;
mod shade;

use std::path::Path;

use glam::Vec3;
use rayon::prelude::*;

pub use camera::Camera;
pub use figure::figure_1;
pub use primitive::Primitive;
pub use scene::{Object, Paint, Scene};
pub use shade::{Light, radiance};

/// The sample points within a pixel (fractions of a pixel).
const SAMPLES: [(f32, f32); 4] = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)];

/// An 8-bit sRGB image, rows from the top, 4 bytes (RGBA, opaque) a
/// pixel.
pub struct Image {
    pub width: u32,
    pub height: u32,
    rgba: Vec<u8>,
}

impl Image {
    /// Pixel `(x, y)`'s RGB (from the top-left corner).
    #[cfg(test)]
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let at = 4 * (y as usize * self.width as usize + x as usize);
        [self.rgba[at], self.rgba[at + 1], self.rgba[at + 2]]
    }

    /// Writes the image as a PNG file.
    pub fn save_png(self, path: &Path) -> Result<(), String> {
        let size = resvg::tiny_skia::IntSize::from_wh(self.width, self.height)
            .ok_or("render: an empty image")?;
        let pixmap = resvg::tiny_skia::Pixmap::from_vec(self.rgba, size)
            .ok_or("render: the image's size and bytes differ")?;
        pixmap
            .save_png(path)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))
    }
}

/// `scene` seen by `camera` under `light`, rows rendered in parallel.
pub fn render(scene: &Scene, light: &Light, camera: &Camera) -> Image {
    let row = 4 * camera.width as usize;
    let mut rgba = vec![255u8; row * camera.height as usize];
    rgba.par_chunks_mut(row)
        .enumerate()
        .for_each(|(y, pixels)| {
            for (x, pixel) in pixels.chunks_exact_mut(4).enumerate() {
                let colour = SAMPLES.iter().fold(Vec3::ZERO, |sum, (dx, dy)| {
                    let ray = camera.ray(x as f32 + dx, y as f32 + dy);
                    sum + radiance(scene, light, &ray)
                }) / SAMPLES.len() as f32;
                pixel[..3].copy_from_slice(&colour.to_array().map(colour::to_srgb));
            }
        });
    Image {
        width: camera.width,
        height: camera.height,
        rgba,
    }
}
