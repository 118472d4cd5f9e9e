//! Which world a collision set serves.
//!
//! A set keeps its own state about a world's bodies: their colliders,
//! excluded pairs, groups and self-collision settings. A world that
//! restored a snapshot without its set (or with the set's snapshot of
//! another moment) may have bodies the set knows nothing of: a ragdoll
//! restored that way has no colliders and falls through the ground. So the
//! two are tied, cheaply:
//!
//! - **The set records the world's [`Timeline`](vertebra_world::Timeline)** (a run of states: a world
//!   begins one when made and a new one with every snapshot it restores)
//!   when it serves the world: at `find_contacts_into`, `build_ragdoll`,
//!   `remove_ragdoll`, `recreate_ragdoll`, `restore` and [`Collisions::attach`].
//!   Every call that takes the world ([`Collisions::find_contacts`] too,
//!   and [`Collisions::snapshot`]) refuses a world on another timeline
//!   with [`Error::WorldMismatch`], everything unchanged: the world
//!   restored a snapshot since (the set's own snapshot was not restored
//!   after it), or it is another world. A set that has never served a
//!   world serves any world that was never restored, and refuses one that
//!   was: a fresh set does not know the restored bodies either.
//! - **The set's snapshot records the world's bodies** as they were when
//!   it was taken ([`census`]: every live body's handle, hashed), and
//!   [`Collisions::restore`] refuses it for a world whose bodies differ
//!   (a world snapshot of another moment, with bodies added or removed
//!   between the two): [`Error::WorldMismatch`], the set unchanged.
//!
//! The legitimate flows cost a comparison of two numbers a call, and a
//! hash over the bodies' handles per snapshot and restore: snapshot both
//! (`World::snapshot`, then [`Collisions::snapshot`] with the world) and
//! restore both (`World::restore`, then [`Collisions::restore`]), in this
//! world, another one or another process, as often as every frame. A set
//! that is right for a restored world as it is (a world restored from a
//! snapshot taken before the set existed, with colliders added for its
//! bodies since) is declared so with [`Collisions::attach`].

use vertebra_world::{Error, World};

use crate::set::Collisions;

/// Why a set refuses a world on a timeline it does not serve.
const NOT_SERVED: &str = "this collision set does not serve the world as it is: the world restored a snapshot since the set last served it, or it is another world; restore the set's snapshot taken with the world's after the world's (or declare the set as it is with attach)";

/// Why a set that never served a world refuses a restored one.
const NEW_FOR_RESTORED: &str = "a collision set that never served this world, which restored a snapshot: restore the set's snapshot taken with the world's (or declare the set as it is with attach)";

/// Why a set's snapshot is refused for a world with other bodies.
pub(crate) const OTHER_BODIES: &str = "the collision-set snapshot was taken with another state of the world (other bodies): restore the world's snapshot taken with it first";

impl Collisions {
    /// Declares that the set, as it is, serves `world` from now on.
    ///
    /// A set serves one world's run of states (`vertebra_world::Timeline`):
    /// it records the world's when it serves it (`find_contacts_into`,
    /// `build_ragdoll`, `remove_ragdoll`, `recreate_ragdoll`, `restore`,
    /// this call), and every call that takes the world refuses one on
    /// another timeline with `Err(WorldMismatch)`: a world that restored a
    /// snapshot since, without the set's own snapshot restored after it
    /// (its bodies may not be those the set knows), or another world. A
    /// set that never served a world refuses a restored one. Restoring the
    /// set's snapshot taken with the world's is the usual way back; this
    /// call is for a set known to be right for the world as it is (a world
    /// restored from a snapshot taken before the set existed, with
    /// colliders added for its bodies since). Refused, with nothing
    /// changed, when a collider's body is not in `world`
    /// (`Err(Error::Collider)`, naming the first). See `docs/contacts.md`.
    pub fn attach(&mut self, world: &World) -> Result<(), Error> {
        for (index, collider) in self.colliders().enumerate() {
            if let Err(e) = world.body(collider.body) {
                return Err(collider.refused(index, e));
            }
        }
        self.serve(world);
        Ok(())
    }

    /// `Ok` when the set may serve `world` now; the refusal otherwise.
    pub(crate) fn check_serves(&self, world: &World) -> Result<(), Error> {
        let now = world.timeline();
        match self.serves {
            Some(served) if served == now => Ok(()),
            Some(_) => Err(Error::WorldMismatch(NOT_SERVED)),
            None if now.restored() => Err(Error::WorldMismatch(NEW_FOR_RESTORED)),
            None => Ok(()),
        }
    }

    /// Records that the set serves `world`'s timeline (after a call that
    /// checked it, or restored or attached the set).
    pub(crate) fn serve(&mut self, world: &World) {
        self.serves = Some(world.timeline());
    }
}

/// The identity of `world`'s bodies: the hash of every live body's handle
/// (slot, lineage, generation) in slot order. The same for a world and its
/// snapshot restored anywhere (the slots, lineage and generations are
/// restored exactly), different once a body is added or removed.
pub(crate) fn census(world: &World) -> u64 {
    let bodies = world.bodies();
    let mut hash = xxhash_rust::xxh3::Xxh3::new();
    for handle in (0..bodies.capacity()).filter_map(|i| bodies.handle_at(i)) {
        let (index, lineage, generation) = handle.to_raw();
        hash.update(&index.to_le_bytes());
        hash.update(&lineage.to_le_bytes());
        hash.update(&generation.to_le_bytes());
    }
    hash.digest()
}
