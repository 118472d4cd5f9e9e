//! Limit part: one angular inequality, hard or soft, for every joint
//! limit (cone, ellipse, pyramid, twist range, hinge range).
//!
//! The caller measures the violation `C >= 0` (0 where the limit holds)
//! and its axis `n` (turning b by `x` about `n` grows `C` by `x`), and the
//! violation `C_0` at the substep's start (the limit start pass,
//! `limited.rs`, before the bodies are predicted). With
//! `w = n^T (I_a^-1 + I_b^-1) n` the correction is the angle part's
//! XPBD step with damping (Macklin et al. 2016, eq. 26), as the drive's
//! (`drive.rs`, whose header derives it), on one axis:
//!
//! `dlambda = -(C + alpha~ lambda + gamma (C - C_0)) / ((1 + gamma) w + alpha~)`
//!
//! `alpha~ = alpha / h^2`, `gamma = damping_time / h`, accumulated in
//! `lambda` over the substep's iterations. The limit's settings, per lane,
//! as the drive's: `alpha = compliance + period2 w` and `damping_time`:
//!
//! - hard: all three 0; then the step is exactly the angle part's hard
//!   correction (`dlambda = -C / w`), bit for bit (the plain XPBD
//!   expression is kept and selected wherever `period2 / h^2 + gamma` is 0).
//! - compliance `c` (rad / (N m)) and damping `d` (N m s / rad): `alpha =
//!   c`, `damping_time = c d`: the torque on the excess is `-C / c - d
//!   dC/dt`.
//! - frequency `f` (Hz) and damping ratio `zeta`, on the limit's own
//!   effective inertia `1 / w`: `period2 = 1 / omega^2`, `damping_time =
//!   2 zeta / omega` (`omega = 2 pi f`). The masses cancel and one
//!   iteration is the implicit Euler step of `C'' = -omega^2 C - 2 zeta
//!   omega C'` (the drive header's derivation with `W` a scalar): the
//!   excess is an oscillator at `f` with ratio `zeta` whatever the bodies.
//!
//! Where the limit holds (`C = 0`) the part does nothing: the accumulated
//! `lambda` and the damping term are masked out, so damping acts only
//! while the limit is exceeded. While it is exceeded the spring-damper is
//! two-sided (the damper may pull, the accumulated `lambda` is not clamped
//! to push only, unlike Jolt's and Box2D's soft limits): a critically
//! damped excess `C = v t e^(-omega t)` then returns to the limit without
//! crossing it, whereas clamping the push would release the limb at
//! `t = 2 / omega` moving outward at `e^-2 = 13.5%` of its impact speed: a
//! rebound. The damping's `C - C_0` counts only the excess: a limit
//! entered during the substep has `C_0 = 0`.

use vertebra_math::{Lane, Vec3};

use super::angle;
use crate::body::{BodyLanes, safe_ratio};

/// A limit's softness, per lane, scaled to the substep (see the module
/// documentation).
#[derive(Clone, Copy, Debug)]
pub struct Softness<L> {
    /// `compliance / h^2` (rad / (N m s^2)).
    pub alpha_tilde: L,
    /// `period2 / h^2` (dimensionless): compliance per unit `w`.
    pub spring: L,
    /// `gamma = damping_time / h` (dimensionless).
    pub gamma: L,
}

impl<L: Lane> Softness<L> {
    /// A hard limit: all zero.
    #[inline(always)]
    pub fn hard() -> Self {
        let zero = L::splat(0.0);
        Self {
            alpha_tilde: zero,
            spring: zero,
            gamma: zero,
        }
    }

    /// From per-lane `compliance` (rad / (N m)), `period2` (s^2) and
    /// `damping_time` (s), with `1 / h` and `1 / h^2`.
    #[inline(always)]
    pub fn new(compliance: L, period2: L, damping_time: L, inv_h: L, inv_h2: L) -> Self {
        Self {
            alpha_tilde: compliance * inv_h2,
            spring: period2 * inv_h2,
            gamma: damping_time * inv_h,
        }
    }
}

/// Corrects a violation `c` (rad, >= 0) about the axis `n`, given in
/// each body's own frame, `[R_a^T n, R_b^T n]` (as every limit measures
/// it), `c0` the violation at the substep's start; returns the new
/// accumulated `lambda` (N m s^2). `w` and the turns come from the same
/// body-frame `S n` ([`angle::apply_local`]).
#[inline(always)]
pub fn solve_local<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    [n_a, n_b]: [Vec3<L>; 2],
    (c, c0): (L, L),
    soft: Softness<L>,
    lambda: L,
) -> L {
    let (s_a, s_b) = (a.inv_inertia.mul_vec(n_a), b.inv_inertia.mul_vec(n_b));
    let dlambda = multiplier_change(n_a.dot(s_a) + n_b.dot(s_b), (c, c0), soft, lambda);
    angle::apply_local(a, b, (s_a, s_b), dlambda);
    lambda + dlambda
}

/// `dlambda` for the generalised inverse mass `w` (the module
/// documentation's step).
#[inline(always)]
fn multiplier_change<L: Lane>(w: L, (c, c0): (L, L), soft: Softness<L>, lambda: L) -> L {
    let zero = L::splat(0.0);
    let active = c.gt(zero);
    let held = L::select(active, lambda, zero);
    // Hard and compliance-only lanes: the angle part's expression, bit for
    // bit.
    let plain = (
        -L::splat(1.0) * c - soft.alpha_tilde * held,
        w + soft.alpha_tilde,
    );
    let alpha = soft.alpha_tilde + soft.spring * w;
    let damping = L::select(active, soft.gamma * (c - c0), zero);
    let sprung = (
        -(c + alpha * held + damping),
        w * (L::splat(1.0) + soft.gamma) + alpha,
    );
    let damped = (soft.spring + soft.gamma).gt(zero);
    safe_ratio(
        L::select(damped, sprung.0, plain.0),
        L::select(damped, sprung.1, plain.1),
    )
}
