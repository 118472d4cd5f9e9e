//! The direct joint solve (`direct`): its dense blocks' `L D L^T` against
//! an f64 reference, every joint row's Jacobian against central finite
//! differences, one pass over small trees exact to first order (with the
//! linear momentum kept), every backend giving the scalar reference's bits,
//! and the topology's elimination order and refusals.

mod common;

use common::{RawRows, flatten, moved, to_rows, turned, unit_quat, vec};
use glam::{DVec3, Mat3, Quat as GQuat, Vec3 as GVec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::{BodyLanes, BodyRows, PairStart, StartLane};
use vertebra_kernels::direct::ldl::{self, MAX, PACKED, at};
use vertebra_kernels::direct::rows::{Geometry, JointRows, Rows, SwingRows};
use vertebra_kernels::direct::{
    JointLane, NONE, NodeKind, PositionPass, SubstepScale, Topology, TopologyError, TreeBlock,
};
use vertebra_kernels::limited::LimitLane;
use vertebra_kernels::parts::limit::Softness;
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
        let pivot = m[c].clone();
        for row in &mut m[c + 1..] {
            let f = row[c] / pivot[c];
            for (v, p) in row.iter_mut().zip(&pivot).skip(c) {
                *v -= f * p;
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
    factor_n(&mut f, n);
    let mut x = [0.0f32; MAX];
    for (x, b) in x.iter_mut().zip(b) {
        *x = *b as f32;
    }
    solve_n(&f, n, &mut x);
    (f, x[..n].to_vec())
}

/// `ldl::factor` at a size known only at run time.
fn factor_n(f: &mut [f32; PACKED], n: usize) {
    match n {
        1 => ldl::factor::<f32, 1>(f),
        2 => ldl::factor::<f32, 2>(f),
        3 => ldl::factor::<f32, 3>(f),
        4 => ldl::factor::<f32, 4>(f),
        5 => ldl::factor::<f32, 5>(f),
        _ => ldl::factor::<f32, 6>(f),
    }
}

/// `ldl::solve` at a size known only at run time.
fn solve_n(f: &[f32; PACKED], n: usize, x: &mut [f32; MAX]) {
    match n {
        1 => ldl::solve::<f32, 1>(f, x),
        2 => ldl::solve::<f32, 2>(f, x),
        3 => ldl::solve::<f32, 3>(f, x),
        4 => ldl::solve::<f32, 4>(f, x),
        5 => ldl::solve::<f32, 5>(f, x),
        _ => ldl::solve::<f32, 6>(f, x),
    }
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
            a[zero].fill(0.0);
            for row in &mut a {
                row[zero] = 0.0;
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

// ---------------------------------------------------------------------------
// Every row's Jacobian: `direct::rows` against central finite differences.
// ---------------------------------------------------------------------------

fn unit(r: &mut StdRng) -> GVec3 {
    vec(r, 1.0).normalize_or(GVec3::X)
}

fn lanes(p: GVec3, q: GQuat) -> BodyLanes<f32> {
    BodyLanes {
        p: p.into(),
        inv_mass: 1.0,
        q: q.into(),
        inv_inertia: Sym3::diagonal(Vec3::splat(GVec3::ONE)),
    }
}

fn pair_start(s: &StartLane) -> PairStart<f32> {
    PairStart {
        gap: s.gap.into(),
        arm_a: s.arm_a.into(),
        arm_b: s.arm_b.into(),
    }
}

/// A joint as `Rows::measure` sees it.
struct Measured {
    kind: JointRows,
    a: BodyLanes<f32>,
    b: BodyLanes<f32>,
    g: Geometry<f32>,
}

/// The 12 coordinates `(p_a, theta_a, p_b, theta_b)` (world).
const COORDINATES: usize = 12;
const LINEAR: [usize; 6] = [0, 1, 2, 6, 7, 8];
const ANGULAR: [usize; 6] = [3, 4, 5, 9, 10, 11];

impl Measured {
    fn rows(&self) -> Rows<f32> {
        Rows::measure(self.kind, &self.a, &self.b, &self.g)
    }

    /// The analytic Jacobian, row by row over the 12 coordinates.
    fn analytic(&self) -> [[f64; COORDINATES]; MAX] {
        let rows = self.rows();
        let mut out = [[0.0; COORDINATES]; MAX];
        for (k, row) in out.iter_mut().enumerate() {
            for c in 0..6 {
                row[c] = rows.ja[k][c] as f64;
                row[6 + c] = rows.jb[k][c] as f64;
            }
        }
        out
    }

    /// Central differences of every row, the rotations applied exactly.
    fn numeric(&self) -> [[f64; COORDINATES]; MAX] {
        let h = 1e-3f32;
        let mut out = [[0.0; COORDINATES]; MAX];
        for coordinate in 0..COORDINATES {
            let e = GVec3::AXES[coordinate % 3];
            let c = |s: f32| {
                let v = e * (s * h);
                let (mut a, mut b) = (self.a, self.b);
                let body = if coordinate < 6 { &mut a } else { &mut b };
                *body = if (coordinate / 3) % 2 == 0 {
                    moved(*body, v)
                } else {
                    turned(*body, v)
                };
                Rows::measure(self.kind, &a, &b, &self.g).c
            };
            let (plus, minus) = (c(1.0), c(-1.0));
            for (k, row) in out.iter_mut().enumerate() {
                row[coordinate] = (plus[k] as f64 - minus[k] as f64) / (2.0 * h as f64);
            }
        }
        out
    }

    /// The largest difference between the analytic and the numeric
    /// Jacobian over rows `rows` and the coordinates `coordinates`.
    fn deviation(&self, rows: core::ops::Range<usize>, coordinates: &[usize]) -> f64 {
        let (analytic, numeric) = (self.analytic(), self.numeric());
        let mut worst = 0.0f64;
        for k in rows {
            for &c in coordinates {
                worst = worst.max((analytic[k][c] - numeric[k][c]).abs());
            }
        }
        worst
    }

    /// The largest error over rows `rows`: a limit row's violation (its
    /// signed distance where positive, else 0), any other's size.
    fn error(&self, rows: core::ops::Range<usize>) -> f64 {
        let c = self.rows().c;
        rows.map(|k| match self.kind.is_limit(k) {
            true => (c[k] as f64).max(0.0),
            false => (c[k] as f64).abs(),
        })
        .fold(0.0, f64::max)
    }

    /// Along the step `dx = -J^T C` of the analytic Jacobian over rows
    /// `rows` (gradient descent on `|C|^2 / 2` with unit masses), the true
    /// first-order change of `|C|^2 / 2` (numeric `J`) over the predicted
    /// one: 1 for an exact Jacobian, positive for a descent direction.
    fn descent(&self, rows: core::ops::Range<usize>) -> f64 {
        let (analytic, numeric) = (self.analytic(), self.numeric());
        let c = self.rows().c;
        let mut dx = [0.0f64; COORDINATES];
        for k in rows.clone() {
            for (d, j) in dx.iter_mut().zip(&analytic[k]) {
                *d -= j * c[k] as f64;
            }
        }
        let change = |j: &[[f64; COORDINATES]; MAX]| -> f64 {
            rows.clone()
                .map(|k| c[k] as f64 * j[k].iter().zip(&dx).map(|(j, d)| j * d).sum::<f64>())
                .sum()
        };
        change(&numeric) / change(&analytic)
    }
}

/// Random bodies (up to 1 m from the origin, any orientation) and a random
/// start of step.
fn random_bodies(r: &mut StdRng) -> (BodyLanes<f32>, BodyLanes<f32>) {
    (
        lanes(vec(r, 1.0), unit_quat(r)),
        lanes(vec(r, 1.0), unit_quat(r)),
    )
}

/// A point, hinge or fixed joint whose frames (world) are `frame` on a
/// and `misalignment frame` on b, with random anchors and start: the point
/// rows are exact everywhere, so the anchors need not meet.
fn joint(r: &mut StdRng, kind: JointRows, misalignment: GQuat) -> Measured {
    let (a, b) = random_bodies(r);
    let (qa, qb) = (GQuat::from(a.q), GQuat::from(b.q));
    let frame = unit_quat(r);
    let start = common::start(r, false);
    Measured {
        kind,
        a,
        b,
        g: Geometry {
            anchor_a: vec(r, 0.5).into(),
            anchor_b: vec(r, 0.5).into(),
            frame_a: (qa.inverse() * frame).into(),
            frame_b: (qb.inverse() * misalignment * frame).into(),
            rest_length: 0.0,
            swing_max: core::f32::consts::PI,
            twist: [-core::f32::consts::PI, core::f32::consts::PI],
            ellipse: [1.0, 1.0],
            pyramid: [[-core::f32::consts::PI, core::f32::consts::PI]; 2],
            softness: Softness::hard(),
            start: pair_start(&start),
        },
    }
}

/// A rod on its arc, its ends `distance` apart, a's tangent at `bend`
/// (rad) from the chord (0: straight), then b's frame turned by
/// `misalignment` (world).
fn rod(r: &mut StdRng, distance: f32, bend: f32, misalignment: GQuat) -> Measured {
    let (a, mut b) = random_bodies(r);
    let o = unit(r);
    b.p = (GVec3::from(a.p) + o * distance).into();
    let (qa, qb) = (GQuat::from(a.q), GQuat::from(b.q));
    // a's tangent `bend` from o; b's the reflection of a's about o.
    let side = o.any_orthonormal_vector();
    let ta = GQuat::from_axis_angle(side, bend) * o;
    let frame_a =
        GQuat::from_rotation_arc(GVec3::X, ta) * GQuat::from_rotation_x(r.random_range(-3.0..3.0));
    let reflected = 2.0 * ta.dot(o) * o - ta;
    let frame_b = misalignment * GQuat::from_rotation_arc(ta, reflected) * frame_a;
    let psi = ta.angle_between(reflected);
    let rest_length = if psi > 0.0 {
        distance * psi / (2.0 * (psi / 2.0).sin())
    } else {
        distance
    };
    Measured {
        kind: JointRows::Rod,
        a,
        b,
        g: Geometry {
            anchor_a: Vec3::zero(),
            anchor_b: Vec3::zero(),
            frame_a: (qa.inverse() * frame_a).into(),
            frame_b: (qb.inverse() * frame_b).into(),
            rest_length,
            swing_max: core::f32::consts::PI,
            twist: [-core::f32::consts::PI, core::f32::consts::PI],
            ellipse: [1.0, 1.0],
            pyramid: [[-core::f32::consts::PI, core::f32::consts::PI]; 2],
            softness: Softness::hard(),
            // The rows' displacements measured from the origin: no gap.
            start: pair_start(&StartLane::default()),
        },
    }
}

/// A random rotation by `angle` (rad).
fn turn(r: &mut StdRng, angle: f32) -> GQuat {
    GQuat::from_axis_angle(unit(r), angle)
}

#[test]
fn point_rows_are_exact_gradients_everywhere() {
    let mut r = StdRng::seed_from_u64(10);
    for kind in [
        JointRows::Socket(SwingRows::Cone),
        JointRows::Hinge,
        JointRows::Fixed,
    ] {
        for _ in 0..200 {
            let angle = r.random_range(0.0..3.0);
            let misalignment = turn(&mut r, angle);
            let m = joint(&mut r, kind, misalignment);
            let all: Vec<usize> = (0..COORDINATES).collect();
            let deviation = m.deviation(0..3, &all);
            assert!(
                deviation < 1e-3,
                "{kind:?} point rows: deviation {deviation:.2e}"
            );
        }
    }
}

/// Rows exact only at zero error (the hinge axis, the lock, the rod's
/// curve): near it, misaligned by 1e-3 to 1e-2 rad, the analytic Jacobian
/// is the numeric one to first order in the error, `|J - J_num| <= k |C|`
/// plus the differences' own error (`2e-3`: `f32` rows over `2h = 2e-3`).
/// Measured over 2000 joints: `k` is 1/2 for the hinge and the lock (the
/// rotation vector's `[C]x / 2`), 1/2 to 1 for the curve (its positional
/// part taken times half the chord). Beyond (0.1 to 2.5 rad), `J` is no longer the gradient
/// (the same `k |C|`, growing toward pi), but the step `-J^T C` still lowers
/// `|C|^2` at the rate the rows predict, to within 10% (measured: 1%).
fn check_first_order(name: &str, m: &Measured, rows: core::ops::Range<usize>, scale: f64, k: f64) {
    let error = m.error(rows.clone());
    let angular = m.deviation(rows.clone(), &ANGULAR);
    let linear = m.deviation(rows.clone(), &LINEAR) / scale;
    let bound = 2e-3 + k * error;
    assert!(
        angular <= bound && linear <= bound,
        "{name}: error {error:.2e}, deviation angular {angular:.2e}, linear {linear:.2e} \
         x chord/2 (bound {bound:.2e})"
    );
}

fn check_descent(name: &str, m: &Measured, rows: core::ops::Range<usize>) {
    let descent = m.descent(rows);
    assert!(
        (0.9..=1.1).contains(&descent),
        "{name}: the rows' step lowers |C|^2 at {descent:.3} of the predicted rate"
    );
}

/// A rod's chord `d`, and the scale of its curve rows' positional part
/// (`2 / d`, at least 1).
fn chord_scale(d: f32) -> f64 {
    (2.0 / d as f64).max(1.0)
}

#[test]
fn hinge_axis_lock_and_curve_rows_are_gradients_at_zero_error_and_first_order_beyond() {
    let mut r = StdRng::seed_from_u64(11);
    for small in [true, false] {
        for _ in 0..300 {
            let angle = if small {
                r.random_range(1e-3..1e-2)
            } else {
                r.random_range(0.1..2.5)
            };
            let misalignment = turn(&mut r, angle);
            let hinge = joint(&mut r, JointRows::Hinge, misalignment);
            let fixed = joint(&mut r, JointRows::Fixed, misalignment);
            let d = r.random_range(0.2..1.0);
            let bend = r.random_range(0.0..1.5);
            let rod = rod(&mut r, d, bend, misalignment);
            if small {
                check_first_order("hinge axis", &hinge, 3..5, 1.0, 0.6);
                check_first_order("lock", &fixed, 3..6, 1.0, 0.6);
                check_first_order("curve", &rod, 0..2, chord_scale(d), 1.2);
            } else {
                check_descent("hinge axis", &hinge, 3..5);
                check_descent("lock", &fixed, 3..6);
                check_descent("curve", &rod, 0..2);
            }
        }
    }
}

/// The curve's two rows span the plane normal to `r + t_b` from a hint
/// that must not lie in that normal. A rod bent 90 degrees in its frame's
/// XY plane has `r` (a's tangent reflected about the chord) along a's own
/// +Y: with a's +Y as the hint the plane's axes came from round-off, and
/// neither row was the gradient of its error (nor, where the round-off
/// left the hint along `s`, held the curve at all).
#[test]
fn curve_rows_stay_gradients_for_a_rod_bent_a_right_angle_in_its_frame_plane() {
    let mut r = StdRng::seed_from_u64(12);
    for _ in 0..100 {
        let q = unit_quat(&mut r);
        let d = r.random_range(0.2..1.0f32);
        // In a's frame: t_a = +X, the chord at 45 degrees in XY, so the
        // reflection of t_a about it is +Y.
        let o = q * GVec3::new(1.0, 1.0, 0.0).normalize();
        let angle = r.random_range(0.0..1e-2);
        let misalignment = turn(&mut r, angle);
        let a = lanes(vec(&mut r, 1.0), q);
        let b = lanes(GVec3::from(a.p) + o * d, unit_quat(&mut r));
        let frame_b = misalignment * q * GQuat::from_rotation_z(core::f32::consts::FRAC_PI_2);
        let rod = Measured {
            kind: JointRows::Rod,
            a,
            b,
            g: Geometry {
                anchor_a: Vec3::zero(),
                anchor_b: Vec3::zero(),
                frame_a: GQuat::IDENTITY.into(),
                frame_b: (GQuat::from(b.q).inverse() * frame_b).into(),
                rest_length: d * core::f32::consts::FRAC_PI_2
                    / (2.0 * core::f32::consts::FRAC_PI_4.sin()),
                swing_max: core::f32::consts::PI,
                twist: [-core::f32::consts::PI, core::f32::consts::PI],
                ellipse: [1.0, 1.0],
                pyramid: [[-core::f32::consts::PI, core::f32::consts::PI]; 2],
                softness: Softness::hard(),
                start: pair_start(&StartLane::default()),
            },
        };
        check_first_order("curve bent 90 degrees", &rod, 0..2, chord_scale(d), 1.2);
    }
}

/// The rod's length row, `C = |d| - chord(l0, psi)`, is corrected as the
/// paper does, "purely through linear motion" (`J = [-o, 0 | o, 0]`): its
/// positional part is the exact gradient at any configuration, its angular
/// part is zero by design. The true angular gradient, `-chord'(psi)
/// dpsi/dtheta`, vanishes for a straight rod (`chord` is even in `psi`),
/// so there the row is first-order exact and the direct solve converges
/// quadratically; for a bent rod it does not, and the length converges
/// only linearly (`bent_rods_converge_over_a_few_passes`).
#[test]
fn rod_length_row_is_the_gradient_of_its_linear_part_and_drops_the_bend() {
    let mut r = StdRng::seed_from_u64(13);
    for _ in 0..300 {
        let d = r.random_range(0.2..1.0);
        let (bend, angle) = (r.random_range(0.0..1.5), r.random_range(0.0..2.5));
        let misalignment = turn(&mut r, angle);
        let mut rod = rod(&mut r, d, bend, misalignment);
        rod.g.rest_length *= r.random_range(0.5..2.0);
        let deviation = rod.deviation(2..3, &LINEAR);
        assert!(
            deviation < 1e-3,
            "length row / p: deviation {deviation:.2e}"
        );
        let analytic = rod.analytic()[2];
        assert!(ANGULAR.iter().all(|&c| analytic[c] == 0.0));
    }
    for _ in 0..100 {
        let d = r.random_range(0.2..1.0);
        let angle = r.random_range(0.0..1e-2);
        let misalignment = turn(&mut r, angle);
        let straight = rod(&mut r, d, 0.0, misalignment);
        let left_out = straight.deviation(2..3, &ANGULAR);
        assert!(
            left_out < 2e-3 + d as f64 * angle as f64,
            "straight rod: the length row's angular gradient is {left_out:.2e}"
        );
        let bend = r.random_range(0.5..1.5);
        let bent = rod(&mut r, d, bend, misalignment);
        let left_out = bent.deviation(2..3, &ANGULAR);
        assert!(
            left_out > 0.02 * d as f64,
            "bent rod: the length row's angular gradient is only {left_out:.2e}"
        );
    }
}

// ---------------------------------------------------------------------------
// Trees: `direct::PositionPass`.
// ---------------------------------------------------------------------------

#[derive(Clone, Debug)]
struct Body {
    /// Coordinates at the start of the step (m, world).
    x: DVec3,
    q: GQuat,
    mass: f32,
    /// Body frame (kg m^2).
    inertia: Mat3,
}

#[derive(Clone, Debug)]
struct Joint {
    kind: JointRows,
    a: Option<usize>,
    b: Option<usize>,
    anchor_a: GVec3,
    anchor_b: GVec3,
    frame_a: GQuat,
    frame_b: GQuat,
    rest_length: f32,
    start: StartLane,
}

/// Bodies and joints, the joints built satisfied at the bodies' start
/// pose; a joint with a side `None` holds to the static `ground`.
#[derive(Clone, Debug)]
struct Tree {
    bodies: Vec<Body>,
    joints: Vec<Joint>,
    ground: (DVec3, GQuat),
}

/// `10^u`, `u` uniform in `[lo, hi)`.
fn log_uniform(r: &mut StdRng, lo: f32, hi: f32) -> f32 {
    10f32.powf(r.random_range(lo..hi))
}

fn body_at(r: &mut StdRng, x: DVec3, mass: f32) -> Body {
    let turn = Mat3::from_quat(unit_quat(r));
    let shape = GVec3::new(
        r.random_range(0.005..0.05),
        r.random_range(0.005..0.05),
        r.random_range(0.005..0.05),
    );
    Body {
        x,
        q: unit_quat(r),
        mass,
        inertia: turn * Mat3::from_diagonal(shape * mass) * turn.transpose(),
    }
}

impl Tree {
    fn new() -> Self {
        Self {
            bodies: Vec::new(),
            joints: Vec::new(),
            ground: (DVec3::new(0.1, 0.2, -0.3), GQuat::from_rotation_y(0.4)),
        }
    }

    fn pose(&self, side: Option<usize>) -> (DVec3, GQuat) {
        side.map_or(self.ground, |i| (self.bodies[i].x, self.bodies[i].q))
    }

    /// Joins `a` and `b` by a joint of `kind` satisfied as they stand: at
    /// `point` with the world frame `frame`; a rod between the centres,
    /// a's tangent along `frame`'s +X, b's its reflection about the chord,
    /// its rest length the arc's (straight when `frame`'s +X is the chord).
    fn join(
        &mut self,
        kind: JointRows,
        a: Option<usize>,
        b: Option<usize>,
        point: DVec3,
        frame: GQuat,
    ) {
        let ((xa, qa), (xb, qb)) = (self.pose(a), self.pose(b));
        let (anchor_a, anchor_b, frame_b, rest_length) = if kind == JointRows::Rod {
            let chord = (xb - xa).as_vec3();
            let o = chord.normalize();
            let ta = frame * GVec3::X;
            let reflected = 2.0 * ta.dot(o) * o - ta;
            let psi = ta.angle_between(reflected);
            let arc = if psi > 1e-6 {
                psi / (2.0 * (psi / 2.0).sin())
            } else {
                1.0
            };
            let frame_b = GQuat::from_rotation_arc(ta, reflected) * frame;
            (GVec3::ZERO, GVec3::ZERO, frame_b, chord.length() * arc)
        } else {
            let local = |x: DVec3, q: GQuat| q.inverse() * (point - x).as_vec3();
            (local(xa, qa), local(xb, qb), frame, 0.0)
        };
        self.joints.push(Joint {
            kind,
            a,
            b,
            anchor_a,
            anchor_b,
            frame_a: qa.inverse() * frame,
            frame_b: qb.inverse() * frame_b,
            rest_length,
            start: StartLane::new(xa, qa, anchor_a, xb, qb, anchor_b),
        });
    }

    /// A joint of `kind` between `a` and `b` at the midpoint of their
    /// centres; a rod's straight, the others' frame at random.
    fn link(&mut self, r: &mut StdRng, kind: JointRows, a: Option<usize>, b: Option<usize>) {
        let ((xa, _), (xb, _)) = (self.pose(a), self.pose(b));
        let frame = if kind == JointRows::Rod {
            let o = (xb - xa).as_vec3().normalize();
            GQuat::from_rotation_arc(GVec3::X, o)
                * GQuat::from_rotation_x(r.random_range(-3.0..3.0))
        } else {
            unit_quat(r)
        };
        self.join(kind, a, b, (xa + xb) * 0.5, frame);
    }

    fn topology(&self) -> Topology {
        let joints: Vec<_> = self
            .joints
            .iter()
            .map(|j| (j.kind, j.a.map(|i| i as u32), j.b.map(|i| i as u32)))
            .collect();
        Topology::new(self.bodies.len(), &joints).expect("a tree")
    }
}

/// Six bodies hanging 0.3 m apart below a static anchor, masses
/// alternating 0.05 and 50 kg, each joined to the one above by `kinds`
/// in turn.
fn hanging_chain(r: &mut StdRng, kinds: &[JointRows]) -> Tree {
    let mut tree = Tree::new();
    let mut above = tree.ground.0;
    for i in 0..6 {
        let x = above + DVec3::new(0.0, -0.3, 0.0) + vec(r, 0.05).as_dvec3();
        let mass = if i % 2 == 0 { 0.05 } else { 50.0 };
        tree.bodies.push(body_at(r, x, mass));
        let a = if i == 0 { None } else { Some(i - 1) };
        tree.link(r, kinds[i % kinds.len()], a, Some(i));
        above = x;
    }
    tree
}

/// A humanoid-like star, free: a 10 kg root and four chains of three
/// bodies (0.01 to 10 kg), each chain's joints every kind in turn.
fn star(r: &mut StdRng) -> Tree {
    const KINDS: [JointRows; 4] = [
        JointRows::Hinge,
        JointRows::Fixed,
        JointRows::Rod,
        JointRows::Socket(SwingRows::Cone),
    ];
    let mut tree = Tree::new();
    tree.bodies.push(body_at(r, DVec3::ZERO, 10.0));
    let directions = [DVec3::X, -DVec3::X, DVec3::NEG_Y, DVec3::Y];
    for (c, direction) in directions.into_iter().enumerate() {
        let mut previous = 0;
        for k in 0..3 {
            let x = direction * (0.3 * (k + 1) as f64) + vec(r, 0.05).as_dvec3();
            let mass = log_uniform(r, -2.0, 1.0);
            tree.bodies.push(body_at(r, x, mass));
            let index = tree.bodies.len() - 1;
            tree.link(r, KINDS[(c + k) % 4], Some(previous), Some(index));
            previous = index;
        }
    }
    tree
}

/// Each body's offset from its start pose: displacement (m) and world
/// rotation vector (rad).
type Offsets = Vec<(GVec3, GVec3)>;

fn offsets(r: &mut StdRng, tree: &Tree, size: f32) -> Offsets {
    tree.bodies
        .iter()
        .map(|_| (vec(r, size), vec(r, size)))
        .collect()
}

/// One tree in lane 0 of a block: body `i` at row `1 + i`, the ground
/// after the bodies.
struct Scene {
    tree: Tree,
    topology: Topology,
}

impl Scene {
    fn new(tree: &Tree) -> Self {
        Self {
            tree: tree.clone(),
            topology: tree.topology(),
        }
    }

    fn side_row(&self, side: Option<usize>) -> u32 {
        (1 + side.unwrap_or(self.tree.bodies.len())) as u32
    }

    /// The rows, each body offset from its start pose by `offsets`.
    fn rows(&self, offsets: &Offsets) -> BodyRows {
        let mut raw = vec![BodyRows::null_raw(); self.tree.bodies.len() + 2];
        for (i, (body, &(dp, dtheta))) in self.tree.bodies.iter().zip(offsets).enumerate() {
            let q = GQuat::from_scaled_axis(dtheta) * body.q;
            raw[1 + i] = [
                BodyRows::pose_row(dp, 1.0 / body.mass, q),
                BodyRows::inertia_row(body.inertia.inverse()),
                BodyRows::velocity_row(GVec3::ZERO, GVec3::ZERO),
            ];
        }
        raw[self.side_row(None) as usize][0] =
            BodyRows::pose_row(GVec3::ZERO, 0.0, self.tree.ground.1);
        to_rows(&raw)
    }

    fn block(&self) -> TreeBlock {
        let mut block = TreeBlock::padding(0, &self.topology);
        block.padding &= !1;
        for (i, body) in self.tree.bodies.iter().enumerate() {
            block.bodies[i].set(0, self.side_row(Some(i)), true, body.mass, body.inertia);
        }
        for (node, j) in block.joints.iter_mut().zip(&self.tree.joints) {
            node.set(
                0,
                &JointLane {
                    body_a: self.side_row(j.a),
                    body_b: self.side_row(j.b),
                    anchor_a: j.anchor_a,
                    anchor_b: j.anchor_b,
                    frame_a: j.frame_a,
                    frame_b: j.frame_b,
                    rest_length: j.rest_length,
                    ..JointLane::FREE
                },
            );
            node.bodies.set_start(0, &j.start);
        }
        block
    }

    /// Joint `j` as the rows stand.
    fn measured(&self, rows: &BodyRows, j: usize) -> Measured {
        let joint = &self.tree.joints[j];
        let gather = |side| BodyLanes::<f32>::gather(rows, &[self.side_row(side)]);
        Measured {
            kind: joint.kind,
            a: gather(joint.a),
            b: gather(joint.b),
            g: Geometry {
                anchor_a: joint.anchor_a.into(),
                anchor_b: joint.anchor_b.into(),
                frame_a: joint.frame_a.into(),
                frame_b: joint.frame_b.into(),
                rest_length: joint.rest_length,
                swing_max: core::f32::consts::PI,
                twist: [-core::f32::consts::PI, core::f32::consts::PI],
                ellipse: [1.0, 1.0],
                pyramid: [[-core::f32::consts::PI, core::f32::consts::PI]; 2],
                softness: Softness::hard(),
                start: pair_start(&joint.start),
            },
        }
    }

    /// The largest joint error (m or rad).
    fn error(&self, rows: &BodyRows) -> f64 {
        (0..self.tree.joints.len())
            .map(|j| {
                let m = self.measured(rows, j);
                m.error(0..m.kind.count())
            })
            .fold(0.0, f64::max)
    }

    /// The bodies' displacements (m, world).
    fn displacements(&self, rows: &BodyRows) -> Vec<GVec3> {
        (0..self.tree.bodies.len())
            .map(|i| {
                BodyLanes::<f32>::gather(rows, &[self.side_row(Some(i))])
                    .p
                    .into()
            })
            .collect()
    }

    /// Body `index`'s unknowns after a pass: `(dp, dtheta)` (m, rad,
    /// world).
    fn unknowns(&self, block: &TreeBlock, index: usize) -> (GVec3, GVec3) {
        let body = NodeKind::Body {
            index: index as u32,
        };
        let node = self.topology.nodes.iter().position(|n| n.kind == body);
        let x = block.scratch[node.expect("every body is a node")]
            .rhs
            .map(|v| v[0]);
        (GVec3::new(x[0], x[1], x[2]), GVec3::new(x[3], x[4], x[5]))
    }
}

/// A substep of 1/60 s.
const SCALE: SubstepScale = SubstepScale {
    inv_h: 60.0,
    inv_h2: 3600.0,
};

fn pass(backend: Backend, rows: &BodyRows, blocks: &mut [TreeBlock], topologies: &[Topology]) {
    backend.dispatch(PositionPass {
        blocks,
        topologies,
        rows,
        scale: SCALE,
    });
}

/// A tree offset by `offsets`: its error before and after each of
/// `passes` passes.
fn errors(tree: &Tree, offsets: &Offsets, passes: usize) -> Vec<f64> {
    let scene = Scene::new(tree);
    let rows = scene.rows(offsets);
    let mut blocks = vec![scene.block()];
    let topologies = [scene.topology.clone()];
    let mut errors = vec![scene.error(&rows)];
    for _ in 0..passes {
        pass(Backend::Scalar, &rows, &mut blocks, &topologies);
        errors.push(scene.error(&rows));
    }
    errors
}

use JointRows::{Fixed, Hinge, Rod};

/// A socket with a circular cone.
const POINT: JointRows = JointRows::Socket(SwingRows::Cone);

/// The trees of the first-order tests, by name: sockets hanging from a
/// static anchor, every kind mixed (straight rods) likewise and with the
/// static body on each joint's other side, and a free star.
fn named_tree(r: &mut StdRng, name: &str) -> Tree {
    match name {
        "sockets" => hanging_chain(r, &[POINT]),
        "mixed" => hanging_chain(r, &[Hinge, Fixed, Rod, POINT, Hinge, Rod]),
        "mixed, each joint's sides swapped" => {
            let mut tree = hanging_chain(r, &[Fixed, Rod, Hinge, POINT, Rod, Hinge]);
            swap_sides(&mut tree);
            tree
        }
        _ => star(r),
    }
}

fn show(errors: &[f64]) -> String {
    let shown: Vec<String> = errors.iter().map(|e| format!("{e:.2e}")).collect();
    shown.join(", ")
}

const TREES: [&str; 4] = [
    "sockets",
    "mixed",
    "mixed, each joint's sides swapped",
    "star",
];

/// Swaps every joint's two sides (the static one now b): the same
/// constraints, measured from the other body.
fn swap_sides(tree: &mut Tree) {
    let joints = std::mem::take(&mut tree.joints);
    for j in joints {
        let ((xa, _), (xb, qb)) = (tree.pose(j.a), tree.pose(j.b));
        let point = xb + (qb * j.anchor_b).as_dvec3();
        let frame = qb * j.frame_b;
        if j.kind == Rod {
            tree.join(Rod, j.b, j.a, xa, frame);
        } else {
            tree.join(j.kind, j.b, j.a, point, frame);
        }
    }
}

/// Offset by 1e-3 to 1e-2 m and rad from satisfied poses, one pass leaves
/// an error of second order (measured: at most 2.4 e0^2, per metre or
/// radian, over these trees; bound 4 e0^2), a second pass one of second
/// order in that (measured 15 e1^2 + round-off; bound 20 e1^2 + 2e-6), and
/// a third only round-off (measured 8e-7; bound 2e-6). At offsets of 1e-3
/// (errors to 1e-2: the rods' curve turns 2/|d| rad per metre) one pass
/// takes off 98% of the error or more (bound 97%).
#[test]
fn one_pass_is_exact_to_first_order_and_a_second_to_round_off() {
    let mut r = StdRng::seed_from_u64(20);
    for size in [1e-2f32, 3e-3, 1e-3] {
        for name in TREES {
            for _ in 0..10 {
                let tree = named_tree(&mut r, name);
                let offsets = offsets(&mut r, &tree, size);
                let e = errors(&tree, &offsets, 3);
                let context = format!("{name}, offsets {size}: errors {}", show(&e));
                assert!(e[1] <= 4.0 * e[0] * e[0] + 1e-6, "{context}");
                assert!(e[2] <= 20.0 * e[1] * e[1] + 2e-6, "{context}");
                assert!(e[3] <= 2e-6, "{context}");
                if size <= 1e-3 {
                    assert!(e[1] <= 3e-2 * e[0], "{context}");
                }
            }
        }
    }
}

/// One pass of a tree in lane 0: the joints measured before it, the
/// bodies' displacements before it, their unknowns, and the rows after.
struct Pass {
    before: Vec<Measured>,
    p_before: Vec<GVec3>,
    dx: Vec<(GVec3, GVec3)>,
    p_after: Vec<GVec3>,
}

fn one_pass(tree: &Tree, offsets: &Offsets) -> Pass {
    let scene = Scene::new(tree);
    let rows = scene.rows(offsets);
    let before = (0..tree.joints.len())
        .map(|j| scene.measured(&rows, j))
        .collect();
    let p_before = scene.displacements(&rows);
    let mut blocks = vec![scene.block()];
    pass(
        Backend::Scalar,
        &rows,
        &mut blocks,
        std::slice::from_ref(&scene.topology),
    );
    Pass {
        before,
        p_before,
        dx: (0..tree.bodies.len())
            .map(|i| scene.unknowns(&blocks[0], i))
            .collect(),
        p_after: scene.displacements(&rows),
    }
}

/// The pass solves `C + J_a dx_a + J_b dx_b = 0` for every row of every
/// joint at once, to f32 round-off grown by the mass ratios of 1000
/// (measured: 1.1e-4 of the largest error; bound 1e-3), and moves each
/// body by its unknowns.
#[test]
fn one_pass_solves_every_linearised_row_and_moves_the_bodies_by_its_unknowns() {
    let mut r = StdRng::seed_from_u64(21);
    for name in TREES {
        for _ in 0..10 {
            let tree = named_tree(&mut r, name);
            let offsets = offsets(&mut r, &tree, 1e-2);
            let pass = one_pass(&tree, &offsets);
            let largest = pass
                .before
                .iter()
                .map(|m| m.error(0..m.kind.count()))
                .fold(0.0, f64::max);
            for (m, joint) in pass.before.iter().zip(&tree.joints) {
                let rows = m.rows();
                for k in 0..m.kind.count() {
                    if m.kind.is_limit(k) && rows.c[k] <= 0.0 {
                        continue; // a limit not violated is not held
                    }
                    let mut linearised = rows.c[k] as f64;
                    for (side, jacobian) in [(joint.a, rows.ja[k]), (joint.b, rows.jb[k])] {
                        let Some(i) = side else { continue };
                        let (dp, dtheta) = pass.dx[i];
                        let x = dp.to_array().into_iter().chain(dtheta.to_array());
                        for (j, x) in jacobian.iter().zip(x) {
                            linearised += *j as f64 * x as f64;
                        }
                    }
                    assert!(
                        linearised.abs() <= 1e-3 * largest,
                        "{name}, {:?} row {k}: {linearised:.2e} left of {largest:.2e}",
                        m.kind
                    );
                }
            }
            for i in 0..tree.bodies.len() {
                let moved = pass.p_after[i] - pass.p_before[i];
                assert!(
                    (moved - pass.dx[i].0).abs().max_element() <= 1e-8,
                    "{name}: body {i} moved {moved} for {}",
                    pass.dx[i].0
                );
            }
        }
    }
}

/// The constraint impulses of a free tree are internal: every row's
/// linear Jacobians on its two bodies are opposite, so `sum m dp = 0` to
/// round-off (measured 2e-7 of `sum m |dp|`; bound 1e-5). The angular
/// momentum about the centre of mass, `sum I dtheta + (x - c) x m dp`, is
/// kept to first order: each row's exact gradient is, and the rows are
/// exact at zero error (measured: 1.3e-2 of its terms' sum at offsets of
/// 1e-2, 5e-4 at 1e-3; bound twice the offset).
#[test]
fn a_free_tree_keeps_its_linear_momentum_and_its_angular_to_first_order() {
    let mut r = StdRng::seed_from_u64(22);
    for size in [1e-2f32, 1e-3] {
        for _ in 0..10 {
            let tree = star(&mut r);
            let offsets = offsets(&mut r, &tree, size);
            let pass = one_pass(&tree, &offsets);
            let x: Vec<DVec3> = tree
                .bodies
                .iter()
                .zip(&pass.p_before)
                .map(|(b, p)| b.x + p.as_dvec3())
                .collect();
            let total: f64 = tree.bodies.iter().map(|b| b.mass as f64).sum();
            let centre = tree
                .bodies
                .iter()
                .zip(&x)
                .map(|(b, x)| *x * b.mass as f64)
                .sum::<DVec3>()
                / total;
            let (mut linear, mut linear_scale) = (DVec3::ZERO, 0.0);
            let (mut angular, mut angular_scale) = (DVec3::ZERO, 0.0);
            for (i, body) in tree.bodies.iter().enumerate() {
                let m = body.mass as f64;
                let (dp, dtheta) = (pass.dx[i].0.as_dvec3(), pass.dx[i].1.as_dvec3());
                linear += m * dp;
                linear_scale += m * dp.length();
                let turn = Mat3::from_quat(GQuat::from_scaled_axis(offsets[i].1) * body.q);
                let inertia = (turn * body.inertia * turn.transpose()).as_dmat3();
                let (spin, orbit) = (inertia * dtheta, (x[i] - centre).cross(m * dp));
                angular += spin + orbit;
                angular_scale += spin.length() + orbit.length();
            }
            let linear = linear.length() / linear_scale;
            let angular = angular.length() / angular_scale;
            assert!(
                linear <= 1e-5,
                "offsets {size}: linear momentum {linear:.2e}"
            );
            assert!(
                angular <= 2.0 * size as f64,
                "offsets {size}: angular momentum {angular:.2e}"
            );
        }
    }
}

/// Six bodies hanging below a static anchor joined by rods bent 0.3 to 1
/// rad (their ends' tangents at half that to the chord).
fn bent_rod_chain(r: &mut StdRng) -> Tree {
    let mut tree = hanging_chain(r, &[POINT]);
    tree.joints.clear();
    for i in 0..6 {
        let a = if i == 0 { None } else { Some(i - 1) };
        let ((xa, _), (xb, _)) = (tree.pose(a), tree.pose(Some(i)));
        let o = (xb - xa).as_vec3().normalize();
        let half = r.random_range(0.15..0.5);
        let ta = GQuat::from_axis_angle(o.any_orthonormal_vector(), half) * o;
        tree.join(Rod, a, Some(i), xa, GQuat::from_rotation_arc(GVec3::X, ta));
    }
    tree
}

/// A bent rod's length row leaves out how its chord changes with the bend
/// (`rod_length_row_is_the_gradient_of_its_linear_part_and_drops_the_bend`),
/// and the bend is free in the hard rows: each pass bends the rods as the
/// other rows need and leaves the chord's change, `chord'(psi) dpsi`, to
/// the next. The error falls linearly, not quadratically (measured on one
/// of these trees at offsets of 1e-3: 7.2e-3, 3.7e-4, 1.8e-5, 3.8e-6,
/// 8.3e-7; on another at 1e-2, not even monotonically: 8.8e-2, 9.5e-2,
/// 5.5e-3, 3.7e-4, 6.1e-5). Checked: four passes at offsets of 1e-3 take
/// off 99.9% of the error.
#[test]
fn bent_rods_converge_over_a_few_passes() {
    let mut r = StdRng::seed_from_u64(23);
    for _ in 0..10 {
        let tree = bent_rod_chain(&mut r);
        let offsets = offsets(&mut r, &tree, 1e-3);
        let e = errors(&tree, &offsets, 4);
        assert!(e[4] <= 1e-3 * e[0], "errors {}", show(&e));
    }
}

// ---------------------------------------------------------------------------
// Every backend: the scalar reference's bits.
// ---------------------------------------------------------------------------

/// A tree's joints as `Topology::new` takes them: rows and bodies.
type Shape = Vec<(JointRows, Option<u32>, Option<u32>)>;

/// One block of trees and its topology.
#[derive(Clone)]
struct Trees {
    block: TreeBlock,
    topology: Topology,
}

const KINDS: [JointRows; 4] = [POINT, Hinge, Fixed, Rod];

/// Static bodies at the end of the rows, shared by every lane.
const STATICS: usize = 2;

/// A random tree shape of 1 to 7 bodies: each body after the first (in a
/// random order) joined to one before it, either way round, by a random
/// kind; sometimes one joint to a static body; the joints shuffled.
fn random_shape(r: &mut StdRng) -> (usize, Shape) {
    let n = r.random_range(1..=7);
    let mut order: Vec<u32> = (0..n as u32).collect();
    shuffle(r, &mut order);
    let kind = |r: &mut StdRng| KINDS[r.random_range(0..KINDS.len())];
    let mut joints = Vec::new();
    for k in 1..n {
        let (parent, child) = (order[r.random_range(0..k)], order[k]);
        let (a, b) = if r.random_bool(0.5) {
            (parent, child)
        } else {
            (child, parent)
        };
        joints.push((kind(r), Some(a), Some(b)));
    }
    if r.random_bool(0.6) {
        let body = Some(order[r.random_range(0..n)]);
        joints.push(if r.random_bool(0.5) {
            (kind(r), None, body)
        } else {
            (kind(r), body, None)
        });
    }
    shuffle(r, &mut joints);
    (n, joints)
}

fn shuffle<T>(r: &mut StdRng, items: &mut [T]) {
    for i in (1..items.len()).rev() {
        items.swap(i, r.random_range(0..=i));
    }
}

/// Fills `lane` of `block` with a tree of its topology's shape at random
/// (adversarial: all its bodies at one point, so rods' ends meet; anchors
/// at the centres; hinge axes exactly opposed; frames exactly aligned;
/// identity orientations; a vanishing rest length; a start of step of
/// zero), its bodies' rows from `first_row`.
fn random_lane(
    r: &mut StdRng,
    raw: &mut RawRows,
    block: &mut TreeBlock,
    shape: &[(JointRows, Option<u32>, Option<u32>)],
    lane: usize,
    first_row: usize,
    adversarial: bool,
) {
    let chance = |r: &mut StdRng, p: f64| adversarial && r.random_bool(p);
    let together = chance(r, 0.2);
    // The offset from the start pose (m, rad): none, small or large.
    let size = [0.0, 1e-3, 0.3][r.random_range(0..3)];
    let offset = |r: &mut StdRng| {
        if size > 0.0 {
            vec(r, size)
        } else {
            GVec3::ZERO
        }
    };
    let mut poses = Vec::new();
    for (i, node) in block.bodies.iter_mut().enumerate() {
        let x = if together {
            DVec3::ZERO
        } else {
            vec(r, 1.0).as_dvec3()
        };
        let q = if chance(r, 0.3) {
            GQuat::IDENTITY
        } else {
            unit_quat(r)
        };
        let mass = log_uniform(r, -3.0, 3.0);
        let mut body = body_at(r, x, mass);
        body.q = q;
        let (dp, dtheta) = (offset(r), offset(r));
        let row = first_row + i;
        raw[row] = [
            BodyRows::pose_row(dp, 1.0 / body.mass, GQuat::from_scaled_axis(dtheta) * q),
            BodyRows::inertia_row(body.inertia.inverse()),
            BodyRows::velocity_row(vec(r, 1.0), vec(r, 1.0)),
        ];
        node.set(lane, row as u32, true, body.mass, body.inertia);
        poses.push((x, q));
    }
    let statics = raw.len() - STATICS;
    for (node, &(kind, a, b)) in block.joints.iter_mut().zip(shape) {
        let side = |r: &mut StdRng, side: Option<u32>| match side {
            Some(i) => (first_row + i as usize, poses[i as usize]),
            None => {
                let row = statics + r.random_range(0..STATICS);
                (row, (DVec3::ZERO, GQuat::from_slice(&raw[row][0][4..])))
            }
        };
        let ((row_a, (xa, qa)), (row_b, (xb, qb))) = (side(r, a), side(r, b));
        let centred = kind == Rod || chance(r, 0.3);
        let anchor = |r: &mut StdRng| if centred { GVec3::ZERO } else { vec(r, 0.5) };
        let (anchor_a, anchor_b) = (anchor(r), anchor(r));
        let frame_a = unit_quat(r);
        let frame_b = match r.random_range(0..if adversarial { 4 } else { 1 }) {
            1 => qb.inverse() * qa * frame_a * GQuat::from_rotation_y(core::f32::consts::PI),
            2 => qb.inverse() * qa * frame_a,
            _ => unit_quat(r),
        };
        let start = if chance(r, 0.3) {
            StartLane::default()
        } else {
            StartLane::new(xa, qa, anchor_a, xb, qb, anchor_b)
        };
        node.set(
            lane,
            &JointLane {
                body_a: row_a as u32,
                body_b: row_b as u32,
                anchor_a,
                anchor_b,
                frame_a,
                frame_b,
                rest_length: if chance(r, 0.2) {
                    1e-6
                } else {
                    r.random_range(0.1..2.0)
                },
                // Limits that bind (active rows) as often as not.
                swing_max: r.random_range(0.0..core::f32::consts::PI),
                twist: {
                    let lo = r.random_range(-core::f32::consts::PI..0.0);
                    [lo, r.random_range(lo..core::f32::consts::PI)]
                },
                ..JointLane::FREE
            },
        );
        node.bodies.set_start(lane, &start);
    }
    block.padding &= !(1 << lane);
}

/// `blocks` blocks of random shapes, each lane (but one in ten, padding)
/// a random tree of its block's shape.
fn tree_scene(seed: u64, blocks: usize, adversarial: bool) -> (RawRows, Vec<Trees>) {
    let mut r = StdRng::seed_from_u64(seed);
    let shapes: Vec<_> = (0..blocks).map(|_| random_shape(&mut r)).collect();
    let rows: usize = shapes.iter().map(|(n, _)| n * BLOCK_LANES).sum();
    let mut raw = vec![BodyRows::null_raw(); 1 + rows + STATICS];
    for row in &mut raw[1 + rows..] {
        row[0] = BodyRows::pose_row(GVec3::ZERO, 0.0, unit_quat(&mut r));
    }
    let mut out = Vec::new();
    let mut first_row = 1;
    for (index, (n, shape)) in shapes.iter().enumerate() {
        let topology = Topology::new(*n, shape).expect("a tree");
        let mut block = TreeBlock::padding(index as u32, &topology);
        for lane in 0..BLOCK_LANES {
            if !r.random_bool(0.1) {
                random_lane(
                    &mut r,
                    &mut raw,
                    &mut block,
                    shape,
                    lane,
                    first_row + lane * n,
                    adversarial,
                );
            }
        }
        first_row += n * BLOCK_LANES;
        out.push(Trees { block, topology });
    }
    (raw, out)
}

/// Makes `lane` padding, as `TreeBlock::padding` lays it out: the null
/// row, written nowhere, a unit mass; joints between null rows.
fn clear_lane(trees: &mut Trees, lane: usize) {
    let block = &mut trees.block;
    block.padding |= 1 << lane;
    for body in &mut block.bodies {
        body.set(lane, 0, false, 1.0, Mat3::IDENTITY);
    }
    let empty = JointLane::FREE;
    for joint in &mut block.joints {
        joint.set(lane, &empty);
        joint.bodies.set_start(lane, &StartLane::default());
    }
}

/// Two passes (the second re-linearised where the first left the bodies):
/// every row, and every live lane's unknowns.
fn run_trees(backend: Backend, raw: &RawRows, trees: &[Trees]) -> Vec<f32> {
    let rows = to_rows(raw);
    let topologies: Vec<Topology> = trees.iter().map(|t| t.topology.clone()).collect();
    let mut blocks: Vec<TreeBlock> = trees.iter().map(|t| t.block.clone()).collect();
    for _ in 0..2 {
        pass(backend, &rows, &mut blocks, &topologies);
    }
    let mut out = flatten(&rows);
    for (block, topology) in blocks.iter().zip(&topologies) {
        for lane in (0..BLOCK_LANES).filter(|lane| block.padding & (1 << lane) == 0) {
            for (node, scratch) in topology.nodes.iter().zip(&block.scratch) {
                let size = match node.kind {
                    NodeKind::Body { .. } => 6,
                    NodeKind::Joint { rows, .. } => rows.count(),
                };
                out.extend(scratch.rhs[..size].iter().map(|v| v[lane]));
            }
        }
    }
    out
}

#[test]
fn random_trees_agree_on_every_backend() {
    common::agree_over_seeds(0..40, false, tree_scene, run_trees);
}

#[test]
fn adversarial_trees_agree_on_every_backend_and_stay_finite() {
    common::agree_over_seeds(200..280, true, tree_scene, run_trees);
}

#[test]
fn blocks_of_one_to_eight_trees_agree_on_every_backend() {
    common::padded_blocks_agree(400..410, tree_scene, clear_lane, run_trees);
}

// ---------------------------------------------------------------------------
// `Topology::new`: the elimination order, and what is not a tree.
// ---------------------------------------------------------------------------

/// Every body and joint is one node; every node's parent comes after it
/// and the root, the only node without one, last (the grounded joint if
/// there is one, else body 0); a joint's sides name its bodies' nodes
/// (`NONE` for a static side) and its rows; a body's parent is a joint
/// touching it, a joint's one of its sides; so every parent link is an
/// edge of the tree, and every edge is a parent link.
fn check_order(topology: &Topology, bodies: usize, joints: &Shape) {
    let nodes = &topology.nodes;
    assert_eq!((topology.bodies, topology.joints), (bodies, joints.len()));
    assert_eq!(nodes.len(), bodies + joints.len());
    let body_node = |i: u32| {
        nodes
            .iter()
            .position(|n| n.kind == NodeKind::Body { index: i })
            .expect("every body is a node") as u32
    };
    let root = nodes.last().expect("a node");
    match joints
        .iter()
        .position(|&(_, a, b)| a.is_none() || b.is_none())
    {
        Some(j) => {
            assert!(matches!(root.kind, NodeKind::Joint { index, .. } if index as usize == j))
        }
        None => assert_eq!(root.kind, NodeKind::Body { index: 0 }),
    }
    let mut joint_seen = vec![false; joints.len()];
    for (n, node) in nodes.iter().enumerate() {
        if n + 1 == nodes.len() {
            assert_eq!(node.parent, NONE, "the root has a parent");
        } else {
            assert!(
                node.parent != NONE && node.parent as usize > n,
                "node {n} before its parent"
            );
        }
        match node.kind {
            NodeKind::Body { index } => {
                assert_eq!(body_node(index), n as u32, "body {index} twice");
                if node.parent != NONE {
                    let NodeKind::Joint { a, b, .. } = nodes[node.parent as usize].kind else {
                        panic!("body {index}'s parent is a body");
                    };
                    assert!(
                        a == n as u32 || b == n as u32,
                        "body {index}'s parent joint is not its"
                    );
                }
            }
            NodeKind::Joint { index, rows, a, b } => {
                let (kind, ja, jb) = joints[index as usize];
                assert!(!joint_seen[index as usize], "joint {index} twice");
                joint_seen[index as usize] = true;
                assert_eq!(rows, kind);
                assert_eq!(a, ja.map_or(NONE, body_node));
                assert_eq!(b, jb.map_or(NONE, body_node));
                for side in [a, b].into_iter().filter(|&s| s != NONE) {
                    let edge = node.parent == side || nodes[side as usize].parent == n as u32;
                    assert!(
                        edge,
                        "joint {index}'s edge to node {side} is no parent link"
                    );
                }
                if node.parent != NONE {
                    assert!(
                        node.parent == a || node.parent == b,
                        "joint {index}'s parent is not its body"
                    );
                }
            }
        }
    }
}

#[test]
fn topology_orders_every_node_after_its_children_and_the_root_last() {
    let mut r = StdRng::seed_from_u64(30);
    for _ in 0..500 {
        let (n, shape) = random_shape(&mut r);
        let topology = Topology::new(n, &shape).expect("a tree");
        check_order(&topology, n, &shape);
    }
    for tree in [hanging_chain(&mut r, &[POINT]), star(&mut r)] {
        let shape: Shape = tree
            .joints
            .iter()
            .map(|j| (j.kind, j.a.map(|i| i as u32), j.b.map(|i| i as u32)))
            .collect();
        check_order(&tree.topology(), tree.bodies.len(), &shape);
    }
}

#[test]
fn topology_refuses_loops_disconnected_sets_and_bad_joints() {
    use TopologyError::{BadJoint, Disconnected, Loop};
    let cases: [(&str, usize, Shape, TopologyError); 11] = [
        (
            "a triangle",
            3,
            vec![
                (POINT, Some(0), Some(1)),
                (Hinge, Some(1), Some(2)),
                (Rod, Some(2), Some(0)),
            ],
            Loop,
        ),
        (
            "two joints between one pair",
            2,
            vec![(POINT, Some(0), Some(1)), (Fixed, Some(1), Some(0))],
            Loop,
        ),
        (
            "a body joined to itself",
            2,
            vec![(POINT, Some(0), Some(1)), (Hinge, Some(1), Some(1))],
            Loop,
        ),
        (
            "two joints to static bodies",
            2,
            vec![
                (POINT, None, Some(0)),
                (POINT, Some(0), Some(1)),
                (POINT, Some(1), None),
            ],
            Loop,
        ),
        (
            "two grounded pairs",
            2,
            vec![(POINT, None, Some(0)), (POINT, Some(1), None)],
            Loop,
        ),
        ("two free bodies", 2, vec![], Disconnected),
        (
            "two pairs",
            4,
            vec![(POINT, Some(0), Some(1)), (Rod, Some(2), Some(3))],
            Disconnected,
        ),
        (
            "a body left out",
            2,
            vec![(POINT, None, Some(0))],
            Disconnected,
        ),
        ("nothing", 0, vec![], Disconnected),
        (
            "a body past the count",
            3,
            vec![(POINT, Some(0), Some(1)), (POINT, Some(1), Some(3))],
            BadJoint,
        ),
        (
            "a joint to no body",
            2,
            vec![(POINT, Some(0), Some(1)), (POINT, None, None)],
            BadJoint,
        ),
    ];
    for (name, bodies, joints, expected) in cases {
        assert_eq!(Topology::new(bodies, &joints), Err(expected), "{name}");
    }
    // Any random tree with one joint more closes a loop; with one of its
    // joints between two bodies fewer, it falls apart.
    let mut r = StdRng::seed_from_u64(31);
    for _ in 0..300 {
        let (n, mut shape) = random_shape(&mut r);
        if n < 2 {
            continue;
        }
        let mut fewer = shape.clone();
        let inner = fewer
            .iter()
            .position(|&(_, a, b)| a.is_some() && b.is_some());
        fewer.remove(inner.expect("n > 1 bodies are joined"));
        assert_eq!(Topology::new(n, &fewer), Err(Disconnected), "{fewer:?}");
        let (a, b) = (r.random_range(0..n as u32), r.random_range(0..n as u32));
        shape.insert(r.random_range(0..=shape.len()), (POINT, Some(a), Some(b)));
        assert_eq!(Topology::new(n, &shape), Err(Loop), "{shape:?}");
    }
}
