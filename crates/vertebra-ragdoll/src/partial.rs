//! Partial ragdolls: any body switched between dynamic and kinematic at run
//! time, and the kinematic ones moved along the animation with matching
//! velocities (as Jolt's `Ragdoll::DriveToPoseUsingKinematics`), so that
//! the legs stay animated while the upper body goes limp, or the hips are
//! carried by a character controller while the rest hangs.
//!
//! A kinematic body moves exactly as the animation does and pulls on its
//! dynamic neighbours through their joints with infinite mass; the joints
//! between two kinematic bodies do nothing (both move by the animation). A
//! simplified (rod-spine) ragdoll's interior spine bones have no body: they
//! cannot be made kinematic, and they follow the rod's ends by the spine
//! mapping ([`crate::SpineMapping`]). Make the rod's ends kinematic to
//! animate the spine: the ends are then on the animation, the bones between
//! them where the mapping puts them (the animation's spine shape only if it
//! bends as the mapping assumes).

use vertebra_world::{BodyKind, MAX_TIME_STEP, MIN_TIME_STEP, World};

use crate::error::RagdollError;
use crate::pose::Pose;
use crate::ragdoll::Ragdoll;
use vertebra_math::DefaultFloatMode;

impl Ragdoll {
    /// Makes the body named `body` (its description's name, e.g. `thigh_l`)
    /// kinematic (`true`: moved only by its velocity, which
    /// [`Ragdoll::drive_to_pose_using_kinematics`] sets from the animation)
    /// or dynamic (`false`: simulated, with its own mass). Its velocity is
    /// kept either way, so a body released mid-motion moves on as it was
    /// moving (`World::set_body_kind`). Refused with nothing changed for a
    /// name that is not a body of the ragdoll (a simplified ragdoll's
    /// interior spine bones have none) or a body no longer in `world`,
    /// naming the body.
    pub fn set_body_kinematic(
        &self,
        world: &mut World,
        body: &str,
        kinematic: bool,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let (k, handle) = self.named_body(body, "set_body_kinematic")?;
        world
            .set_body_kind(handle, kind(kinematic))
            .map_err(|e| RagdollError::world(&self.body_context(k), e))
    }

    /// Sets every body's kind at once: `kinematic[k]` for described body
    /// `k`, in the description's body order (`true` kinematic, `false`
    /// dynamic), as [`Ragdoll::set_body_kinematic`] sets one. A simplified
    /// ragdoll's interior spine bones have no body: their entries must be
    /// `false` (make the rod's ends kinematic instead). All or nothing:
    /// every entry and body is checked before any changes; refused for a
    /// mask of another length, a `true` on a bone without a body, a removed
    /// ragdoll or a body no longer in `world` (named).
    pub fn set_kinematic(&self, world: &mut World, kinematic: &[bool]) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.root()?;
        if kinematic.len() != self.desc.bodies.len() {
            return Err(RagdollError::OutOfRange {
                context: "set_kinematic".to_owned(),
                field: "kinematic",
                reason: format!(
                    "has {} entries; needs one per described body ({})",
                    kinematic.len(),
                    self.desc.bodies.len()
                ),
            });
        }
        let mut changes = Vec::new();
        for (k, (&on, body)) in kinematic.iter().zip(&self.bodies).enumerate() {
            match body {
                Some(handle) => {
                    world
                        .body(*handle)
                        .map_err(|e| RagdollError::world(&self.body_context(k), e))?;
                    changes.push((k, *handle, on));
                }
                None if on => {
                    return Err(RagdollError::OutOfRange {
                        context: self.body_context(k),
                        field: "kinematic",
                        reason: "is true, but an interior spine bone of a simplified ragdoll \
                                 has no body (make the rod's ends kinematic)"
                            .to_owned(),
                    });
                }
                None => {}
            }
        }
        for (k, handle, on) in changes {
            world
                .set_body_kind(handle, kind(on))
                .map_err(|e| RagdollError::world(&self.body_context(k), e))?;
        }
        Ok(())
    }

    /// Per described body, whether it is kinematic now (`false` for an
    /// interior spine bone of a simplified ragdoll, which has no body).
    /// Refused for a removed ragdoll or a body no longer in `world`.
    pub fn kinematic(&self, world: &World) -> Result<Vec<bool>, RagdollError> {
        self.root()?;
        let mut mask = vec![false; self.desc.bodies.len()];
        for (k, handle) in self.live_bodies() {
            let i = world
                .bodies()
                .index(handle)
                .map_err(|e| RagdollError::world(&self.body_context(k), e))?;
            mask[k] = world.bodies().kind[i] == BodyKind::Kinematic;
        }
        Ok(mask)
    }

    /// Moves every kinematic body of the ragdoll to its bone of `pose` (the
    /// animation's pose as the next step ends: centre of mass, m, world,
    /// and orientation relative to bind pose) over the next step of `dt`
    /// seconds, with the velocities that take it there
    /// (`World::move_kinematic`), as Jolt's `DriveToPoseUsingKinematics`
    /// does for a whole ragdoll. Call it every frame with the animation's
    /// next pose: the kinematic bodies are on the animation after every
    /// step, and the dynamic bodies jointed to them are pulled along at the
    /// animation's velocities, not teleported. Dynamic bodies are left to
    /// the simulation (drive them with [`Ragdoll::drive_following`]); the
    /// pose's interior spine bones of a simplified ragdoll are not read
    /// (no body). All or nothing: refused with every velocity as it was
    /// for a pose that does not fit the description, `dt` outside
    /// `MIN_TIME_STEP` to `MAX_TIME_STEP`, a removed ragdoll, a body no
    /// longer in `world`, or a move the world refuses (a bone beyond the
    /// world's speed limits in `dt`: named).
    pub fn drive_to_pose_using_kinematics(
        &self,
        world: &mut World,
        pose: &Pose,
        dt: f32,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.check_not_removed()?;
        pose.validate(&self.desc)?;
        if !(MIN_TIME_STEP..=MAX_TIME_STEP).contains(&dt) {
            return Err(RagdollError::OutOfRange {
                context: "drive_to_pose_using_kinematics".to_owned(),
                field: "dt",
                reason: format!(
                    "is {dt}; must be a time step of {MIN_TIME_STEP} s to {MAX_TIME_STEP} s"
                ),
            });
        }
        let kinematic = self.kinematic(world)?;
        // Every body checked before any moves: a refused one leaves the
        // world as it was (velocities, and islands asleep).
        let mut moves = Vec::new();
        for (k, handle) in self.live_bodies().filter(|&(k, _)| kinematic[k]) {
            let (position, orientation) = pose.bones[k];
            let velocities = world
                .kinematic_velocities(handle, position, orientation, dt)
                .map_err(|e| RagdollError::world(&self.body_context(k), e))?;
            moves.push((k, handle, velocities));
        }
        for (k, handle, (linear, angular)) in moves {
            world
                .set_body_velocity(handle, linear, angular)
                .map_err(|e| RagdollError::world(&self.body_context(k), e))?;
        }
        Ok(())
    }
}

/// The world's kind for a kinematic flag.
fn kind(kinematic: bool) -> BodyKind {
    if kinematic {
        BodyKind::Kinematic
    } else {
        BodyKind::Dynamic
    }
}
