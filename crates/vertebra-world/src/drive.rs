//! The angular drive: how a socket's body b is turned toward a target
//! orientation relative to body a (a damped spring with a torque limit,
//! following a target that may move), and its validation. The derivation
//! is in `vertebra_kernels::parts::drive`; the guide in `docs/ragdolls.md`.

use core::f32::consts::TAU;
use vertebra_math::PortableQuat;

use glam::{Quat, Vec3};
use vertebra_kernels::driven::DriveLane;
use vertebra_store::{Error, check_unit_quat};

/// The lowest drive frequency (Hz): a period of about 17 minutes. Lower
/// ones are no drive at all, and `1 / omega^2` would leave `f32`.
pub const MIN_DRIVE_FREQUENCY: f32 = 1e-3;

/// The largest drive damping ratio: far past critical (1), and small
/// enough that `2 zeta / omega` stays a number.
pub const MAX_DRIVE_DAMPING_RATIO: f32 = 1e3;

/// The largest damping time `compliance * damping` (s) of a drive given by
/// compliance (a damping ratio of ~1e6 at 1 Hz).
pub const MAX_DRIVE_DAMPING_TIME: f32 = 1e6;

/// How strong a drive is.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum DriveStrength {
    /// XPBD compliance and damping coefficient: the torque is
    /// `-C / compliance - damping dC/dt` for the error rotation `C`.
    /// Independent of the time step and iteration count; how fast it
    /// moves a body depends on the body's inertia.
    Compliance {
        /// Compliance (rad / (N m)), the inverse of stiffness; 0 is
        /// infinitely stiff (and then damping does nothing).
        compliance: f32,
        /// Damping coefficient (N m s / rad).
        damping: f32,
    },
    /// A damped spring at `frequency` with `damping_ratio` whatever the
    /// bodies' inertia (as Jolt's `SpringSettings` and Box2D's soft
    /// constraints): stiffness and damping are scaled by the drive's
    /// effective inertia, per substep.
    Spring {
        /// Natural frequency (Hz), at least [`MIN_DRIVE_FREQUENCY`];
        /// infinity is infinitely stiff.
        frequency: f32,
        /// Damping ratio in [0, [`MAX_DRIVE_DAMPING_RATIO`]]: 1 is
        /// critical (no overshoot), below it oscillates.
        damping_ratio: f32,
    },
}

/// Drives a socket's body b toward an orientation relative to body a.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AngularDrive {
    /// b's joint frame relative to a's joint frame (unit quaternion), as
    /// the next step begins. The world advances it by `target_velocity`
    /// every substep and, while it moves (a nonzero `target_velocity`),
    /// writes it back after each step; the solver then starts the next
    /// step from this value (normalised), as a restored snapshot does. A
    /// still target reads back as it was given.
    pub target: Quat,
    /// The target's angular velocity (rad/s, in a's joint frame); damping
    /// acts on the joint's angular velocity relative to it.
    pub target_velocity: Vec3,
    /// Stiffness and damping.
    pub strength: DriveStrength,
    /// The largest torque the drive exerts (N m, not negative); infinity
    /// is unlimited. A hit beyond it turns the joint away from the target.
    pub max_torque: f32,
}

impl AngularDrive {
    /// A drive that holds `target` exactly (zero compliance).
    pub fn rigid(target: Quat) -> Self {
        Self::compliant(target, 0.0, 0.0)
    }

    /// A drive of compliance (rad / (N m)) and damping (N m s / rad).
    pub fn compliant(target: Quat, compliance: f32, damping: f32) -> Self {
        Self {
            target,
            target_velocity: Vec3::ZERO,
            strength: DriveStrength::Compliance {
                compliance,
                damping,
            },
            max_torque: f32::INFINITY,
        }
    }

    /// A drive of natural frequency (Hz) and damping ratio.
    pub fn spring(target: Quat, frequency: f32, damping_ratio: f32) -> Self {
        Self {
            strength: DriveStrength::Spring {
                frequency,
                damping_ratio,
            },
            ..Self::rigid(target)
        }
    }

    /// With a torque limit (N m).
    pub fn with_max_torque(mut self, max_torque: f32) -> Self {
        self.max_torque = max_torque;
        self
    }

