//! Pins (`direct::pin`): a 69 kg trunk fixed to a 1 kg foot box standing on
//! the ground on four pinned corners, one substep of 1/60 s solved from its
//! prediction, against the closed forms of a rigid body on the ground: held
//! up whole, sliding at Coulomb's deceleration, held where friction
//! suffices, let go when lifted; and every backend the scalar's bits with
//! random pins in every lane.

mod common;

use common::{flatten, to_rows};
use glam::{DVec3, Mat3, Quat, Vec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::{BodyRows, LaneBlock, PairLane, StartLane};
use vertebra_kernels::direct::pin::{PIN_STIFFNESS, PinLane, PinNode};
use vertebra_kernels::direct::rows::JointRows;
use vertebra_kernels::direct::{JointLane, MAX_PASSES, PositionPass, Topology, TreeBlock};
use vertebra_kernels::pass::SubstepScale;
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;

/// The substep (s) and gravity (m/s^2).
const H: f32 = 1.0 / 60.0;
const G: f32 = 9.81;
const SCALE: SubstepScale = SubstepScale {
    inv_h: 60.0,
    inv_h2: 3600.0,
};

/// The foot's half extents (m) and the two masses (kg).
const FOOT: Vec3 = Vec3::new(0.3, 0.04, 0.3);
const FOOT_MASS: f32 = 1.0;
const TRUNK_MASS: f32 = 69.0;
const TOTAL: f32 = FOOT_MASS + TRUNK_MASS;
/// The trunk's centre above the foot's (m).
const TRUNK_UP: f32 = 0.5;

/// Rows: 1 the foot, 2 the trunk, 3 the ground (static, at the origin).
const FOOT_ROW: u32 = 1;
const TRUNK_ROW: u32 = 2;
const GROUND_ROW: u32 = 3;

fn box_inertia(mass: f32, half: Vec3) -> Mat3 {
    let s = half * 2.0;
    Mat3::from_diagonal(
        Vec3::new(
            s.y * s.y + s.z * s.z,
            s.x * s.x + s.z * s.z,
            s.x * s.x + s.y * s.y,
        ) * (mass / 12.0),
    )
}

fn foot_centre() -> DVec3 {
    DVec3::new(0.0, f64::from(FOOT.y), 0.0)
}

fn trunk_centre() -> DVec3 {
    foot_centre() + DVec3::new(0.0, f64::from(TRUNK_UP), 0.0)
}

const TRUNK_HALF: Vec3 = Vec3::new(0.15, 0.3, 0.1);

/// One standing foot and trunk per lane: the trunk fixed to the foot, the
/// foot's four bottom corners pinned to the ground with friction `mu[lane]`.
fn block(topology: &Topology, mu: &[f32; BLOCK_LANES], lanes: usize) -> TreeBlock {
    let mut block = TreeBlock::padding(0, topology);
    block.take_pins();
    let joint_at = foot_centre() + DVec3::new(0.0, f64::from(FOOT.y), 0.0);
    for (lane, &mu) in mu.iter().enumerate().take(lanes) {
        block.padding &= !(1 << lane);
        let (foot, trunk) = (lane_row(FOOT_ROW, lane), lane_row(TRUNK_ROW, lane));
        block.bodies[0].set(lane, foot, true, FOOT_MASS, box_inertia(FOOT_MASS, FOOT));
        block.bodies[1].set(
            lane,
            trunk,
            true,
            TRUNK_MASS,
            box_inertia(TRUNK_MASS, TRUNK_HALF),
        );
        let anchor_a = (joint_at - foot_centre()).as_vec3();
        let anchor_b = (joint_at - trunk_centre()).as_vec3();
        let joint = JointLane {
            body_a: foot,
            body_b: trunk,
            anchor_a,
            anchor_b,
            ..JointLane::FREE
        };
        block.joints[0].set(lane, &joint);
        let start = StartLane::new(
            foot_centre(),
            Quat::IDENTITY,
            anchor_a,
            trunk_centre(),
            Quat::IDENTITY,
            anchor_b,
        );
        block.joints[0].bodies.set_start(lane, &start);
        let ground = lane_row(GROUND_ROW, lane);
        for (k, (sx, sz)) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
            .into_iter()
            .enumerate()
        {
            let corner = Vec3::new(sx * FOOT.x, 0.0, sz * FOOT.z);
            let on_foot = corner - foot_centre().as_vec3();
            let pin = PinLane {
                pair: PairLane {
                    body_a: ground,
                    body_b: foot,
                    dynamic_a: false,
                    dynamic_b: true,
                },
                point_a: corner,
                point_b: on_foot,
                normal: Vec3::Y,
                friction: mu,
                overlap: 0.0,
                start: StartLane::new(
                    DVec3::ZERO,
                    Quat::IDENTITY,
                    corner,
                    foot_centre(),
                    Quat::IDENTITY,
                    on_foot,
                ),
                tree_is_b: true,
            };
            block.pins[0].set(lane, k, &pin, PIN_STIFFNESS * TOTAL);
        }
    }
    block
}

/// Lane `lane`'s row of body `row` (three rows a lane).
fn lane_row(row: u32, lane: usize) -> u32 {
    row + 3 * lane as u32
}

/// One lane's bodies as the substep predicted them: both moved by
/// `offset` (m, world) and turned by nothing, moving at `velocity`.
#[derive(Clone, Copy)]
struct Predicted {
    offset: Vec3,
    velocity: Vec3,
}

fn rows(lanes: &[Predicted]) -> BodyRows {
    let mut raw = vec![BodyRows::null_raw(); 1 + 3 * lanes.len()];
    for (lane, p) in lanes.iter().enumerate() {
        let body = |mass: f32, half: Vec3| {
            [
                BodyRows::pose_row(p.offset, 1.0 / mass, Quat::IDENTITY),
                BodyRows::inertia_row(box_inertia(mass, half).inverse()),
                BodyRows::velocity_row(p.velocity, Vec3::ZERO),
            ]
        };
        raw[lane_row(FOOT_ROW, lane) as usize] = body(FOOT_MASS, FOOT);
        raw[lane_row(TRUNK_ROW, lane) as usize] = body(TRUNK_MASS, TRUNK_HALF);
        raw[lane_row(GROUND_ROW, lane) as usize][0] =
            BodyRows::pose_row(Vec3::ZERO, 0.0, Quat::IDENTITY);
    }
    to_rows(&raw)
}

fn topology() -> Topology {
    Topology::new(2, &[(JointRows::Fixed, Some(0), Some(1))]).expect("a tree")
}

/// Solves one lane's substep from `predicted` with friction `mu`: the
/// trunk's displacement (m, world) and the pins' summed impulse on the
/// foot (kg m, world: the ground's normal along +y).
fn solve(predicted: Predicted, mu: f32) -> (Vec3, Vec3) {
    let topology = topology();
    let mut blocks = [block(&topology, &[mu; BLOCK_LANES], 1)];
    let rows = rows(&[predicted]);
    run(Backend::Scalar, &rows, &mut blocks, &topology);
    let trunk = vertebra_kernels::body::BodyLanes::<f32>::gather(&rows, &[TRUNK_ROW]).p;
    let pins: &PinNode = &blocks[0].pins[0];
    let pushed = (0..4)
        .filter_map(|k| pins.substep(0, k))
        .map(|(normal, friction)| Vec3::Y * normal + friction)
        .sum();
    (trunk.into(), pushed)
}

fn run(backend: Backend, rows: &BodyRows, blocks: &mut [TreeBlock], topology: &Topology) {
    PositionPass {
        blocks,
        topologies: core::slice::from_ref(topology),
        rows,
        scale: SCALE,
        passes: MAX_PASSES,
    }
    .run(backend);
}

/// What gravity gives in a substep (m): `g h^2`.
fn sag() -> f32 {
    G * H * H
}

#[test]
fn standing_on_pins_holds_the_whole_tree_up() {
    let (trunk, pushed) = solve(
        Predicted {
            offset: Vec3::new(0.0, -sag(), 0.0),
            velocity: Vec3::new(0.0, -G * H, 0.0),
        },
        0.5,
    );
    // Held to a hundredth of a substep's sag, where an iterated contact
    // keeps 1/70 of each push on the 1 kg foot.
    assert!(trunk.y.abs() < 0.01 * sag(), "trunk {trunk}");
    assert!(
        trunk.x.abs() < 1e-7 && trunk.z.abs() < 1e-7,
        "trunk {trunk}"
    );
    let expected = TOTAL * sag();
    assert!(
        (pushed.y - expected).abs() < 0.01 * expected,
        "normal impulse {} against {expected}",
        pushed.y
    );
}

#[test]
fn sliding_on_pins_decelerates_at_coulombs_rate() {
    let mu = 0.4;
    let speed = 2.0;
    let (trunk, pushed) = solve(
        Predicted {
            offset: Vec3::new(speed * H, -sag(), 0.0),
            velocity: Vec3::new(speed, -G * H, 0.0),
        },
        mu,
    );
    let expected = speed * H - mu * sag();
    assert!(
        (trunk.x - expected).abs() < 0.02 * mu * sag(),
        "slid {} against {expected}",
        trunk.x
    );
    let friction = Vec3::new(pushed.x, 0.0, pushed.z).length();
    assert!(
        (friction - mu * pushed.y).abs() < 0.01 * mu * pushed.y,
        "friction {friction} against mu x {}",
        pushed.y
    );
    assert!(pushed.x < 0.0, "friction against the slide: {pushed}");
}

#[test]
fn a_push_within_the_cone_is_held() {
    let mu = 0.4;
    let push = 0.5 * mu * sag();
    let (trunk, _) = solve(
        Predicted {
            offset: Vec3::new(push, -sag(), -push),
            velocity: Vec3::new(push / H, -G * H, -push / H),
        },
        mu,
    );
    // A held pin gives way by what it holds over its stiffness: the whole
    // push's 1 / PIN_STIFFNESS.
    let give = 1.5 / PIN_STIFFNESS * push;
    assert!(
        trunk.x.abs() < give && trunk.z.abs() < give,
        "moved {trunk} under a push of {push}"
    );
}

#[test]
fn a_push_beyond_the_cone_slides_by_what_coulomb_leaves() {
    let mu = 0.4;
    let push = 3.0 * mu * sag();
    // Still as the solve starts: the held pass finds the way.
    let (trunk, pushed) = solve(
        Predicted {
            offset: Vec3::new(0.0, -sag(), push),
            velocity: Vec3::ZERO,
        },
        mu,
    );
    let expected = push - mu * sag();
    assert!(
        (trunk.z - expected).abs() < 0.03 * mu * sag(),
        "slid {} against {expected}",
        trunk.z
    );
    assert!(trunk.x.abs() < 0.01 * mu * sag(), "sideways {}", trunk.x);
    assert!(pushed.z < 0.0, "friction against the push: {pushed}");
}

#[test]
fn a_lifted_tree_is_let_go() {
    let lift = Vec3::new(0.0, 0.01, 0.0);
    let (trunk, pushed) = solve(
        Predicted {
            offset: lift,
            velocity: lift / H,
        },
        0.5,
    );
    assert_eq!(trunk, lift);
    assert_eq!(pushed, Vec3::ZERO);
}

#[test]
fn every_backend_solves_random_pins_to_the_scalar_bits() {
    let topology = topology();
    for seed in 0..20u64 {
        let mut r = StdRng::seed_from_u64(seed);
        let lanes = r.random_range(1..=BLOCK_LANES);
        let mu: [f32; BLOCK_LANES] = core::array::from_fn(|_| r.random_range(0.0..1.2));
        let predicted: Vec<Predicted> = (0..lanes)
            .map(|_| {
                let speed = if r.random_bool(0.5) { 2.0 } else { 0.004 };
                let way = Vec3::new(r.random_range(-1.0..1.0), 0.0, r.random_range(-1.0..1.0));
                let lift = if r.random_bool(0.2) { 0.01 } else { -sag() };
                Predicted {
                    offset: way * (speed * H) + Vec3::new(0.0, lift, 0.0),
                    velocity: way * speed,
                }
            })
            .collect();
        let solved = |backend: Backend| {
            let mut blocks = [block(&topology, &mu, lanes)];
            let rows = rows(&predicted);
            run(backend, &rows, &mut blocks, &topology);
            let mut bits = flatten(&rows);
            for k in 0..4 {
                for lane in 0..lanes {
                    let (normal, friction) = blocks[0].pins[0].substep(lane, k).unwrap();
                    bits.push(normal);
                    bits.extend(friction.to_array());
                }
            }
            bits
        };
        let reference = solved(Backend::Scalar);
        for backend in Backend::available() {
            let got = solved(backend);
            let same = reference
                .iter()
                .zip(&got)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(
                same,
                "seed {seed}: {backend:?} differs from the scalar path"
            );
        }
    }
}
