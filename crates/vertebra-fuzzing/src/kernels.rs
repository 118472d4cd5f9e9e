//! Arbitrary lanes through the socket (plain and shaped), hinge, fixed,
//! rod and contact kernels, and the direct solve.

use core::f32::consts::PI;

use glam::{Mat3, Vec3};
use vertebra_kernels::body::{BodyRows, JointFrames, LaneBlock, PairLane, StartLane};
use vertebra_kernels::contact::{self, ContactBlock, ContactLane};
use vertebra_kernels::direct::{self, JointLane, JointRows, SwingRows, Topology, TreeBlock};
use vertebra_kernels::driven::{self, DriveLane};
use vertebra_kernels::fixed::{self, FixedBlock, FixedLane};
use vertebra_kernels::hinge::{self, HingeBlock, HingeLane};
use vertebra_kernels::limited::{self, LimitLane};
use vertebra_kernels::pass::{self, SubstepScale};
use vertebra_kernels::rod::{self, RodBlock, RodLane, RodSoftness};
use vertebra_kernels::socket::{self, ShapedLimits, SocketBlock, SocketLane};
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;
use vertebra_math::check::same_bits;

use crate::input::Input;

/// Rows per lane pair plus two static rows at the end (row 0 is null).
const BODIES: usize = 2 * BLOCK_LANES + 2;

type RawRows = Vec<[[f32; 8]; 3]>;

fn raw_rows(input: &mut Input) -> RawRows {
    let mut rows = vec![BodyRows::null_raw(); BODIES + 1];
    for (i, row) in rows.iter_mut().enumerate().skip(1) {
        let fixed = i > 2 * BLOCK_LANES || input.pick(10) == 0;
        let inverse_mass = if fixed { 0.0 } else { input.positive(10.0) };
        let axes = Mat3::from_quat(input.quat());
        let diagonal = Vec3::new(
            input.positive(50.0),
            input.positive(50.0),
            input.positive(50.0),
        );
        let inverse_inertia = if fixed {
            Mat3::ZERO
        } else {
            axes * Mat3::from_diagonal(diagonal) * axes.transpose()
        };
        *row = [
            BodyRows::pose_row(input.vec3(5.0), inverse_mass, input.quat()),
            BodyRows::inertia_row(inverse_inertia),
            BodyRows::velocity_row(input.vec3(10.0), input.vec3(10.0)),
        ];
    }
    rows
}

/// Lane `k`'s two rows: its own pair, or a static row on one side (a
/// written row belongs to one lane only, as the colouring ensures).
fn lane_bodies(input: &mut Input, rows: &RawRows, k: usize) -> (u32, u32, bool, bool) {
    let own = |j: usize| (1 + 2 * k + j) as u32;
    let fixed = (2 * BLOCK_LANES + 1 + input.pick(2)) as u32;
    let (a, b) = match input.pick(4) {
        0 => (fixed, own(1)),
        1 => (own(0), fixed),
        _ => (own(0), own(1)),
    };
    let dynamic = |row: u32| rows[row as usize][0][3] > 0.0;
    (a, b, dynamic(a), dynamic(b))
}

fn sorted_range(input: &mut Input) -> [f32; 2] {
    let (x, y) = (input.float(PI), input.float(PI));
    if x <= y { [x, y] } else { [y, x] }
}

fn softness(input: &mut Input) -> RodSoftness {
    match input.pick(4) {
        0 => RodSoftness::Compliance(input.float(1.0).abs()),
        1 => RodSoftness::Damped {
            compliance: input.float(1.0).abs(),
            damping_time: input.float(1.0).abs(),
        },
        2 => RodSoftness::Spring {
            period2: input.float(1.0).abs(),
            damping_time: input.float(1.0).abs(),
        },
        _ => RodSoftness::Relaxation(input.float(1.0).abs().min(1.0)),
    }
}

/// A start of step for one lane (see `vertebra_kernels::body::PairStart`).
fn start(input: &mut Input) -> StartLane {
    StartLane {
        gap: input.vec3(1.0),
        arm_a: input.vec3(1.0),
        arm_b: input.vec3(1.0),
    }
}