    /// With a target angular velocity (rad/s, a's joint frame).
    pub fn with_target_velocity(mut self, velocity: Vec3) -> Self {
        self.target_velocity = velocity;
        self
    }

    /// Following an animation (as Jolt's `DriveToPoseUsingMotors`): the
    /// target is `prev` (b's joint frame relative to a's) as the next step
    /// begins and turns at constant angular velocity to reach `pose` when
    /// it ends, `dt` seconds later (the step's `dt`). Call it every frame
    /// with the animation's last two poses.
    ///
    /// `Err` (naming the `following time step`) for a `dt` that is not
    /// finite or below [`MIN_TIME_STEP`](crate::MIN_TIME_STEP), zero and
    /// negative ones included: a negative `dt` would turn the target away
    /// from `pose`. A turn too fast for the world (beyond
    /// [`MAX_ANGULAR_SPEED_LIMIT`](crate::MAX_ANGULAR_SPEED_LIMIT)) is
    /// refused when the drive is added or set, as any drive's velocity.
    pub fn following(mut self, prev: Quat, pose: Quat, dt: f32) -> Result<Self, Error> {
        crate::checks::following_time_step(dt)?;
        let turn = vertebra_math::Quat::<f32>::from(pose.mul_portable(prev.conjugate()));
        self.target = prev;
        self.target_velocity = Vec3::from(turn.to_rotation_vector()) / dt;
        Ok(self)
    }

    /// Checks the target, its velocity, the strength and the torque limit;
    /// the error names the field.
    pub fn validate(&self) -> Result<(), Error> {
        validate_drive(self)
    }

    /// The kernel's lane data (`parts::drive`: `alpha = compliance +
    /// period2 W`, `gamma h = damping_time`).
    pub(crate) fn lane(&self) -> DriveLane {
        let (compliance, period2, damping_time) = match self.strength {
            DriveStrength::Compliance {
                compliance,
                damping,
            } => (compliance, 0.0, compliance * damping),
            DriveStrength::Spring {
                frequency,
                damping_ratio,
            } => {
                let omega = TAU * frequency;
                (0.0, 1.0 / (omega * omega), 2.0 * damping_ratio / omega)
            }
        };
        DriveLane {
            target: self.target.normalize_portable(),
            velocity: self.target_velocity,
            compliance,
            period2,
            damping_time,
            max_torque: self.max_torque,
        }
    }
}

/// Checks a drive's target, its velocity, strength and torque limit.
pub(crate) fn validate_drive(d: &AngularDrive) -> Result<(), Error> {
    check_unit_quat("drive target", d.target)?;
    crate::checks::angular_velocity(
        d.target_velocity,
        "drive target velocity",
        "drive target velocity (at most MAX_ANGULAR_SPEED_LIMIT)",
    )?;
    match d.strength {
        DriveStrength::Compliance {
            compliance,
            damping,
        } => {
            finite_not_negative("drive compliance", compliance)?;
            finite_not_negative("drive damping", damping)?;
            if compliance * damping > MAX_DRIVE_DAMPING_TIME {
                return Err(Error::OutOfRange(
                    "drive damping (compliance times damping at most 1e6 s)",
                ));
            }
        }
        DriveStrength::Spring {
            frequency,
            damping_ratio,
        } => {
            if frequency.is_nan() {
                return Err(Error::NonFinite("drive frequency"));
            }
            if frequency < MIN_DRIVE_FREQUENCY {
                return Err(Error::OutOfRange("drive frequency (at least 1e-3 Hz)"));
            }
            finite_not_negative("drive damping ratio", damping_ratio)?;
            if damping_ratio > MAX_DRIVE_DAMPING_RATIO {
                return Err(Error::OutOfRange("drive damping ratio (at most 1e3)"));
            }
        }
    }
    if d.max_torque.is_nan() {
        return Err(Error::NonFinite("drive max torque"));
    }
    if d.max_torque < 0.0 {
        return Err(Error::NonPositive("drive max torque"));
    }
    Ok(())
}

fn finite_not_negative(what: &'static str, x: f32) -> Result<(), Error> {
    if !x.is_finite() {
        return Err(Error::NonFinite(what));
    }
    if x < 0.0 {
        return Err(Error::NonPositive(what));
    }
    Ok(())
}
