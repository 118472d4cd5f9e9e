//! How hard a ragdoll is driven toward an animation pose: a strength per
//! joint and the settings for the whole ragdoll (a description's `[drive]`
//! table). Driving a built ragdoll with them: `pose_drive.rs`.

use glam::Quat;
use vertebra_world::AngularDrive;

use crate::error::RagdollError;

/// How hard a joint is driven.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Strength {
    /// Zero compliance: the target is a hard constraint.
    Infinite,
    /// XPBD compliance (rad / (N m)): time-step and iteration independent;
    /// damped by [`DriveSettings::damping`].
    Compliance(f32),
    /// A damped spring of natural frequency (Hz) and damping ratio (1 is
    /// critical) on each joint's own effective inertia.
    Spring {
        /// Natural frequency (Hz).
        frequency: f32,
        /// Damping ratio.
        damping_ratio: f32,
    },
}

/// Drive settings for a whole ragdoll, with optional per-joint overrides.
#[derive(Clone, Debug, PartialEq)]
pub struct DriveSettings {
    /// The strength of every joint without an override.
    pub strength: Strength,
    /// Damping coefficient (N m s / rad) of joints driven by
    /// [`Strength::Compliance`] (a spring's damping is its ratio).
    pub damping: f32,
    /// The largest torque (N m) each joint's drive exerts; infinity is
    /// unlimited.
    pub max_torque: f32,
    /// Per described joint, an override (empty: none). A simplified
    /// ragdoll's rod takes the override of the spine's first joint.
    pub joints: Vec<Option<Strength>>,
}

impl DriveSettings {
    /// Every joint at `strength`, no damping, no torque limit, no
    /// overrides.
    pub fn uniform(strength: Strength) -> Self {
        Self {
            strength,
            damping: 0.0,
            max_torque: f32::INFINITY,
            joints: Vec::new(),
        }
    }

    /// With a damping coefficient (N m s / rad).
    pub fn with_damping(mut self, damping: f32) -> Self {
        self.damping = damping;
        self
    }

    /// With a torque limit (N m).
    pub fn with_max_torque(mut self, max_torque: f32) -> Self {
        self.max_torque = max_torque;
        self
    }

    /// The drive `strength` gives a socket aimed at `target`.
    pub(crate) fn socket_drive(&self, strength: Strength, target: Quat) -> AngularDrive {
        let drive = match strength {
            Strength::Infinite => AngularDrive::rigid(target),
            Strength::Compliance(c) => AngularDrive::compliant(target, c, self.damping),
            Strength::Spring {
                frequency,
                damping_ratio,
            } => AngularDrive::spring(target, frequency, damping_ratio),
        };
        drive.with_max_torque(self.max_torque)
    }

    pub(crate) fn validate(&self, joints: usize) -> Result<(), RagdollError> {
        let out = |field: &'static str, reason: &str| RagdollError::OutOfRange {
            context: "drive".to_owned(),
            field,
            reason: reason.to_owned(),
        };
        if !(self.damping.is_finite() && self.damping >= 0.0) {
            return Err(out("damping", "must be finite and not negative"));
        }
        if self.max_torque.is_nan() || self.max_torque < 0.0 {
            return Err(out("max_torque", "must be a number, not negative"));
        }
        for s in core::iter::once(&self.strength).chain(self.joints.iter().flatten()) {
            // The world checks every range; a strength is tried on an
            // identity drive so that a refusal names the settings' field.
            if let Err(e) = self.socket_drive(*s, Quat::IDENTITY).validate() {
                let field = match s {
                    Strength::Spring { .. } => "strength (frequency, damping ratio)",
                    _ => "strength (compliance, damping)",
                };
                return Err(out(field, &e.to_string()));
            }
        }
        if !self.joints.is_empty() && self.joints.len() != joints {
            return Err(out("joints", &format!("needs {joints} entries or none")));
        }
        Ok(())
    }

    pub(crate) fn strength(&self, joint: usize) -> Strength {
        self.joints
            .get(joint)
            .copied()
            .flatten()
            .unwrap_or(self.strength)
    }
}
