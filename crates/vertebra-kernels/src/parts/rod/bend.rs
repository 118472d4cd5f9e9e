//! Bending (soft) and the bend limit (hard).
//!
//! Soft bending pulls `t_b` toward its rest direction `d = F(0) d_rest`
//! (`d_rest` in a's material frame; `d_rest = x` is a straight rest shape).
//! The error is the angle `C = atan2(|d x t_b|, d . t_b)` about
//! `n = (d x t_b)/|d x t_b|`: turning `b` about `n` grows it and turning `a`
//! about `n` (which turns `d` with it) shrinks it, so the angle part
//! applies with one axis. For a rest bend in the current bend plane this
//! is `psi - psi_rest`, the paper's `C_bend` (eqs. 10-11) in XPBD form; out
//! of that plane it is the geodesic distance to the rest direction, so a
//! rest bend has a plane, not only an angle. The energy
//! `1/2 k_b kappa^2 l0` with `kappa = C / l0` is `1/2 (k_b / l0) C^2`: the
//! compliance is `l0 / k_b`.
//!
//! As a drive it is damped, sprung and capped by `super::drive`, whose
//! header derives the bend's effective inertia.
//!
//! The limit keeps `psi <= psi_max`: `C = max(psi - psi_max, 0)` about the
//! bend axis `t_a x t_b`, hard.

use vertebra_math::{Lane, Vec3, poly};

use super::drive::{self, Drive, bend_weight};
use super::{Frames, LocalFrames, bend_angle};
use crate::body::BodyLanes;
use crate::parts::angle;

/// The axis and angle from the rest direction to `t_b`.
#[inline(always)]
pub fn measure<L: Lane>(f: &Frames<L>, rest_direction: Vec3<L>) -> (Vec3<L>, L) {
    let d = f.fa.rotate(rest_direction);
    let (n, sin) = d.cross(f.tb).normalize_or_zero();
    (n, poly::atan2(sin, d.dot(f.tb)))
}

/// The error as a rotation vector `C n` (rad, world): the bend's state at
/// the substep's start, read along the axis of the moment by [`solve`].
#[inline(always)]
pub fn start<L: Lane>(f: &Frames<L>, rest_direction: Vec3<L>) -> Vec3<L> {
    let (n, c) = measure(f, rest_direction);
    n.scale(c)
}

/// One soft bending correction, damped against the error `start` had as
/// the substep began; returns the new accumulated `lambda`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    m: &LocalFrames<L>,
    rest_direction: Vec3<L>,
    rest_length: L,
    d: &Drive<L>,
    start: Vec3<L>,
    lambda: L,
) -> L {
    let (n, c) = measure(&m.f, rest_direction);
    let (ra, rb) = (a.local_response(n), b.local_response(m.in_b(n)));
    let w = bend_weight(a, b, (ra.weight, rb.weight), rest_length);
    drive::solve(a, b, (&ra, &rb), c, c - start.dot(n), w, d, lambda)
}

/// How far `psi` exceeds the limit (rad, >= 0), and the bend axis.
#[inline(always)]
pub fn violation<L: Lane>(f: &Frames<L>, max_bend: L) -> (Vec3<L>, L) {
    let (n, psi) = bend_angle(f.ta, f.tb);
    (n, (psi - max_bend).max(L::splat(0.0)))
}

/// Enforces `psi <= max_bend`; returns the overshoot before the correction.
#[inline(always)]
pub fn limit<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    m: &LocalFrames<L>,
    max_bend: L,
) -> L {
    let (n, c) = violation(&m.f, max_bend);
    angle::solve_local(a, b, [n, m.in_b(n)], c);
    c
}
