//! Saving a world's full state and restoring it bit for bit (rollback).
//!
//! A snapshot holds everything a step reads that outlives a step: the body
//! store (poses, velocities, masses, pending forces, slots), the joints and
//! their slots, the colouring (its history decides the solve order, so it
//! is saved, not rebuilt), and the contacts set for the next step. The
//! block layout is rebuilt from those on the next step, exactly as it was
//! built before. The solver settings are not part of it: they belong to the
//! world, and stepping is bit-identical across backends and thread counts.
//!
//! Bytes: `"VTBSNAP1"`, the world's id (u64 LE), the xxh3 hash of the
//! payload (u64 LE), then the payload (postcard).

use std::sync::atomic::{AtomicU64, Ordering};

use serde::{Deserialize, Serialize};
use vertebra_scheduler::Colouring;
use vertebra_store::{BodyStore, Error, Slots};

use crate::{Contact, RodDesc, SocketDesc, World};

const MAGIC: &[u8; 8] = b"VTBSNAP1";
const HEADER: usize = 24;

/// A world's full state at one instant: [`World::snapshot`] takes it,
/// [`World::restore`] puts it back. Stepping on from a restored world gives
/// the same bits as stepping on from the original did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Snapshot {
    bytes: Vec<u8>,
}

impl Snapshot {
    /// The encoded snapshot (to store or send).
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// A snapshot from bytes [`Snapshot::as_bytes`] gave; checked when it is
    /// restored.
    pub fn from_bytes(bytes: Vec<u8>) -> Self {
        Self { bytes }
    }
}

/// A process-unique id, different across processes too (hashed with the
/// process's random hasher keys).
pub(crate) fn new_world_id() -> u64 {
    use std::hash::{BuildHasher, RandomState};
    static NEXT: AtomicU64 = AtomicU64::new(0);
    RandomState::new().hash_one(NEXT.fetch_add(1, Ordering::Relaxed))
}

#[derive(Serialize, Deserialize)]
struct State {
    bodies: BodyStore,
    joints_at: Vec<u32>,
    socket_slots: Slots,
    sockets: Vec<Option<SocketDesc>>,
    rod_slots: Slots,
    rods: Vec<Option<RodDesc>>,
    colouring: Colouring,
    contacts: Vec<Contact>,
}

impl State {
    fn is_consistent(&self) -> bool {
        let b = &self.bodies;
        let sound = |i: usize| {
            b.is_finite(i)
                && vertebra_store::check_unit_quat("orientation", b.orientation[i]).is_ok()
        };
        self.bodies.is_consistent()
            && self.joints_at.len() == self.bodies.capacity()
            && self.socket_slots.is_consistent()
            && self.rod_slots.is_consistent()
            && self.sockets.len() == self.socket_slots.capacity()
            && self.rods.len() == self.rod_slots.capacity()
            && (0..b.capacity()).all(sound)
    }
}

impl World {
    /// The world's full state now (see [`Snapshot`]).
    pub fn snapshot(&self) -> Snapshot {
        let state = State {
            bodies: self.bodies.clone(),
            joints_at: self.joints_at.clone(),
            socket_slots: self.socket_slots.clone(),
            sockets: self.sockets.clone(),
            rod_slots: self.rod_slots.clone(),
            rods: self.rods.clone(),
            colouring: self.colouring.clone(),
            contacts: self.contacts.clone(),
        };
        let payload = postcard::to_allocvec(&state).expect("the state always encodes");
        let mut bytes = Vec::with_capacity(HEADER + payload.len());
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&self.id.to_le_bytes());
        bytes.extend_from_slice(&xxhash_rust::xxh3::xxh3_64(&payload).to_le_bytes());
        bytes.extend_from_slice(&payload);
        Snapshot { bytes }
    }

    /// Puts the world back to `snapshot`: bodies, joints and contacts added
    /// since are gone, removed ones are back, and the handles of the time
    /// are valid again. `Err(ForeignSnapshot)` for another world's snapshot,
    /// `Err(CorruptSnapshot)` for damaged bytes; the world is unchanged on
    /// error.
    pub fn restore(&mut self, snapshot: &Snapshot) -> Result<(), Error> {
        let bytes = &snapshot.bytes;
        if bytes.len() < HEADER || &bytes[..8] != MAGIC {
            return Err(Error::CorruptSnapshot("not a vertebra snapshot"));
        }
        let word = |k: usize| u64::from_le_bytes(bytes[k..k + 8].try_into().expect("8 bytes"));
        if word(8) != self.id {
            return Err(Error::ForeignSnapshot);
        }
        let payload = &bytes[HEADER..];
        if xxhash_rust::xxh3::xxh3_64(payload) != word(16) {
            return Err(Error::CorruptSnapshot("checksum mismatch"));
        }
        let state: State = postcard::from_bytes(payload)
            .map_err(|_| Error::CorruptSnapshot("undecodable state"))?;
        if !state.is_consistent() {
            return Err(Error::CorruptSnapshot("inconsistent state"));
        }
        self.bodies = state.bodies;
        self.joints_at = state.joints_at;
        self.socket_slots = state.socket_slots;
        self.sockets = state.sockets;
        self.rod_slots = state.rod_slots;
        self.rods = state.rods;
        self.colouring = state.colouring;
        self.contacts = state.contacts;
        self.layout_dirty = true;
        self.measure_residuals();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn world_ids_differ() {
        assert_ne!(new_world_id(), new_world_id());
    }
}
