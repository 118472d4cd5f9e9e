//! Workloads shared by the criterion (time) and iai-callgrind (instruction
//! count) benchmarks, so both measure exactly the same work.

use glam::{Mat3, Quat as GQuat, Vec3 as GVec3};
use vertebra_kernels::body::{BodyRows, JointFrames, LaneBlock, PairLane, StartLane};
use vertebra_kernels::contact::{self, ContactBlock, ContactLane};
use vertebra_kernels::driven::DriveLane;
use vertebra_kernels::fixed::{self, FixedBlock, FixedLane};
use vertebra_kernels::hinge::{self, HingeBlock, HingeLane};
use vertebra_kernels::pass::{SubstepScale, run};
use vertebra_kernels::rod::{self, RodBlock, RodLane, RodSoftness};
use vertebra_kernels::socket::{self, ShapedLimits, SocketBlock, SocketLane};
use vertebra_math::block::BLOCK_LANES;
use vertebra_math::map::{LaneMap, map_arrays};
use vertebra_math::{Backend, BackendChoice, Lane, Quat, Vec3, poly};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneConfig, SceneWorld, build};
use vertebra_world::{JointSolver, SolverConfig};

/// The backends the instruction-count benches measure, by argument index:
/// 0 scalar, 1 portable, 2 sse4, 3 avx2 (8 lanes).
pub const INSTRUCTION_BACKENDS: [Backend; 4] = [
    Backend::Scalar,
    Backend::Portable,
    Backend::Sse41,
    Backend::Avx2,
];

/// Elements per workload: 4 KiB per array, in L1 with room to spare.
pub const ELEMENTS: usize = 1024;

/// Input and output arrays for one [`LaneMap`] on one backend.
pub struct Workload {
    backend: Backend,
    inputs: Vec<Vec<f32>>,
    outputs: Vec<Vec<f32>>,
}

impl Workload {
    /// Deterministic inputs in `[lo, hi)` for `map` on `backend`.
    pub fn new<M: LaneMap>(backend: Backend, _map: &M, lo: f32, hi: f32) -> Self {
        if !backend.is_available() {
            eprintln!("warning: {backend} is not available here; it runs as scalar");
        }
        // A low-discrepancy sequence per column: spread, repeatable, no RNG.
        let inputs = (0..M::INPUTS)
            .map(|c| {
                let step = 0.618_034 + 0.1 * c as f32;
                (0..ELEMENTS)
                    .map(|k| lo + (hi - lo) * (k as f32 * step).fract())
                    .collect()
            })
            .collect();
        Self {
            backend,
            inputs,
            outputs: vec![vec![0.0; ELEMENTS]; M::OUTPUTS],
        }
    }

    /// Runs `map` over every element once.
    pub fn run<M: LaneMap>(&mut self, map: &M) {
        let inputs: Vec<&[f32]> = self.inputs.iter().map(|c| c.as_slice()).collect();
        let mut outputs: Vec<&mut [f32]> =
            self.outputs.iter_mut().map(|c| c.as_mut_slice()).collect();
        map_arrays(self.backend, map, &inputs, &mut outputs);
    }

    /// The first output array (to keep the work observable).
    pub fn output(&self) -> &[f32] {
        &self.outputs[0]
    }
}

/// `sin_cos(x)`.
pub struct SinCos;
impl LaneMap for SinCos {
    const INPUTS: usize = 1;
    const OUTPUTS: usize = 2;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        (o[0], o[1]) = poly::sin_cos(i[0]);
    }
}

/// `acos(x)`.
pub struct Acos;
impl LaneMap for Acos {
    const INPUTS: usize = 1;
    const OUTPUTS: usize = 1;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        o[0] = poly::acos(i[0]);
    }
}

/// `atan2(y, x)`.
pub struct Atan2;
impl LaneMap for Atan2 {
    const INPUTS: usize = 2;
    const OUTPUTS: usize = 1;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        o[0] = poly::atan2(i[0], i[1]);
    }
}

/// `sin(x/2)/x`.
pub struct HalfSinc;
impl LaneMap for HalfSinc {
    const INPUTS: usize = 1;
    const OUTPUTS: usize = 1;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        o[0] = poly::half_sinc(i[0]);
    }
}

