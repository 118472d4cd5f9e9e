//! Which pairs of colliders are tested: the excluded pairs of bodies
//! ([`Collisions::exclude`], a joint's two bodies), and the whole rule the
//! broad phase asks of each pair ([`Collisions::may_collide`]): two
//! bodies, one of them dynamic, not excluded, groups that meet, not kept
//! apart by their ragdoll's self-collision.
//!
//! Its own file because it is the rule, in one place, whoever sets its
//! parts: the groups and self-collision are set in `groups.rs`, the
//! excluded pairs by the ragdoll calls (`ragdoll.rs`) too. A pair of
//! bodies is keyed in one order ([`ordered`], lower slot first), as the
//! contact events and the snapshot key theirs.

use vertebra_world::{BodyHandle, BodyKind, World};

use crate::set::Collisions;

/// A pair of bodies in one order: the lower slot first.
pub(crate) fn ordered(a: BodyHandle, b: BodyHandle) -> (BodyHandle, BodyHandle) {
    if a.index() <= b.index() {
        (a, b)
    } else {
        (b, a)
    }
}

impl Collisions {
    /// Never tests the pair `(a, b)` (e.g. a joint's two bodies).
    pub fn exclude(&mut self, a: BodyHandle, b: BodyHandle) {
        self.excluded.insert(ordered(a, b));
    }

    /// Whether the pair `(a, b)` is never tested (either order).
    pub fn is_excluded(&self, a: BodyHandle, b: BodyHandle) -> bool {
        self.excluded.contains(&ordered(a, b))
    }

    pub(crate) fn may_collide(&self, world: &World, a: usize, b: usize) -> bool {
        let (ca, cb) = (&self.colliders[a].0, &self.colliders[b].0);
        let dynamic = |h: BodyHandle| world.bodies().kind[h.index()] == BodyKind::Dynamic;
        ca.body != cb.body
            && (dynamic(ca.body) || dynamic(cb.body))
            && !self.excluded.contains(&ordered(ca.body, cb.body))
            && ca.groups.membership & cb.groups.filter != 0
            && cb.groups.membership & ca.groups.filter != 0
            && !self.kept_apart(ca.body, cb.body)
    }
}
