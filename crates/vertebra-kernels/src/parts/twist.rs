//! Twist part: a range limit on the rotation about the twist axis (hard, 1
//! degree of freedom when active).
//!
//! The relative rotation `r = (q_a F_a)* (q_b F_b)` splits as
//! `r = swing twist` with `twist` about +X (`Quat::swing_twist`); the twist
//! angle `phi` in [-pi, pi] is its angle, `2 atan2(r_x, r_w)` with the sign
//! of `r_w` taken out, which needs only those two components of `r`
//! ([`angle`]). Outside `[lo, hi]` the error is
//! `e = phi - clamp(phi, lo, hi)`, corrected about the world axis
//! `t_b = q_b F_b x` with sign `sign(e)`: turning `b` by `x` about `t_b`
//! multiplies `r` by a twist of `x` on the right, which adds exactly `x` to
//! `phi`. A range of `[-pi, pi]` never binds: a disabled limit.
//!
//! The kernels (the socket's, the hinge's) measure the same angle in the
//! bodies' own frames ([`violation_local`]): from b's orientation relative
//! to a,
//! `R_a^T R_b` (one quaternion product), `r = F_a* (q_a* q_b F_b)`, whose
//! twist about +X is `2 atan2(r_x, r_w)` (the sign of `r_w` taken out),
//! and the axis `t_b` is `(q_a* q_b F_b) x` in a's frame and `F_b x` in
//! b's, ready for [`super::limit::solve_local`] and
//! [`super::angle::solve_local`], which then need no rotation into or
//! out of either body. [`measure`] (world) is the residual's.

use vertebra_math::{Lane, Quat, Vec3, poly};

use crate::body::BodyLanes;

/// The world twist axis `t_b` and the twist angle `phi` (rad).
#[inline(always)]
pub fn measure<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> (Vec3<L>, L) {
    let f = super::frames(a, b, frame_a, frame_b);
    (f.tb, angle(f.fa, f.fb))
}

/// The twist angle (rad, in [-pi, pi]) about +X of `r = f_a* f_b`:
/// `2 atan2(r_x, r_w)` with the sign of `r_w` taken out
/// ([`Quat::twist_angle`] about +X), from the only two components of the
/// product it needs, `r_x = aw bx - ax bw - ay bz + az by` and
/// `r_w = f_a . f_b`.
#[inline(always)]
pub fn angle<L: Lane>(fa: Quat<L>, fb: Quat<L>) -> L {
    let rx = fa.w * fb.x - fa.x * fb.w - fa.y * fb.z + fa.z * fb.y;
    let rw = fa.dot(fb);
    let sign = L::splat(1.0).copysign(rw);
    L::splat(2.0) * poly::atan2(rx * sign, rw * sign)
}

/// `phi - clamp(phi, lo, hi)`: signed excess beyond the range (rad).
#[inline(always)]
pub fn signed_violation<L: Lane>(phi: L, lo: L, hi: L) -> L {
    phi - phi.max(lo).min(hi)
}

/// The signed distance (rad) of `phi` past the nearer bounded end of
/// `[lo, hi]`, and the sign of the axis along which it grows: positive
/// beyond the range, negative inside it (how far the end is), so that a
/// linearisation predicts where a step would cross it (the direct solve's
/// active set, `direct::rows`). An end at pi or beyond (-pi or beyond for
/// `lo`) is no end: with neither bounded the distance is `free`, far
/// inside, and never crossed.
#[inline(always)]
pub fn signed<L: Lane>(phi: L, lo: L, hi: L, free: L) -> (L, L) {
    let pi = L::splat(core::f32::consts::PI);
    let above = L::select(hi.ge(pi), free, phi - hi);
    let below = L::select(lo.le(-pi), free, lo - phi);
    let upper = above.ge(below);
    (
        above.max(below),
        L::select(upper, L::splat(1.0), L::splat(-1.0)),
    )
}

/// Enforces the range; returns the |excess| before the correction (rad).
/// Measured and corrected in the bodies' own frames
/// ([`violation_local`], [`super::angle::solve_local`]).
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
    lo: L,
    hi: L,
) -> L {
    let (axes, c) = violation_local(a, b, frame_a, frame_b, lo, hi);
    super::angle::solve_local(a, b, axes, c);
    c
}

/// The twist angle `phi` (rad) and the axis `t_b` in each body's own frame
/// (`[R_a^T t_b, R_b^T t_b]`), from b's orientation relative to a's.
#[inline(always)]
pub fn measure_local<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> ([Vec3<L>; 2], L) {
    // b's joint frame in a's body frame, then relative to a's joint frame.
    let fb = (a.q.conjugate() * b.q) * frame_b;
    (
        [super::axis_x(fb), super::axis_x(frame_b)],
        angle(frame_a, fb),
    )
}

/// The violation `|e|` (rad) and the axis `sign(e) t_b` along which it
/// grows, in the bodies' own frames ([`measure_local`]).
#[inline(always)]
pub fn violation_local<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
    lo: L,
    hi: L,
) -> ([Vec3<L>; 2], L) {
    let ([axis_a, axis_b], phi) = measure_local(a, b, frame_a, frame_b);
    let e = signed_violation(phi, lo, hi);
    let sign = L::splat(1.0).copysign(e);
    ([axis_a.scale(sign), axis_b.scale(sign)], e.abs())
}