/// Normalises a quaternion and rotates a vector by it.
pub struct QuatRotate;
impl LaneMap for QuatRotate {
    const INPUTS: usize = 7;
    const OUTPUTS: usize = 3;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        let q = Quat::new(i[0], i[1], i[2], i[3]).normalize();
        let v = q.rotate(Vec3::new(i[4], i[5], i[6]));
        (o[0], o[1], o[2]) = (v.x, v.y, v.z);
    }
}

/// A batch of constraints the joint benchmarks time.
pub trait ConstraintWorkload {
    /// One position iteration over every constraint.
    fn iterate(&mut self);
    /// A value that depends on the work (to keep it observable).
    fn probe(&self) -> f32;
}

/// Where a joint workload's bodies lie in memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// Joint `k` on bodies `2k + 1` and `2k + 2`: gathers walk the rows in
    /// order (with 1024 joints everything fits in L2).
    InCache,
    /// Joint `k` on two bodies scattered by a fixed permutation of all the
    /// bodies: with [`OUT_OF_CACHE_JOINTS`] joints the rows and blocks
    /// (about 90 MB) outgrow the last-level cache, and every gather misses.
    OutOfCache,
}

/// Where the benches' joints sit on their bodies: anchors 11 cm from
/// each centre, frames 0.3 rad apart about z.
fn frames() -> JointFrames {
    JointFrames {
        anchor_a: GVec3::new(0.05, 0.1, 0.0),
        anchor_b: GVec3::new(-0.05, -0.1, 0.0),
        frame_a: GQuat::IDENTITY,
        frame_b: GQuat::from_rotation_z(0.3),
    }
}

/// Joints in an out-of-cache workload: 2^18 joints on 2^19 bodies.
pub const OUT_OF_CACHE_JOINTS: usize = 1 << 18;

impl Placement {
    /// The body rows (1-based: row 0 is the null body) of joint `k` among
    /// `bodies` (a power of two).
    fn bodies(self, k: usize, bodies: usize) -> (u32, u32) {
        let scatter = |i: usize| match self {
            Placement::InCache => i,
            // An odd multiplier is a bijection modulo a power of two.
            Placement::OutOfCache => i.wrapping_mul(0x9E37_79B1) & (bodies - 1),
        };
        ((scatter(2 * k) + 1) as u32, (scatter(2 * k + 1) + 1) as u32)
    }
}

/// A batch of socket joints, each lane on its own two dynamic bodies (as
/// one colour is), the joints violated so every correction does work: point,
/// swing cone and twist range always, the angular drive when `drive`.
pub struct SocketWorkload {
    backend: Backend,
    drive: bool,
    shaped: bool,
    rows: BodyRows,
    blocks: Vec<SocketBlock>,
}

impl SocketWorkload {
    /// `sockets` joints (a power of two, at least 8) on `backend`.
    pub fn new(backend: Backend, sockets: usize, drive: bool, placement: Placement) -> Self {
        if !backend.is_available() {
            eprintln!("warning: {backend} is not available here; it runs as scalar");
        }
        let blocks = sockets.div_ceil(BLOCK_LANES);
        let rows = BodyRows::with_bodies(blocks * BLOCK_LANES * 2);
        let spread = |k: usize, c: f32| (k as f32 * (0.618_034 + c)).fract() - 0.5;
        for body in 0..blocks * BLOCK_LANES * 2 {
            let q = GQuat::from_euler(
                glam::EulerRot::XYZ,
                spread(body, 0.1),
                spread(body, 0.2),
                spread(body, 0.3),
            );
            let p = GVec3::new(
                body as f32 * 0.1,
                spread(body, 0.4),
                spread(body, 0.5) * 0.1,
            );
            let inertia = Mat3::from_diagonal(GVec3::new(20.0, 30.0, 60.0));
            rows.pose[body + 1].set(BodyRows::pose_row(p, 1.0, q));
            rows.inertia[body + 1].set(BodyRows::inertia_row(inertia));
        }
        let mut out = vec![SocketBlock::padding(); blocks];
        for k in 0..blocks * BLOCK_LANES {
            let (body_a, body_b) = placement.bodies(k, blocks * BLOCK_LANES * 2);
            let lane = SocketLane {
                pair: PairLane::dynamic(body_a, body_b),
                frames: frames(),
                swing_max: 0.2,
                twist: [-0.1, 0.1],
                drive: drive.then_some(DriveLane {
                    target: GQuat::from_rotation_x(0.2),
                    compliance: 0.001,
                    damping_time: 0.001,
                    ..DriveLane::OFF
                }),
                shaped: ShapedLimits::FREE,
            };
            out[k / BLOCK_LANES].set(k % BLOCK_LANES, &lane);
        }
        Self {
            backend,
            drive,
            shaped: false,
            rows,
            blocks: out,
        }
    }

