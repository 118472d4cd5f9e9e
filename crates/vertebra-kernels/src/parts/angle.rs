//! Angle part: one rotational correction (1 degree of freedom), hard or
//! soft. Every angular part reduces to it.
//!
//! The caller measures an angle error `C` and the axes along which it
//! changes: turning `b` by a small `x` about `n_b` grows `C` by `x`, and
//! turning `a` by `x` about `n_a` shrinks it by `x` (so `dC/dtheta_b = n_b`,
//! `dC/dtheta_a = -n_a`). For a plain relative angle `n_a = n_b`; the rod's
//! curve and twist have different axes on each side. Then
//! `w = n_a^T I_a^-1 n_a + n_b^T I_b^-1 n_b` and
//! `dlambda = (-beta C - alpha~ lambda) / (w + alpha~)`; `b` turns by
//! `I_b^-1 n_b dlambda` and `a` by `-I_a^-1 n_a dlambda` (Müller et al.
//! 2020, sec. 3.3.2). `beta` is 1 for XPBD; a PBD relaxation factor in
//! [0, 1] otherwise (then `alpha~ = 0`). A zero axis or `C = 0` gives no
//! correction.

use vertebra_math::{Lane, Vec3};

use crate::body::{BodyLanes, Response, safe_ratio};

/// How hard a correction pulls: XPBD compliance, or a PBD relaxation
/// factor, per lane.
#[derive(Clone, Copy, Debug)]
pub struct Softness<L> {
    /// `compliance / h^2` (0 for hard parts and for relaxation).
    pub alpha_tilde: L,
    /// The fraction of the error removed per iteration (1 for XPBD).
    pub relaxation: L,
}

/// Applies a hard correction with the axis given in each body's own frame,
/// `[R_a^T n_a, R_b^T n_b]`: `w = n_a . S_a n_a + n_b . S_b n_b` from the
/// same `S n` that turns the bodies ([`apply_local`]), with no rotation
/// into or out of a body.
#[inline(always)]
pub fn solve_local<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    [n_a, n_b]: [Vec3<L>; 2],
    c: L,
) {
    let (s_a, s_b) = (a.inv_inertia.mul_vec(n_a), b.inv_inertia.mul_vec(n_b));
    let dlambda = safe_ratio(-c, n_a.dot(s_a) + n_b.dot(s_b));
    apply_local(a, b, (s_a, s_b), dlambda);
}

/// Turns `b` by `I_b^-1 n_b dlambda` and `a` by `-I_a^-1 n_a dlambda`,
/// from their responses to `n_a` and `n_b` (`crate::body::Response`: the
/// turns in the bodies' own frames).
#[inline(always)]
pub fn apply<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    (ra, rb): (&Response<L>, &Response<L>),
    dlambda: L,
) {
    b.turn_local(rb.turn, dlambda);
    a.turn_local(ra.turn, -dlambda);
}

/// Turns `b` by `R_b turn_b dlambda` and `a` by `-R_a turn_a dlambda`,
/// each turn given in its body's own frame (`turn = S n` with the
/// body-frame inverse inertia `S` and axis `n = R^T n_world`: the parts that
/// measure in the bodies' frames form `w = n^T S n` from the same `S n`,
/// and need no rotation into the body, nor out of it:
/// `BodyLanes::turn_local`).
#[inline(always)]
pub fn apply_local<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    (turn_a, turn_b): (Vec3<L>, Vec3<L>),
    dlambda: L,
) {
    b.turn_local(turn_b, dlambda);
    a.turn_local(turn_a, -dlambda);
}
