//! What a step reports: residual joint error (the paper's figure 8 metric)
//! and a hash of the full state.

use glam::{Quat, Vec3};
use vertebra_kernels::body::BodyRows;
use vertebra_kernels::residual::{Residual, ResidualPass};
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;
use vertebra_scheduler::Colouring;
use vertebra_store::{BodyHandle, BodyStore, Slots};

use crate::joint::{JointHandle, JointKind};
use crate::layout::Layout;
use crate::rod::RodHandle;
use crate::{Contact, JointDesc, RodDesc, RodStiffness, World};

/// One joint's residual error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointResidual<H> {
    /// The joint.
    pub joint: H,
    /// Linear error (cm): a joint's anchor separation, a rod's `|C_len|`.
    pub linear_cm: f32,
    /// Angular error (rad): limit overshoot (a socket's swing, whatever
    /// its shape, and twist; a hinge's range), plus a hinge's angle between
    /// its axes, a fixed joint's angle between its frames, a rod's curve
    /// error (the angle between `t_b` and the reflection of `t_a`).
    pub angular_rad: f32,
    /// The part of `angular_rad` that is limit overshoot (rad): how far
    /// past its swing cone, twist or hinge range (a rod: its bend or twist
    /// limit) the joint is. Zero for a fixed joint.
    pub limit_rad: f32,
}

/// Residual error at the end of a step, as the design brief defines it:
/// `eps_lin` sums the joints' linear errors (cm), `eps_ang` their angular
/// ones (rad).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Residuals {
    /// Sum of linear errors (cm).
    pub eps_lin_cm: f32,
    /// Sum of angular errors (rad).
    pub eps_ang_rad: f32,
    /// Per joint, in slot order.
    pub joints: Vec<JointResidual<JointHandle>>,
    /// Per rod, in slot order.
    pub rods: Vec<JointResidual<RodHandle>>,
}

/// Per-lane residuals of every joint and rod block, kept by the world
/// between measurements so that measuring allocates nothing once warm.
#[derive(Clone, Debug, Default)]
pub(crate) struct LaneResiduals {
    sockets: Vec<[f32; 3]>,
    hinges: Vec<[f32; 3]>,
    fixed: Vec<[f32; 3]>,
    rods: Vec<[f32; 3]>,
}

/// Every lane's residual of `blocks`, into `out` (its capacity kept).
fn measure<B: Residual>(backend: Backend, blocks: &[B], rows: &BodyRows, out: &mut Vec<[f32; 3]>) {
    out.clear();
    out.resize(blocks.len() * BLOCK_LANES, [0.0; 3]);
    backend.dispatch(ResidualPass { blocks, rows, out });
}

/// A lane's residual as a joint's: the linear error in cm.
fn joint_residual<H>(joint: H, [lin, ang, limit]: [f32; 3]) -> JointResidual<H> {
    JointResidual {
        joint,
        linear_cm: lin * 100.0,
        angular_rad: ang,
        limit_rad: limit,
    }
}

/// Measures every joint and rod at the rows' poses into
/// `world.residuals`, in slot order, reusing its vectors and the lane
/// buffers (no allocation once they have grown to the world's size, while
/// no island sleeps). A sleeping island's joints are not laid out: while
/// one sleeps, the measurement lays out every joint for itself.
pub(crate) fn residuals(world: &mut World) {
    let everything;
    let layout = if world.islands.asleep().contains(&true) {
        // Rows and layout both from the poses now (the rows held each
        // awake body's motion since the step's start).
        crate::step::upload(&world.bodies, world.rows.get());
        let awake = vec![false; world.bodies.capacity()];
        everything = Layout::build(
            &world.colouring,
            &world.joints,
            &world.rods,
            &world.bodies,
            &awake,
            (&crate::bins::Bins::default(), None),
        )
        .started(&world.bodies);
        &everything
    } else {
        &world.layout
    };
    let rows = &*world.rows.get();
    let backend = world.backend;
    let lanes = &mut world.residual_lanes;
    measure(backend, &layout.sockets.blocks, rows, &mut lanes.sockets);
    measure(backend, &layout.hinges.blocks, rows, &mut lanes.hinges);
    measure(backend, &layout.fixed.blocks, rows, &mut lanes.fixed);
    measure(backend, &layout.rods.blocks, rows, &mut lanes.rods);
    let out = &mut world.residuals;
    out.joints.clear();
    for (slot, desc) in world.joints.iter().enumerate() {
        let Some(desc) = desc else { continue };
        let (per_lane, place) = match desc.kind {
            JointKind::Socket(_) => (&lanes.sockets, &layout.sockets.place),
            JointKind::Hinge { .. } => (&lanes.hinges, &layout.hinges.place),
            JointKind::Fixed => (&lanes.fixed, &layout.fixed.place),
        };
        let (block, lane) = place[slot];
        let joint = world
            .joint_slots
            .handle_at(slot)
            .expect("laid-out joints are live");
        out.joints
            .push(joint_residual(joint, per_lane[block * BLOCK_LANES + lane]));
    }
    out.rods.clear();
    for (slot, desc) in world.rods.iter().enumerate() {
        if desc.is_none() {
            continue;
        }
        let (block, lane) = layout.rods.place[slot];
        let rod = world
            .rod_slots
            .handle_at(slot)
            .expect("laid-out rods are live");
        out.rods
            .push(joint_residual(rod, lanes.rods[block * BLOCK_LANES + lane]));
    }
    let lin = out
        .joints
        .iter()
        .map(|j| j.linear_cm)
        .chain(out.rods.iter().map(|j| j.linear_cm));
    let ang = out
        .joints
        .iter()
        .map(|j| j.angular_rad)
        .chain(out.rods.iter().map(|j| j.angular_rad));
    (out.eps_lin_cm, out.eps_ang_rad) = (lin.sum(), ang.sum());
}

