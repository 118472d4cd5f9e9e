//! The socket kernel's passes (plain and shaped path, with and without
//! drives) give the scalar reference's bits on every backend, for random
//! and adversarial joints.

mod common;

use common::{RawRows, agree_over_seeds, flatten, lane_bodies, rows, to_rows, unit_quat, vec};
use glam::{Quat, Vec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::{JointFrames, LaneBlock};
use vertebra_kernels::driven;
use vertebra_kernels::limited;
use vertebra_kernels::pass::{self, SubstepScale};
use vertebra_kernels::residual::ResidualPass;
use vertebra_kernels::socket::{self, ShapedLimits, SocketBlock, SocketLane};
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;

/// A 60 Hz substep's scales.
const SCALE: SubstepScale = SubstepScale {
    inv_h: 60.0,
    inv_h2: 3600.0,
};

const STATICS: usize = 4;

/// Blocks of random sockets; `adversarial` mixes in coincident anchors,
/// opposite or equal twist axes, zero anchors, extreme compliances and
/// degenerate shapes (the smallest semi-axis, zero-width pyramids).
fn scene(seed: u64, blocks: usize, adversarial: bool) -> (RawRows, Vec<SocketBlock>) {
    let mut r = StdRng::seed_from_u64(seed);
    let rows = rows(&mut r, blocks * BLOCK_LANES, STATICS, adversarial);
    let mut out = Vec::new();
    for block_index in 0..blocks {
        let mut block = SocketBlock::padding();
        for lane in 0..BLOCK_LANES {
            if r.random_bool(0.1) {
                continue; // a padding lane
            }
            let (body_a, body_b) =
                lane_bodies(&mut r, &rows, block_index * BLOCK_LANES + lane, STATICS);
            let mut anchor_a = vec(&mut r, 0.3);
            let mut anchor_b = vec(&mut r, 0.3);
            let frame_a = unit_quat(&mut r);
            let mut frame_b = unit_quat(&mut r);
            if adversarial && r.random_bool(0.3) {
                // Anchors that coincide in the world, and twist axes exactly
                // opposite (swing = pi) or equal (swing = 0).
                let pose = |row: u32| rows[row as usize][0];
                let (pa, qa) = (
                    Vec3::from_slice(&pose(body_a)[..3]),
                    Quat::from_slice(&pose(body_a)[4..]),
                );
                let (pb, qb) = (
                    Vec3::from_slice(&pose(body_b)[..3]),
                    Quat::from_slice(&pose(body_b)[4..]),
                );
                anchor_b = qb.inverse() * (pa + qa * anchor_a - pb);
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
            let pi = core::f32::consts::PI;
            block.set(
                lane,
                &SocketLane {
                    pair: common::pair(&rows, body_a, body_b),
                    frames: JointFrames {
                        anchor_a,
                        anchor_b,
                        frame_a,
                        frame_b,
                    },
                    swing_max: if r.random_bool(0.7) {
                        r.random_range(0.0..3.2f32).min(pi)
                    } else {
                        pi
                    },
                    twist: if r.random_bool(0.7) {
                        let lo = r.random_range(-3.0..0.5f32);
                        [lo, r.random_range(lo..3.1)]
                    } else {
                        [-pi, pi]
                    },
                    drive: r
                        .random_bool(0.6)
                        .then(|| common::random_drive(&mut r, compliance)),
                    shaped: shaped(&mut r, adversarial, compliance),
                },
            );
            block
                .bodies
                .set_start(lane, &common::start(&mut r, adversarial));
            for c0 in &mut block.limit_start {
                c0[lane] = common::limit_start(&mut r);
            }
        }
        out.push(block);
    }
    (rows, out)
}

/// Random shaped limits: an ellipse, a pyramid (angle ranges) and a
/// softness of any kind; adversarial ones degenerate.
fn shaped(r: &mut StdRng, adversarial: bool, compliance: f32) -> ShapedLimits {
    let semi = |r: &mut StdRng| match r.random_range(0..4) {
        0 if adversarial => 0.001,
        1 => 1.0,
        _ => r.random_range(0.001..1.0f32),
    };
    let pi = core::f32::consts::PI;
    let range = |r: &mut StdRng| match r.random_range(0..4) {
        0 if adversarial => [0.0, 0.0],
        1 => [-pi, pi],
        _ => {
            let lo = r.random_range(-3.0..0.5f32);
            [lo, r.random_range(lo..pi)]
        }
    };
    ShapedLimits {
        ellipse: [semi(r), semi(r)],
        pyramid: [range(r), range(r)],
        softness: common::limit_softness(r, compliance),
    }
}

/// Every float the passes produce: rows, multipliers, residuals.
fn run(backend: Backend, raw: &RawRows, blocks: &[SocketBlock]) -> Vec<f32> {
    let rows = to_rows(raw);
    let mut blocks = blocks.to_vec();
    // Every kernel variant: with the drive part (disabled lanes multiply
    // it by zero) and without, plain and shaped path.
    pass::run::<driven::Starts<SocketBlock>>(backend, &mut blocks, &rows, 1.0 / 60.0);
    for iteration in 0..2 {
        if iteration == 1 {
            // The limits' start on moved bodies: the damping then acts on
            // a nonzero `C - C_0`.
            pass::run::<limited::Starts<SocketBlock>>(backend, &mut blocks, &rows, ());
        }
        pass::run::<socket::Positions<true, false>>(backend, &mut blocks, &rows, SCALE);
        pass::run::<socket::Positions<false, false>>(backend, &mut blocks, &rows, SCALE);
        pass::run::<socket::Positions<true, true>>(backend, &mut blocks, &rows, SCALE);
        pass::run::<socket::Positions<false, true>>(backend, &mut blocks, &rows, SCALE);
    }
    let mut residual = vec![[0.0f32; 3]; blocks.len() * BLOCK_LANES];
    backend.dispatch(ResidualPass {
        blocks: &blocks,
        rows: &rows,
        out: &mut residual,
    });
    let mut out = flatten(&rows);
    for b in &blocks {
        for v in [&b.drive.lambda, &b.drive.start] {
            out.extend(bytemuck::cast_slice::<_, f32>(core::slice::from_ref(v)));
        }
        out.extend(bytemuck::cast_slice::<_, f32>(core::slice::from_ref(
            &b.drive.settings.target,
        )));
        out.extend(b.limit_lambda.iter().flatten());
        out.extend(b.limit_start.iter().flatten());
        // What each socket did to its bodies: its force and torque.
        out.extend(bytemuck::cast_slice::<_, f32>(core::slice::from_ref(
            &b.reaction,
        )));
    }
    out.extend(residual.iter().flatten());
    out
}

#[test]
fn random_joints_agree_on_every_backend() {
    agree_over_seeds(0..40, false, scene, run);
}

#[test]
fn adversarial_joints_agree_on_every_backend_and_stay_finite() {
    agree_over_seeds(100..160, true, scene, run);
}

#[test]
fn blocks_of_one_to_eight_sockets_agree_on_every_backend() {
    common::padded_blocks_agree(400..406, scene, SocketBlock::clear, run);
}