fn socket_block(input: &mut Input, rows: &RawRows) -> SocketBlock {
    let mut block = SocketBlock::padding();
    for k in 0..BLOCK_LANES {
        let (body_a, body_b, dynamic_a, dynamic_b) = lane_bodies(input, rows, k);
        let lane = SocketLane {
            pair: PairLane {
                body_a,
                body_b,
                dynamic_a,
                dynamic_b,
            },
            frames: JointFrames {
                anchor_a: input.vec3(1.0),
                anchor_b: input.vec3(1.0),
                frame_a: input.quat(),
                frame_b: input.quat(),
            },
            swing_max: input.float(PI).abs().min(PI),
            twist: sorted_range(input),
            drive: input.flag().then(|| drive_lane(input)),
            shaped: shaped(input),
        };
        block.set(k, &lane);
        block.bodies.set_start(k, &start(input));
    }
    block
}

/// A drive's lane: any target, velocity and settings of its ranges.
fn drive_lane(input: &mut Input) -> DriveLane {
    DriveLane {
        target: input.quat(),
        velocity: input.vec3(20.0),
        compliance: input.float(1.0).abs(),
        period2: input.float(1.0).abs(),
        damping_time: input.float(1.0).abs(),
        max_torque: input.float(100.0).abs(),
    }
}

/// Shaped limits: semi-axes in (0, 1], angle ranges within [-pi, pi].
fn shaped(input: &mut Input) -> ShapedLimits {
    let semi = |x: f32| x.abs().clamp(1e-3, 1.0);
    ShapedLimits {
        ellipse: [semi(input.float(1.0)), semi(input.float(1.0))],
        pyramid: [sorted_range(input), sorted_range(input)],
        softness: limit_lane(input),
    }
}

/// A limit's softness: any settings of its ranges (hard among them).
fn limit_lane(input: &mut Input) -> LimitLane {
    LimitLane {
        compliance: input.float(1.0).abs(),
        period2: input.float(1.0).abs(),
        damping_time: input.float(1.0).abs(),
    }
}

fn hinge_block(input: &mut Input, rows: &RawRows) -> HingeBlock {
    let mut block = HingeBlock::padding();
    for k in 0..BLOCK_LANES {
        let (body_a, body_b, dynamic_a, dynamic_b) = lane_bodies(input, rows, k);
        let lane = HingeLane {
            pair: PairLane {
                body_a,
                body_b,
                dynamic_a,
                dynamic_b,
            },
            frames: JointFrames {
                anchor_a: input.vec3(1.0),
                anchor_b: input.vec3(1.0),
                frame_a: input.quat(),
                frame_b: input.quat(),
            },
            range: sorted_range(input),
            softness: limit_lane(input),
            drive: input.flag().then(|| drive_lane(input)),
        };
        block.set(k, &lane);
        block.bodies.set_start(k, &start(input));
    }
    block
}

fn fixed_block(input: &mut Input, rows: &RawRows) -> FixedBlock {
    let mut block = FixedBlock::padding();
    for k in 0..BLOCK_LANES {
        let (body_a, body_b, dynamic_a, dynamic_b) = lane_bodies(input, rows, k);
        let lane = FixedLane {
            pair: PairLane {
                body_a,
                body_b,
                dynamic_a,
                dynamic_b,
            },
            frames: JointFrames {
                anchor_a: input.vec3(1.0),
                anchor_b: input.vec3(1.0),
                frame_a: input.quat(),
                frame_b: input.quat(),
            },
        };
        block.set(k, &lane);
        block.bodies.set_start(k, &start(input));
    }
    block
}

fn rod_block(input: &mut Input, rows: &RawRows) -> RodBlock {
    let mut block = RodBlock::padding();
    for k in 0..BLOCK_LANES {
        let (body_a, body_b, dynamic_a, dynamic_b) = lane_bodies(input, rows, k);
        let lane = RodLane {
            pair: PairLane {
                body_a,
                body_b,
                dynamic_a,
                dynamic_b,
            },
            frame_a: input.quat(),
            frame_b: input.quat(),
            rest_length: input.float(2.0).abs().max(1e-3),
            bend_rest: input.vec3(1.0).try_normalize().unwrap_or(Vec3::X),
            twist_rest: input.float(PI),
            bend_rest_velocity: Vec3::ZERO,
            twist_rest_velocity: 0.0,
            bend: softness(input),
            twist: softness(input),
            bend_max: input.float(PI).abs().min(PI),
            twist_range: sorted_range(input),
            max_torque: input.float(100.0).abs(),
        };
        block.set(k, &lane);
        block.bodies.set_start(k, &start(input));
    }
    block
}

