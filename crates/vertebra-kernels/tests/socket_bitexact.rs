//! The socket kernel's passes give the scalar reference's bits on every
//! backend, for random and adversarial joints.

use glam::{Mat3, Quat, Vec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::BodyRows;
use vertebra_kernels::socket::{PositionPass, ResidualPass, SocketBlock, SocketLane, VelocityPass};
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;
use vertebra_math::check::same_bits;

fn unit_quat(r: &mut StdRng) -> Quat {
    Quat::from_xyzw(
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
    )
    .normalize()
}

fn vec(r: &mut StdRng, scale: f32) -> Vec3 {
    Vec3::new(
        r.random_range(-scale..scale),
        r.random_range(-scale..scale),
        r.random_range(-scale..scale),
    )
}

/// A random symmetric positive definite inverse inertia (or zero).
fn inverse_inertia(r: &mut StdRng) -> Mat3 {
    let q = Mat3::from_quat(unit_quat(r));
    let d = Vec3::new(
        r.random_range(0.1..50.0),
        r.random_range(0.1..50.0),
        r.random_range(0.1..50.0),
    );
    q * Mat3::from_diagonal(d) * q.transpose()
}

/// A scene for one pass: rows and blocks, where every block's written rows
/// are distinct (as the colouring guarantees). `adversarial` mixes in
/// coincident anchors, opposite twist axes, zero masses, exact rest poses
/// and huge or tiny compliances.
fn scene(seed: u64, blocks: usize, adversarial: bool) -> (Vec<[[f32; 8]; 3]>, Vec<SocketBlock>) {
    let mut r = StdRng::seed_from_u64(seed);
    let statics = 4;
    let bodies = blocks * BLOCK_LANES * 2 + statics;
    let mut rows = vec![[[0.0f32; 8]; 3]; bodies + 1];
    rows[0] = [
        BodyRows::pose_row(Vec3::ZERO, 0.0, Quat::IDENTITY),
        [0.0; 8],
        [0.0; 8],
    ];
    for (i, row) in rows.iter_mut().enumerate().skip(1) {
        let fixed = i > bodies - statics || (adversarial && r.random_bool(0.1));
        let inv_mass = if fixed {
            0.0
        } else {
            r.random_range(0.01..10.0)
        };
        let inertia = if fixed {
            Mat3::ZERO
        } else {
            inverse_inertia(&mut r)
        };
        let q = if adversarial && r.random_bool(0.2) {
            Quat::IDENTITY
        } else {
            unit_quat(&mut r)
        };
        *row = [
            BodyRows::pose_row(vec(&mut r, 3.0), inv_mass, q),
            BodyRows::inertia_row(inertia),
            BodyRows::velocity_row(vec(&mut r, 5.0), vec(&mut r, 5.0)),
        ];
    }
    let mut out = Vec::new();
    for block_index in 0..blocks {
        let mut block = SocketBlock::padding();
        for lane in 0..BLOCK_LANES {
            if r.random_bool(0.1) {
                continue; // a padding lane
            }
            let own = |k: usize| (1 + (block_index * BLOCK_LANES + lane) * 2 + k) as u32;
            let static_row = (bodies - r.random_range(0..statics)) as u32;
            let (body_a, body_b) = match r.random_range(0..4) {
                0 => (static_row, own(1)),
                1 => (own(0), static_row),
                _ => (own(0), own(1)),
            };
            let dynamic = |row: u32| rows[row as usize][0][3] > 0.0;
            let mut anchor_a = vec(&mut r, 0.3);
            let mut anchor_b = vec(&mut r, 0.3);
            let frame_a = unit_quat(&mut r);
            let mut frame_b = unit_quat(&mut r);
            if adversarial && r.random_bool(0.3) {
                // Anchors that coincide in the world, and twist axes exactly
                // opposite (swing = pi) or equal (swing = 0).
                let (pa, qa) = (
                    Vec3::from_slice(&rows[body_a as usize][0][..3]),
                    Quat::from_slice(&rows[body_a as usize][0][4..]),
                );
                let (pb, qb) = (
                    Vec3::from_slice(&rows[body_b as usize][0][..3]),
                    Quat::from_slice(&rows[body_b as usize][0][4..]),
                );
                let world = pa + qa * anchor_a;
                anchor_b = qb.inverse() * (world - pb);
                let flip = if r.random_bool(0.5) {
                    Quat::from_rotation_y(core::f32::consts::PI)
                } else {
                    Quat::IDENTITY
                };
                frame_b = qb.inverse() * qa * frame_a * flip;
            }
            if adversarial && r.random_bool(0.1) {
                anchor_a = Vec3::ZERO;
                anchor_b = Vec3::ZERO;
            }
            let compliance = match r.random_range(0..4) {
                0 => 0.0,
                1 => 1e-9,
                2 => 1e9,
                _ => r.random_range(0.0..0.1),
            };
            block.set(
                lane,
                &SocketLane {
                    body_a,
                    body_b,
                    dynamic_a: dynamic(body_a),
                    dynamic_b: dynamic(body_b),
                    anchor_a,
                    anchor_b,
                    frame_a,
                    frame_b,
                    swing_max: if r.random_bool(0.7) {
                        r.random_range(0.0..3.2f32).min(core::f32::consts::PI)
                    } else {
                        core::f32::consts::PI
                    },
                    twist: if r.random_bool(0.7) {
                        let lo = r.random_range(-3.0..0.5f32);
                        [lo, r.random_range(lo..3.1)]
                    } else {
                        [-core::f32::consts::PI, core::f32::consts::PI]
                    },
                    drive: r
                        .random_bool(0.6)
                        .then(|| (unit_quat(&mut r), compliance, r.random_range(0.0..20.0))),
                },
            );
        }
        out.push(block);
    }
    (rows, out)
}

fn to_rows(raw: &[[[f32; 8]; 3]]) -> BodyRows {
    let rows = BodyRows::with_bodies(raw.len() - 1);
    for (i, r) in raw.iter().enumerate() {
        rows.pose[i].set(r[0]);
        rows.inertia[i].set(r[1]);
        rows.velocity[i].set(r[2]);
    }
    rows
}

/// Every float the passes produce: rows, multipliers, residuals.
fn run(backend: Backend, raw: &[[[f32; 8]; 3]], blocks: &[SocketBlock]) -> Vec<f32> {
    let rows = to_rows(raw);
    let mut blocks = blocks.to_vec();
    // Both kernel variants: with the drive part (disabled lanes multiply
    // it by zero) and without.
    for _ in 0..2 {
        backend.dispatch(PositionPass::<true> {
            blocks: &mut blocks,
            rows: &rows,
            inv_h2: 3600.0,
        });
        backend.dispatch(PositionPass::<false> {
            blocks: &mut blocks,
            rows: &rows,
            inv_h2: 3600.0,
        });
    }
    backend.dispatch(VelocityPass {
        blocks: &blocks,
        rows: &rows,
        h: 1.0 / 60.0,
    });
    let mut residual = vec![[0.0f32; 2]; blocks.len() * BLOCK_LANES];
    backend.dispatch(ResidualPass {
        blocks: &blocks,
        rows: &rows,
        out: &mut residual,
    });
    let mut out: Vec<f32> = Vec::new();
    for i in 0..raw.len() {
        out.extend(rows.pose[i].get());
        out.extend(rows.velocity[i].get());
    }
    for b in &blocks {
        out.extend(bytemuck::cast_slice::<_, f32>(core::slice::from_ref(
            &b.drive_lambda,
        )));
    }
    out.extend(residual.iter().flatten());
    out
}

fn assert_backends_agree(seed: u64, adversarial: bool) {
    let (raw, blocks) = scene(seed, 6, adversarial);
    let expected = run(Backend::Scalar, &raw, &blocks);
    assert!(
        expected.iter().all(|x| x.is_finite()),
        "seed {seed}: the scalar reference produced a non-finite value"
    );
    for backend in Backend::available() {
        let actual = run(backend, &raw, &blocks);
        if let Some(k) = (0..expected.len()).find(|&k| !same_bits(expected[k], actual[k])) {
            panic!(
                "seed {seed}: {backend} differs at float {k}: {:e} vs scalar {:e}",
                actual[k], expected[k]
            );
        }
    }
}

#[test]
fn random_joints_agree_on_every_backend() {
    for seed in 0..40 {
        assert_backends_agree(seed, false);
    }
}

#[test]
fn adversarial_joints_agree_on_every_backend_and_stay_finite() {
    for seed in 100..160 {
        assert_backends_agree(seed, true);
    }
}
