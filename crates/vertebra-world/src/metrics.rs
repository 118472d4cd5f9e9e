//! What a step reports: residual joint error (the paper's figure 8 metric)
//! and a hash of the full state.

use vertebra_kernels::socket::ResidualPass;
use vertebra_math::block::BLOCK_LANES;
use vertebra_store::BodyStore;

use crate::World;
use crate::layout::EMPTY;
use crate::socket::SocketHandle;

/// One socket's residual error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SocketResidual {
    /// The socket.
    pub socket: SocketHandle,
    /// Anchor separation (cm).
    pub linear_cm: f32,
    /// Swing and twist limit overshoot (rad).
    pub angular_rad: f32,
}

/// Residual error at the end of a step: `eps_lin` is the sum of anchor
/// separations (cm), `eps_ang` the sum of angular limit violations (rad),
/// over every joint, as the design brief defines them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Residuals {
    /// Sum of anchor separations (cm).
    pub eps_lin_cm: f32,
    /// Sum of angular violations (rad).
    pub eps_ang_rad: f32,
    /// Per socket, in slot order.
    pub sockets: Vec<SocketResidual>,
}

pub(crate) fn residuals(world: &World) -> Residuals {
    let blocks = &world.layout.blocks;
    let mut per_lane = vec![[0.0f32; 2]; blocks.len() * BLOCK_LANES];
    world.backend.dispatch(ResidualPass {
        blocks,
        rows: &world.rows,
        out: &mut per_lane,
    });
    let mut sockets: Vec<SocketResidual> = world
        .layout
        .lane_socket
        .iter()
        .zip(&per_lane)
        .filter(|(slot, _)| **slot != EMPTY)
        .map(|(&slot, &[lin, ang])| SocketResidual {
            socket: world
                .socket_slots
                .handle_at(slot as usize)
                .expect("laid-out sockets are live"),
            linear_cm: lin * 100.0,
            angular_rad: ang,
        })
        .collect();
    sockets.sort_by_key(|s| s.socket.index());
    Residuals {
        eps_lin_cm: sockets.iter().map(|s| s.linear_cm).sum(),
        eps_ang_rad: sockets.iter().map(|s| s.angular_rad).sum(),
        sockets,
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
