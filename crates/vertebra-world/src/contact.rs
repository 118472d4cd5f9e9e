//! Contacts fed to the solver: by an engine's own collision detection, or
//! by `vertebra-collide`. `contact_layout.rs` colours them every step and
//! the step solves them before the joints in each iteration.

use glam::Vec3;
use vertebra_store::{BodyHandle, BodyStore, Error, check_point, check_unit_vec};

/// A contact between two bodies for the next step.
///
/// **The normal's sign is the contact's meaning**: `normal` points out of
/// `body_a` into `body_b`, the direction the contact pushes `body_b` (and
/// `-normal` pushes `body_a`). Engines differ here: some give the normal
/// from the first shape to the second, some the reverse. A contact with
/// its bodies exchanged and its normal not flipped (or the reverse) pushes
/// the bodies into each other; the world cannot tell, because it does not
/// know the bodies' shapes (the sign of `(centre_b - centre_a) . normal`
/// proves nothing for a hollow body: a ball resting in a bowl, a ragdoll
/// in a car). Exchange the bodies with [`Contact::reversed`], which flips
/// the normal with them.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Contact {
    /// The first body.
    pub body_a: BodyHandle,
    /// The second body.
    pub body_b: BodyHandle,
    /// The contact point, midway between the two surfaces (m, world).
    pub point: Vec3,
    /// The normal out of `body_a` into `body_b`: the direction the contact
    /// pushes `body_b` (unit, world). See the type's docs on its sign.
    pub normal: Vec3,
    /// Penetration depth along the normal (m); negative for a gap. At most
    /// [`MAX_COORDINATE`](vertebra_store::MAX_COORDINATE) either way: no
    /// overlap of bodies in range is deeper, and a depth of 1e30 m threw a
    /// body out to 3.7e30 m.
    pub depth: f32,
    /// Friction coefficient (static and dynamic), >= 0.
    pub friction: f32,
    /// Coefficient of restitution, in [0, 1].
    pub restitution: f32,
}

impl Contact {
    /// The same contact with its bodies exchanged: `body_a` and `body_b`
    /// swapped and the normal flipped, so it pushes each body as `self`
    /// does. The point, depth, friction and restitution are the pair's and
    /// stay.
    pub fn reversed(self) -> Self {
        Self {
            body_a: self.body_b,
            body_b: self.body_a,
            normal: -self.normal,
            ..self
        }
    }

    /// Checks every field but the bodies' liveness.
    pub fn validate(&self) -> Result<(), Error> {
        if self.body_a == self.body_b {
            return Err(Error::SameBody);
        }
        check_point("contact point", self.point)?;
        check_unit_vec("contact normal", self.normal)?;
        if !self.depth.is_finite() {
            return Err(Error::NonFinite("contact depth"));
        }
        if self.depth.abs() > vertebra_store::MAX_COORDINATE {
            return Err(Error::OutOfRange("contact depth (at most 1e6 m)"));
        }
        if !self.friction.is_finite() {
            return Err(Error::NonFinite("contact friction"));
        }
        if self.friction < 0.0 {
            return Err(Error::NonPositive("contact friction"));
        }
        if !(0.0..=1.0).contains(&self.restitution) {
            return Err(Error::OutOfRange("contact restitution (0 to 1)"));
        }
        Ok(())
    }

    /// Checks the bodies too (live in `bodies`, and at least one
    /// dynamic): what [`World::set_contacts`](crate::World::set_contacts)
    /// checks of each contact, in order.
    pub fn validate_with(&self, bodies: &BodyStore) -> Result<(), Error> {
        self.validate()?;
        crate::checks::joint_bodies(bodies, self.body_a, self.body_b)
    }
}

/// Checks a list as [`World::set_contacts`](crate::World::set_contacts)
/// does: the first wrong contact's error, with its index in the list.
pub(crate) fn validate_all(contacts: &[Contact], bodies: &BodyStore) -> Result<(), Error> {
    contacts.iter().enumerate().try_for_each(|(index, c)| {
        c.validate_with(bodies).map_err(|reason| Error::Contact {
            index,
            reason: Box::new(reason),
        })
    })
}
