//! Curve part (paper eq. 6, hard, 2 degrees of freedom): `t_b` must be the
//! reflection of `t_a` about the chord direction `o = (p_b - p_a)/|p_b - p_a|`,
//! so that a circular arc joins the bodies.
//!
//! The chord `p_b - p_a` is measured from the start of the step
//! ([`PairStart::chord`]).
//!
//! The reflection `r = 2 (t_a . o) o - t_a` is a half turn about `o`. The
//! error is the angle `theta = atan2(|r x t_b|, r . t_b)` about
//! `n = (r x t_b)/|r x t_b|`, one angle per iteration as the angle part
//! does. Its gradients (checked against finite differences in
//! `tests/rod_gradients.rs`; derived in `docs/rod-constraint.md`):
//!
//! - turning `b` about `n` grows it: `dtheta/dtheta_b = n`;
//! - turning `a` by `x` about `u` turns `r` by `x` about the reflected axis
//!   `2 (u . o) o - u`: `dtheta/dtheta_a = -n_a`, `n_a = 2 (n . o) o - n`;
//! - moving `b` turns `o`, hence `r`: with `e = n x r` (the unit direction
//!   from `r` toward `t_b`),
//!   `dtheta/dp_b = -(2/|d|) (1 - o o^T) ((e . o) t_a + (t_a . o) e) = g`
//!   and `dtheta/dp_a = -g`.
//!
//! The positional gradient matters: without it nothing holds the bodies on
//! the arc sideways (the length part moves them along `o` only), and a
//! cantilevered rod swings down like a pendulum on a string. With it, the
//! generalised inverse mass is
//! `w = n_a^T I_a^-1 n_a + n_b^T I_b^-1 n_b + |g|^2 (1/m_a + 1/m_b)`.
//! `theta = 0` (and no correction) where the ends coincide or the axis is
//! undefined (`t_b = -r`).

use vertebra_math::{Lane, Vec3, poly};

use super::Frames;
use crate::body::{BodyLanes, PairStart, safe_ratio};
use crate::parts::angle;

/// The curve error and its gradients.
#[derive(Clone, Copy, Debug)]
pub struct Curve<L> {
    /// `theta` (rad).
    pub theta: L,
    /// `-dtheta/dtheta_a`.
    pub n_a: Vec3<L>,
    /// `dtheta/dtheta_b`.
    pub n_b: Vec3<L>,
    /// `dtheta/dp_b` (1/m); `dtheta/dp_a` is its negative.
    pub g: Vec3<L>,
}

/// Measures the curve error and its gradients.
#[inline(always)]
pub fn measure<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    f: &Frames<L>,
    start: &PairStart<L>,
) -> Curve<L> {
    let two = L::splat(2.0);
    let (o, distance) = start.chord(a, b).normalize_or_zero();
    let apart = distance.gt(L::splat(0.0));
    let ta_o = f.ta.dot(o);
    let r = o.scale(two * ta_o) - f.ta;
    let (n, sin) = r.cross(f.tb).normalize_or_zero();
    let theta = L::select(apart, poly::atan2(sin, r.dot(f.tb)), L::splat(0.0));
    let e = n.cross(r);
    let along = f.ta.scale(e.dot(o)) + e.scale(ta_o);
    let across = along - o.scale(along.dot(o));
    let g = across.scale(-safe_ratio(two, distance));
    Curve {
        theta,
        n_a: o.scale(two * n.dot(o)) - n,
        n_b: n,
        g: Vec3::select(apart, g, Vec3::zero()),
    }
}

/// Moves and turns the bodies toward an admissible arc; returns the error
/// before the correction (rad).
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    f: &Frames<L>,
    start: &PairStart<L>,
) -> L {
    let c = measure(a, b, f, start);
    let (ra, rb) = (a.angular_response(c.n_a), b.angular_response(c.n_b));
    let w = ra.weight + rb.weight + c.g.length_squared() * (a.inv_mass + b.inv_mass);
    let dlambda = safe_ratio(-c.theta, w);
    angle::apply(a, b, (&ra, &rb), dlambda);
    b.p += c.g.scale(dlambda * b.inv_mass);
    a.p -= c.g.scale(dlambda * a.inv_mass);
    c.theta
}
