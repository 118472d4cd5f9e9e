//! Dense symmetric blocks of at most 9 x 9, one per lane, packed by rows
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
//!
//! **Held rows.** A joint's first `E` rows are always there (its equality
//! parts); its last `K` (its limits) only where a lane holds them
//! ([`Held`]). A row no lane of a slice holds is skipped outright; a row
//! some lanes hold is computed in all, and in a lane that does not hold
//! it every value it leaves (its row and column of `L`, its pivot, its
//! entry of a solved vector) is `+0`. Every later use of those values
//! subtracts their product, and `x - (+0) = x` for every `x` (signed
//! zeros included), so such a lane gets the bits it would get without the
//! row: a lane's result never depends on what its slice's other lanes
//! hold (every backend, bit for bit).

use vertebra_math::Lane;

/// The largest block: a pyramid socket's nine rows (its point, two swing
/// rows, its twist and its drive's three).
pub const MAX: usize = 9;

/// Entries of a packed 9 x 9 lower triangle.
pub const PACKED: usize = MAX * (MAX + 1) / 2;

/// A pivot is kept when it exceeds this fraction of its diagonal entry:
/// round-off in `f32` leaves about `1e-7` of a dependent row's entry.
pub const PIVOT_TOLERANCE: f32 = 1.0e-5;

/// The packed index of entry `(i, j)`, `i >= j`.
#[inline(always)]
pub const fn at(i: usize, j: usize) -> usize {
    i * (i + 1) / 2 + j
}

/// Which of a block's `K` last rows each lane holds (`lanes`), and
/// whether any lane of the slice does (`any`: else the row is skipped).
#[derive(Clone, Copy)]
pub struct Held<L: Lane, const K: usize> {
    /// The lanes that hold each row.
    pub lanes: [L::Mask; K],
    /// Some lane of the slice holds the row.
    pub any: [bool; K],
}

impl<L: Lane, const K: usize> Held<L, K> {
    /// Every row held (a block with no optional rows: `K = 0`).
    #[inline(always)]
    pub fn all() -> Self {
        let zero = L::splat(0.0);
        Self {
            lanes: [zero.eq(zero); K],
            any: [true; K],
        }
    }

    /// Whether row `i` of a block of `e` always-held rows is computed.
    #[inline(always)]
    pub fn computed(&self, e: usize, i: usize) -> bool {
        i < e || self.any[i - e]
    }

    /// `value` where row `i` is held (`i >= e`), else `+0`; always
    /// `value` for `i < e`.
    #[inline(always)]
    pub fn keep(&self, e: usize, i: usize, value: L) -> L {
        if i < e {
            value
        } else {
            L::select(self.lanes[i - e], value, L::splat(0.0))
        }
    }
}

/// Factors the leading `N x N` block of `a` in place, every row held:
/// [`factor_held`] with no optional rows.
#[inline(always)]
pub fn factor<L: Lane, const N: usize>(a: &mut [L; PACKED]) {
    factor_held::<L, N, 0>(a, &Held::all());
}

/// Factors the leading `(E + K) x (E + K)` block of `a` in place, row by
/// row (each row's `L` from a forward solve against the rows above):
/// afterwards entry `(i, j)`, `i > j`, holds `L_ij` and entry `(i, i)`
/// holds `1 / D_i` (0 for a dropped pivot, `+0` for a row not held).
#[inline(always)]
pub fn factor_held<L: Lane, const E: usize, const K: usize>(
    a: &mut [L; PACKED],
    held: &Held<L, K>,
) {
    let n = E + K;
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let tolerance = L::splat(PIVOT_TOLERANCE);
    for i in 0..n {
        if !held.computed(E, i) {
            continue;
        }
        // `D_k L_ik` of the row being factored.
        let mut scaled = [zero; MAX];
        for k in 0..i {
            if !held.computed(E, k) {
                continue;
            }
            let mut s = a[at(i, k)];
            for t in 0..k {
                if held.computed(E, t) {
                    s -= a[at(k, t)] * scaled[t];
                }
            }
            scaled[k] = held.keep(E, k, held.keep(E, i, s));
        }
        let mut pivot = a[at(i, i)];
        for k in 0..i {
            if held.computed(E, k) {
                let l = held.keep(E, k, held.keep(E, i, scaled[k] * a[at(k, k)]));
                pivot -= l * scaled[k];
                a[at(i, k)] = l;
            }
        }
        let keep = pivot.abs().gt(tolerance * a[at(i, i)].abs());
        let inverse = L::select(keep, one / L::select(keep, pivot, one), zero);
        a[at(i, i)] = held.keep(E, i, inverse);
    }
}

/// `L^-1 x` in place, forward through the unit lower triangle of the
/// factors from [`factor_held`] (a row not held left `+0`). With
/// `w = L^-1 u` and `v = L^-1 x`, `u^T A^-1 x = w^T D^-1 v`: a Schur
/// complement `J^T A^-1 J` needs only the forward half of each column's
/// solve.
#[inline(always)]
pub fn forward_held<L: Lane, const E: usize, const K: usize>(
    f: &[L; PACKED],
    x: &mut [L; MAX],
    held: &Held<L, K>,
) {
    for i in 0..E + K {
        if !held.computed(E, i) {
            continue;
        }
        for k in 0..i {
            if held.computed(E, k) {
                x[i] -= f[at(i, k)] * x[k];
            }
        }
        x[i] = held.keep(E, i, x[i]);
    }
}

/// Solves `A x = x` in place with the factors from [`factor_held`]:
/// forward through `L`, scaled by `D^-1`, back through `L^T` (a row not
/// held gets `+0`).
#[inline(always)]
pub fn solve_held<L: Lane, const E: usize, const K: usize>(
    f: &[L; PACKED],
    x: &mut [L; MAX],
    held: &Held<L, K>,
) {
    let n = E + K;
    forward_held::<L, E, K>(f, x, held);
    for i in 0..n {
        if held.computed(E, i) {
            x[i] *= f[at(i, i)];
        }
    }
    for i in (0..n).rev() {
        if !held.computed(E, i) {
            continue;
        }
        for k in i + 1..n {
            if held.computed(E, k) {
                x[i] -= f[at(k, i)] * x[k];
            }
        }
    }
}

/// Solves `A x = x` in place, every row held ([`solve_held`]).
#[inline(always)]
pub fn solve<L: Lane, const N: usize>(f: &[L; PACKED], x: &mut [L; MAX]) {
    solve_held::<L, N, 0>(f, x, &Held::all());
}

/// `L^-1 x` in place, every row held ([`forward_held`]).
#[inline(always)]
pub fn forward<L: Lane, const N: usize>(f: &[L; PACKED], x: &mut [L; MAX]) {
    forward_held::<L, N, 0>(f, x, &Held::all());
}

/// A mask's lanes as bits (bit `k`: lane `k` of the slice).
#[inline(always)]
pub fn mask_bits<L: Lane>(mask: L::Mask) -> u8 {
    let mut lanes = [0.0f32; vertebra_math::block::BLOCK_LANES];
    L::select(mask, L::splat(1.0), L::splat(0.0)).store(&mut lanes);
    let mut bits = 0u8;
    for (k, lane) in lanes[..L::WIDTH].iter().enumerate() {
        bits |= u8::from(*lane != 0.0) << k;
    }
    bits
}