    /// The same joints on the shaped path, without drives: an elliptical
    /// cone (0.2 and 0.1 rad), a pyramid (+-0.15 rad about each axis) and
    /// the twist range, all soft (compliance 1e-4 rad / (N m)), all
    /// violated.
    pub fn shaped(backend: Backend, sockets: usize, placement: Placement) -> Self {
        let mut work = Self::new(backend, sockets, false, placement);
        let (y, z) = ((0.1f32).sin(), (0.05f32).sin());
        let range = [-0.15, 0.15];
        for block in &mut work.blocks {
            for lane in 0..BLOCK_LANES {
                (block.ellipse_y[lane], block.ellipse_z[lane]) = (y, z);
                for (k, bound) in range.into_iter().enumerate() {
                    block.pyramid_y[k][lane] = bound;
                    block.pyramid_z[k][lane] = bound;
                }
                block.swing_max[lane] = core::f32::consts::PI;
                block.limit_softness.compliance[lane] = 1e-4;
            }
        }
        work.shaped = true;
        work
    }

    /// The joints in the batch.
    pub fn sockets(&self) -> usize {
        self.blocks.len() * BLOCK_LANES
    }
}

/// The substep scales the joint workloads iterate at: a 60 Hz substep.
const SCALE: SubstepScale = SubstepScale {
    inv_h: 60.0,
    inv_h2: 3600.0,
};

impl ConstraintWorkload for SocketWorkload {
    fn iterate(&mut self) {
        let (blocks, rows) = (&mut self.blocks, &self.rows);
        let b = self.backend;
        match (self.drive, self.shaped) {
            (true, false) => run::<socket::Positions<true, false>>(b, blocks, rows, SCALE),
            (false, false) => run::<socket::Positions<false, false>>(b, blocks, rows, SCALE),
            (true, true) => run::<socket::Positions<true, true>>(b, blocks, rows, SCALE),
            (false, true) => run::<socket::Positions<false, true>>(b, blocks, rows, SCALE),
        }
    }
    fn probe(&self) -> f32 {
        self.rows.pose[1].get()[0]
    }
}

/// A batch of hinges laid out as [`SocketWorkload`]'s joints, without
/// drives: each lane's axes apart and its angle beyond a hard range, so
/// every part works.
pub struct HingeWorkload {
    backend: Backend,
    rows: BodyRows,
    blocks: Vec<HingeBlock>,
}

impl HingeWorkload {
    /// `hinges` hinges (a power of two, at least 8) on `backend`.
    pub fn new(backend: Backend, hinges: usize, placement: Placement) -> Self {
        let blocks = hinges.div_ceil(BLOCK_LANES);
        let sockets = SocketWorkload::new(backend, blocks * BLOCK_LANES, false, placement);
        let mut out = vec![HingeBlock::padding(); blocks];
        for k in 0..blocks * BLOCK_LANES {
            let (body_a, body_b) = placement.bodies(k, blocks * BLOCK_LANES * 2);
            let lane = HingeLane {
                pair: PairLane::dynamic(body_a, body_b),
                frames: frames(),
                range: [0.0, 0.05],
                softness: vertebra_kernels::limited::LimitLane::HARD,
                drive: None,
            };
            out[k / BLOCK_LANES].set(k % BLOCK_LANES, &lane);
        }
        Self {
            backend,
            rows: sockets.rows,
            blocks: out,
        }
    }
}

impl ConstraintWorkload for HingeWorkload {
    fn iterate(&mut self) {
        let (blocks, rows) = (&mut self.blocks, &self.rows);
        run::<hinge::Positions<false>>(self.backend, blocks, rows, SCALE);
    }
    fn probe(&self) -> f32 {
        self.rows.pose[1].get()[0]
    }
}

/// A batch of fixed joints laid out as [`SocketWorkload`]'s joints, each
/// off its anchor and its frame.
pub struct FixedWorkload {
    backend: Backend,
    rows: BodyRows,
    blocks: Vec<FixedBlock>,
}

