//! Quaternion, vector and symmetric-matrix identities on every backend, and
//! their bits equal across backends.

mod common;

use common::{assert_agree, random_float, rng};
use glam::{Mat3, Quat as GQuat, Vec3 as GVec3};
use rand::RngExt;
use vertebra_math::map::map_arrays;
use vertebra_math::{Backend, Quat, Sym3, Vec3};

const COUNT: usize = 20_000;

/// Columns: q1 (x y z w), q2 (x y z w), v (x y z), axis (x y z), d (x y z).
fn random_inputs(seed: u64) -> Vec<Vec<f32>> {
    let mut r = rng(seed);
    let mut columns = vec![Vec::new(); 17];
    for _ in 0..COUNT {
        let unit = |r: &mut rand::rngs::StdRng| {
            GQuat::from_xyzw(
                r.random_range(-1.0..1.0),
                r.random_range(-1.0..1.0),
                r.random_range(-1.0..1.0),
                r.random_range(-1.0..1.0),
            )
            .normalize()
        };
        let (q1, q2) = (unit(&mut r), unit(&mut r));
        let v = GVec3::new(
            r.random_range(-5.0..5.0),
            r.random_range(-5.0..5.0),
            r.random_range(-5.0..5.0),
        );
        let axis = GVec3::new(
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
        )
        .normalize_or(GVec3::Y);
        let d = GVec3::new(
            r.random_range(0.0..4.0),
            r.random_range(0.0..4.0),
            r.random_range(0.0..4.0),
        );
        let row = [
            q1.x, q1.y, q1.z, q1.w, q2.x, q2.y, q2.z, q2.w, v.x, v.y, v.z, axis.x, axis.y, axis.z,
            d.x, d.y, d.z,
        ];
        for (c, x) in columns.iter_mut().zip(row) {
            c.push(x);
        }
    }
    columns
}

lane_map!(QuatOps, 17 -> 16, |i, o| {
    let q1 = Quat::new(i[0], i[1], i[2], i[3]);
    let q2 = Quat::new(i[4], i[5], i[6], i[7]);
    let v = Vec3::new(i[8], i[9], i[10]);
    let axis = Vec3::new(i[11], i[12], i[13]);
    let d = Vec3::new(i[14], i[15], i[16]);
    let product = q1 * q2;
    let composed = product.rotate(v);
    let chained = q1.rotate(q2.rotate(v));
    let (swing, twist) = q1.swing_twist(axis);
    let recomposed = swing * twist;
    let round_trip = Quat::from_axis_angle(axis, q2.twist_angle(axis));
    let sym = Sym3::diagonal(d).rotated(q1).mul_vec(v);
    let rv = q1.to_rotation_vector();
    let outputs = [
        composed.x, composed.y, composed.z,
        chained.x, chained.y, chained.z,
        recomposed.x, recomposed.y, recomposed.z, recomposed.w,
        swing.vector().dot(axis), q1.twist_angle(axis),
        sym.x, sym.y, sym.z,
        (rv.length() - q1.angle()) + round_trip.w,
    ];
    o.copy_from_slice(&outputs);
});

#[test]
fn quaternion_operations_agree_bit_for_bit() {
    assert_agree(&QuatOps, &random_inputs(31));
    // Random bits everywhere: degenerate, non-unit and non-finite inputs.
    let mut r = rng(32);
    let wild: Vec<Vec<f32>> = (0..17)
        .map(|_| (0..COUNT).map(|_| random_float(&mut r)).collect())
        .collect();
    assert_agree(&QuatOps, &wild);
}

#[test]
fn identities_hold_on_every_backend() {
    let inputs = random_inputs(33);
    let views: Vec<&[f32]> = inputs.iter().map(|c| c.as_slice()).collect();
    for backend in Backend::available() {
        let mut out = vec![vec![0.0f32; COUNT]; 16];
        let mut outs: Vec<&mut [f32]> = out.iter_mut().map(|c| c.as_mut_slice()).collect();
        map_arrays(backend, &QuatOps, &views, &mut outs);
        for k in 0..COUNT {
            let at = |c: usize| out[c][k];
            let input = |c: usize| inputs[c][k];
            let q1 = GQuat::from_xyzw(input(0), input(1), input(2), input(3));
            let v = GVec3::new(input(8), input(9), input(10));
            let axis = GVec3::new(input(11), input(12), input(13));
            let d = GVec3::new(input(14), input(15), input(16));
            // rotate(q1 q2) = rotate(q1) rotate(q2)
            let composed = GVec3::new(at(0), at(1), at(2));
            let chained = GVec3::new(at(3), at(4), at(5));
            assert!(
                (composed - chained).length() <= 4e-6 * (1.0 + v.length()),
                "{backend} compose"
            );
            // swing * twist = q, the twist about `axis`, the swing perpendicular.
            let recomposed = GQuat::from_xyzw(at(6), at(7), at(8), at(9));
            assert!(
                recomposed.dot(q1).abs() >= 1.0 - 2e-6,
                "{backend} swing-twist recomposes"
            );
            assert!(
                at(10).abs() <= 2e-6,
                "{backend} swing is perpendicular to the axis"
            );
            // The twist angle is glam's angle of the twist part.
            let p = GVec3::new(q1.x, q1.y, q1.z).dot(axis);
            let expected_twist = 2.0 * (p * q1.w.signum()).atan2(q1.w.abs());
            assert!(
                (at(11) - expected_twist).abs() <= 4e-6,
                "{backend} twist angle"
            );
            // R diag(d) R^T v against glam's matrices.
            let r = Mat3::from_quat(q1);
            let expected = r * Mat3::from_diagonal(d) * r.transpose() * v;
            let sym = GVec3::new(at(12), at(13), at(14));
            assert!(
                (sym - expected).length() <= 2e-5 * (1.0 + expected.length()),
                "{backend} sym3"
            );
        }
    }
}

