//! A game's frame with the collision layer: detection, the world's step,
//! then what follows the step (continuous collision for fast bodies, the
//! contact events, the query tree), in one call ([`Collisions::step`]) or
//! in its parts (`find_contacts_into`, `World::swap_contacts`,
//! `World::step`, [`Collisions::after_step`]).
//!
//! `after_step` works from what the step solved, so it checks that the
//! world's last step solved the contacts the set found for it: the record
//! [`Found`] of the last `find_contacts_into` (the world's timeline and
//! step count then, each contact's bodies and closing speed, each
//! collider's pose before the step), against the world's
//! `solved_contacts` and `step_count`.

use glam::Vec3;
use parry3d::math::Pose;
use vertebra_math::DefaultFloatMode;
use vertebra_world::{BodyHandle, BodyKind, Contact, Error, Timeline, World};

use crate::Collisions;

/// Why `after_step` refuses a world whose last step was not the one the
/// set's contacts were found for.
const NOT_FOUND_FOR: &str = "the world's last step did not solve the contacts this set found for it: call find_contacts_into, World::swap_contacts (or set_contacts with that list), World::step, then after_step, once each (or Collisions::step)";

/// What the last `find_contacts_into` found, and for which step.
#[derive(Clone, Default)]
pub(crate) struct Found {
    /// The world's timeline and step count when they were found; `None`
    /// before the first (or after a refused one).
    at: Option<(Timeline, u64)>,
    /// The set's collider version then.
    pub version: u64,
    /// Each contact's bodies, in the list's order.
    pub bodies: Vec<(BodyHandle, BodyHandle)>,
    /// Each contact's closing speed along its normal then (m/s, at least
    /// 0).
    pub closing: Vec<f32>,
    /// Each collider's pose before the step, for the awake dynamic
    /// bodies' (continuous collision); `None` for the rest.
    pub before: Vec<Option<Pose>>,
}

impl Found {
    /// Records `contacts`, just found for `world`'s next step.
    pub fn record(&mut self, set: &Collisions, world: &World, contacts: &[Contact]) {
        self.at = Some((world.timeline(), world.step_count()));
        self.version = set.version;
        self.bodies.clear();
        self.closing.clear();
        let velocity = |b: BodyHandle, p: Vec3| {
            world.body(b).map_or(Vec3::ZERO, |s| {
                s.linear_velocity + s.angular_velocity.cross(p - s.position)
            })
        };
        for c in contacts {
            self.bodies.push((c.body_a, c.body_b));
            let approach =
                (velocity(c.body_b, c.point) - velocity(c.body_a, c.point)).dot(c.normal);
            self.closing.push((-approach).max(0.0));
        }
        self.before.clear();
        self.before.extend(set.colliders.iter().map(|(c, _)| {
            let awake = world.is_asleep(c.body) == Ok(false);
            let dynamic = world.bodies().kind[c.body.index()] == BodyKind::Dynamic;
            let s = world.body(c.body).ok().filter(|_| awake && dynamic)?;
            Some(Pose::from_parts(s.position, s.orientation))
        }));
    }

    /// Whether `world`'s last step solved exactly these contacts.
    fn check(&self, world: &World) -> Result<(), Error> {
        let solved = world.solved_contacts();
        let stepped = self.at == Some((world.timeline(), world.step_count().wrapping_sub(1)));
        let same = solved.len() == self.bodies.len()
            && solved
                .iter()
                .zip(&self.bodies)
                .all(|(c, &(a, b))| (c.body_a, c.body_b) == (a, b));
        if stepped && same {
            Ok(())
        } else {
            Err(Error::WorldMismatch(NOT_FOUND_FOR))
        }
    }
}

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
