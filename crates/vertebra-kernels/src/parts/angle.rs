//! Angle part: one rotational correction about a world axis (1 degree of
//! freedom), hard or soft. Every angular part reduces to it.
//!
//! The caller measures an angle error `C >= 0` and a unit axis `n` such
//! that turning `b` by `+x` about `n` (or `a` by `-x`) grows `C` by `x`.
//! Then `w = n^T I_a^-1 n + n^T I_b^-1 n` and
//! `dlambda = (-C - alpha~ lambda) / (w + alpha~)`; `b` turns by
//! `I_b^-1 (dlambda n)` and `a` by `-I_a^-1 (dlambda n)` (Müller et al.
//! 2020, sec. 3.3.2). `n = 0` or `C = 0` gives no correction.

use vertebra_math::{Lane, Vec3};

use crate::body::{BodyLanes, safe_ratio};

/// Applies the correction; returns `dlambda` (N m s^2), to be added to the
/// part's accumulated `lambda` by soft parts.
#[inline(always)]
pub fn correct<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    n: Vec3<L>,
    c: L,
    alpha_tilde: L,
    lambda: L,
) -> L {
    let w = a.angular_weight(n) + b.angular_weight(n);
    let dlambda = safe_ratio(-c - alpha_tilde * lambda, w + alpha_tilde);
    let turn = n.scale(dlambda);
    b.rotate(b.inv_inertia_mul(turn));
    a.rotate(a.inv_inertia_mul(-turn));
    dlambda
}
