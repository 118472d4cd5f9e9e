//! How hard a ragdoll is driven toward an animation pose: the settings for
//! the whole ragdoll (a description's `[drive]` table), each joint's
//! strength a world [`Spring`]. Driving a built ragdoll with them:
//! `pose_drive.rs`.

use vertebra_world::{Spring, SpringField};

use crate::error::{RagdollError, check_spring, range};
use crate::profile::JointDriveSetting;

/// Drive settings for a whole ragdoll, with optional per-joint overrides.
/// A strength is the world's [`Spring`]: [`Spring::RIGID`] (zero
/// compliance) holds the target as a hard constraint (the paper's
/// "infinite strength"), [`Spring::Compliance`] is time-step and iteration
/// independent with its own damping, [`Spring::Frequency`] a damped
/// spring of that frequency and ratio on each joint's own effective
/// inertia.
#[derive(Clone, Debug, PartialEq)]
pub struct DriveSettings {
    /// The strength of every joint without an override.
    pub strength: Spring,
    /// The largest torque (N m) each joint's drive exerts; infinity is
    /// unlimited.
    pub max_torque: f32,
    /// Per described joint, an override (empty: none). A simplified
    /// ragdoll's rod takes the override of the spine's first joint.
    pub joints: Vec<Option<Spring>>,
}

impl DriveSettings {
    /// Every joint at `strength`, no torque limit, no overrides.
    pub fn uniform(strength: Spring) -> Self {
        Self {
            strength,
            max_torque: f32::INFINITY,
            joints: Vec::new(),
        }
    }

    /// With a torque limit (N m).
    pub fn with_max_torque(mut self, max_torque: f32) -> Self {
        self.max_torque = max_torque;
        self
    }

    /// One entry per joint of a ragdoll of `joints` joints: each joint's
    /// strength, the shared torque limit.
    pub(crate) fn joint_settings(&self, joints: usize) -> Vec<JointDriveSetting> {
        (0..joints)
            .map(|k| JointDriveSetting {
                strength: Some(self.strength(k)),
                max_torque: self.max_torque,
            })
            .collect()
    }

    /// Checks the settings for a ragdoll of `joints` joints: every strength
    /// as the world checks a drive's, the torque limit, and one override
    /// per joint or none. Errors name `context` (the settings) or, for an
    /// override, `joint(k)`.
    pub(crate) fn validate(
        &self,
        context: &str,
        joints: usize,
        joint: impl Fn(usize) -> String,
    ) -> Result<(), RagdollError> {
        check_spring(context, "strength", self.strength, SpringField::Drive)?;
        range(
            context,
            "max_torque",
            !(self.max_torque.is_nan() || self.max_torque < 0.0),
            "must be a number, not negative",
        )?;
        range(
            context,
            "joints",
            self.joints.is_empty() || self.joints.len() == joints,
            &format!("needs {joints} entries or none"),
        )?;
        for (k, strength) in self.joints.iter().enumerate() {
            if let Some(s) = strength {
                check_spring(&joint(k), "drive", *s, SpringField::Drive)?;
            }
        }
        Ok(())
    }

    pub(crate) fn strength(&self, joint: usize) -> Spring {
        self.joints
            .get(joint)
            .copied()
            .flatten()
            .unwrap_or(self.strength)
    }
}
