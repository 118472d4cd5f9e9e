//! Swing part: a cone limit on the angle between the two joint frames'
//! twist axes (hard, 1 degree of freedom when active).
//!
//! `t_a = q_a F_a x`, `t_b = q_b F_b x` (the frames' +X). The swing angle is
//! `theta = atan2(|t_a x t_b|, t_a . t_b)` in [0, pi] (atan2 rather than
//! acos: accurate at small angles) and the error `C = max(theta - max, 0)`
//! about `n = (t_a x t_b) / |t_a x t_b|`: turning `b` about `n` moves `t_b`
//! away from `t_a`. A limit of `pi` or more never binds, so a disabled
//! limit is `max = pi` and costs no branch. At `theta = pi` exactly `n` is
//! undefined and no correction is made.

use vertebra_math::{Lane, Quat, Vec3, poly};

use crate::body::BodyLanes;

/// The swing axis `n` (unit, or zero) and angle `theta` (rad).
#[inline(always)]
pub fn measure<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> (Vec3<L>, L) {
    let f = super::frames(a, b, frame_a, frame_b);
    let (n, sin) = axis(f.ta, f.tb);
    (n, poly::atan2(sin, f.ta.dot(f.tb)))
}

/// The swing axis `n = (t_a x t_b) / |t_a x t_b|` (unit, or zero when the
/// axes are parallel or antiparallel) and `|t_a x t_b| = sin theta`, in
/// whatever frame `t_a` and `t_b` are given (the hinge axis part,
/// `hinge_axis.rs`, turns about the same `n`, measured in a's frame).
#[inline(always)]
pub fn axis<L: Lane>(ta: Vec3<L>, tb: Vec3<L>) -> (Vec3<L>, L) {
    ta.cross(tb).normalize_or_zero()
}

/// How far the swing exceeds `max_angle` (rad, >= 0).
#[inline(always)]
pub fn violation<L: Lane>(theta: L, max_angle: L) -> L {
    (theta - max_angle).max(L::splat(0.0))
}

/// As [`measure`], in the bodies' own frames: the axis `[R_a^T n,
/// R_b^T n]` and the angle, from b's orientation relative to a's
/// (`t_a = F_a x` and `t_b = (q_a* q_b F_b) x` in a's frame; `n` turned
/// into b's frame by the same relative rotation).
#[inline(always)]
pub fn measure_local<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> ([Vec3<L>; 2], L) {
    let relative = a.q.conjugate() * b.q;
    let (ta, tb) = (super::axis_x(frame_a), super::axis_x(relative * frame_b));
    let (n, sin) = axis(ta, tb);
    (
        [n, relative.inverse_rotate(n)],
        poly::atan2(sin, ta.dot(tb)),
    )
}

/// Enforces the cone; returns the overshoot before the correction (rad).
/// Measured and corrected in the bodies' own frames ([`measure_local`],
/// [`super::angle::solve_local`]).
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
    max_angle: L,
) -> L {
    let (axes, theta) = measure_local(a, b, frame_a, frame_b);
    let c = violation(theta, max_angle);
    super::angle::solve_local(a, b, axes, c);
    c
}
