//! The contact kernel's passes give the scalar reference's bits on every
//! backend, for random and adversarial contacts.

mod common;

use common::{RawRows, agree_over_seeds, flatten, lane_bodies, rows, to_rows, unit_quat, vec};
use glam::Vec3;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::{LaneBlock, PairLane};
use vertebra_kernels::contact::{self, ContactBlock, ContactLane, VelocitySettings};
use vertebra_kernels::pass;
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;

const STATICS: usize = 4;

fn scene(seed: u64, blocks: usize, adversarial: bool) -> (RawRows, Vec<ContactBlock>) {
    let mut r = StdRng::seed_from_u64(seed);
    let rows = rows(&mut r, blocks * BLOCK_LANES, STATICS, adversarial);
    let mut out = Vec::new();
    for block_index in 0..blocks {
        let mut block = ContactBlock::padding();
        for lane in 0..BLOCK_LANES {
            if r.random_bool(0.1) {
                continue;
            }
            let (body_a, body_b) =
                lane_bodies(&mut r, &rows, block_index * BLOCK_LANES + lane, STATICS);
            let normal = unit_quat(&mut r) * Vec3::Y;
            let (point_a, point_b) = if adversarial && r.random_bool(0.3) {
                (Vec3::ZERO, Vec3::ZERO) // at the centres of mass: no lever
            } else {
                (vec(&mut r, 0.5), vec(&mut r, 0.5))
            };
            block.set(
                lane,
                &ContactLane {
                    pair: common::pair(&rows, body_a, body_b),
                    point_a,
                    point_b,
                    normal,
                    friction: if adversarial && r.random_bool(0.2) {
                        0.0
                    } else {
                        r.random_range(0.0..2.0)
                    },
                    restitution: r.random_range(0.0..=1.0),
                    approach: r.random_range(-10.0..10.0),
                    overlap: r.random_range(0.0..0.1),
                    start: common::start(&mut r, adversarial),
                    pinned: r.random_bool(0.2),
                },
            );
        }
        out.push(block);
    }
    (rows, out)
}

fn run(backend: Backend, raw: &RawRows, blocks: &[ContactBlock]) -> Vec<f32> {
    let rows = to_rows(raw);
    let mut blocks = blocks.to_vec();
    for _ in 0..4 {
        pass::run::<contact::Positions>(backend, &mut blocks, &rows, ());
    }
    // The velocity pass, then two relax passes.
    for relax in [false, true, true] {
        let settings = VelocitySettings {
            h: 1.0 / 60.0,
            resting_speed: 0.33,
            relax,
        };
        pass::run::<contact::Velocities>(backend, &mut blocks, &rows, settings);
    }
    let mut out = flatten(&rows);
    for b in &blocks {
        out.extend(b.lambda_n);
        out.extend(b.lambda_v);
        out.extend(b.kicked_n);
        for v in [&b.lambda_t, &b.kicked_t] {
            out.extend(bytemuck::cast_slice::<_, f32>(core::slice::from_ref(v)));
        }
    }
    out
}

#[test]
fn random_contacts_agree_on_every_backend() {
    agree_over_seeds(0..40, false, scene, run);
}

#[test]
fn adversarial_contacts_agree_on_every_backend_and_stay_finite() {
    agree_over_seeds(300..360, true, scene, run);
}

/// A padding lane as `ContactBlock::padding` makes it: null rows, no writes.
fn clear(block: &mut ContactBlock, lane: usize) {
    block.bodies.set(lane, &PairLane::NULL);
}

#[test]
fn blocks_of_one_to_eight_contacts_agree_on_every_backend() {
    common::padded_blocks_agree(400..406, scene, clear, run);
}
