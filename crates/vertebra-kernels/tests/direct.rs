//! The direct joint solve (`direct`): its dense blocks' `L D L^T` against
//! an f64 reference, every joint row's Jacobian against central finite
//! differences, one pass over small trees exact to first order (with the
//! linear momentum kept), every backend giving the scalar reference's bits,
//! and the topology's elimination order and refusals.

mod common;

use common::{RawRows, assert_backends_agree, flatten, to_rows, unit_quat, vec};
use glam::{DVec3, Mat3, Quat as GQuat, Vec3 as GVec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::{BodyLanes, BodyRows, PairStart, StartLane};
use vertebra_kernels::direct::ldl::{self, MAX, PACKED, at};
use vertebra_kernels::direct::rows::{Geometry, JointRows, Rows};
use vertebra_kernels::direct::{
    BodyNode, JointLane, JointNode, NONE, NodeKind, PositionPass, Topology, TopologyError,
    TreeBlock,
};
use vertebra_math::block::BLOCK_LANES;
use vertebra_math::{Backend, Sym3, Vec3};

// ---------------------------------------------------------------------------
// The dense blocks: `direct::ldl`.
// ---------------------------------------------------------------------------

type Dense = Vec<Vec<f64>>;

fn random_matrix(r: &mut StdRng, n: usize) -> Dense {
    (0..n)
        .map(|_| (0..n).map(|_| r.random_range(-1.0..1.0)).collect())
        .collect()
}

/// `B B^T + shift I`.
fn gram(b: &Dense, shift: f64) -> Dense {
    let n = b.len();
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let dot: f64 = (0..n).map(|k| b[i][k] * b[j][k]).sum();
                    dot + if i == j { shift } else { 0.0 }
                })
                .collect()
        })
        .collect()
}

fn mul(a: &Dense, x: &[f64]) -> Vec<f64> {
    a.iter()
        .map(|row| row.iter().zip(x).map(|(a, x)| a * x).sum())
        .collect()
}

/// Gaussian elimination with partial pivoting, in f64: the reference.
fn reference_solve(a: &Dense, b: &[f64]) -> Vec<f64> {
    let n = a.len();
    let mut m: Dense = a
        .iter()
        .zip(b)
        .map(|(row, &b)| row.iter().copied().chain([b]).collect())
        .collect();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))
            .unwrap();
        m.swap(c, p);
        for i in c + 1..n {
            let f = m[i][c] / m[c][c];
            for k in c..=n {
                m[i][k] -= f * m[c][k];
            }
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|k| m[i][k] * x[k]).sum();
        x[i] = (m[i][n] - s) / m[i][i];
    }
    x
}

/// Factors `a` (its lower triangle, in f32) and solves for `b`; returns the
/// factors and the solution.
fn ldl_solve(a: &Dense, b: &[f64]) -> ([f32; PACKED], Vec<f32>) {
    let n = a.len();
    let mut f = [0.0f32; PACKED];
    for i in 0..n {
        for j in 0..=i {
            f[at(i, j)] = a[i][j] as f32;
        }
    }
    ldl::factor(&mut f, n);
    let mut x = [0.0f32; MAX];
    for (x, b) in x.iter_mut().zip(b) {
        *x = *b as f32;
    }
    ldl::solve(&f, n, &mut x);
    (f, x[..n].to_vec())
}

fn norm(x: impl IntoIterator<Item = f64>) -> f64 {
    x.into_iter().map(|v| v * v).sum::<f64>().sqrt()
}

fn relative_error(x: &[f32], reference: &[f64]) -> f64 {
    norm(x.iter().zip(reference).map(|(&x, &r)| x as f64 - r)) / norm(reference.iter().copied())
}

#[test]
fn ldl_solves_positive_and_negative_definite_blocks_of_every_size() {
    let mut r = StdRng::seed_from_u64(1);
    for n in 1..=MAX {
        for trial in 0..200 {
            // A body's block is positive definite, a joint's negative.
            let sign = if trial % 2 == 0 { 1.0 } else { -1.0 };
            let a: Dense = gram(&random_matrix(&mut r, n), 0.3)
                .into_iter()
                .map(|row| row.into_iter().map(|v| sign * v).collect())
                .collect();
            let b: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
            let expected = reference_solve(&a, &b);
            let (_, x) = ldl_solve(&a, &b);
            let error = relative_error(&x, &expected);
            assert!(
                error < 1e-4,
                "n {n}, sign {sign}: relative error {error:.2e} ({x:?} vs {expected:?})"
            );
        }
    }
}

