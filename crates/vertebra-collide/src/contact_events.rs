//! The contact events of a step, as the game reads them: a pair touching
//! ([`Touching`]), a pair that stopped ([`ContactEnded`]), and the step's
//! lists of both ([`ContactEvents`]).
//!
//! Its own file because the set keeps the lists (output, refilled each
//! step) while the rule that fills them works on the set (`events.rs`,
//! whose header says when a pair begins and ends touching): the types sit
//! below the set, the rule above it.

use glam::Vec3;
use vertebra_world::BodyHandle;

use crate::part::RagdollPart;

/// A pair of bodies touching in a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Touching {
    /// The first body (the lower slot).
    pub body_a: BodyHandle,
    /// The second body.
    pub body_b: BodyHandle,
    /// `body_a`'s ragdoll and bone, if it is a ragdoll's.
    pub part_a: Option<RagdollPart>,
    /// `body_b`'s ragdoll and bone, if it is a ragdoll's.
    pub part_b: Option<RagdollPart>,
    /// The step's normal impulse over all of the pair's contacts (N s,
    /// at least 0): how hard they met. The mean force over the step is
    /// this over `dt`.
    pub impulse: f32,
    /// The friction impulse on `body_b` over the step (N s, world).
    pub friction: Vec3,
    /// The point of the contact that pushed hardest (m, world).
    pub point: Vec3,
    /// Its normal, out of `body_a` into `body_b` (unit, world).
    pub normal: Vec3,
    /// How fast the two closed along their normals when the contacts were
    /// found, the fastest of the pair's points (m/s, at least 0): the
    /// speed of the hit.
    pub closing_speed: f32,
}

/// A pair of bodies that stopped touching.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContactEnded {
    /// The first body (the lower slot); may be gone.
    pub body_a: BodyHandle,
    /// The second body; may be gone.
    pub body_b: BodyHandle,
    /// `body_a`'s ragdoll and bone, if the set still knows it.
    pub part_a: Option<RagdollPart>,
    /// `body_b`'s ragdoll and bone, if the set still knows it.
    pub part_b: Option<RagdollPart>,
}

/// The last step's contact events
/// ([`Collisions::events`](crate::Collisions::events)).
#[derive(Clone, Debug, Default)]
pub struct ContactEvents {
    pub(crate) began: Vec<Touching>,
    pub(crate) ended: Vec<ContactEnded>,
    pub(crate) touching: Vec<Touching>,
    /// Scratch: each solved contact's pair (by `live_order`, `events.rs`)
    /// and index, sorted.
    pub(crate) order: Vec<(u64, u32)>,
    /// Scratch: the pairs touching after the step.
    pub(crate) next: Vec<(BodyHandle, BodyHandle)>,
}

impl ContactEvents {
    /// The pairs that began touching in the step, in pair order.
    pub fn began(&self) -> &[Touching] {
        &self.began
    }

    /// The pairs that stopped touching in the step, in pair order.
    pub fn ended(&self) -> &[ContactEnded] {
        &self.ended
    }

    /// Every pair touching with contacts the step solved (those that
    /// began included), with the step's impulses, in pair order. Pairs
    /// kept touching while asleep are not in it (nothing was solved).
    pub fn touching(&self) -> &[Touching] {
        &self.touching
    }
}
