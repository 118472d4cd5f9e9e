//! Finding the contacts ([`Collisions::find_contacts`],
//! [`Collisions::find_contacts_into`]): each collider's pose and reach,
//! the bounds, then round after round of broad and narrow phase, first
//! the pairs with a body that moves, then those of the sleeping islands
//! the last round's contacts touched.
//!
//! Its own file because it is the order of the phases and nothing else:
//! each phase is in its own file (`broad_phase.rs`, `narrow_phase.rs`,
//! `islands.rs`), the working memory in `detection.rs`.

use parry3d::math::Pose;
use vertebra_math::DefaultFloatMode;
use vertebra_world::{Contact, Error, World};

use crate::detection::Detection;
use crate::islands::wake_touched;
use crate::set::Collisions;

impl Collisions {
    /// Every contact between the colliders at the bodies' current poses, in
    /// a deterministic order; feed them to `World::set_contacts` before a
    /// step of `dt` seconds. Contacts are speculative: a pair is caught up
    /// to `prediction` plus how far its bodies can close in within `dt`
    /// (linear speed plus angular speed times the collider's extent), so a
    /// fast body meets the floor instead of passing into it; a gap does
    /// nothing until it closes. `Err(Error::Collider)` names the first
    /// collider whose body is no longer in `world` (remove a body's
    /// colliders with [`Collisions::remove_body`]); `Err(WorldMismatch)`
    /// for a world the set does not serve: one that restored a snapshot
    /// since without the set's own restored after it, or another world
    /// (see [`Collisions::attach`]). Allocates its list and
    /// working memory every call: a game's loop uses
    /// [`Collisions::find_contacts_into`].
    pub fn find_contacts(&self, world: &World, dt: f32) -> Result<Vec<Contact>, Error> {
        let _mode = DefaultFloatMode::enter();
        let mut contacts = Vec::new();
        self.detect(world, dt, &mut Detection::default(), &mut contacts)?;
        Ok(contacts)
    }

    /// [`Collisions::find_contacts`] into `contacts` (emptied first, and
    /// empty on error), with the set's own working memory (bounds, sweep
    /// order, pairs, parry's manifolds) kept from call to call: once it and
    /// `contacts` have grown to the scene's size, a call allocates nothing.
    /// Hand the list to the world without a copy with
    /// `World::swap_contacts`, which gives back the world's previous
    /// list for the next call.
    pub fn find_contacts_into(
        &mut self,
        world: &World,
        dt: f32,
        contacts: &mut Vec<Contact>,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        // Taken out and put back (moving a vector allocates nothing), so
        // that the detection reads the set while it writes its memory.
        let mut scratch = core::mem::take(&mut self.scratch);
        let found = self.detect(world, dt, &mut scratch, contacts);
        self.scratch = scratch;
        if found.is_ok() {
            self.serve(world);
            self.found
                .record(self.version, &self.colliders, world, contacts);
        }
        found
    }

    /// Every contact into `contacts` (emptied first), with `scratch` as
    /// working memory.
    fn detect(
        &self,
        world: &World,
        dt: f32,
        scratch: &mut Detection,
        contacts: &mut Vec<Contact>,
    ) -> Result<(), Error> {
        contacts.clear();
        self.check_serves(world)?;
        vertebra_store::check_positive("time step", dt)?;
        self.sleep_state(world, scratch)?;
        if !scratch.acts.contains(&true) {
            // Every body asleep or still (a settled pile): no pair has a
            // body that moves, so no bounds, sweep or round is needed.
            return Ok(());
        }
        scratch.poses.clear();
        scratch.reach.clear();
        for (index, (c, shape)) in self.colliders.iter().enumerate() {
            let s = world.body(c.body).map_err(|e| c.refused(index, e))?;
            scratch
                .poses
                .push(Pose::from_parts(s.position, s.orientation));
            let extent = shape.compute_local_bounding_sphere().radius;
            let extent = if extent.is_finite() { extent } else { 0.0 };
            scratch
                .reach
                .push((s.linear_velocity.length() + s.angular_velocity.length() * extent) * dt);
        }
        self.bounds(scratch);
        // Pairs where a body moves; then, round after round, the pairs of
        // the sleeping islands those contacts touch (the step wakes them,
        // and they need their contacts with the ground and each other).
        let mut first = true;
        loop {
            self.candidate_pairs(world, scratch, first);
            first = false;
            let from = contacts.len();
            self.narrow(scratch, contacts);
            if !wake_touched(scratch, world, &contacts[from..]) {
                return Ok(());
            }
        }
    }
}
