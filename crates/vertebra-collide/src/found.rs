//! What the last detection found, and for which step ([`Found`]): the
//! world's timeline and step count then, each contact's bodies and closing
//! speed, each collider's pose before the step; and the check that the
//! world's last step solved exactly those contacts.
//!
//! Its own file because the set keeps the record while what reads it
//! works on the set: detection writes it (`detect.rs`), what follows the
//! step checks it (`frame.rs`), the events take the closing speeds
//! (`events.rs`) and continuous collision the poses before
//! (`continuous.rs`).

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use vertebra_world::{BodyHandle, BodyKind, Contact, Error, Timeline, World};

use crate::collider::Collider;

/// Why `after_step` refuses a world whose last step was not the one the
/// set's contacts were found for.
const NOT_FOUND_FOR: &str = "the world's last step did not solve the contacts this set found for it: call find_contacts_into, World::swap_contacts (or set_contacts with that list), World::step, then after_step, once each (or Collisions::step)";

/// What the last `find_contacts_into` found, and for which step.
#[derive(Clone, Default)]
pub(crate) struct Found {
    /// The world's timeline and step count when they were found; `None`
    /// before the first (or after a refused one).
    pub at: Option<(Timeline, u64)>,
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
    /// Records `contacts`, just found for `world`'s next step by a set at
    /// collider `version` with `colliders`.
    pub fn record(
        &mut self,
        version: u64,
        colliders: &[(Collider, SharedShape)],
        world: &World,
        contacts: &[Contact],
    ) {
        self.at = Some((world.timeline(), world.step_count()));
        self.version = version;
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
        self.before.extend(colliders.iter().map(|(c, _)| {
            let awake = world.is_asleep(c.body) == Ok(false);
            let dynamic = world.bodies().kind[c.body.index()] == BodyKind::Dynamic;
            let s = world.body(c.body).ok().filter(|_| awake && dynamic)?;
            Some(Pose::from_parts(s.position, s.orientation))
        }));
    }

    /// Whether `world`'s last step solved exactly these contacts.
    pub fn check(&self, world: &World) -> Result<(), Error> {
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
