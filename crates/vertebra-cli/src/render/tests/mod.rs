//! The ray caster checked against closed forms: each primitive's hits,
//! the tree against testing every primitive, and rendered images (the
//! Lambert value at a sphere's and a capsule's projected centre, the
//! silhouette's area, shadows, the background, refusals, threads).

mod hits;
mod images;

use glam::Vec3;

use super::primitive::Ray;

/// A ray from `origin` along `dir` (normalised here).
fn ray(origin: Vec3, dir: Vec3) -> Ray {
    Ray {
        origin,
        dir: dir.normalize(),
    }
}

/// `a` and `b` within `tolerance` of each other, component by component.
fn close(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}
