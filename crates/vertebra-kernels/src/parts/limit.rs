//! Limit part: one angular inequality, hard or soft, for every joint
//! limit (cone, ellipse, pyramid, twist range, hinge range).
//!
//! The caller measures the violation `C >= 0` (0 where the limit holds)
//! and its axis `n` (turning b by `x` about `n` grows `C` by `x`). The
//! correction is the angle part's XPBD step with the limit's compliance
//! `alpha` (rad / (N m); 0 is hard):
//! `dlambda = (-C - alpha~ lambda) / (w + alpha~)`, `alpha~ = alpha / h^2`,
//! accumulated in `lambda` over the substep's iterations (Macklin et al.
//! 2016). Where the limit holds it does nothing (`C = 0` and the
//! accumulated `lambda` masked out): a soft limit pushes back while it is
//! exceeded, as a spring of stiffness `1 / alpha` (N m / rad) on the
//! excess, and lets go inside. With `alpha = 0` it is exactly the angle
//! part's hard correction.

use vertebra_math::{Lane, Vec3};

use super::angle::{Softness, correct_axes};
use crate::body::BodyLanes;

/// Corrects a violation `c` (rad, >= 0) about `n`; returns the new
/// accumulated `lambda` (N m s^2).
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    n: Vec3<L>,
    c: L,
    alpha_tilde: L,
    lambda: L,
) -> L {
    let active = c.gt(L::splat(0.0));
    let held = L::select(active, lambda, L::splat(0.0));
    let soft = Softness {
        alpha_tilde,
        relaxation: L::splat(1.0),
    };
    lambda + correct_axes(a, b, n, n, c, soft, held)
}
