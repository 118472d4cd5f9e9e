//! Contacts fed to the solver: by an engine's own collision detection, or
//! by `vertebra-collide`. They are coloured on their own every step (they
//! change every step) and solved after the joints in each iteration.

use core::ops::Range;

use glam::Vec3;
use vertebra_kernels::body::StartLane;
use vertebra_kernels::contact::{ContactBlock, ContactLane};
use vertebra_math::block::BLOCK_LANES;
use vertebra_scheduler::{Colouring, MAX_COLOURS};
use vertebra_store::{BodyHandle, BodyKind, BodyStore, Error, check_point, check_unit_vec};

/// A contact between two bodies for the next step.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Contact {
    /// The first body.
    pub body_a: BodyHandle,
    /// The second body.
    pub body_b: BodyHandle,
    /// The contact point, midway between the two surfaces (m, world).
    pub point: Vec3,
    /// The normal from a to b (unit, world).
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

    /// Checks the bodies too: live, and at least one dynamic.
    pub(crate) fn validate_with(&self, bodies: &BodyStore) -> Result<(), Error> {
        self.validate()?;
        crate::checks::joint_bodies(bodies, self.body_a, self.body_b)
    }

    /// Solver data at the bodies' current poses and velocities: the points
    /// on each surface, `depth / 2` either side of `point` along the normal,
    /// with the depth capped at `max_depth`. The cap is the push-out limit:
    /// the solver removes at most `max_depth` of an overlap this step (the
    /// rest is still there at the next detection), so a body teleported
    /// deep into another comes out at the configured speed instead of
    /// being fired out at `depth / dt`, tearing its joints on the way.
    fn lane(&self, bodies: &BodyStore, max_depth: f32) -> ContactLane {
        let (ia, ib) = (self.body_a.index(), self.body_b.index());
        let n = self.normal.normalize();
        let depth = self.depth.min(max_depth);
        let on_a = self.point + n * (0.5 * depth);
        let on_b = self.point - n * (0.5 * depth);
        let local = |i: usize, p: Vec3| bodies.orientation[i].inverse() * (p - bodies.position[i]);
        let velocity = |i: usize, p: Vec3| {
            bodies.linear_velocity[i] + bodies.angular_velocity[i].cross(p - bodies.position[i])
        };
        let (point_a, point_b) = (local(ia, on_a), local(ib, on_b));
        // The points' separation is the contact's own `-depth n`, exactly:
        // rebuilt from the f32 surface points and the bodies' coordinates it
        // would lose a gap or overlap smaller than the coordinates' last
        // digit (a box 1.6 mm over the ground at 100 km hovered there).
        let start = StartLane {
            gap: n * -depth,
            ..StartLane::new(
                bodies.precise_position(ia),
                bodies.orientation[ia],
                point_a,
                bodies.precise_position(ib),
                bodies.orientation[ib],
                point_b,
            )
        };
        ContactLane {
            body_a: ia as u32 + 1,
            body_b: ib as u32 + 1,
            dynamic_a: bodies.kind[ia] == BodyKind::Dynamic,
            dynamic_b: bodies.kind[ib] == BodyKind::Dynamic,
            point_a,
            point_b,
            normal: n,
            friction: self.friction,
            restitution: self.restitution,
            approach: (velocity(ib, self.point) - velocity(ia, self.point)).dot(n),
            overlap: depth.max(0.0),
            start,
        }
    }
}

/// This step's contacts, coloured and in blocks.
#[derive(Clone, Debug, Default)]
pub(crate) struct ContactLayout {
    pub blocks: Vec<ContactBlock>,
    /// Block ranges of the non-empty colours, in order.
    pub colours: Vec<Range<usize>>,
    /// Block range of the overflow set.
    pub overflow: Range<usize>,
    /// Every colour passed [`crate::parallel::colour_is_disjoint`].
    pub disjoint: bool,
}

impl ContactLayout {
    /// Colours `contacts` greedily (in the order given) and lays them out,
    /// each overlap capped at `max_depth` (m) for this step.
    pub fn build(contacts: &[Contact], bodies: &BodyStore, max_depth: f32) -> Self {
        let mut colouring = Colouring::new();
        let dynamic = |h: BodyHandle| {
            (bodies.kind[h.index()] == BodyKind::Dynamic).then_some(h.index() as u32)
        };
        for (k, c) in contacts.iter().enumerate() {
            colouring.add(k as u64, [dynamic(c.body_a), dynamic(c.body_b)]);
        }
        let mut layout = Self::default();
        for colour in 0..MAX_COLOURS {
            let range = layout.append(colouring.colour(colour).iter(), contacts, bodies, max_depth);
            if !range.is_empty() {
                layout.colours.push(range);
            }
        }
        layout.overflow = layout.append(colouring.overflow().iter(), contacts, bodies, max_depth);
        layout.disjoint = layout.colours.iter().all(|r| {
            crate::parallel::colour_is_disjoint(layout.blocks[r.clone()].iter().map(|b| &b.bodies))
        });
        layout
    }

    fn append<'k>(
        &mut self,
        keys: impl Iterator<Item = &'k u64>,
        contacts: &[Contact],
        bodies: &BodyStore,
        max_depth: f32,
    ) -> Range<usize> {
        let start = self.blocks.len();
        for (k, &key) in keys.enumerate() {
            if k % BLOCK_LANES == 0 {
                self.blocks.push(ContactBlock::padding());
            }
            let block = self.blocks.len() - 1;
            self.blocks[block].set(
                k % BLOCK_LANES,
                &contacts[key as usize].lane(bodies, max_depth),
            );
        }
        start..self.blocks.len()
    }
}

/// Checks a whole contact list (bodies live, at least one dynamic) before
/// any is used.
pub(crate) fn validate_all(contacts: &[Contact], bodies: &BodyStore) -> Result<(), Error> {
    contacts.iter().try_for_each(|c| c.validate_with(bodies))
}
