//! The soft bend and twist as drives: XPBD with damping, a spring form and
//! a torque cap, for one angle (the rod's counterpart of `parts::drive`).
//!
//! Damping. The soft part is the damped spring `tau = -K C - D dC/dt` on
//! its error `C` (the bend's angle to its rest direction, or the twist's
//! difference from its rest twist), solved by XPBD with damping (Macklin et
//! al. 2016, eq. 26), one angle at a time:
//!
//! `dlambda = -(C + alpha~ lambda + gamma (C - C_0)) / ((1 + gamma) w + alpha~)`
//!
//! with `w = n_a^T I_a^-1 n_a + n_b^T I_b^-1 n_b` (the angle part's),
//! `alpha~ = K^-1 / h^2`, `gamma = K^-1 D / h`, and `C_0` the error as the
//! substep began (measured by the rod's `Starts`, against the rest the
//! previous substep aimed at: see "Moving rest"), so that `(C - C_0) / h`
//! is the error's rate. The bend's `C` is an angle about an
//! axis `n` that turns as the bend does (it flips when `t_b` passes through
//! its rest direction), so its start is kept as the rotation vector
//! `C_0 n_0` and read along the current axis: `C_0 = (C_0 n_0) . n`. The
//! twist's start is its wrapped error, and the rate wraps too. A Kirchhoff
//! rod with stiffness `k` and damping `d` (N m^2 s: the torque is
//! `(d / l0) dC/dt`, as the stiffness gives `(k / l0) C`) has
//! `K^-1 = l0 / k` and `gamma h = d / k`.
//!
//! Moving rest. The rest shape may move (a rod following an animation):
//! the rest direction turns at `w_r` (rad/s, a's material frame) and the
//! rest twist advances at `v_t` (rad/s). The damping is then to act on the
//! error's rate relative to the rest's, so that a rod moving with its rest
//! is not held back. With `C_0` the error at the substep's start measured
//! against this substep's rest, the bodies change the error by `C - C_0`
//! and the rest by `-h r`, `r` the rate at which the rest moves along the
//! error: for the twist (`C = tau - tau_rest`) `r = v_t`; for the bend,
//! turning `d` by `x` about `n` shrinks `C` by `x`, so `r = (F(0) w_r) . n`,
//! the rest direction's angular velocity read along the current bend axis
//! (its part along `d` turns `d` about itself, and its part along `n x d`
//! moves `d` out of the bend plane: neither changes `C` to first order).
//! The damping term is therefore
//!
//! `gamma (C - C_0 - h r)`.
//!
//! The rod's `Starts` gives it without a rate in the iterations, as the
//! socket's drive does for its moving target (`parts::drive`, "Moving
//! target"): it measures the start error against the previous substep's
//! rest, then advances the rest by `h` ([`advance_direction`],
//! [`advance_twist`]). Against the previous rest the start error is
//! `C_0^- = C_0 + h r`: exactly for the twist (`tau_0 - (tau_rest - h v_t)`,
//! up to the wrap, which the rate's own wrap undoes), and to first order in
//! `h` for the bend (`d` turned back by `h w_r` lengthens the angle by
//! `h r`; the rest is in the bend's start rotation vector `C_0^- n_0`,
//! which is read along the current axis). So the kernel's
//! `gamma (C - C_0^-)` is `gamma (C - C_0 - h r)`. A still rest (zero
//! rates) is not advanced (a select keeps its bits), `C_0^- = C_0`, and
//! every rod computes as before, bit for bit.
//!
//! Spring. A frequency `f` and damping ratio `zeta` on the part's effective
//! inertia `J` (`omega = 2 pi f`): `K = J omega^2`, `D = 2 zeta omega J`, so
//! `alpha = w_J / omega^2` with `w_J = 1 / J`, and `gamma h = 2 zeta /
//! omega`, as the socket's drive. What `J` is:
//!
//! - Twisting turns each body about its own tangent, which moves no
//!   centre of mass and bends nothing: `J = 1 / w`, the angle part's.
//! - Bending does not only turn the bodies: the hard curve part keeps the
//!   chord halfway between the tangents, so a bend carries the bodies'
//!   centres round the arc. With the bodies turned by `theta_a`,
//!   `theta_b` about `n` (`psi = theta_b - theta_a`), the chord turns by
//!   `(theta_a + theta_b) / 2` and the centres move apart across it at
//!   `l0 (theta_a' + theta_b') / 2` (`l0` the chord, to first order).
//!   With the pair's momentum zero the kinetic energy is
//!   `1/2 (I_a theta_a'^2 + I_b theta_b'^2 + mu l0^2 ((theta_a' +
//!   theta_b')/2)^2)`, `mu` the reduced mass; its least value for a given
//!   `psi'` (the free bending mode, the one an impulse excites) is
//!   `1/2 J psi'^2` with
//!   `J = (I_a I_b + (I_a + I_b) mu l0^2 / 4) / (I_a + I_b + mu l0^2)`,
//!   in inverse quantities (`u = n^T I^-1 n`, `v = 1/m_a + 1/m_b`)
//!   `w_J = ((u_a + u_b) v + u_a u_b l0^2) / (v + (u_a + u_b) l0^2 / 4)`
//!   ([`bend_weight`]). A held base (`u_a = 0`, `m_a` infinite) gives
//!   `J = I_b + m_b l0^2 / 4`, the chest turning about the rod's middle;
//!   equal bodies give `J = I / 2` (the centres stay on the chord); no
//!   length gives the angle part's `1 / (u_a + u_b)`.
//!
//! A driven rod is then an oscillator at `f` in bending and in twisting.
//! The soft part's own step divides by `(1 + gamma) w + alpha~` with the
//! rotational `w` (it only turns the bodies; the curve part moves them),
//! so one iteration does not land on the implicit Euler step as the
//! socket's drive does: the iterations converge to it.
//!
//! Torque cap. `lambda` accumulates the substep's angular impulse times
//! `h` (N m s^2); where `|lambda + dlambda|` would exceed `max_torque h^2`
//! it is held there (a select per lane) and only the part of `dlambda` that
//! gets there is applied. Infinity caps nothing, bit for bit.
//!
//! A part with neither damping nor spring (`gamma = 0`, `alpha = alpha~`)
//! takes the angle part's correction bit for bit (`parts::angle`): the
//! undriven rods of the golden scenes are unchanged.

