//! Powered ragdolls: every joint driven toward a target animation pose
//! (the paper's figure 7 drives "with infinite strength").
//!
//! Sockets use their angular drive; the rod is driven through its rest
//! shape: its rest bend and twist become the target pose's (and, following
//! an animation, move at the rates that reach the next pose's, as a
//! socket's target moves at its target velocity), and its bending and
//! twisting take the drive's strength, damping and torque limit (mapped
//! from the sockets it replaces: `rod_stiffness`).

use glam::Vec3;
use vertebra_math::{DefaultFloatMode, PortableQuat};
use vertebra_world::{AngularDrive, JointHandle, JointKind, RodDesc, RodStiffness, Spring, World};

use crate::drive::DriveSettings;
use crate::error::RagdollError;
use crate::model::rod_name;
use crate::pose::Pose;
use crate::profile::JointDriveSetting;
use crate::ragdoll::Ragdoll;

/// The rod's bending and twisting for a drive strength, when it replaces
/// `joints` sockets in series (each a spring-damper of compliance `c` and
/// damping `D`). In series every socket carries the same torque `tau`, so
/// each turns by the same `C_i` with `tau = C_i / c + D C_i'`, and the
/// chain by `C = n C_i`: `tau = C / (n c) + (D / n) C'`. The rod's torque is
/// `(k / l0) C + (d / l0) C'`, so `k = l0 / (n c)` and `d = l0 D / n` (its
/// damping time `d / k = c D`, the socket's). A spring given by frequency
/// is the rod's own spring at that frequency and ratio (on its effective
/// inertia); zero compliance ([`Spring::RIGID`]) is a rigid rod.
/// `docs/ragdolls.md`, "Drives", measures the two spines against each
/// other.
fn rod_stiffness(strength: Spring, rest_length: f32, joints: usize) -> RodStiffness {
    let n = joints.max(1) as f32;
    match strength {
        Spring::Compliance {
            compliance: 0.0, ..
        } => RodStiffness::Kirchhoff(f32::INFINITY),
        Spring::Compliance {
            compliance: c,
            damping,
        } => RodStiffness::Damped {
            stiffness: rest_length / (n * c),
            damping: rest_length * damping / n,
        },
        Spring::Frequency {
            frequency,
            damping_ratio,
        } => RodStiffness::Spring {
            frequency,
            damping_ratio,
        },
    }
}

/// Every joint's drive (`None`: not driven) and the rod's shape, made and
/// checked, not yet set.
pub(crate) struct JointDrives {
    sockets: Vec<(JointHandle, Option<AngularDrive>)>,
    rod: Option<(vertebra_world::RodHandle, RodDesc)>,
}

impl Ragdoll {
    /// Drives every joint toward `target`, held still (every socket's
    /// target velocity and the rod's rest rates are zero). Call it again
    /// with each new animation pose; it changes drive settings in place.
    /// A moving animation is better followed by [`Ragdoll::drive_following`].
    pub fn drive_to(
        &self,
        world: &mut World,
        target: &Pose,
        settings: &DriveSettings,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.drive(world, target, None, settings)
    }

    /// Drives every joint along a moving animation: from `prev` (the pose
    /// as this step begins) to `pose` (as it ends, `dt` seconds later), as
    /// Jolt's `DriveToPoseUsingMotors(prev, pose, dt)`. Each joint's target
    /// starts at `prev`'s relative rotation and turns at the angular
    /// velocity that reaches `pose`'s at the step's end
    /// (`AngularDrive::following`); the rod's rest shape likewise starts at
    /// `prev`'s bend and twist and moves at the rates that reach `pose`'s
    /// (`RodDesc::following`). So every drive follows the animation without
    /// lagging a frame behind and its damping acts on the motion relative
    /// to the animation's, not relative to rest. Call it every frame with
    /// the animation's last two poses (`docs/ragdolls.md`, "Drives").
    pub fn drive_following(
        &self,
        world: &mut World,
        prev: &Pose,
        pose: &Pose,
        dt: f32,
        settings: &DriveSettings,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.check_not_removed()?;
        prev.validate(&self.desc)?;
        if !(dt.is_finite() && dt >= vertebra_world::MIN_TIME_STEP) {
            return Err(RagdollError::OutOfRange {
                context: "drive".to_owned(),
                field: "dt",
                reason: format!(
                    "is {dt}; must be a time step of at least {} s",
                    vertebra_world::MIN_TIME_STEP
                ),
            });
        }
        self.drive(world, pose, Some((prev, dt)), settings)
    }

    fn drive(
        &self,
        world: &mut World,
        target: &Pose,
        from: Option<(&Pose, f32)>,
        settings: &DriveSettings,
    ) -> Result<(), RagdollError> {
        self.check_not_removed()?;
        let joints = &self.desc.joints;
        settings.validate("drive", joints.len(), |k| {
            format!("joint `{}`", joints[k].name)
        })?;
        let settings = settings.joint_settings(joints.len());
        let drives = self.joint_drives(world, target, from, &settings)?;
        self.set_joint_drives(world, drives)
    }

