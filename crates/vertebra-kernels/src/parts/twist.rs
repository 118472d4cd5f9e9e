//! Twist part: a range limit on the rotation about the twist axis (hard, 1
//! degree of freedom when active).
//!
//! The relative rotation `r = (q_a F_a)* (q_b F_b)` splits as
//! `r = swing twist` with `twist` about +X (`Quat::swing_twist`); the twist
//! angle `phi` in [-pi, pi] is its angle. Outside `[lo, hi]` the error is
//! `e = phi - clamp(phi, lo, hi)`, corrected about the world axis
//! `t_b = q_b F_b x` with sign `sign(e)`: turning `b` by `x` about `t_b`
//! multiplies `r` by a twist of `x` on the right, which adds exactly `x` to
//! `phi`. A range of `[-pi, pi]` never binds: a disabled limit.
//!
//! Of `r` the twist needs only `r_x` and `r_w` ([`angle_about_x`]): half
//! the quaternion product.

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
    (f.tb, angle_about_x(f.fa, f.fb))
}

/// The signed angle in [-pi, pi] of the twist about +X of `fa* fb`
/// (rad): [`Quat::twist_angle`] of the product, from the two of its
/// components it reads.
#[inline(always)]
pub fn angle_about_x<L: Lane>(fa: Quat<L>, fb: Quat<L>) -> L {
    let x = fa.w * fb.x - fa.x * fb.w - fa.y * fb.z + fa.z * fb.y;
    let w = fa.w * fb.w + fa.x * fb.x + fa.y * fb.y + fa.z * fb.z;
    let sign = L::splat(1.0).copysign(w);
    L::splat(2.0) * poly::atan2(x * sign, w * sign)
}

/// `phi - clamp(phi, lo, hi)`: signed excess beyond the range (rad).
#[inline(always)]
pub fn excess<L: Lane>(phi: L, lo: L, hi: L) -> L {
    phi - phi.max(lo).min(hi)
}

/// The violation `|e|` (rad) and the axis `sign(e) t_b` along which it
/// grows.
#[inline(always)]
pub fn violation<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
    lo: L,
    hi: L,
) -> (Vec3<L>, L) {
    let (axis, phi) = measure(a, b, frame_a, frame_b);
    let e = excess(phi, lo, hi);
    (axis.scale(L::splat(1.0).copysign(e)), e.abs())
}

/// Enforces the range; returns the |excess| before the correction (rad).
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
    lo: L,
    hi: L,
) -> L {
    let (n, c) = violation(a, b, frame_a, frame_b, lo, hi);
    super::angle::correct(a, b, n, c, L::splat(0.0), L::splat(0.0));
    c
}