use vertebra_math::{Lane, Vec3, poly};

use crate::body::{BodyLanes, Response, safe_ratio};
use crate::parts::angle::{self, Softness};

/// A soft part's drive settings for this substep, per lane.
#[derive(Clone, Copy, Debug)]
pub struct Drive<L> {
    /// Compliance over `h^2`, or the relaxation factor.
    pub soft: Softness<L>,
    /// `1 / (omega h)^2`: compliance per unit effective inverse inertia
    /// over `h^2` (0 unless given by frequency).
    pub spring: L,
    /// `gamma` (damping time over `h`).
    pub gamma: L,
    /// The largest accumulated `|lambda|`: `max_torque h^2` (N m s^2).
    pub limit: L,
}

/// The effective inverse inertia of bending about `n` (1/(kg m^2)): `w_J`
/// of the module documentation, for a rod of length `rest_length` (m),
/// from the bodies' responses to a turn about `n` (`ua = n^T I_a^-1 n`,
/// `ub` the same for b).
#[inline(always)]
pub fn bend_weight<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    (ua, ub): (L, L),
    rest_length: L,
) -> L {
    let v = a.inv_mass + b.inv_mass;
    let l2 = rest_length * rest_length;
    safe_ratio(
        (ua + ub) * v + ua * ub * l2,
        v + (ua + ub) * l2 * L::splat(0.25),
    )
}

/// The rest direction `rest` (unit, a's material frame) advanced by `h`
/// seconds at `velocity` (rad/s, the same frame): turned by the drives'
/// [`turn`](crate::parts::drive::turn) and renormalised. Only the part of
/// `velocity` perpendicular to `rest` moves it. A still rest is returned
/// as it is, bit for bit.
#[inline(always)]
pub fn advance_direction<L: Lane>(rest: Vec3<L>, velocity: Vec3<L>, h: L) -> Vec3<L> {
    let (turn, moving) = crate::parts::drive::turn(velocity, h);
    let (turned, _) = turn.rotate(rest).normalize_or_zero();
    Vec3::select(moving, turned, rest)
}

/// The rest twist `rest` (rad) advanced by `h` seconds at `rate` (rad/s),
/// wrapped to [-pi, pi]. A still rest is returned as it is, bit for bit
/// (not wrapped).
#[inline(always)]
pub fn advance_twist<L: Lane>(rest: L, rate: L, h: L) -> L {
    let advanced = poly::wrap_angle(rest + rate * h);
    L::select(rate.ne(L::splat(0.0)), advanced, rest)
}

/// One damped, sprung, capped correction of the angle `c` (axes as in
/// `parts::angle`, given as the bodies' responses to them); `rate` is
/// `C - C_0` (rad) and `w_spring` the part's effective inverse inertia.
/// Returns the new accumulated `lambda`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    (ra, rb): (&Response<L>, &Response<L>),
    c: L,
    rate: L,
    w_spring: L,
    d: &Drive<L>,
    lambda: L,
) -> L {
    let w = ra.weight + rb.weight;
    let s = d.soft;
    let plain = safe_ratio(
        -s.relaxation * c - s.alpha_tilde * lambda,
        w + s.alpha_tilde,
    );
    let alpha = s.alpha_tilde + d.spring * w_spring;
    let damped = safe_ratio(
        -s.relaxation * c - alpha * lambda - d.gamma * rate,
        (L::splat(1.0) + d.gamma) * w + alpha,
    );
    let dlambda = L::select((d.spring + d.gamma).gt(L::splat(0.0)), damped, plain);
    let (lambda, dlambda) = cap(lambda, dlambda, d.limit);
    angle::apply(a, b, (ra, rb), dlambda);
    lambda
}

/// `lambda + dlambda` held to `[-limit, limit]`, and the step that gets
/// there (`dlambda` itself, bit for bit, within the limit).
#[inline(always)]
fn cap<L: Lane>(lambda: L, dlambda: L, limit: L) -> (L, L) {
    let total = lambda + dlambda;
    let over = total.abs().gt(limit);
    let held = limit.copysign(total);
    (
        L::select(over, held, total),
        L::select(over, held - lambda, dlambda),
    )
}