/// The rods' rest rates (rad/s), zero or not lane by lane; read after
/// everything else, so that older corpus files keep their meaning (their
/// rods' rests stay still).
fn rest_rates(input: &mut Input, block: &mut RodBlock) {
    for k in 0..BLOCK_LANES {
        if input.flag() {
            block.bend_rest_velocity.set(k, input.vec3(10.0));
            block.twist_rest_velocity[k] = input.float(10.0);
        }
    }
}

fn contact_block(input: &mut Input, rows: &RawRows) -> ContactBlock {
    let mut block = ContactBlock::padding();
    for k in 0..BLOCK_LANES {
        let (body_a, body_b, dynamic_a, dynamic_b) = lane_bodies(input, rows, k);
        let lane = ContactLane {
            pair: PairLane {
                body_a,
                body_b,
                dynamic_a,
                dynamic_b,
            },
            point_a: input.vec3(1.0),
            point_b: input.vec3(1.0),
            normal: input.vec3(1.0).try_normalize().unwrap_or(Vec3::Y),
            friction: input.float(2.0).abs(),
            restitution: input.float(1.0).abs().min(1.0),
            approach: input.float(10.0),
            overlap: input.float(0.1).abs(),
            start: start(input),
            pinned: input.flag(),
        };
        block.set(k, &lane);
        block.bodies.set_start(k, &start(input));
    }
    block
}

/// One block of each kernel.
type Blocks = (SocketBlock, RodBlock, ContactBlock, HingeBlock, FixedBlock);

/// One time in four, every block keeps only the lanes of an arbitrary
/// pattern and the rest become padding (as a colour's last block, or a
/// single ragdoll's, is mostly padding): the backends then skip slices or
/// run half a block at four lanes, and must still give the scalar bits.
fn pad(input: &mut Input, blocks: &mut Blocks) {
    if input.pick(4) != 0 {
        return;
    }
    let live = input.pick(1 << BLOCK_LANES);
    for lane in 0..BLOCK_LANES {
        if live & (1 << lane) == 0 {
            blocks.0.clear(lane);
            blocks.1.clear(lane);
            blocks.2.bodies.set(lane, &PairLane::NULL);
            blocks.3.clear(lane);
            blocks.4.clear(lane);
        }
    }
}

/// A block of direct-solve trees of one shape: each lane's own two rows
/// joined by a joint of any kind, and now and then a second joint (any
/// kind) from a static row to the first body, the tree's root; masses and
/// inertias arbitrary, sockets and hinges driven or not, lanes padding at
/// random.
fn tree_block(input: &mut Input) -> (Topology, TreeBlock) {
    let kinds = [
        JointRows::Socket(SwingRows::Cone, false),
        JointRows::Socket(SwingRows::Ellipse, true),
        JointRows::Socket(SwingRows::Pyramid, false),
        JointRows::Socket(SwingRows::Pyramid, true),
        JointRows::Hinge(false),
        JointRows::Hinge(true),
        JointRows::Fixed,
        JointRows::Rod,
    ];
    let mut shape = vec![(kinds[input.pick(kinds.len())], Some(0), Some(1))];
    let grounded = input.flag();
    if grounded {
        shape.push((kinds[input.pick(kinds.len())], None, Some(0)));
    }
    let topology = Topology::new(2, &shape).expect("a tree");
    let mut block = TreeBlock::padding(0, &topology);
    let fixed = (2 * BLOCK_LANES + 1) as u32;
    for lane in 0..BLOCK_LANES {
        if input.pick(8) == 0 {
            continue; // a padding lane
        }
        block.padding &= !(1 << lane);
        let own = |j: usize| (1 + 2 * lane + j) as u32;
        for (k, node) in block.bodies.iter_mut().enumerate() {
            let inertia = Mat3::from_diagonal(Vec3::new(
                input.positive(5.0),
                input.positive(5.0),
                input.positive(5.0),
            ));
            node.set(lane, own(k), true, input.positive(50.0), inertia);
        }
        let sides = [(own(0), own(1)), (fixed, own(0))];
        for ((joint, &(a, b)), &(kind, ..)) in block.joints.iter_mut().zip(&sides).zip(&shape) {
            let twist = sorted_range(input);
            let drivable = kind.count() > kind.first_drive();
            let drive = (drivable && input.flag()).then(|| drive_lane(input));
            joint.set(
                lane,
                &JointLane {
                    body_a: a,
                    body_b: b,
                    anchor_a: input.vec3(0.5),
                    anchor_b: input.vec3(0.5),
                    frame_a: input.quat(),
                    frame_b: input.quat(),
                    rest_length: input.positive(1.0),
                    swing_max: input.float(PI).abs(),
                    twist,
                    ellipse: [input.positive(1.0), input.positive(1.0)],
                    pyramid: [sorted_range(input), sorted_range(input)],
                    softness: if input.flag() {
                        LimitLane {
                            compliance: input.positive(1.0),
                            period2: input.positive(0.01),
                            damping_time: input.positive(0.1),
                        }
                    } else {
                        LimitLane::HARD
                    },
                    drive,
                },
            );
            block.soft |= joint.is_soft(lane);
            block.driven |= drive.is_some();
            joint.bodies.set_start(lane, &start(input));
        }
    }
    (topology, block)
}

