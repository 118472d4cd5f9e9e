//! Which ragdoll and bone a body is ([`RagdollPart`]), and the set's table
//! of them ([`Parts`]).
//!
//! Its own file because everything that names a body to the game names its
//! part too (query hits, contact events, the snapshot), while the table is
//! filled only by the ragdoll calls (`ragdoll.rs`): a leaf that all of them
//! read and that reads nothing of the crate.

use vertebra_world::BodyHandle;

/// The ragdoll part of each body the set knows as a ragdoll's, by slot
/// (looked up for every hit and every touching pair: an index and a
/// handle compare, no hashing).
#[derive(Clone, Debug, Default)]
pub(crate) struct Parts {
    by_slot: Vec<Option<(BodyHandle, RagdollPart)>>,
}

impl Parts {
    /// `body`'s part, if the set knows it.
    pub(crate) fn get(&self, body: BodyHandle) -> Option<RagdollPart> {
        match self.by_slot.get(body.index()) {
            Some(Some((b, part))) if *b == body => Some(*part),
            _ => None,
        }
    }

    /// Records `body`'s part.
    pub(crate) fn insert(&mut self, body: BodyHandle, part: RagdollPart) {
        if self.by_slot.len() <= body.index() {
            self.by_slot.resize(body.index() + 1, None);
        }
        self.by_slot[body.index()] = Some((body, part));
    }

    /// Forgets `body`'s part (nothing to forget is not an error).
    pub(crate) fn remove(&mut self, body: BodyHandle) {
        if self.get(body).is_some() {
            self.by_slot[body.index()] = None;
        }
    }

    /// Every body's part, in slot order.
    pub(crate) fn iter(&self) -> impl Iterator<Item = (BodyHandle, RagdollPart)> + '_ {
        self.by_slot.iter().flatten().copied()
    }
}

/// Which ragdoll and bone a body is, in hits and events.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct RagdollPart {
    /// The ragdoll, named by its first body (`Ragdoll::first_body`).
    pub ragdoll: BodyHandle,
    /// The body's index in the ragdoll's description
    /// (`Ragdoll::description().bodies[bone]`, whose `name` is the
    /// bone's).
    pub bone: u32,
}
