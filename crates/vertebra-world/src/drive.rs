//! The angular drive: how a socket's body b is turned toward a target
//! orientation relative to body a (a damped spring with a torque limit,
//! following a target that may move), and its validation. The derivation
//! is in `vertebra_kernels::parts::drive`; the guide in `docs/ragdolls.md`.

use vertebra_math::PortableQuat;

use glam::{Quat, Vec3};
use vertebra_kernels::driven::DriveLane;
use vertebra_store::{Error, check_unit_quat};

use crate::spring::{Spring, SpringField};

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
    /// Stiffness and damping ([`Spring`]; its errors name the `drive`).
    pub strength: Spring,
    /// The largest torque the drive exerts (N m, not negative); infinity
    /// is unlimited. A hit beyond it turns the joint away from the target.
    pub max_torque: f32,
}

impl AngularDrive {
    /// A drive toward a still `target` at `strength`, without a torque
    /// limit.
    pub fn new(target: Quat, strength: Spring) -> Self {
        Self {
            target,
            target_velocity: Vec3::ZERO,
            strength,
            max_torque: f32::INFINITY,
        }
    }

    /// A drive that holds `target` exactly ([`Spring::RIGID`]).
    pub fn rigid(target: Quat) -> Self {
        Self::new(target, Spring::RIGID)
    }

    /// A drive of compliance (rad / (N m)) and damping (N m s / rad).
    pub fn compliant(target: Quat, compliance: f32, damping: f32) -> Self {
        let strength = Spring::Compliance {
            compliance,
            damping,
        };
        Self::new(target, strength)
    }

    /// A drive of natural frequency (Hz) and damping ratio.
    pub fn spring(target: Quat, frequency: f32, damping_ratio: f32) -> Self {
        let strength = Spring::Frequency {
            frequency,
            damping_ratio,
        };
        Self::new(target, strength)
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
        let spring = self.strength.lane();
        DriveLane {
            target: self.target.normalize_portable(),
            velocity: self.target_velocity,
            compliance: spring.compliance,
            period2: spring.period2,
            damping_time: spring.damping_time,
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
    d.strength.check(SpringField::Drive)?;
    if d.max_torque.is_nan() {
        return Err(Error::NonFinite("drive max torque"));
    }
    if d.max_torque < 0.0 {
        return Err(Error::NonPositive("drive max torque"));
    }
    Ok(())
}
