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

use crate::body::{BodyLanes, safe_ratio};

/// How hard a correction pulls: XPBD compliance, or a PBD relaxation
/// factor, per lane.
#[derive(Clone, Copy, Debug)]
pub struct Softness<L> {
    /// `compliance / h^2` (0 for hard parts and for relaxation).
    pub alpha_tilde: L,
    /// The fraction of the error removed per iteration (1 for XPBD).
    pub relaxation: L,
}

impl<L: Lane> Softness<L> {
    /// A hard part.
    #[inline(always)]
    pub fn hard() -> Self {
        Self {
            alpha_tilde: L::splat(0.0),
            relaxation: L::splat(1.0),
        }
    }
}

/// Applies the correction with the same axis on both bodies; returns
/// `dlambda`.
#[inline(always)]
pub fn correct<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    n: Vec3<L>,
    c: L,
    alpha_tilde: L,
    lambda: L,
) -> L {
    let soft = Softness {
        alpha_tilde,
        relaxation: L::splat(1.0),
    };
    correct_axes(a, b, n, n, c, soft, lambda)
}

/// Applies the correction with axis `n_a` on `a` and `n_b` on `b`; returns
/// `dlambda`, to be added to the part's accumulated `lambda` by soft parts.
#[inline(always)]
pub fn correct_axes<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    n_a: Vec3<L>,
    n_b: Vec3<L>,
    c: L,
    soft: Softness<L>,
    lambda: L,
) -> L {
    let ((s_a, w_a), (s_b, w_b)) = (a.angular_response(n_a), b.angular_response(n_b));
    let dlambda = safe_ratio(
        -soft.relaxation * c - soft.alpha_tilde * lambda,
        w_a + w_b + soft.alpha_tilde,
    );
    turn(a, b, s_a, s_b, dlambda);
    dlambda
}

/// Turns `b` by `s_b dlambda` and `a` by `-s_a dlambda`, with the bodies'
/// responses `s = I^-1 n` ([`BodyLanes::angular_response`]).
#[inline(always)]
pub fn turn<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    s_a: Vec3<L>,
    s_b: Vec3<L>,
    dlambda: L,
) {
    b.rotate(s_b.scale(dlambda));
    a.rotate(s_a.scale(-dlambda));
}
