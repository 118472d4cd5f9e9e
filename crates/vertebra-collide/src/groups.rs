//! Which colliders may touch, set per body and per ragdoll: collision
//! groups (Rapier's `InteractionGroups`: membership and filter bit sets)
//! on every collider of a body or of a ragdoll in one call, and whether a
//! ragdoll's own bodies collide with each other (Jolt's
//! `GroupFilterTable`, reduced to the one question a ragdoll asks of it).
//!
//! A pair of colliders is tested when all of these hold (jointed pairs are
//! never tested, whatever the groups say):
//!
//! - different bodies, at least one dynamic;
//! - not an excluded pair ([`Collisions::exclude`]: a joint's two bodies);
//! - `a.membership & b.filter != 0` and `b.membership & a.filter != 0`;
//! - not two bodies of one ragdoll whose self-collision is off.

use vertebra_ragdoll::{Ragdoll, RagdollError};
use vertebra_world::{BodyHandle, Error};

use crate::collider::CollisionGroups;
use crate::set::Collisions;

/// The most groups a set gives ragdolls whose self-collision is off: 2^48
/// (a ragdoll's turned off a million times a second for nine years), as a
/// world's slot table gives at most 2^48 generations.
pub const MAX_SELF_COLLISION_GROUPS: u64 = 1 << 48;

/// The error for a body that has no collider in the set.
fn no_collider() -> Error {
    Error::StaleHandle("collider body")
}

impl Collisions {
    /// Sets the groups of every collider on `body`. Refused, with nothing
    /// changed, when the set has no collider on `body`
    /// (`StaleHandle("collider body")`).
    pub fn set_body_groups(
        &mut self,
        body: BodyHandle,
        groups: CollisionGroups,
    ) -> Result<(), Error> {
        self.set_groups(&[body], groups)
    }

    /// Sets the groups of every collider on every body of `ragdoll` (e.g.
    /// a player's ragdoll that the player's own weapons pass through).
    /// All or nothing: refused, with nothing changed, when a body of the
    /// ragdoll has no collider in the set (add it with
    /// [`Collisions::add_ragdoll`] first), and for a removed ragdoll
    /// (`RagdollError::Removed`, naming it).
    pub fn set_ragdoll_groups(
        &mut self,
        ragdoll: &Ragdoll,
        groups: CollisionGroups,
    ) -> Result<(), RagdollError> {
        ragdoll.check_not_removed()?;
        Ok(self.set_groups(&ragdoll_bodies(ragdoll), groups)?)
    }

    /// Whether the bodies of `ragdoll` that no joint joins collide with
    /// each other: on (`true`) as added, the default, so a ragdoll's arm
    /// still meets its own legs; off, no two of its bodies are ever tested
    /// (cheaper, and what a game wants of a ragdoll whose limbs may pass
    /// through each other). Its bodies keep colliding with everything else.
    /// Jointed pairs are never tested either way. Refused, with nothing
    /// changed, as [`Collisions::set_ragdoll_groups`] is, and when turning
    /// it off would take a group beyond the [`MAX_SELF_COLLISION_GROUPS`]
    /// the set ever gives (only a restored snapshot's counter gets near
    /// it): `Error::Collider` naming the ragdoll's first body and its first
    /// collider, `OutOfRange` as the reason.
    pub fn set_ragdoll_self_collision(
        &mut self,
        ragdoll: &Ragdoll,
        collide: bool,
    ) -> Result<(), RagdollError> {
        ragdoll.check_not_removed()?;
        let bodies = ragdoll_bodies(ragdoll);
        self.check_colliders(&bodies)?;
        // Every group below the counter may be in use: one more is the
        // counter itself, and the counter goes up by one, never past the
        // limit (so never wraps onto a group in use).
        let given = if collide {
            None
        } else {
            let next = self.next_apart.checked_add(1);
            match next.filter(|&n| n <= MAX_SELF_COLLISION_GROUPS) {
                Some(next) => Some((self.next_apart, next)),
                None => return Err(self.groups_exhausted(bodies[0]).into()),
            }
        };
        for body in &bodies {
            self.apart.remove(body);
        }
        if let Some((group, next)) = given {
            self.next_apart = next;
            self.apart.extend(bodies.iter().map(|&b| (b, group)));
        }
        Ok(())
    }

    /// The refusal of a group past [`MAX_SELF_COLLISION_GROUPS`] for the
    /// ragdoll whose first body is `body` (which has a collider: checked).
    fn groups_exhausted(&self, body: BodyHandle) -> Error {
        let index = self.colliders().position(|c| c.body == body);
        Error::Collider {
            index: index.unwrap_or(0),
            body,
            reason: Box::new(Error::OutOfRange(
                "ragdoll self-collision group (all 2^48 given)",
            )),
        }
    }

    /// Whether the bodies of `ragdoll` collide with each other (see
    /// [`Collisions::set_ragdoll_self_collision`]): `false` once it was
    /// turned off for this ragdoll, until turned on again.
    pub fn ragdoll_self_collision(&self, ragdoll: &Ragdoll) -> bool {
        let bodies = ragdoll_bodies(ragdoll);
        let first = bodies.first().and_then(|b| self.apart.get(b));
        let apart = first.is_some() && bodies.iter().all(|b| self.apart.get(b) == first);
        !apart
    }

    /// Whether two bodies are of one ragdoll whose self-collision is off.
    pub(crate) fn kept_apart(&self, a: BodyHandle, b: BodyHandle) -> bool {
        matches!((self.apart.get(&a), self.apart.get(&b)), (Some(x), Some(y)) if x == y)
    }

    /// `groups` on every collider of `bodies`, all checked first.
    fn set_groups(&mut self, bodies: &[BodyHandle], groups: CollisionGroups) -> Result<(), Error> {
        self.check_colliders(bodies)?;
        for (collider, _) in &mut self.colliders {
            if bodies.contains(&collider.body) {
                collider.groups = groups;
            }
        }
        Ok(())
    }

    /// Every one of `bodies` (at least one) has a collider in the set.
    fn check_colliders(&self, bodies: &[BodyHandle]) -> Result<(), Error> {
        let has_one = |b: &BodyHandle| self.colliders().any(|c| c.body == *b);
        if bodies.is_empty() || !bodies.iter().all(has_one) {
            return Err(no_collider());
        }
        Ok(())
    }
}

/// The handles of every body `ragdoll` has.
fn ragdoll_bodies(ragdoll: &Ragdoll) -> Vec<BodyHandle> {
    ragdoll.bodies.iter().flatten().copied().collect()
}
