//! What a step reports: residual joint error (the paper's figure 8 metric)
//! and a hash of the full state.

use vertebra_kernels::body::BodyRows;
use vertebra_kernels::residual::{Residual, ResidualPass};
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;
use vertebra_scheduler::Colouring;
use vertebra_store::{BodyStore, Slots};

use crate::joint::JointHandle;
use crate::layout::EMPTY;
use crate::rod::RodHandle;
use crate::{Contact, JointDesc, RodDesc, World};

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

/// Per-lane residuals of blocks (each `(lane_slot, per_lane)`) to
/// per-joint ones, in slot order.
fn collect<H>(
    kinds: &[(&[u32], &[[f32; 3]])],
    handle: impl Fn(usize) -> Option<H>,
) -> Vec<JointResidual<H>> {
    let mut joints: Vec<(u32, JointResidual<H>)> = kinds
        .iter()
        .flat_map(|(lane_slot, per_lane)| lane_slot.iter().zip(per_lane.iter()))
        .filter(|(slot, _)| **slot != EMPTY)
        .map(|(&slot, &[lin, ang, limit])| {
            let joint = handle(slot as usize).expect("laid-out joints are live");
            (
                slot,
                JointResidual {
                    joint,
                    linear_cm: lin * 100.0,
                    angular_rad: ang,
                    limit_rad: limit,
                },
            )
        })
        .collect();
    joints.sort_by_key(|j| j.0);
    joints.into_iter().map(|j| j.1).collect()
}

/// Every lane's residual of `blocks`.
fn measure<B: Residual>(backend: Backend, blocks: &[B], rows: &BodyRows) -> Vec<[f32; 3]> {
    let mut out = vec![[0.0f32; 3]; blocks.len() * BLOCK_LANES];
    backend.dispatch(ResidualPass {
        blocks,
        rows,
        out: &mut out,
    });
    out
}

pub(crate) fn residuals(world: &mut World) -> Residuals {
    let rows = &*world.rows.get();
    let layout = &world.layout;
    let backend = world.backend;
    let sockets = measure(backend, &layout.sockets.blocks, rows);
    let hinges = measure(backend, &layout.hinges.blocks, rows);
    let fixed = measure(backend, &layout.fixed.blocks, rows);
    let rods = measure(backend, &layout.rods.blocks, rows);
    let joints = collect(
        &[
            (&layout.sockets.lane_slot, &sockets),
            (&layout.hinges.lane_slot, &hinges),
            (&layout.fixed.lane_slot, &fixed),
        ],
        |s| world.joint_slots.handle_at(s),
    );
    let rods = collect(&[(&layout.rods.lane_slot, &rods)], |s| {
        world.rod_slots.handle_at(s)
    });
    let lin = joints
        .iter()
        .map(|j| j.linear_cm)
        .chain(rods.iter().map(|j| j.linear_cm));
    let ang = joints
        .iter()
        .map(|j| j.angular_rad)
        .chain(rods.iter().map(|j| j.angular_rad));
    Residuals {
        eps_lin_cm: lin.sum(),
        eps_ang_rad: ang.sum(),
        joints,
        rods,
    }
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
    rods: &'a [Option<RodDesc>],
    /// The solve order.
    colouring: &'a Colouring,
    /// The contacts set for the next step.
    contacts: &'a [Contact],
}

/// xxh3 over the bits of [`Hashed`] (postcard: floats as their bits).
pub(crate) fn state_hash(world: &World) -> u64 {
    let state = Hashed {
        bodies: &world.bodies,
        joints_at: &world.joints_at,
        joint_slots: &world.joint_slots,
        joints: &world.joints,
        rod_slots: &world.rod_slots,
        rods: &world.rods,
        colouring: &world.colouring,
        contacts: &world.contacts,
    };
    // Which world issued the handles, and their generations, change no
    // step: equal worlds hash alike whoever built them.
    let bytes = vertebra_store::serialize_physical_only(|| postcard::to_allocvec(&state))
        .expect("the state always encodes");
    xxhash_rust::xxh3::xxh3_64(&bytes)
}
