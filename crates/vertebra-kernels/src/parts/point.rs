//! Point part: two anchors coincide (3 degrees of freedom, hard).
//!
//! With `r_a = q_a a_local`, `r_b = q_b b_local` and
//! `d = (p_b + r_b) - (p_a + r_a)` (measured from the start of the step,
//! [`PairStart::separation`]), the constraint is `C = |d| = 0`,
//! corrected along `n = d / |d|` (Müller et al. 2020, sec. 3.3.1):
//! `dlambda = -C / (w_a + w_b)` with `w = 1/m + (r x n)^T I^-1 (r x n)`,
//! then `+dlambda n` is applied to `b` at `r_b` and `-dlambda n` to `a` at
//! `r_a`. Solving along `n` alone is exact for the positional part (the
//! error has no other direction); the rotations are linearised.

use vertebra_math::{Lane, Vec3};

use crate::body::{BodyLanes, PairStart, safe_ratio};

/// The anchors' world lever arms and their separation `d` (m), from `a`'s
/// anchor to `b`'s.
#[inline(always)]
pub fn separation<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    local_a: Vec3<L>,
    local_b: Vec3<L>,
    start: &PairStart<L>,
) -> (Vec3<L>, Vec3<L>, Vec3<L>) {
    let ra = a.q.rotate(local_a);
    let rb = b.q.rotate(local_b);
    (ra, rb, start.separation(a, b, ra, rb))
}

/// Moves `a` and `b` so that their anchors coincide (to first order in the
/// rotations). Returns the separation before the correction (m).
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    local_a: Vec3<L>,
    local_b: Vec3<L>,
    start: &PairStart<L>,
) -> L {
    let (ra, rb, d) = separation(a, b, local_a, local_b, start);
    let (n, c) = d.normalize_or_zero();
    let (resp_a, resp_b) = (a.positional_response(ra, n), b.positional_response(rb, n));
    let dlambda = safe_ratio(-c, resp_a.weight + resp_b.weight);
    b.push(n, &resp_b, dlambda);
    a.push(n, &resp_a, -dlambda);
    c
}
