//! A small ray caster, no GPU: figure 1 (the pile of ragdolls at rest).
//!
//! **Camera** (`camera.rs`): a pinhole at the eye looking at a target,
//! +Y up, with a vertical field of view.
//!
//! **Sampling** ([`render`]): one ray from the eye through each pixel's
//! centre, and where that pixel or a neighbour sees another object or a
//! clearly different colour (an edge: a silhouette, a shadow's or a
//! checker's border), four rays on a 2 x 2 grid (offsets 1/4 and 3/4 of a
//! pixel) whose linear colours are averaged instead: antialiasing where it
//! shows, at under half the cost of four rays everywhere (figure 1: 0.47
//! of the cycles).
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
//! Each centre sample, and then each pixel, is computed on its own from
//! the scene, the camera, the light and the centre samples, so the image
//! is the same bytes whatever the number of threads rendering it.

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
pub use figure::{capsules, figure_1};
pub use primitive::Primitive;
pub use scene::{Object, Paint, Scene};
use shade::Sample;
pub use shade::{Light, sample};

/// The sample points within a pixel where it is sampled four times
/// (fractions of a pixel).
const SAMPLES: [(f32, f32); 4] = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)];

/// Neighbouring centres whose 8-bit sRGB values differ by more than this
/// in a channel mark an edge (a shadow's, a checker's).
const EDGE: u8 = 16;

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

/// `scene` seen by `camera` under `light`, rows rendered in parallel:
/// first one ray through each pixel's centre, then, where a pixel or one
/// of its eight neighbours sees another object or a colour more than
/// [`EDGE`] away, the average of four rays on a 2 x 2 grid instead.
pub fn render(scene: &Scene, light: &Light, camera: &Camera) -> Image {
    let (width, height) = (camera.width as usize, camera.height as usize);
    let centres: Vec<(Sample, [u8; 3])> = (0..width * height)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % width) as f32, (i / width) as f32);
            let seen = sample(scene, light, &camera.ray(x + 0.5, y + 0.5));
            (seen, seen.colour.to_array().map(colour::to_srgb))
        })
        .collect();
    let mut rgba = vec![255u8; 4 * width * height];
    rgba.par_chunks_mut(4 * width)
        .enumerate()
        .for_each(|(y, pixels)| {
            for (x, pixel) in pixels.chunks_exact_mut(4).enumerate() {
                let rgb = if on_edge(&centres, width, height, x, y) {
                    let sum = SAMPLES.iter().fold(Vec3::ZERO, |sum, (dx, dy)| {
                        let ray = camera.ray(x as f32 + dx, y as f32 + dy);
                        sum + sample(scene, light, &ray).colour
                    });
                    (sum / SAMPLES.len() as f32).to_array().map(colour::to_srgb)
                } else {
                    centres[y * width + x].1
                };
                pixel[..3].copy_from_slice(&rgb);
            }
        });
    Image {
        width: camera.width,
        height: camera.height,
        rgba,
    }
}

/// Whether pixel `(x, y)`'s centre sample differs from a neighbour's in
/// object or by more than [`EDGE`] in a channel.
fn on_edge(centres: &[(Sample, [u8; 3])], width: usize, height: usize, x: usize, y: usize) -> bool {
    let (here, rgb) = centres[y * width + x];
    let rows = y.saturating_sub(1)..(y + 2).min(height);
    rows.flat_map(|v| (x.saturating_sub(1)..(x + 2).min(width)).map(move |u| v * width + u))
        .any(|k| {
            let (there, other) = centres[k];
            there.object != here.object || rgb.iter().zip(other).any(|(a, b)| a.abs_diff(b) > EDGE)
        })
}

#[cfg(test)]
mod tests;
