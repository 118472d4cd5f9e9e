//! The calls a game makes on a whole ragdoll: where it is (its root
//! transform, its bounds), how it moves (one velocity for every body, an
//! impulse on a named body).

use glam::{Quat, Vec3};
use vertebra_world::{BodyHandle, World};

use crate::error::RagdollError;
use crate::model::BodyDef;
use crate::ragdoll::Ragdoll;
use vertebra_math::DefaultFloatMode;

impl Ragdoll {
    /// The root body's centre of mass (m, world) and orientation (relative
    /// to the bind pose, as a [`crate::Pose`]'s bones are): the root is the
    /// description's `root` (the hips of the reference humanoid), which
    /// every built ragdoll has. Refused for a removed ragdoll or a root
    /// body no longer in `world`.
    pub fn root_transform(&self, world: &World) -> Result<(Vec3, Quat), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let s = world
            .body(self.root()?)
            .map_err(|e| RagdollError::world(&self.body_context(self.desc.root), e))?;
        Ok((s.position, s.orientation))
    }

    /// The smallest world-axis box (m, world: `(min, max)`) around every
    /// body's capsule at its current pose, radii included (a simplified
    /// ragdoll's interior spine bones have no body and are not in it; the
    /// rod's ends are). For culling and for picking a ragdoll. Refused as
    /// [`Ragdoll::root_transform`], or naming a body no longer in `world`.
    pub fn bounds(&self, world: &World) -> Result<(Vec3, Vec3), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.root()?;
        let mut bounds = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for (k, body) in self.live_bodies() {
            let s = world
                .body(body)
                .map_err(|e| RagdollError::world(&self.body_context(k), e))?;
            let (low, high) = capsule_bounds(&self.desc.bodies[k], s.position, s.orientation);
            bounds = (bounds.0.min(low), bounds.1.max(high));
        }
        Ok(bounds)
    }

    /// Sets every body's velocity so that the ragdoll moves as one rigid
    /// body: `linear` (m/s, world) is the velocity of the root body's
    /// centre of mass `x_root`, `angular` (rad/s, world) the angular
    /// velocity of every body, and a body whose centre of mass is at `x`
    /// gets `linear + angular x (x - x_root)`. Joints are not strained by
    /// it. For a ragdoll thrown, or one taking over an animated
    /// character's motion. All or nothing: refused with nothing changed
    /// for non-finite velocities, a body no longer in `world` (named), or
    /// a body's velocity that overflows `f32`.
    pub fn set_velocity(
        &self,
        world: &mut World,
        linear: Vec3,
        angular: Vec3,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        for (field, v) in [("linear velocity", linear), ("angular velocity", angular)] {
            if !v.is_finite() {
                return Err(RagdollError::NonFinite {
                    context: "ragdoll velocity".to_owned(),
                    field,
                });
            }
        }
        let (root, _) = self.root_transform(world)?;
        let mut velocities = Vec::new();
        for (k, body) in self.live_bodies() {
            let s = world
                .body(body)
                .map_err(|e| RagdollError::world(&self.body_context(k), e))?;
            let v = linear + angular.cross(s.position - root);
            if !v.is_finite() {
                return Err(RagdollError::OutOfRange {
                    context: self.body_context(k),
                    field: "velocity",
                    reason: "overflows f32 (angular velocity times distance from the root)"
                        .to_owned(),
                });
            }
            velocities.push((k, body, v));
        }
        for (k, body, v) in velocities {
            world
                .set_body_velocity(body, v, angular)
                .map_err(|e| RagdollError::world(&self.body_context(k), e))?;
        }
        Ok(())
    }

    /// Applies an impulse (N s, world) to the ragdoll's body named `body`
    /// (its description's name, e.g. `chest`): at the world `point` (m),
    /// or through the body's centre of mass for `None`. The body's
    /// velocities change at once (`World::apply_impulse_at`); its joints
    /// pass the hit on to the rest of the ragdoll in the next step.
    /// Refused with nothing changed for a name that is not a body of the
    /// ragdoll (a simplified ragdoll's interior spine bones have none),
    /// and for whatever the world refuses (a non-finite impulse, a point
    /// out of range), naming the body.
    pub fn apply_impulse(
        &self,
        world: &mut World,
        body: &str,
        impulse: Vec3,
        point: Option<Vec3>,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let (k, handle) = self.named_body(body, "impulse")?;
        let in_body = |e| RagdollError::world(&self.body_context(k), e);
        match point {
            Some(p) => world.apply_impulse_at(handle, impulse, p),
            None => world.apply_impulse(handle, impulse),
        }
        .map_err(in_body)
    }

    /// The described index and the handle of the body named `name`, for
    /// the call `call` (which errors name): refused for a name that is not
    /// a described body, for a body of a removed ragdoll, and for an
    /// interior spine bone of a simplified ragdoll (it has no body).
    pub(crate) fn named_body(
        &self,
        name: &str,
        call: &str,
    ) -> Result<(usize, BodyHandle), RagdollError> {
        let unknown = |context: String| RagdollError::UnknownBody {
            context,
            field: "body",
            name: name.to_owned(),
        };
        let k = self
            .desc
            .bodies
            .iter()
            .position(|b| b.name == name)
            .ok_or_else(|| unknown(call.to_owned()))?;
        self.check_not_removed()?;
        let handle = self.bodies[k].ok_or_else(|| {
            unknown(format!(
                "{call} (an interior spine bone of a simplified ragdoll has no body)"
            ))
        })?;
        Ok((k, handle))
    }

    /// The root body's handle; a removed ragdoll has none
    /// ([`RagdollError::Removed`]).
    pub(crate) fn root(&self) -> Result<BodyHandle, RagdollError> {
        self.bodies[self.desc.root].ok_or_else(|| self.removed())
    }

    /// `Ok` unless the ragdoll has been removed from its world
    /// ([`Ragdoll::remove`], or `vertebra_collide::Collisions::remove_ragdoll`):
    /// then [`RagdollError::Removed`], naming it. Every call that takes a
    /// ragdoll refuses a removed one this way, before anything else (a
    /// removed ragdoll has no bodies, joints or rod: mapped, it would put
    /// every bone at the world origin).
    pub fn check_not_removed(&self) -> Result<(), RagdollError> {
        self.root().map(drop)
    }

    /// The error for a call on a removed ragdoll.
    fn removed(&self) -> RagdollError {
        RagdollError::Removed {
            ragdoll: self.desc.name.clone(),
        }
    }

    /// Every body the ragdoll has, with its described index.
    pub(crate) fn live_bodies(&self) -> impl Iterator<Item = (usize, BodyHandle)> + '_ {
        self.bodies
            .iter()
            .enumerate()
            .filter_map(|(k, b)| b.map(|b| (k, b)))
    }

    /// How errors name described body `k`.
    pub(crate) fn body_context(&self, k: usize) -> String {
        format!("body `{}`", self.desc.bodies[k].name)
    }
}

/// The world-axis box `(min, max)` (m) around a body's capsule (the
/// described segment about its midpoint, the centre of mass, swept by the
/// radius) at `position` and `orientation` (relative to the bind pose).
fn capsule_bounds(def: &BodyDef, position: Vec3, orientation: Quat) -> (Vec3, Vec3) {
    let half_segment = (def.segment[1] - def.segment[0]) * 0.5;
    let reach = (orientation * half_segment).abs() + Vec3::splat(def.radius);
    (position - reach, position + reach)
}