impl FixedWorkload {
    /// `joints` fixed joints (a power of two, at least 8) on `backend`.
    pub fn new(backend: Backend, joints: usize, placement: Placement) -> Self {
        let blocks = joints.div_ceil(BLOCK_LANES);
        let sockets = SocketWorkload::new(backend, blocks * BLOCK_LANES, false, placement);
        let mut out = vec![FixedBlock::padding(); blocks];
        for k in 0..blocks * BLOCK_LANES {
            let (body_a, body_b) = placement.bodies(k, blocks * BLOCK_LANES * 2);
            let lane = FixedLane {
                pair: PairLane::dynamic(body_a, body_b),
                frames: frames(),
            };
            out[k / BLOCK_LANES].set(k % BLOCK_LANES, &lane);
        }
        Self {
            backend,
            rows: sockets.rows,
            blocks: out,
        }
    }
}

impl ConstraintWorkload for FixedWorkload {
    fn iterate(&mut self) {
        run::<fixed::Positions>(self.backend, &mut self.blocks, &self.rows, ());
    }
    fn probe(&self) -> f32 {
        self.rows.pose[1].get()[0]
    }
}

/// A batch of rods laid out as [`SocketWorkload`]'s joints: each lane on
/// its own two dynamic bodies, every rod bent, twisted and off its arc, with
/// bending and twisting stiffness and both limits, so every part works.
pub struct RodWorkload {
    backend: Backend,
    rows: BodyRows,
    blocks: Vec<RodBlock>,
}

impl RodWorkload {
    /// `rods` rods (a power of two, at least 8) on `backend`.
    pub fn new(backend: Backend, rods: usize, placement: Placement) -> Self {
        let blocks = rods.div_ceil(BLOCK_LANES);
        // The same bodies as the socket workload, so the costs compare.
        let sockets = SocketWorkload::new(backend, blocks * BLOCK_LANES, false, placement);
        let mut out = vec![RodBlock::padding(); blocks];
        for k in 0..blocks * BLOCK_LANES {
            let (body_a, body_b) = placement.bodies(k, blocks * BLOCK_LANES * 2);
            let lane = RodLane {
                pair: PairLane::dynamic(body_a, body_b),
                frame_a: GQuat::from_rotation_z(0.1),
                frame_b: GQuat::from_rotation_z(0.5),
                rest_length: 0.12,
                bend_rest: GVec3::X,
                twist_rest: 0.0,
                bend_rest_velocity: GVec3::ZERO,
                twist_rest_velocity: 0.0,
                bend: RodSoftness::Compliance(0.06),
                twist: RodSoftness::Compliance(0.06),
                bend_max: 0.3,
                twist_range: [-0.1, 0.1],
                max_torque: f32::INFINITY,
            };
            out[k / BLOCK_LANES].set(k % BLOCK_LANES, &lane);
        }
        Self {
            backend,
            rows: sockets.rows,
            blocks: out,
        }
    }

    /// The rods in the batch.
    pub fn rods(&self) -> usize {
        self.blocks.len() * BLOCK_LANES
    }
}

impl ConstraintWorkload for RodWorkload {
    fn iterate(&mut self) {
        let (blocks, rows) = (&mut self.blocks, &self.rows);
        run::<rod::Positions>(self.backend, blocks, rows, SCALE);
    }
    fn probe(&self) -> f32 {
        self.rows.pose[1].get()[0]
    }
}

/// A batch of contacts laid out as the joint workloads: each lane on its
/// own two dynamic bodies, penetrating and sliding, so both the normal and
/// the friction corrections work.
pub struct ContactWorkload {
    backend: Backend,
    rows: BodyRows,
    blocks: Vec<ContactBlock>,
}

impl ContactWorkload {
    /// `contacts` contacts (a power of two, at least 8) on `backend`.
    pub fn new(backend: Backend, contacts: usize, placement: Placement) -> Self {
        let blocks = contacts.div_ceil(BLOCK_LANES);
        let bodies = SocketWorkload::new(backend, blocks * BLOCK_LANES, false, placement);
        let mut out = vec![ContactBlock::padding(); blocks];
        for k in 0..blocks * BLOCK_LANES {
            let (body_a, body_b) = placement.bodies(k, blocks * BLOCK_LANES * 2);
            let lane = ContactLane {
                pair: PairLane::dynamic(body_a, body_b),
                point_a: GVec3::new(0.05, 0.12, 0.0),
                point_b: GVec3::new(-0.04, -0.13, 0.01),
                normal: GVec3::new(0.1, 1.0, 0.05).normalize(),
                friction: 0.6,
                restitution: 0.2,
                approach: -1.0,
                overlap: 0.0,
                start: StartLane::default(),
                pinned: false,
            };
            out[k / BLOCK_LANES].set(k % BLOCK_LANES, &lane);
        }
        Self {
            backend,
            rows: bodies.rows,
            blocks: out,
        }
    }

