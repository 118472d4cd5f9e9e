//! Powered ragdolls: every joint driven toward a target animation pose
//! (the paper's figure 7 drives "with infinite strength").
//!
//! Sockets use their angular drive; the rod is driven through its rest
//! shape: its rest bend and twist become the target pose's, and its
//! bending and twisting take the drive's strength.

use glam::Vec3;
use vertebra_world::{AngularDrive, JointKind, RodStiffness, World};

use crate::error::RagdollError;
use crate::pose::Pose;
use crate::ragdoll::{Ragdoll, rod_name};

/// How hard a joint is driven.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Strength {
    /// Zero compliance: the target is a hard constraint.
    Infinite,
    /// XPBD compliance (rad / (N m)): time-step and iteration independent.
    Compliance(f32),
}

/// Drive settings for a whole ragdoll, with optional per-joint overrides.
#[derive(Clone, Debug, PartialEq)]
pub struct DriveSettings {
    /// The strength of every joint without an override.
    pub strength: Strength,
    /// Damping rate (1/s) of the sockets' drives.
    pub damping: f32,
    /// Per described joint, an override (empty: none). A simplified
    /// ragdoll's rod takes the override of the spine's first joint.
    pub joints: Vec<Option<Strength>>,
}

impl DriveSettings {
    /// Every joint at `strength`, no damping, no overrides.
    pub fn uniform(strength: Strength) -> Self {
        Self {
            strength,
            damping: 0.0,
            joints: Vec::new(),
        }
    }

    fn validate(&self, joints: usize) -> Result<(), RagdollError> {
        let bad =
            |s: &Strength| matches!(s, Strength::Compliance(c) if !(c.is_finite() && *c >= 0.0));
        if bad(&self.strength) || self.joints.iter().flatten().any(bad) {
            return Err(RagdollError::OutOfRange {
                context: "drive".to_owned(),
                field: "compliance",
                reason: "must be finite and not negative".to_owned(),
            });
        }
        if !(self.damping.is_finite() && self.damping >= 0.0) {
            return Err(RagdollError::OutOfRange {
                context: "drive".to_owned(),
                field: "damping",
                reason: "must be finite and not negative".to_owned(),
            });
        }
        if !self.joints.is_empty() && self.joints.len() != joints {
            return Err(RagdollError::OutOfRange {
                context: "drive".to_owned(),
                field: "joints",
                reason: format!("needs {joints} entries or none"),
            });
        }
        Ok(())
    }

    fn strength(&self, joint: usize) -> Strength {
        self.joints
            .get(joint)
            .copied()
            .flatten()
            .unwrap_or(self.strength)
    }
}

impl Ragdoll {
    /// Drives every joint toward `target`. Call it again with each new
    /// animation pose; it changes drive settings in place.
    pub fn drive_to(
        &self,
        world: &mut World,
        target: &Pose,
        settings: &DriveSettings,
    ) -> Result<(), RagdollError> {
        target.validate(&self.desc)?;
        settings.validate(self.desc.joints.len())?;
        for (k, (j, socket)) in self.desc.joints.iter().zip(&self.joints).enumerate() {
            // A fixed joint has no rotation to drive.
            let (Some(socket), false) = (socket, j.kind == JointKind::Fixed) else {
                continue;
            };
            let frame = j.frame;
            let relative =
                (target.bones[j.parent].1 * frame).inverse() * (target.bones[j.child].1 * frame);
            let compliance = match settings.strength(k) {
                Strength::Infinite => 0.0,
                Strength::Compliance(c) => c,
            };
            let drive = AngularDrive {
                target: relative.normalize(),
                compliance,
                damping: settings.damping,
            };
            world
                .set_joint_drive(*socket, Some(drive))
                .map_err(|e| RagdollError::world(&format!("joint `{}`", j.name), e))?;
        }
        if let (Some(rod), Some(rest), Some(spine)) = (self.rod, self.rod_rest, &self.desc.spine) {
            let (base, top) = (
                target.bones[spine.bodies[0]].1,
                target.bones[*spine.bodies.last().expect("a chain")].1,
            );
            let (f0, f1) = (base * rest.frame_a, top * rest.frame_b);
            let tb = f1 * Vec3::X;
            let stiffness = match settings.strength(spine.joints[0]) {
                Strength::Infinite => RodStiffness::Kirchhoff(f32::INFINITY),
                Strength::Compliance(c) => RodStiffness::Kirchhoff(rest.rest_length / c),
            };
            let mut driven = rest.with_stiffness(stiffness, stiffness);
            driven.bend_rest = (f0.inverse() * tb).normalize();
            driven.twist_rest = crate::mapping::rod_twist(f0, f1);
            world
                .set_rod(rod, driven)
                .map_err(|e| RagdollError::world(&rod_name(&self.desc), e))?;
        }
        Ok(())
    }

    /// Turns every drive off: sockets without drives, the rod back to its
    /// rest shape and passive stiffness.
    pub fn release_drives(&self, world: &mut World) -> Result<(), RagdollError> {
        for (socket, j) in self.joints.iter().zip(&self.desc.joints) {
            if let Some(socket) = socket {
                world
                    .set_joint_drive(*socket, None)
                    .map_err(|e| RagdollError::world(&format!("joint `{}`", j.name), e))?;
            }
        }
        if let (Some(rod), Some(rest)) = (self.rod, self.rod_rest) {
            world
                .set_rod(rod, rest)
                .map_err(|e| RagdollError::world(&rod_name(&self.desc), e))?;
        }
        Ok(())
    }
}