#[test]
fn ldl_drops_a_row_of_zeros_and_solves_the_others_exactly() {
    let mut r = StdRng::seed_from_u64(2);
    for n in 1..=MAX {
        for zero in 0..n {
            let mut a = gram(&random_matrix(&mut r, n), 0.3);
            for k in 0..n {
                a[zero][k] = 0.0;
                a[k][zero] = 0.0;
            }
            let b: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
            let (f, x) = ldl_solve(&a, &b);
            assert_eq!(f[at(zero, zero)], 0.0, "n {n}: the zero pivot is kept");
            assert_eq!(x[zero], 0.0, "n {n}: the zero row's unknown moved");
            // The others: the system without that row and column.
            if n > 1 {
                let error = relative_error(&x, &solve_without(&a, &b, zero));
                assert!(error < 1e-4, "n {n}, zero row {zero}: error {error:.2e}");
            }
        }
    }
}

#[test]
fn ldl_drops_the_later_of_two_equal_rows_and_still_solves_a_consistent_system() {
    // Two joints' rows that repeat each other (a hinge at 180 degrees, a
    // rod whose ends meet) make `J M^-1 J^T` singular: the later pivot is
    // round-off, dropped, its unknown zero, and the system still solved.
    let mut r = StdRng::seed_from_u64(3);
    for n in 2..=MAX {
        for _ in 0..100 {
            let first = r.random_range(0..n - 1);
            let second = r.random_range(first + 1..n);
            let mut b = random_matrix(&mut r, n);
            for (k, row) in b.iter_mut().enumerate() {
                row[k] += 2.0;
            }
            b[second] = b[first].clone();
            let a = gram(&b, 0.0);
            let x0: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
            let rhs = mul(&a, &x0);
            let (f, x) = ldl_solve(&a, &rhs);
            assert!(x.iter().all(|v| v.is_finite()), "n {n}: {x:?}");
            assert_eq!(f[at(second, second)], 0.0, "n {n}: dependent pivot kept");
            assert_eq!(x[second], 0.0, "n {n}: the repeated row's unknown moved");
            let x64: Vec<f64> = x.iter().map(|&v| v as f64).collect();
            let residual = norm(mul(&a, &x64).iter().zip(&rhs).map(|(a, b)| a - b));
            assert!(
                residual < 1e-4 * norm(rhs.iter().copied()),
                "n {n}: residual {residual:.2e}"
            );
        }
    }
}

/// The reduced system without row and column `drop`, solved in f64.
fn solve_without(a: &Dense, b: &[f64], drop: usize) -> Vec<f64> {
    let keep: Vec<usize> = (0..a.len()).filter(|&k| k != drop).collect();
    let reduced: Dense = keep
        .iter()
        .map(|&i| keep.iter().map(|&j| a[i][j]).collect())
        .collect();
    let rb: Vec<f64> = keep.iter().map(|&i| b[i]).collect();
    let mut x = reference_solve(&reduced, &rb);
    x.insert(drop, 0.0);
    x
}

/// What NaN does. A NaN on the diagonal is never a pivot (the comparison
/// that keeps one is false for NaN), so its `1/D` is exactly 0 and the
/// entries of `L` below it `finite * 0`: the row is dropped as a zero row
/// is, and the others are solved without it, finite. A NaN off the
/// diagonal enters `L` itself and reaches every unknown: the blocks do
/// not launder NaN, so the world must keep it out of the rows.
#[test]
fn ldl_drops_a_nan_pivot_but_spreads_a_nan_coupling_to_every_unknown() {
    let mut r = StdRng::seed_from_u64(4);
    for n in 2..=MAX {
        let a = gram(&random_matrix(&mut r, n), 0.3);
        let b: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
        for nan in 0..n {
            let mut poisoned = a.clone();
            poisoned[nan][nan] = f64::NAN;
            let (f, x) = ldl_solve(&poisoned, &b);
            assert_eq!(f[at(nan, nan)], 0.0, "n {n}: a NaN pivot was kept");
            assert!(x.iter().all(|v| v.is_finite()), "n {n}: {x:?}");
            let error = relative_error(&x, &solve_without(&a, &b, nan));
            assert!(error < 1e-4, "n {n}, NaN pivot {nan}: error {error:.2e}");
        }
        let i = r.random_range(1..n);
        let mut poisoned = a.clone();
        poisoned[i][r.random_range(0..i)] = f64::NAN;
        let (_, x) = ldl_solve(&poisoned, &b);
        assert!(x.iter().all(|v| v.is_nan()), "n {n}: {x:?}");
    }
}