/// What [`World::state_hash`] covers: everything a step reads that
/// outlives the step, as a snapshot holds it. Each piece of state is one
/// field here; a new one is hashed by adding its line (a new body quantity
/// is a `BodyStore` field, hashed with the store).
#[derive(serde::Serialize)]
struct Hashed<'a> {
    /// Every slot's kind, pose, velocities, mass and inertia (and their
    /// inverses), pending force and torque, damping, each coordinate's low
    /// part; which slots are live and free (where the next body goes).
    bodies: &'a BodyStore,
    joints_at: &'a [u32],
    joint_slots: &'a Slots,
    joints: &'a [Option<JointDesc>],
    rod_slots: &'a Slots,
    rods: Vec<HashedRod<'a>>,
    /// The solve order.
    colouring: &'a Colouring,
    /// Every body's island and stillness, every island's sleep and split
    /// state.
    islands: &'a crate::islands::Islands,
    /// The contacts set for the next step.
    contacts: &'a [Contact],
    /// The bodies' drives, when any body has one: a world without them
    /// hashes no list, so its hash does not depend on a feature it does
    /// not use (as [`HashedRod`]).
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    body_drives: &'a [crate::body_drive::BodyDrives],
}

/// A rod slot as the state hash encodes it: `Free` (no rod), `Still` (a
/// rod whose rest shape is still: its description alone) or `Moving` (the
/// description, then the rest's rates). Postcard encodes an enum as its
/// variant index, so the first two are the bytes of an `Option` of the
/// description: a world whose rods' rest shapes never move hashes no
/// rates, and its hash does not depend on a feature it does not use (the
/// golden hashes of `crates/vertebra-scenes/tests/golden.rs` hold it).
/// Snapshots store the description as it is.
#[derive(serde::Serialize)]
enum HashedRod<'a> {
    Free,
    Still(StillRod<'a>),
    Moving(StillRod<'a>, Vec3, f32),
}

/// A rod's description without its rest shape's rates, field for field in
/// [`RodDesc`]'s order.
#[derive(serde::Serialize)]
struct StillRod<'a> {
    body_a: BodyHandle,
    body_b: BodyHandle,
    frame_a: Quat,
    frame_b: Quat,
    rest_length: f32,
    bend_rest: Vec3,
    twist_rest: f32,
    bending: &'a RodStiffness,
    twisting: &'a RodStiffness,
    bend_limit: Option<f32>,
    twist_limit: Option<[f32; 2]>,
    max_torque: f32,
}

impl<'a> From<&'a Option<RodDesc>> for HashedRod<'a> {
    fn from(slot: &'a Option<RodDesc>) -> Self {
        let Some(d) = slot else { return Self::Free };
        let still = StillRod {
            body_a: d.body_a,
            body_b: d.body_b,
            frame_a: d.frame_a,
            frame_b: d.frame_b,
            rest_length: d.rest_length,
            bend_rest: d.bend_rest,
            twist_rest: d.twist_rest,
            bending: &d.bending,
            twisting: &d.twisting,
            bend_limit: d.bend_limit,
            twist_limit: d.twist_limit,
            max_torque: d.max_torque,
        };
        if d.bend_rest_velocity == Vec3::ZERO && d.twist_rest_velocity == 0.0 {
            Self::Still(still)
        } else {
            Self::Moving(still, d.bend_rest_velocity, d.twist_rest_velocity)
        }
    }
}

/// xxh3 over the bits of [`Hashed`] (postcard: floats as their bits).
pub(crate) fn state_hash(world: &World) -> u64 {
    let state = Hashed {
        bodies: &world.bodies,
        joints_at: &world.joints_at,
        joint_slots: &world.joint_slots,
        joints: &world.joints,
        rod_slots: &world.rod_slots,
        rods: world.rods.iter().map(HashedRod::from).collect(),
        colouring: &world.colouring,
        islands: &world.islands,
        contacts: &world.contacts,
        body_drives: &world.body_drives,
    };
    // Which world issued the handles, and their generations, change no
    // step: equal worlds hash alike whoever built them.
    let bytes = vertebra_store::serialize_physical_only(|| postcard::to_allocvec(&state))
        .expect("the state always encodes");
    xxhash_rust::xxh3::xxh3_64(&bytes)
}
