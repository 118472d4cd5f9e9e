//! Dense symmetric blocks of at most 6 x 6, one per lane, packed by rows
//! of their lower triangle, and their `L D L^T` factorisation: the
//! diagonal blocks of the direct solve (a body's 6 x 6, a joint's rows).
//!
//! A body's block is positive definite (its mass plus what its children
//! add), a joint's negative definite (minus its rows' generalised inverse
//! masses): `L D L^T` with a signed `D` factors both without a square
//! root. A pivot at most [`PIVOT_TOLERANCE`] of its diagonal entry (a row
//! that repeats others, or a row of zeros: a hinge's axes at exactly 180
//! degrees, a rod whose ends meet) is dropped, decided by a select: its
//! row gets no correction, the others stay exact.

use vertebra_math::Lane;

/// The largest block: a body's six degrees of freedom, a fixed joint's
/// six rows.
pub const MAX: usize = 6;

/// Entries of a packed 6 x 6 lower triangle.
pub const PACKED: usize = MAX * (MAX + 1) / 2;

/// A pivot is kept when it exceeds this fraction of its diagonal entry:
/// round-off in `f32` leaves about `1e-7` of a dependent row's entry.
pub const PIVOT_TOLERANCE: f32 = 1.0e-5;

/// The packed index of entry `(i, j)`, `i >= j`.
#[inline(always)]
pub const fn at(i: usize, j: usize) -> usize {
    i * (i + 1) / 2 + j
}

/// Factors the leading `N x N` block of `a` in place: afterwards entry
/// `(i, j)`, `i > j`, holds `L_ij` and entry `(i, i)` holds `1 / D_i` (0
/// for a dropped pivot).
#[inline(always)]
pub fn factor<L: Lane, const N: usize>(a: &mut [L; PACKED]) {
    let n = N;
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let tolerance = L::splat(PIVOT_TOLERANCE);
    let mut pivots = [zero; MAX];
    for j in 0..n {
        let diagonal = a[at(j, j)];
        let mut pivot = diagonal;
        let mut scaled = [zero; MAX];
        for k in 0..j {
            scaled[k] = a[at(j, k)] * pivots[k];
            pivot -= a[at(j, k)] * scaled[k];
        }
        let keep = pivot.abs().gt(tolerance * diagonal.abs());
        let inverse = L::select(keep, one / L::select(keep, pivot, one), zero);
        pivots[j] = L::select(keep, pivot, zero);
        for i in j + 1..n {
            let mut s = a[at(i, j)];
            for k in 0..j {
                s -= a[at(i, k)] * scaled[k];
            }
            a[at(i, j)] = s * inverse;
        }
        a[at(j, j)] = inverse;
    }
}

/// Solves `A x = x` in place with the factors from [`factor`]: forward
/// through `L`, scaled by `D^-1`, back through `L^T`.
#[inline(always)]
pub fn solve<L: Lane, const N: usize>(f: &[L; PACKED], x: &mut [L; MAX]) {
    let n = N;
    forward::<L, N>(f, x);
    for i in 0..n {
        x[i] *= f[at(i, i)];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            x[i] -= f[at(k, i)] * x[k];
        }
    }
}

/// `L^-1 x` in place, forward through the unit lower triangle of the
/// factors from [`factor`]. With `w = L^-1 u` and `v = L^-1 x`,
/// `u^T A^-1 x = w^T D^-1 v`: a Schur complement `J^T A^-1 J` needs only
/// the forward half of each column's solve.
#[inline(always)]
pub fn forward<L: Lane, const N: usize>(f: &[L; PACKED], x: &mut [L; MAX]) {
    for i in 0..N {
        for k in 0..i {
            x[i] -= f[at(i, k)] * x[k];
        }
    }
}