    /// Every joint's drive and the rod's shape toward `target` (from
    /// `from`, following), each made and checked; nothing set yet, so a
    /// refused call changes nothing (a joint or rod no longer in `world`
    /// included). `settings` holds one entry per
    /// described joint (the caller checked them); the rod takes the spine's
    /// first joint's.
    pub(crate) fn joint_drives(
        &self,
        world: &World,
        target: &Pose,
        from: Option<(&Pose, f32)>,
        settings: &[JointDriveSetting],
    ) -> Result<JointDrives, RagdollError> {
        self.check_not_removed()?;
        target.validate(&self.desc)?;
        if let Some((prev, _)) = from {
            prev.validate(&self.desc)?;
        }
        let relative = |pose: &Pose, j: &crate::JointDef| {
            let frame = j.frame;
            (pose.bones[j.parent].1.mul_portable(frame).inverse())
                .mul_portable(pose.bones[j.child].1.mul_portable(frame))
                .normalize_portable()
        };
        let mut sockets = Vec::with_capacity(self.joints.len());
        for ((j, joint), setting) in self.desc.joints.iter().zip(&self.joints).zip(settings) {
            // A fixed joint has no rotation to drive.
            let (Some(joint), false) = (joint, j.kind == JointKind::Fixed) else {
                continue;
            };
            let world_error = |e| RagdollError::world(&format!("joint `{}`", j.name), e);
            world.joint(*joint).map_err(world_error)?;
            let Some(strength) = setting.strength else {
                sockets.push((*joint, None));
                continue;
            };
            let end = relative(target, j);
            let mut drive = AngularDrive::new(end, strength).with_max_torque(setting.max_torque);
            if let Some((prev, dt)) = from {
                drive = drive
                    .following(relative(prev, j), end, dt)
                    .map_err(world_error)?;
            }
            drive.validate().map_err(world_error)?;
            sockets.push((*joint, Some(drive)));
        }
        let rod = match (self.rod, self.rod_rest, &self.desc.spine) {
            (Some(rod), Some(rest), Some(spine)) => {
                let rod_error = |e| RagdollError::world(&rod_name(&self.desc), e);
                world.rod(rod).map_err(rod_error)?;
                let setting = settings[spine.joints[0]];
                let shape = setting
                    .strength
                    .map(|strength| {
                        self.driven_rod(rest, spine, strength, setting.max_torque, target, from)
                    })
                    .transpose()?
                    .unwrap_or(rest);
                Some((rod, shape))
            }
            _ => None,
        };
        Ok(JointDrives { sockets, rod })
    }

    /// The rod's shape driven toward `target` at `strength`.
    fn driven_rod(
        &self,
        rest: RodDesc,
        spine: &crate::SpineDef,
        strength: Spring,
        max_torque: f32,
        target: &Pose,
        from: Option<(&Pose, f32)>,
    ) -> Result<RodDesc, RagdollError> {
        // A pose's rod shape: `t_b` in a's material frame, and the twist.
        let shape = |pose: &Pose| {
            let (base, top) = (
                pose.bones[spine.bodies[0]].1,
                pose.bones[*spine.bodies.last().expect("a chain")].1,
            );
            let (f0, f1) = (
                base.mul_portable(rest.frame_a),
                top.mul_portable(rest.frame_b),
            );
            let tb = f1 * Vec3::X;
            (
                (f0.inverse() * tb).normalize(),
                vertebra_world::rod_twist(f0, f1),
            )
        };
        let stiffness = rod_stiffness(strength, rest.rest_length, spine.joints.len());
        let driven = rest
            .with_stiffness(stiffness, stiffness)
            .with_max_torque(max_torque);
        let world_error = |e| RagdollError::world(&rod_name(&self.desc), e);
        let driven = match from {
            Some((prev, dt)) => driven
                .following(shape(prev), shape(target), dt)
                .map_err(world_error)?,
            None => {
                let (bend_rest, twist_rest) = shape(target);
                RodDesc {
                    bend_rest,
                    twist_rest,
                    ..driven.with_rest_velocity(Vec3::ZERO, 0.0)
                }
            }
        };
        driven.validate().map_err(world_error)?;
        Ok(driven)
    }

    /// Sets drives [`Ragdoll::joint_drives`] made and checked.
    pub(crate) fn set_joint_drives(
        &self,
        world: &mut World,
        drives: JointDrives,
    ) -> Result<(), RagdollError> {
        for (joint, drive) in drives.sockets {
            (world.set_joint_drive(joint, drive))
                .map_err(|e| RagdollError::world("joint drive", e))?;
        }
        if let Some((rod, shape)) = drives.rod {
            (world.set_rod(rod, shape))
                .map_err(|e| RagdollError::world(&rod_name(&self.desc), e))?;
        }
        Ok(())
    }

    /// Turns every drive off: sockets without drives, the rod back to its
    /// rest shape and passive stiffness.
    pub fn release_drives(&self, world: &mut World) -> Result<(), RagdollError> {
        self.check_not_removed()?;
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
