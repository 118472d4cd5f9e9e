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
pub mod length;
pub mod twist;

use vertebra_math::{Lane, Quat, Vec3, poly};

use crate::body::BodyLanes;

/// Both material frames and their tangents.
#[derive(Clone, Copy, Debug)]
pub struct Frames<L> {
    /// `F(0) = q_a F_a`.
    pub fa: Quat<L>,
    /// `F(1) = q_b F_b`.
    pub fb: Quat<L>,
    /// `t_a = F(0) x`.
    pub ta: Vec3<L>,
    /// `t_b = F(1) x`.
    pub tb: Vec3<L>,
}

/// Measures the material frames at the bodies' current orientations.
#[inline(always)]
pub fn frames<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> Frames<L> {
    let x = Vec3::splat(crate::TWIST_AXIS);
    let (fa, fb) = (a.q * frame_a, b.q * frame_b);
    Frames {
        fa,
        fb,
        ta: fa.rotate(x),
        tb: fb.rotate(x),
    }
}

/// The bend axis (unit, or zero when straight or folded back) and the bend
/// angle `psi` in [0, pi].
#[inline(always)]
pub fn bend_angle<L: Lane>(ta: Vec3<L>, tb: Vec3<L>) -> (Vec3<L>, L) {
    let (n, sin) = ta.cross(tb).normalize_or_zero();
    (n, poly::atan2(sin, ta.dot(tb)))
}
