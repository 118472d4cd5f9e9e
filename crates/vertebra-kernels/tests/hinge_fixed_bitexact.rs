//! The hinge and fixed kernels' passes give the scalar reference's bits on
//! every backend, for random and adversarial joints.

mod common;

use common::{RawRows, agree_over_seeds, flatten, lane_bodies, rows, to_rows, unit_quat, vec};
use glam::{Quat, Vec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::{JointFrames, LaneBlock};
use vertebra_kernels::driven::{self, DriveLane};
use vertebra_kernels::fixed::{self, FixedBlock, FixedLane};
use vertebra_kernels::hinge::{self, HingeBlock, HingeLane};
use vertebra_kernels::limited;
use vertebra_kernels::pass::{self, SubstepScale};
use vertebra_kernels::residual::ResidualPass;
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;

/// A 60 Hz substep's scales.
const SCALE: SubstepScale = SubstepScale {
    inv_h: 60.0,
    inv_h2: 3600.0,
};

const STATICS: usize = 4;

/// One random joint's bodies, anchors and frames; `adversarial` mixes in
/// anchors that coincide, frames equal, turned about +Y by exactly pi
/// (antiparallel axes: exactly so where the orientations and a's frame are
/// the identity), by pi as `f32` rounds it, by 179.9 degrees, by 90
/// degrees or within 0.1 degree of it, and zero anchors.
struct Joint {
    body_a: u32,
    body_b: u32,
    anchor_a: Vec3,
    anchor_b: Vec3,
    frame_a: Quat,
    frame_b: Quat,
}

fn joint(r: &mut StdRng, rows: &RawRows, lane: usize, adversarial: bool) -> Joint {
    let (body_a, body_b) = lane_bodies(r, rows, lane, STATICS);
    let mut j = Joint {
        body_a,
        body_b,
        anchor_a: vec(r, 0.3),
        anchor_b: vec(r, 0.3),
        frame_a: unit_quat(r),
        frame_b: unit_quat(r),
    };
    if adversarial && r.random_bool(0.3) {
        let pose = |row: u32| rows[row as usize][0];
        let (pa, qa) = (
            Vec3::from_slice(&pose(body_a)[..3]),
            Quat::from_slice(&pose(body_a)[4..]),
        );
        let (pb, qb) = (
            Vec3::from_slice(&pose(body_b)[..3]),
            Quat::from_slice(&pose(body_b)[4..]),
        );
        j.anchor_b = qb.inverse() * (pa + qa * j.anchor_a - pb);
        let turn = match r.random_range(0..6) {
            0 => Quat::IDENTITY,
            1 => Quat::from_xyzw(0.0, 1.0, 0.0, 0.0),
            2 => Quat::from_rotation_y(core::f32::consts::PI),
            3 => Quat::from_rotation_y(179.9f32.to_radians()),
            4 => Quat::from_rotation_y(core::f32::consts::FRAC_PI_2),
            _ => Quat::from_rotation_y(r.random_range(89.9f32..90.1).to_radians()),
        };
        if r.random_bool(0.3) {
            j.frame_a = Quat::IDENTITY;
        }
        j.frame_b = qb.inverse() * qa * j.frame_a * turn;
    }
    if adversarial && r.random_bool(0.1) {
        (j.anchor_a, j.anchor_b) = (Vec3::ZERO, Vec3::ZERO);
    }
    j
}

fn compliance(r: &mut StdRng) -> f32 {
    match r.random_range(0..4) {
        0 => 0.0,
        1 => 1e-9,
        2 => 1e9,
        _ => r.random_range(0.0..0.1),
    }
}

/// Adversarial inertia on dynamic bodies: none (a body that only
/// translates) or about one axis only (a singular hinge axis `K` when both
/// sides are so).
fn degenerate_inertia(r: &mut StdRng, rows: &mut RawRows) {
    for row in rows.iter_mut().skip(1) {
        if row[0][3] > 0.0 && r.random_bool(0.15) {
            let axis = vec(r, 1.0).normalize_or(Vec3::X);
            let inertia = if r.random_bool(0.5) {
                glam::Mat3::ZERO
            } else {
                glam::Mat3::from_cols(axis * axis.x, axis * axis.y, axis * axis.z) * 3.0
            };
            row[1] = vertebra_kernels::body::BodyRows::inertia_row(inertia);
        }
    }
}

fn hinges(seed: u64, blocks: usize, adversarial: bool) -> (RawRows, Vec<HingeBlock>) {
    let mut r = StdRng::seed_from_u64(seed);
    let mut rows = rows(&mut r, blocks * BLOCK_LANES, STATICS, adversarial);
    if adversarial {
        degenerate_inertia(&mut r, &mut rows);
    }
    let mut out = Vec::new();
    for block_index in 0..blocks {
        let mut block = HingeBlock::padding();
        for lane in 0..BLOCK_LANES {
            if r.random_bool(0.1) {
                continue; // a padding lane
            }
            let mut j = joint(&mut r, &rows, block_index * BLOCK_LANES + lane, adversarial);
            if adversarial && r.random_bool(0.05) {
                // Exactly antiparallel axes: both bodies unturned, a's frame
                // the identity, b's turned by exactly pi about +Y.
                for body in [j.body_a, j.body_b] {
                    rows[body as usize][0][4..].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
                }
                (j.frame_a, j.frame_b) = (Quat::IDENTITY, Quat::from_xyzw(0.0, 1.0, 0.0, 0.0));
            }
            let pi = core::f32::consts::PI;
            let range = match r.random_range(0..3) {
                0 => [-pi, pi],
                1 if adversarial => [0.0, 0.0],
                _ => {
                    let lo = r.random_range(-3.0..0.5f32);
                    [lo, r.random_range(lo..3.1)]
                }
            };
            let limit = compliance(&mut r);
            let drive = compliance(&mut r);
            block.set(
                lane,
                &HingeLane {
                    pair: common::pair(&rows, j.body_a, j.body_b),
                    frames: JointFrames {
                        anchor_a: j.anchor_a,
                        anchor_b: j.anchor_b,
                        frame_a: j.frame_a,
                        frame_b: j.frame_b,
                    },
                    range,
                    softness: common::limit_softness(&mut r, limit),
                    drive: r.random_bool(0.6).then(|| DriveLane {
                        target: unit_quat(&mut r),
                        velocity: vec(&mut r, 20.0),
                        compliance: drive,
                        damping_time: r.random_range(0.0..1.0),
                        max_torque: if r.random_bool(0.5) {
                            r.random_range(0.0..50.0)
                        } else {
                            f32::INFINITY
                        },
                        ..DriveLane::OFF
                    }),
                },
            );
            block
                .bodies
                .set_start(lane, &common::start(&mut r, adversarial));
            block.limit_start[lane] = common::limit_start(&mut r);
        }
        out.push(block);
    }
    (rows, out)
}

fn fixed_joints(seed: u64, blocks: usize, adversarial: bool) -> (RawRows, Vec<FixedBlock>) {
    let mut r = StdRng::seed_from_u64(seed);
    let rows = rows(&mut r, blocks * BLOCK_LANES, STATICS, adversarial);
    let mut out = Vec::new();
    for block_index in 0..blocks {
        let mut block = FixedBlock::padding();
        for lane in 0..BLOCK_LANES {
            if r.random_bool(0.1) {
                continue;
            }
            let j = joint(&mut r, &rows, block_index * BLOCK_LANES + lane, adversarial);
            block.set(
                lane,
                &FixedLane {
                    pair: common::pair(&rows, j.body_a, j.body_b),
                    frames: JointFrames {
                        anchor_a: j.anchor_a,
                        anchor_b: j.anchor_b,
                        frame_a: j.frame_a,
                        frame_b: j.frame_b,
                    },
                },
            );
            block
                .bodies
                .set_start(lane, &common::start(&mut r, adversarial));
        }
        out.push(block);
    }
    (rows, out)
}

/// Every float the hinge passes produce: rows, multipliers, residuals.
fn run_hinges(backend: Backend, raw: &RawRows, blocks: &[HingeBlock]) -> Vec<f32> {
    let rows = to_rows(raw);
    let mut blocks = blocks.to_vec();
    pass::run::<driven::Starts<HingeBlock>>(backend, &mut blocks, &rows, 1.0 / 60.0);
    for iteration in 0..2 {
        if iteration == 1 {
            // The range's start on moved bodies: a nonzero `C - C_0`.
            pass::run::<limited::Starts<HingeBlock>>(backend, &mut blocks, &rows, ());
        }
        pass::run::<hinge::Positions<true>>(backend, &mut blocks, &rows, SCALE);
        pass::run::<hinge::Positions<false>>(backend, &mut blocks, &rows, SCALE);
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
        out.extend(b.limit_lambda);
        out.extend(b.limit_start);
        out.extend(bytemuck::cast_slice::<_, f32>(core::slice::from_ref(
            &b.reaction,
        )));
    }
    out.extend(residual.iter().flatten());
    out
}

/// Every float the fixed joints' passes produce: rows and residuals.
fn run_fixed(backend: Backend, raw: &RawRows, blocks: &[FixedBlock]) -> Vec<f32> {
    let rows = to_rows(raw);
    let mut blocks = blocks.to_vec();
    for _ in 0..2 {
        pass::run::<fixed::Positions>(backend, &mut blocks, &rows, ());
    }
    let mut residual = vec![[0.0f32; 3]; blocks.len() * BLOCK_LANES];
    backend.dispatch(ResidualPass {
        blocks: &blocks,
        rows: &rows,
        out: &mut residual,
    });
    let mut out = flatten(&rows);
    for b in &blocks {
        out.extend(bytemuck::cast_slice::<_, f32>(core::slice::from_ref(
            &b.reaction,
        )));
    }
    out.extend(residual.iter().flatten());
    out
}

#[test]
fn random_hinges_agree_on_every_backend() {
    agree_over_seeds(0..40, false, hinges, run_hinges);
}

#[test]
fn adversarial_hinges_agree_on_every_backend_and_stay_finite() {
    agree_over_seeds(100..160, true, hinges, run_hinges);
}

#[test]
fn random_fixed_joints_agree_on_every_backend() {
    agree_over_seeds(0..40, false, fixed_joints, run_fixed);
}

#[test]
fn adversarial_fixed_joints_agree_on_every_backend_and_stay_finite() {
    agree_over_seeds(100..160, true, fixed_joints, run_fixed);
}

#[test]
fn blocks_of_one_to_eight_hinges_or_fixed_joints_agree_on_every_backend() {
    common::padded_blocks_agree(400..406, hinges, HingeBlock::clear, run_hinges);
    common::padded_blocks_agree(400..406, fixed_joints, FixedBlock::clear, run_fixed);
}
