//! The rod kernel gives the scalar reference's bits on every backend, for
//! random and adversarial rods: straight, folded back, coincident ends,
//! huge and tiny stiffness, relaxation and compliance, damped and sprung
//! parts, torque caps that bind and that do not, rest shapes still and
//! moving (slow, fast, along the rest direction, wrapping past pi).

mod common;

use common::{RawRows, agree_over_seeds, dynamic, flatten, lane_bodies, rows, to_rows, unit_quat};
use glam::{Quat, Vec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::LaneBlock;
use vertebra_kernels::pass::{self, SubstepScale};
use vertebra_kernels::residual::ResidualPass;
use vertebra_kernels::rod::{self, RodBlock, RodLane, RodSoftness};
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;

/// A 60 Hz substep's scales.
const SCALE: SubstepScale = SubstepScale {
    inv_h: 60.0,
    inv_h2: 3600.0,
};

const STATICS: usize = 4;

fn softness(r: &mut StdRng) -> RodSoftness {
    match r.random_range(0..9) {
        0 => RodSoftness::Compliance(0.0),
        1 => RodSoftness::Compliance(1e-9),
        2 => RodSoftness::Compliance(1e9),
        3 => RodSoftness::Relaxation(r.random_range(0.0..1.0)),
        4 => RodSoftness::Damped {
            compliance: r.random_range(0.0..0.5),
            damping_time: r.random_range(0.0..0.2),
        },
        5 => RodSoftness::Damped {
            compliance: 1e-9,
            damping_time: 1e6,
        },
        6 => RodSoftness::Spring {
            period2: r.random_range(0.0..0.1),
            damping_time: r.random_range(0.0..0.5),
        },
        7 => RodSoftness::Spring {
            period2: 2.5e4,
            damping_time: 0.0,
        },
        _ => RodSoftness::Compliance(r.random_range(0.0..0.5)),
    }
}

/// A torque cap: none, zero, or one that binds now and then (N m).
fn max_torque(r: &mut StdRng) -> f32 {
    match r.random_range(0..4) {
        0 => 0.0,
        1 => r.random_range(0.0..50.0),
        _ => f32::INFINITY,
    }
}

/// A rest shape's rates (rad/s): still, moving, or (adversarial) fast,
/// along the rest direction itself, or a twist that wraps past pi within
/// a substep.
fn rest_rates(r: &mut StdRng, bend_rest: Vec3, adversarial: bool) -> (Vec3, f32) {
    match r.random_range(0..if adversarial { 6 } else { 3 }) {
        0 => (Vec3::ZERO, 0.0),
        1 => (
            Vec3::new(
                r.random_range(-5.0..5.0),
                r.random_range(-5.0..5.0),
                r.random_range(-5.0..5.0),
            ),
            r.random_range(-5.0..5.0),
        ),
        2 => (Vec3::Z * r.random_range(-2.0..2.0), 0.0),
        3 => (bend_rest * 3.0, -1e-30),
        4 => (Vec3::new(0.0, 1e6, -1e6), 1e6),
        _ => (Vec3::new(1e-30, 0.0, 0.0), 300.0),
    }
}

fn scene(seed: u64, blocks: usize, adversarial: bool) -> (RawRows, Vec<RodBlock>) {
    let mut r = StdRng::seed_from_u64(seed);
    let mut rows = rows(&mut r, blocks * BLOCK_LANES, STATICS, adversarial);
    let mut out = Vec::new();
    for block_index in 0..blocks {
        let mut block = RodBlock::padding();
        for lane in 0..BLOCK_LANES {
            if r.random_bool(0.1) {
                continue;
            }
            let (body_a, body_b) =
                lane_bodies(&mut r, &rows, block_index * BLOCK_LANES + lane, STATICS);
            let mut frame_a = unit_quat(&mut r);
            let mut frame_b = unit_quat(&mut r);
            let pose = |rows: &RawRows, row: u32| rows[row as usize][0];
            if adversarial {
                let qa = Quat::from_slice(&pose(&rows, body_a)[4..]);
                let qb = Quat::from_slice(&pose(&rows, body_b)[4..]);
                match r.random_range(0..4) {
                    // Straight: both tangents along the chord.
                    0 => {
                        let pa = Vec3::from_slice(&pose(&rows, body_a)[..3]);
                        let pb = Vec3::from_slice(&pose(&rows, body_b)[..3]);
                        let o = (pb - pa).normalize_or(Vec3::X);
                        frame_a = qa.inverse() * Quat::from_rotation_arc(Vec3::X, o);
                        frame_b = qb.inverse() * Quat::from_rotation_arc(Vec3::X, o);
                    }
                    // Folded back: t_b = -t_a.
                    1 => {
                        frame_b = qb.inverse()
                            * qa
                            * frame_a
                            * Quat::from_rotation_y(core::f32::consts::PI)
                    }
                    // Coincident ends (only where b's row is its own).
                    2 if dynamic(&rows, body_b) && body_b as usize <= blocks * BLOCK_LANES * 2 => {
                        let pa: [f32; 3] = pose(&rows, body_a)[..3].try_into().unwrap();
                        rows[body_b as usize][0][..3].copy_from_slice(&pa);
                    }
                    _ => {}
                }
            }
            let pi = core::f32::consts::PI;
            let bend_rest = (Quat::from_rotation_z(r.random_range(0.0..2.0)) * Vec3::X).normalize();
            let twist_rest = if adversarial && r.random_bool(0.2) {
                pi - 1e-3
            } else {
                r.random_range(-0.5..0.5)
            };
            let (bend_rest_velocity, twist_rest_velocity) =
                rest_rates(&mut r, bend_rest, adversarial);
            block.set(
                lane,
                &RodLane {
                    pair: common::pair(&rows, body_a, body_b),
                    frame_a,
                    frame_b,
                    rest_length: if adversarial && r.random_bool(0.1) {
                        1e-6
                    } else {
                        r.random_range(0.1..2.0)
                    },
                    bend_rest,
                    twist_rest,
                    bend_rest_velocity,
                    twist_rest_velocity,
                    bend: softness(&mut r),
                    twist: softness(&mut r),
                    bend_max: if r.random_bool(0.7) {
                        r.random_range(0.0..pi)
                    } else {
                        pi
                    },
                    twist_range: if r.random_bool(0.7) {
                        let lo = r.random_range(-3.0..0.5f32);
                        [lo, r.random_range(lo..3.1)]
                    } else {
                        [-pi, pi]
                    },
                    max_torque: max_torque(&mut r),
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

fn run(backend: Backend, raw: &RawRows, blocks: &[RodBlock]) -> Vec<f32> {
    let rows = to_rows(raw);
    let mut blocks = blocks.to_vec();
    // Two substeps: the second damps against a start taken after the first
    // moved the bodies and the rest.
    for _ in 0..2 {
        pass::run::<rod::Starts>(backend, &mut blocks, &rows, 1.0 / 60.0);
        blocks.iter_mut().for_each(RodBlock::reset_lambdas);
        for _ in 0..4 {
            pass::run::<rod::Positions>(backend, &mut blocks, &rows, SCALE);
        }
    }
    let mut residual = vec![[0.0f32; 3]; blocks.len() * BLOCK_LANES];
    backend.dispatch(ResidualPass {
        blocks: &blocks,
        rows: &rows,
        out: &mut residual,
    });
    let mut out = flatten(&rows);
    for b in &blocks {
        out.extend(b.bend_lambda);
        out.extend(b.twist_lambda);
        out.extend(b.twist_start);
        out.extend(b.twist_rest);
        for lane in 0..BLOCK_LANES {
            out.extend(b.bend_start.get(lane).to_array());
            out.extend(b.bend_rest.get(lane).to_array());
        }
    }
    out.extend(residual.iter().flatten());
    out
}

#[test]
fn random_rods_agree_on_every_backend() {
    agree_over_seeds(0..40, false, scene, run);
}

#[test]
fn adversarial_rods_agree_on_every_backend_and_stay_finite() {
    agree_over_seeds(200..280, true, scene, run);
}

#[test]
fn blocks_of_one_to_eight_rods_agree_on_every_backend() {
    common::padded_blocks_agree(400..406, scene, RodBlock::clear, run);
}
