//! What a step reports: residual joint error (the paper's figure 8 metric)
//! and a hash of the full state.

use vertebra_kernels::residual::ResidualPass;
use vertebra_math::block::BLOCK_LANES;
use vertebra_store::BodyStore;

use crate::World;
use crate::layout::EMPTY;
use crate::rod::RodHandle;
use crate::socket::SocketHandle;

/// One joint's residual error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointResidual<H> {
    /// The joint.
    pub joint: H,
    /// Linear error (cm): a socket's anchor separation, a rod's `|C_len|`.
    pub linear_cm: f32,
    /// Angular error (rad): limit overshoot, plus a rod's curve error (the
    /// angle between `t_b` and the reflection of `t_a`).
    pub angular_rad: f32,
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
    /// Per socket, in slot order.
    pub sockets: Vec<JointResidual<SocketHandle>>,
    /// Per rod, in slot order.
    pub rods: Vec<JointResidual<RodHandle>>,
}

/// Per-lane residuals to per-joint ones, in slot order.
fn collect<H>(
    lane_slot: &[u32],
    per_lane: &[[f32; 2]],
    handle: impl Fn(usize) -> Option<H>,
) -> Vec<JointResidual<H>> {
    let mut joints: Vec<(u32, JointResidual<H>)> = lane_slot
        .iter()
        .zip(per_lane)
        .filter(|(slot, _)| **slot != EMPTY)
        .map(|(&slot, &[lin, ang])| {
            let joint = handle(slot as usize).expect("laid-out joints are live");
            (
                slot,
                JointResidual {
                    joint,
                    linear_cm: lin * 100.0,
                    angular_rad: ang,
                },
            )
        })
        .collect();
    joints.sort_by_key(|j| j.0);
    joints.into_iter().map(|j| j.1).collect()
}

pub(crate) fn residuals(world: &mut World) -> Residuals {
    let rows = &*world.rows.get();
    let (sockets, rods) = (&world.layout.sockets, &world.layout.rods);
    let mut socket_lanes = vec![[0.0f32; 2]; sockets.blocks.len() * BLOCK_LANES];
    world.backend.dispatch(ResidualPass {
        blocks: &sockets.blocks,
        rows,
        out: &mut socket_lanes,
    });
    let mut rod_lanes = vec![[0.0f32; 2]; rods.blocks.len() * BLOCK_LANES];
    world.backend.dispatch(ResidualPass {
        blocks: &rods.blocks,
        rows,
        out: &mut rod_lanes,
    });
    let sockets = collect(&sockets.lane_slot, &socket_lanes, |s| {
        world.socket_slots.handle_at(s)
    });
    let rods = collect(&rods.lane_slot, &rod_lanes, |s| {
        world.rod_slots.handle_at(s)
    });
    let lin = sockets
        .iter()
        .map(|j| j.linear_cm)
        .chain(rods.iter().map(|j| j.linear_cm));
    let ang = sockets
        .iter()
        .map(|j| j.angular_rad)
        .chain(rods.iter().map(|j| j.angular_rad));
    Residuals {
        eps_lin_cm: lin.sum(),
        eps_ang_rad: ang.sum(),
        sockets,
        rods,
    }
}

/// xxh3 over the bits of every live body's slot, position, orientation and
/// velocities, in slot order.
pub(crate) fn state_hash(bodies: &BodyStore) -> u64 {
    let mut bytes = Vec::with_capacity(bodies.capacity() * 56);
    for i in 0..bodies.capacity() {
        if !bodies.is_live(i) {
            continue;
        }
        bytes.extend_from_slice(&(i as u32).to_le_bytes());
        let values = bodies.position[i]
            .to_array()
            .into_iter()
            .chain(bodies.orientation[i].to_array())
            .chain(bodies.linear_velocity[i].to_array())
            .chain(bodies.angular_velocity[i].to_array());
        for v in values {
            bytes.extend_from_slice(&v.to_bits().to_le_bytes());
        }
    }
    xxhash_rust::xxh3::xxh3_64(&bytes)
}
