//! Curve part (paper eq. 6, hard, 2 degrees of freedom): `t_b` must be the
//! reflection of `t_a` about the chord direction `o = (p_b - p_a)/|p_b - p_a|`,
//! so that a circular arc joins the bodies.
//!
//! The reflection `r = 2 (t_a . o) o - t_a` is a half turn about `o`. The
//! error is the angle `theta = atan2(|r x t_b|, r . t_b)` about
//! `n = (r x t_b)/|r x t_b|`; turning `b` about `n` grows it
//! (`dtheta/dtheta_b = n`). Turning `a` by `x` about `u` turns `r` by `x`
//! about the reflected axis `2 (u . o) o - u`, which shrinks `theta` by
//! `x (R_o u) . n = x u . (R_o n)`: so `dtheta/dtheta_a = -n_a` with
//! `n_a = 2 (n . o) o - n`. The correction is by rotation only (positions,
//! hence `o`, are the length part's), one angle per iteration, as the
//! angle part does. `theta = 0` where the ends coincide (no chord) or the
//! axis is undefined (`t_b = -r`).

use vertebra_math::{Lane, Vec3, poly};

use super::Frames;
use crate::body::BodyLanes;
use crate::parts::angle::{self, Softness};

/// The axes `(n_a, n_b)` and the curve error `theta` (rad).
#[inline(always)]
pub fn measure<L: Lane>(a: &BodyLanes<L>, b: &BodyLanes<L>, f: &Frames<L>) -> (Vec3<L>, Vec3<L>, L) {
    let (o, distance) = (b.p - a.p).normalize_or_zero();
    let r = o.scale(L::splat(2.0) * f.ta.dot(o)) - f.ta;
    let (n, sin) = r.cross(f.tb).normalize_or_zero();
    let theta = L::select(distance.gt(L::splat(0.0)), poly::atan2(sin, r.dot(f.tb)), L::splat(0.0));
    let n_a = o.scale(L::splat(2.0) * n.dot(o)) - n;
    (n_a, n, theta)
}

/// Turns the bodies toward an admissible arc; returns the error before
/// the correction (rad).
#[inline(always)]
pub fn solve<L: Lane>(a: &mut BodyLanes<L>, b: &mut BodyLanes<L>, f: &Frames<L>) -> L {
    let (n_a, n_b, theta) = measure(a, b, f);
    angle::correct_axes(a, b, n_a, n_b, theta, Softness::hard(), L::splat(0.0));
    theta
}