lane_map!(Integrate, 7 -> 5, |i, o| {
    // 10 000 steps of 1/600 s at a constant spin: stays unit, turns by |w| t.
    let omega = Vec3::new(i[4], i[5], i[6]);
    let mut q = Quat::new(i[0], i[1], i[2], i[3]);
    let dt = L::splat(1.0 / 600.0);
    for _ in 0..10_000 {
        q = q.integrate(omega, dt);
    }
    o[0] = q.x;
    o[1] = q.y;
    o[2] = q.z;
    o[3] = q.w;
    o[4] = q.dot(q);
});

#[test]
fn integration_keeps_unit_norm_and_follows_the_spin() {
    let mut r = rng(34);
    let n = 64;
    let mut columns = vec![Vec::new(); 7];
    for _ in 0..n {
        let q = GQuat::from_euler(
            glam::EulerRot::XYZ,
            r.random_range(-3.0..3.0),
            r.random_range(-1.5..1.5),
            r.random_range(-3.0..3.0),
        );
        let omega = GVec3::new(
            r.random_range(-2.0..2.0),
            r.random_range(-2.0..2.0),
            r.random_range(-2.0..2.0),
        );
        for (c, x) in columns
            .iter_mut()
            .zip([q.x, q.y, q.z, q.w, omega.x, omega.y, omega.z])
        {
            c.push(x);
        }
    }
    let out = assert_agree(&Integrate, &columns);
    for k in 0..n {
        // Renormalised every step: within a few ulps of 1, with no drift.
        assert!(
            (out[4][k] - 1.0).abs() <= 4.0 * f32::EPSILON,
            "unit norm kept: {}",
            out[4][k]
        );
        let q0 = GQuat::from_xyzw(columns[0][k], columns[1][k], columns[2][k], columns[3][k]);
        let omega = GVec3::new(columns[4][k], columns[5][k], columns[6][k]);
        let q = GQuat::from_xyzw(out[0][k], out[1][k], out[2][k], out[3][k]);
        // Exact for a constant world-space spin: q(t) = exp(w t / 2) q0.
        let exact = GQuat::from_scaled_axis(omega * (10_000.0 / 600.0)) * q0;
        // First-order steps lag by O(|w|^3 dt^2 t); at dt = 1/600 that is small.
        assert!(
            q.dot(exact).abs() >= 1.0 - 1e-4,
            "spin followed: {q:?} vs {exact:?}"
        );
    }
}

lane_map!(Degenerate, 4 -> 8, |i, o| {
    let q = Quat::new(i[0], i[1], i[2], i[3]).normalize();
    let (n, len) = Vec3::new(i[0], i[1], i[2]).normalize_or_zero();
    o[0] = q.x;
    o[1] = q.y;
    o[2] = q.z;
    o[3] = q.w;
    o[4] = n.x;
    o[5] = n.y;
    o[6] = n.z;
    o[7] = len;
});

#[test]
fn safe_zero_cases_give_identity_and_zero() {
    // Zero, NaN, infinite, and so small that the squared length underflows.
    let cases = [
        [0.0f32, 0.0, 0.0, 0.0],
        [f32::NAN, 0.0, 0.0, 1.0],
        [f32::INFINITY, 0.0, 0.0, 0.0],
        [1e-30, 0.0, 0.0, 0.0],
        [1e-18, 0.0, 0.0, 0.0],
    ];
    let columns: Vec<Vec<f32>> = (0..4)
        .map(|c| cases.iter().map(|r| r[c]).collect())
        .collect();
    let out = assert_agree(&Degenerate, &columns);
    let at = |k: usize| out.iter().map(|column| column[k]).collect::<Vec<f32>>();
    for k in 0..4 {
        // Identity quaternion and zero vector (the length slot is free).
        assert_eq!(at(k)[..7], [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], "case {k}");
    }
    // A small vector whose squared length is still normal normalises.
    assert_eq!([out[0][4], out[3][4], out[4][4]], [1.0, 0.0, 1.0]);
}

#[test]
fn glam_conversions_round_trip() {
    let q = GQuat::from_rotation_y(0.7);
    let v = GVec3::new(1.0, -2.0, 3.0);
    assert_eq!(GQuat::from(Quat::<f32>::from(q)), q);
    assert_eq!(GVec3::from(Vec3::<f32>::from(v)), v);
    assert!((GVec3::from(Quat::<f32>::from(q).rotate(v.into())) - q * v).length() < 1e-6);
}