/// One position pass of each kernel over the same rows, on `backend`:
/// every row's pose afterwards.
fn run(
    backend: Backend,
    raw: &RawRows,
    blocks: &Blocks,
    (topology, tree): &(Topology, TreeBlock),
    inv_h2: f32,
) -> Vec<f32> {
    let rows = BodyRows::from_raw(raw);
    let (mut sockets, mut rods, mut contacts) = ([blocks.0], [blocks.1], [blocks.2]);
    let (mut hinges, mut fixed) = ([blocks.3], [blocks.4]);
    let h = 1.0 / inv_h2.sqrt();
    let scale = SubstepScale {
        inv_h: inv_h2.sqrt(),
        inv_h2,
    };
    pass::run::<driven::Starts<SocketBlock>>(backend, &mut sockets, &rows, h);
    pass::run::<driven::Starts<HingeBlock>>(backend, &mut hinges, &rows, h);
    // The limits' start before the plain pass moves the bodies: the shaped
    // path's damping then sees a nonzero `C - C_0`.
    pass::run::<limited::Starts<SocketBlock>>(backend, &mut sockets, &rows, ());
    pass::run::<limited::Starts<HingeBlock>>(backend, &mut hinges, &rows, ());
    pass::run::<socket::Positions<true, false>>(backend, &mut sockets, &rows, scale);
    pass::run::<socket::Positions<true, true>>(backend, &mut sockets, &rows, scale);
    pass::run::<hinge::Positions<true>>(backend, &mut hinges, &rows, scale);
    pass::run::<fixed::Positions>(backend, &mut fixed, &rows, ());
    pass::run::<rod::Starts>(backend, &mut rods, &rows, h);
    pass::run::<rod::Positions>(backend, &mut rods, &rows, scale);
    pass::run::<contact::Positions>(backend, &mut contacts, &rows, ());
    let mut trees = [tree.clone()];
    backend.dispatch(direct::StartPass {
        blocks: &mut trees,
        topologies: core::slice::from_ref(topology),
        rows: &rows,
        h,
    });
    direct::PositionPass {
        blocks: &mut trees,
        topologies: core::slice::from_ref(topology),
        rows: &rows,
        scale,
        passes: direct::MAX_PASSES,
    }
    .run(backend);
    (0..rows.pose.len())
        .flat_map(|i| rows.pose[i].get())
        .collect()
}

/// Arbitrary bodies and lanes (unit or arbitrary quaternions, any floats one
/// time in eight) through the socket (with drive, plain and shaped), hinge
/// (with drive), fixed, rod and contact position passes and the direct
/// solve of a block of trees: every backend gives the scalar reference's bits, and input with
/// no wild value gives finite poses.
pub fn kernels(data: &[u8]) {
    let mut input = Input::new(data);
    let raw = raw_rows(&mut input);
    let mut blocks = (
        socket_block(&mut input, &raw),
        rod_block(&mut input, &raw),
        contact_block(&mut input, &raw),
        hinge_block(&mut input, &raw),
        fixed_block(&mut input, &raw),
    );
    let inv_h2 = 1.0 / (input.positive(0.05) * input.positive(0.05));
    rest_rates(&mut input, &mut blocks.1);
    pad(&mut input, &mut blocks);
    let tree = tree_block(&mut input);
    let expected = run(Backend::Scalar, &raw, &blocks, &tree, inv_h2);
    for backend in Backend::available() {
        let actual = run(backend, &raw, &blocks, &tree, inv_h2);
        if let Some(k) = (0..expected.len()).find(|&k| !same_bits(expected[k], actual[k])) {
            panic!(
                "{backend} differs at float {k}: {:e} vs scalar {:e}",
                actual[k], expected[k]
            );
        }
    }
    if !input.wild {
        assert!(
            expected.iter().all(|x| x.is_finite()),
            "finite, valid lanes gave a non-finite pose"
        );
    }
}
