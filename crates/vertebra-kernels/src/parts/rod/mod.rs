//! The rod's parts (paper sections 5.1-5.5), over one shared measurement
//! of the two material frames.
//!
//! Bodies `a` and `b` carry the rod at their centres of mass; their
//! material frames are `F(0) = q_a F_a` and `F(1) = q_b F_b`, and the
//! tangents `t_a`, `t_b` are the frames' +X axes. The bend angle is
//! `psi = atan2(|t_a x t_b|, t_a . t_b)` (the paper's `acos(t_a . t_b)`,
//! computed without its loss of precision near 0), bending about
//! `n = (t_a x t_b) / |t_a x t_b|`. The derivations are in
//! `docs/rod-constraint.md`.

pub mod bend;
pub mod curve;
pub mod drive;
pub mod length;
pub mod twist;

use vertebra_math::{Lane, Vec3, poly};

pub use crate::parts::{Frames, frames};

/// The bend axis (unit, or zero when straight or folded back) and the bend
/// angle `psi` in [0, pi].
#[inline(always)]
pub fn bend_angle<L: Lane>(ta: Vec3<L>, tb: Vec3<L>) -> (Vec3<L>, L) {
    let (n, sin) = ta.cross(tb).normalize_or_zero();
    (n, poly::atan2(sin, ta.dot(tb)))
}
