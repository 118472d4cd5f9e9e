//! A game's frame with the collision layer: detection, the world's step,
//! then what follows the step (continuous collision for fast bodies, the
//! contact events, the query tree), in one call ([`Collisions::step`]) or
//! in its parts (`find_contacts_into`, `World::swap_contacts`,
//! `World::step`, [`Collisions::after_step`]).
//!
//! `after_step` works from what the step solved, so it checks that the
//! world's last step solved the contacts the set found for it: the record
//! `Found` (`found.rs`) of the last `find_contacts_into` (the world's
//! timeline and step count then, each contact's bodies and closing speed,
//! each collider's pose before the step), against the world's
//! `solved_contacts` and `step_count`.

use vertebra_math::DefaultFloatMode;
use vertebra_world::{Error, World};

use crate::set::Collisions;

impl Collisions {
    /// What follows a step of `world` whose contacts this set found
    /// (`find_contacts_into`, then `World::swap_contacts` and
    /// `World::step`), in order: fast bodies moved back to where they
    /// would first have passed into static geometry ([continuous
    /// collision](crate::Collisions::continuous_bodies)), the step's
    /// contact events ([`Collisions::events`]), and the query tree
    /// ([`Collisions::refresh_queries`]). Refused, with nothing changed:
    /// a world the set does not serve (`WorldMismatch`), a world whose
    /// last step did not solve the contacts this set last found for it
    /// (`WorldMismatch`: called twice, or after a step fed other
    /// contacts), a collider whose body is gone (`Collider`).
    pub fn after_step(&mut self, world: &mut World) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        self.check_serves(world)?;
        self.found.check(world)?;
        for (index, (c, _)) in self.colliders.iter().enumerate() {
            world.body(c.body).map_err(|e| c.refused(index, e))?;
        }
        self.sweep_fast_bodies(world)?;
        self.update_events(world);
        // Consumed: a second call for the same step is refused.
        self.found.at = None;
        self.refresh_queries(world)
    }

    /// A whole frame of `dt` seconds: the contacts found
    /// ([`Collisions::find_contacts_into`] into a list the set keeps) and
    /// handed to the world without a copy, the world's step, then
    /// [`Collisions::after_step`]. What a game calls once a frame; the
    /// parts are there for one that steps the world itself. Refused before
    /// anything changes for what `find_contacts_into` or `World::step`
    /// refuse (a world the set does not serve, a collider whose body is
    /// gone, a time step out of range). A steady frame allocates nothing.
    pub fn step(&mut self, world: &mut World, dt: f32) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        world.check_time_step(dt)?;
        let mut list = core::mem::take(&mut self.frame_contacts);
        let found = self
            .find_contacts_into(world, dt, &mut list)
            .and_then(|()| world.swap_contacts(&mut list));
        self.frame_contacts = list;
        found?;
        world.step(dt)?;
        self.after_step(world)
    }
}