    /// The contacts in the batch.
    pub fn contacts(&self) -> usize {
        self.blocks.len() * BLOCK_LANES
    }
}

impl ConstraintWorkload for ContactWorkload {
    fn iterate(&mut self) {
        let (blocks, rows) = (&mut self.blocks, &self.rows);
        run::<contact::Positions>(self.backend, blocks, rows, ());
    }
    fn probe(&self) -> f32 {
        self.rows.pose[1].get()[0]
    }
}

/// The scenes' frame time step (s).
pub const DT: f32 = 1.0 / 60.0;

/// The ragdoll drop with `count` ragdolls (30 per pit) at 20 iterations on
/// `threads` threads, one second (60 frames) in: piled up, many contacts.
pub fn drop_scene(spine: SpineMode, count: usize, threads: usize) -> SceneWorld {
    let mut scene = drop_scene_with(spine, count, threads, BackendChoice::Auto, 0);
    advance_drop(&mut scene, 0..60);
    scene
}

/// [`drop_scene`] as built, before its first frame (its ragdolls as a
/// switch from animation meets them); [`advance_drop`] runs its frames.
pub fn drop_scene_built(spine: SpineMode, count: usize, threads: usize) -> SceneWorld {
    drop_scene_with(spine, count, threads, BackendChoice::Auto, 0)
}

/// Frames `frames` of a ragdoll drop.
pub fn advance_drop(scene: &mut SceneWorld, frames: core::ops::Range<usize>) {
    for frame in frames {
        scene
            .advance(Scene::RagdollDrop, frame, DT)
            .expect("a frame");
    }
}

/// [`drop_scene`] on one thread with a forced backend.
pub fn drop_scene_on(spine: SpineMode, count: usize, backend: Backend) -> SceneWorld {
    drop_scene_with(spine, count, 1, BackendChoice::Forced(backend), 60)
}

/// Frames of the ragdoll drop after which its pile has formed: three
/// seconds in, every ragdoll has landed and the pile's top has settled
/// near 1 m, its fastest body under 1 m/s (one second in they are still
/// landing, the fastest at 3.6 m/s; the highest layer starts 5.5 m up).
pub const PILE_FRAMES: usize = 180;

/// The 30-ragdoll drop on one thread with a forced backend, its pile
/// formed ([`PILE_FRAMES`] in): what a game's rays and contact events
/// meet once the ragdolls lie in a heap.
pub fn drop_pile_on(spine: SpineMode, backend: Backend) -> SceneWorld {
    drop_scene_with(spine, 30, 1, BackendChoice::Forced(backend), PILE_FRAMES)
}

/// Rays at the formed pile ([`drop_pile_on`]): from 3 m above every
/// seventh body of its ragdolls, slanted a little, toward that body's
/// centre (origin m, unit direction, world), so each meets the pile.
pub fn rays_at_the_pile(scene: &SceneWorld) -> Vec<(GVec3, GVec3)> {
    let bodies = scene
        .ragdolls
        .iter()
        .flat_map(|r| r.bodies.iter().flatten());
    bodies
        .step_by(7)
        .map(|&body| {
            let centre = scene.world.body(body).expect("a live body").position;
            let from = centre + GVec3::new(0.3, 3.0, 0.2);
            (from, (centre - from).normalize())
        })
        .collect()
}

fn drop_scene_with(
    spine: SpineMode,
    count: usize,
    threads: usize,
    backend: BackendChoice,
    frames: usize,
) -> SceneWorld {
    let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
    (config.ragdolls, config.threads, config.backend) = (count, threads, backend);
    let mut scene = build(&config).expect("the drop scene");
    advance_drop(&mut scene, 0..frames);
    scene
}

