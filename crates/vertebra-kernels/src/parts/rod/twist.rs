//! Rod twisting (soft) and the twist limit (hard), measured exactly.
//!
//! The twist is the angle about `t_b` between `F(1)` and `F(0)` carried
//! along the arc by its natural (parallel-transport) frame. For a circular
//! arc that transport is the minimal rotation `M` taking `t_a` to `t_b`
//! (about the bend axis, by `psi`), so `tau` is the angle of the rotation
//! `(M F(0))* F(1)`, which turns about x only: `Quat::twist_angle`, from
//! the product's x and real components alone (`parts::twist::angle`).
//! The paper's `tau = xi - psi` (eq. 12, `xi` the total angle between the
//! frames) is not this: it cannot be negative, and a bend of `psi` with a
//! twist of `tau` has `xi = 2 acos(cos(psi/2) cos(tau/2)) != psi + tau`.
//!
//! Gradients. Turning `b` by `x` about `t_b` multiplies `F(1)` by a twist
//! of `x`, and turning `a` about `t_a` turns `M F(0)` about `t_b` (M is
//! unchanged): along the tangents, `dtau/dtheta_b . t_b = 1` and
//! `dtau/dtheta_a . t_a = -1`. But tilting a tangent also changes `M`,
//! which twists the transported frame: differentiating the half-way
//! quaternion gives, with the Rodrigues vector `k = (t_a x t_b) /
//! (1 + t_a . t_b)` of `M` (`|k| = tan(psi/2)`),
//! `dtau/dtheta_a = -(t_a - t_a x k)` and `dtau/dtheta_b = t_b + t_b x k`
//! (derivation in `docs/rod-constraint.md`; checked against finite
//! differences in `tests/rod_gradients.rs`). The energy
//! `1/2 k_t (tau/l0)^2 l0` gives the compliance `l0 / k_t`, as for bending;
//! damping, the spring form and the torque cap are `super::drive`'s.

use vertebra_math::{Lane, Quat, Vec3, poly};

use super::drive::{self, Drive};
use super::{Frames, LocalFrames};
use crate::body::{BodyLanes, safe_ratio};
use crate::parts::angle;
use crate::parts::twist::signed_violation;

/// The axes `(n_a, n_b)` with `dtau/dtheta_a = -n_a`, `dtau/dtheta_b = n_b`.
/// Near `psi = pi` (`1 + t_a . t_b` below 1e-6) `k` is dropped: the twist
/// is undefined there, and the limits keep rods well away from it.
#[inline(always)]
pub fn axes<L: Lane>(f: &Frames<L>) -> (Vec3<L>, Vec3<L>) {
    let k =
        f.ta.cross(f.tb)
            .scale(safe_ratio(L::splat(1.0), L::splat(1.0) + f.ta.dot(f.tb)));
    let k = Vec3::select(
        (L::splat(1.0) + f.ta.dot(f.tb)).gt(L::splat(1e-6)),
        k,
        Vec3::zero(),
    );
    (f.ta - f.ta.cross(k), f.tb + f.tb.cross(k))
}

/// The twist angle `tau` in [-pi, pi] (rad).
#[inline(always)]
pub fn measure<L: Lane>(f: &Frames<L>) -> L {
    // M = (t_a x t_b, 1 + t_a . t_b), the half-way quaternion, not
    // normalised: the twist angle is an atan2 of two components of the
    // product, which any positive multiple of M leaves as they are. Folded
    // back (1 + t_a . t_b at most 1e-6, where `axes` drops k too) it is the
    // identity.
    let w = L::splat(1.0) + f.ta.dot(f.tb);
    let minimal = Quat::select(
        w.gt(L::splat(1e-6)),
        Quat::from_parts(f.ta.cross(f.tb), w),
        Quat::identity(),
    );
    crate::parts::twist::angle(minimal * f.fa, f.fb)
}

/// The error `tau - rest`, wrapped to [-pi, pi]: a rod twisted past pi
/// from its rest twist turns back the short way, not the long way round.
#[inline(always)]
pub fn signed_rest_violation<L: Lane>(f: &Frames<L>, rest: L) -> L {
    poly::wrap_angle(measure(f) - rest)
}

/// One soft twisting correction toward `rest`, damped against the error
/// `start` as the substep began (the rate wraps too); returns the new
/// `lambda`. Twisting moves no centre: its effective inverse inertia is
/// the angle part's `w` (`super::drive`).
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    m: &LocalFrames<L>,
    rest: L,
    d: &Drive<L>,
    start: L,
    lambda: L,
) -> L {
    let c = signed_rest_violation(&m.f, rest);
    let (n_a, n_b) = axes(&m.f);
    let (ra, rb) = (a.local_response(n_a), b.local_response(m.in_b(n_b)));
    let rate = poly::wrap_angle(c - start);
    drive::solve(a, b, (&ra, &rb), c, rate, ra.weight + rb.weight, d, lambda)
}

/// Enforces `lo <= tau <= hi`; returns |excess| before the correction.
#[inline(always)]
pub fn limit<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    m: &LocalFrames<L>,
    lo: L,
    hi: L,
) -> L {
    let e = signed_violation(measure(&m.f), lo, hi);
    let (n_a, n_b) = axes(&m.f);
    angle::solve_local(a, b, [n_a, m.in_b(n_b)], e);
    e.abs()
}