/// The reference ragdoll alone: passive bending (the hips held, the upper
/// body slumping) at 1 substep x 4 iterations on one thread, one second
/// (60 frames) in, on `backend`, its residuals not measured. No colliders,
/// so a frame is the step.
pub fn single_ragdoll(spine: SpineMode, backend: BackendChoice) -> SceneWorld {
    single_ragdoll_solved(spine, backend, JointSolver::Iterative)
}

/// [`single_ragdoll`] with its joints solved by `joints`.
pub fn single_ragdoll_solved(
    spine: SpineMode,
    backend: BackendChoice,
    joints: JointSolver,
) -> SceneWorld {
    let mut config = SceneConfig::new(Scene::PassiveBending, spine);
    (config.substeps, config.iterations, config.backend) = (1, 4, backend);
    config.joints = joints;
    config.measure_residuals = false;
    let mut scene = build(&config).expect("the passive-bending scene");
    for frame in 0..60 {
        scene.advance(config.scene, frame, DT).expect("a frame");
    }
    scene
}

/// The frames a lone ragdoll is dropped for before it is timed lying on
/// the ground: three seconds, when every body is on it (the lowest centre
/// 4.5 cm up) but not all are still (the fastest at 0.04 to 0.17 m/s).
pub const LONE_SETTLE_FRAMES: usize = 180;

/// The reference ragdoll alone, dropped onto the ground (the ragdoll-drop
/// scene with one ragdoll) and lying there [`LONE_SETTLE_FRAMES`] frames
/// in: its contacts with the ground found every frame, so a frame
/// ([`SceneWorld::frame`]) is collision detection and the step, what a game
/// pays for a ragdoll on the ground that is still awake (sleeping off, as
/// in the scenes). Solved by `solver`'s joint solve at its substeps x iterations,
/// on one thread on `backend`, its residuals not measured.
pub fn lone_ragdoll_on_ground(
    spine: SpineMode,
    backend: BackendChoice,
    solver: &SolverConfig,
) -> SceneWorld {
    let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
    config.ragdolls = 1;
    (config.substeps, config.iterations, config.joints) =
        (solver.substeps, solver.iterations, solver.joints);
    config.relax_contacts = solver.relax_contacts;
    config.backend = backend;
    config.measure_residuals = false;
    let mut scene = build(&config).expect("the drop scene with one ragdoll");
    for frame in 0..LONE_SETTLE_FRAMES {
        scene.frame(config.scene, frame, DT).expect("a frame");
    }
    scene
}

/// The solvers a lone ragdoll on the ground is timed with, by name: the
/// paper's (iterated, 1 x 20, `SolverConfig::paper`), the iterated solve
/// at 1 x 4, and the direct solve with relaxed contacts at 1 x 4 and at
/// 1 x 8 (the world's default; `docs/direct.md`, "The default").
pub fn lone_solvers() -> [(&'static str, SolverConfig); 4] {
    let iterated = |iterations| SolverConfig {
        iterations,
        ..SolverConfig::paper()
    };
    let direct = |iterations| SolverConfig {
        iterations,
        ..SolverConfig::default()
    };
    [
        ("iterated_1x20", iterated(20)),
        ("iterated_1x4", iterated(4)),
        ("direct_1x4", direct(4)),
        ("direct_1x8", direct(8)),
    ]
}

/// `scene` (the ragdoll drop, [`Scene::RagdollDrop`], or its anatomical
/// twin, [`Scene::AnatomicalDrop`]) with 30 ragdolls (their default), its
/// joints solved directly ([`JointSolver::Direct`]) at 1 substep x 4
/// iterations on one thread on `backend`, its residuals not measured, one
/// second (60 frames) in: falling and landing, many contacts.
pub fn direct_drop_scene(scene: Scene, spine: SpineMode, backend: BackendChoice) -> SceneWorld {
    direct_drop_scene_at(scene, spine, backend, 60)
}

/// [`direct_drop_scene`] `frames` frames in.
pub fn direct_drop_scene_at(
    scene: Scene,
    spine: SpineMode,
    backend: BackendChoice,
    frames: usize,
) -> SceneWorld {
    let mut config = SceneConfig::new(scene, spine);
    (config.substeps, config.iterations) = (1, 4);
    (config.ragdolls, config.threads, config.backend) = (30, 1, backend);
    config.joints = JointSolver::Direct;
    config.measure_residuals = false;
    let mut world = build(&config).expect("the drop scene");
    for frame in 0..frames {
        world.advance(config.scene, frame, DT).expect("a frame");
    }
    world
}
