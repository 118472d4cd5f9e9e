//! A ragdoll held in the world by its animation: every dynamic body pulled
//! toward its bone's pose by a world drive, some bodies kept upright, and
//! the joints driven too, one call a frame (`Ragdoll::follow`). The world
//! drives' caps are per kilogram, so a cap under gravity's acceleration
//! keeps the ragdoll's own weight on its feet: it stands because it
//! balances, not because the drives carry it.

use glam::Vec3;
use vertebra_math::DefaultFloatMode;
use vertebra_store::BodyKind;
use vertebra_world::{BodyHandle, Spring, SpringField, UprightDrive, World, WorldDrive};

use crate::drive::DriveSettings;
use crate::error::{RagdollError, check_spring, range};
use crate::model::RagdollDesc;
use crate::pose::Pose;
use crate::profile::{BodyDriveSetting, Profile, UprightSetting};
use crate::ragdoll::Ragdoll;

/// One body kept upright: the axis that points up in the animation's pose
/// is held near world up (+Y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Upright {
    /// The described body (its index in the description).
    pub body: usize,
    /// Stiffness and damping across the axis.
    pub strength: Spring,
    /// The largest torque (N m; infinity is unlimited).
    pub max_torque: f32,
}

/// How hard every body is pulled toward its bone's pose in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldDriveSettings {
    /// The position part's strength (`None`: positions free).
    pub linear: Option<Spring>,
    /// The orientation part's strength (`None`: orientations free).
    pub angular: Option<Spring>,
    /// Each body's force cap per kilogram of its mass (N/kg, i.e. m/s^2;
    /// infinity is unlimited): the drives together never push harder than
    /// the ragdoll's mass times this, so below gravity's 9.81 they cannot
    /// hold the ragdoll up alone.
    pub max_acceleration: f32,
    /// Each body's torque cap (N m; infinity is unlimited).
    pub max_torque: f32,
    /// Bodies kept upright, each at most once.
    pub uprights: Vec<Upright>,
}

/// Everything that drives a ragdoll along its animation: its joints and
/// its bodies in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct PhysicalAnimation {
    /// The joints' drives (`Ragdoll::drive_following`).
    pub joints: DriveSettings,
    /// The bodies' world drives (`Ragdoll::world_drive_following`).
    pub world: WorldDriveSettings,
}

impl WorldDriveSettings {
    /// Checks the settings for a ragdoll of `bodies` bodies; errors name
    /// `world drive` and the field, or the upright by its index.
    fn validate(&self, bodies: usize) -> Result<(), RagdollError> {
        let context = "world drive";
        if let Some(s) = self.linear {
            check_spring(context, "linear", s, SpringField::WorldPosition)?;
        }
        if let Some(s) = self.angular {
            check_spring(context, "angular", s, SpringField::WorldOrientation)?;
        }
        let cap = |x: f32| !(x.is_nan() || x < 0.0);
        let reason = "must be a number, not negative";
        range(
            context,
            "max_acceleration",
            cap(self.max_acceleration),
            reason,
        )?;
        range(context, "max_torque", cap(self.max_torque), reason)?;
        for (k, u) in self.uprights.iter().enumerate() {
            let context = format!("world drive upright {k}");
            let once = !self.uprights[..k].iter().any(|v| v.body == u.body);
            range(
                &context,
                "body",
                u.body < bodies,
                &format!("must be below {bodies}"),
            )?;
            range(
                &context,
                "body",
                once,
                "names a body an earlier upright names",
            )?;
            check_spring(&context, "strength", u.strength, SpringField::Upright)?;
            range(&context, "max_torque", cap(u.max_torque), reason)?;
        }
        Ok(())
    }
}

impl Profile {
    /// The profile `animation` gives `desc`: every joint the joint drive
    /// settings' (their per-joint strengths included), every body the
    /// world drive settings', the uprights on their bodies. Refused, naming
    /// the field, for settings `Ragdoll::follow` refuses. An infinite
    /// frequency, rigid to the world, becomes the rigid zero compliance a
    /// profile holds (and a file writes), so that the profile is one
    /// `Ragdoll::follow_profile` and `ProfileBlend` take.
    pub fn from_animation(
        name: &str,
        desc: &RagdollDesc,
        animation: &PhysicalAnimation,
    ) -> Result<Self, RagdollError> {
        let (joints, world) = (&animation.joints, &animation.world);
        joints.validate("drive", desc.joints.len(), |k| {
            format!("joint `{}`", desc.joints[k].name)
        })?;
        world.validate(desc.bodies.len())?;
        let body = BodyDriveSetting {
            linear: world.linear.map(rigid_as_compliance),
            angular: world.angular.map(rigid_as_compliance),
            max_acceleration: world.max_acceleration,
            max_torque: world.max_torque,
            upright: None,
        };
        let mut bodies = vec![body; desc.bodies.len()];
        for u in &world.uprights {
            if let Some(b) = bodies.get_mut(u.body) {
                b.upright = Some(UprightSetting {
                    strength: rigid_as_compliance(u.strength),
                    max_torque: u.max_torque,
                });
            }
        }
        let mut joints = joints.joint_settings(desc.joints.len());
        for j in &mut joints {
            j.strength = j.strength.map(rigid_as_compliance);
        }
        Ok(Self {
            name: name.to_owned(),
            joints,
            bodies,
        })
    }
}

/// `s`, with an infinite frequency (rigid) as the zero compliance
/// [`Spring::RIGID`]: the world lays both out alike.
fn rigid_as_compliance(s: Spring) -> Spring {
    match s {
        Spring::Frequency { frequency, .. } if frequency.is_infinite() => Spring::RIGID,
        s => s,
    }
}

impl Ragdoll {
    /// Pulls every dynamic body toward its bone's pose in `pose`, held
    /// still, and keeps the settings' bodies upright as `pose` has them
    /// (see [`Ragdoll::world_drive_following`]).
    pub fn world_drive_to(
        &self,
        world: &mut World,
        pose: &Pose,
        settings: &WorldDriveSettings,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.world_drive(world, pose, None, settings)
    }

    /// Pulls every dynamic body along the animation: its world drive's
    /// target starts at its bone's pose in `prev` and moves to `pose`'s as
    /// the step of `dt` ends (`WorldDrive::following`); each upright body's
    /// axis that is up in `pose` is held near world up. Kinematic bodies
    /// (a partial ragdoll's) are left to the animation. Refused, nothing
    /// changed, for settings or poses out of range (the error names them);
    /// call it every frame with the animation's last two poses.
    pub fn world_drive_following(
        &self,
        world: &mut World,
        prev: &Pose,
        pose: &Pose,
        dt: f32,
        settings: &WorldDriveSettings,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.world_drive(world, pose, Some((prev, dt)), settings)
    }

    /// The joints' and the bodies' drives along the animation, one call a
    /// frame: [`Ragdoll::drive_following`] and
    /// [`Ragdoll::world_drive_following`], both checked before either
    /// changes anything.
    pub fn follow(
        &self,
        world: &mut World,
        poses: (&Pose, &Pose),
        dt: f32,
        animation: &PhysicalAnimation,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.check_not_removed()?;
        let profile = Profile::from_animation("", &self.desc, animation)?;
        self.follow_checked(world, poses, dt, &profile)
    }

    /// Every joint and body driven along the animation by `profile` (as
    /// [`Ragdoll::follow`] does; a [`crate::ProfileBlend`]'s current profile
    /// each frame, for one that blends), one call a frame: joints whose
    /// entry has no strength and bodies without drives are released.
    /// Refused, nothing changed, for a profile not made for this ragdoll
    /// (the error names its entry) or poses out of range.
    pub fn follow_profile(
        &self,
        world: &mut World,
        poses: (&Pose, &Pose),
        dt: f32,
        profile: &Profile,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.check_not_removed()?;
        profile.validate(&self.desc)?;
        self.follow_checked(world, poses, dt, profile)
    }

    fn follow_checked(
        &self,
        world: &mut World,
        (prev, pose): (&Pose, &Pose),
        dt: f32,
        profile: &Profile,
    ) -> Result<(), RagdollError> {
        self.check_poses(pose, Some((prev, dt)))?;
        let from = Some((prev, dt));
        let bodies = self.world_drives(world, pose, from, &profile.bodies)?;
        let joints = self.joint_drives(world, pose, from, &profile.joints)?;
        self.set_joint_drives(world, joints)?;
        set_world_drives(world, bodies)
    }

    /// Clears every body's world and upright drive.
    /// Refused, nothing changed, for a body no longer in `world`.
    pub fn release_world_drives(&self, world: &mut World) -> Result<(), RagdollError> {
        self.check_not_removed()?;
        let mut dynamic = Vec::with_capacity(self.bodies.len());
        for (k, body) in self.bodies.iter().enumerate() {
            let Some(body) = *body else { continue };
            if self.body_index_in(world, k, body)?.1 == BodyKind::Dynamic {
                dynamic.push(body);
            }
        }
        for body in dynamic {
            let clear = |w: &mut World| {
                w.set_world_drive(body, None)?;
                w.set_upright_drive(body, None)
            };
            clear(world).map_err(|e| RagdollError::world("world drive", e))?;
        }
        Ok(())
    }

    /// Described body `k`'s `body` in `world`: its index and kind; refused,
    /// naming the body, for a handle `world` did not issue or has removed.
    fn body_index_in(
        &self,
        world: &World,
        k: usize,
        body: BodyHandle,
    ) -> Result<(usize, BodyKind), RagdollError> {
        let i = (world.bodies().index(body))
            .map_err(|e| RagdollError::world(&format!("body `{}`", self.desc.bodies[k].name), e))?;
        Ok((i, world.bodies().kind[i]))
    }

    /// Everything [`Ragdoll::world_drive`] checks before it changes
    /// anything.
    fn check_world_drive(
        &self,
        pose: &Pose,
        from: Option<(&Pose, f32)>,
        settings: &WorldDriveSettings,
    ) -> Result<(), RagdollError> {
        self.check_not_removed()?;
        settings.validate(self.desc.bodies.len())?;
        self.check_poses(pose, from)
    }

    /// The poses (and the time step) a drive follows, checked.
    fn check_poses(&self, pose: &Pose, from: Option<(&Pose, f32)>) -> Result<(), RagdollError> {
        pose.validate(&self.desc)?;
        if let Some((prev, dt)) = from {
            prev.validate(&self.desc)?;
            range(
                "world drive",
                "dt",
                dt.is_finite() && dt >= vertebra_world::MIN_TIME_STEP,
                "must be a time step of at least 1e-6 s",
            )?;
        }
        Ok(())
    }

    fn world_drive(
        &self,
        world: &mut World,
        pose: &Pose,
        from: Option<(&Pose, f32)>,
        settings: &WorldDriveSettings,
    ) -> Result<(), RagdollError> {
        self.check_world_drive(pose, from, settings)?;
        let animation = PhysicalAnimation {
            joints: DriveSettings::uniform(Spring::RIGID),
            world: settings.clone(),
        };
        let profile = Profile::from_animation("", &self.desc, &animation)?;
        let drives = self.world_drives(world, pose, from, &profile.bodies)?;
        set_world_drives(world, drives)
    }

    /// Every dynamic body's world and upright drive (`None`: released),
    /// each made and checked (nothing set yet: a refused call changes
    /// nothing). `settings` holds one entry per described body (the caller
    /// checked them and the poses).
    fn world_drives(
        &self,
        world: &World,
        pose: &Pose,
        from: Option<(&Pose, f32)>,
        settings: &[BodyDriveSetting],
    ) -> Result<Vec<BodyDrive>, RagdollError> {
        let mut drives = Vec::with_capacity(self.bodies.len());
        for ((k, body), setting) in self.bodies.iter().enumerate().zip(settings) {
            let Some(body) = *body else { continue };
            let (i, kind) = self.body_index_in(world, k, body)?;
            if kind != BodyKind::Dynamic {
                continue;
            }
            let world_error = |e| {
                let name = format!("body `{}`", self.desc.bodies[k].name);
                RagdollError::world(&name, e)
            };
            let (position, orientation) = pose.bones[k];
            let drive = if setting.linear.is_some() || setting.angular.is_some() {
                let mut drive = WorldDrive::new(position, orientation, Spring::RIGID)
                    .with_strengths(setting.linear, setting.angular)
                    .with_caps(
                        world.bodies().mass[i] * setting.max_acceleration,
                        setting.max_torque,
                    );
                if let Some((prev, dt)) = from {
                    drive = drive
                        .following(prev.bones[k], pose.bones[k], dt)
                        .map_err(world_error)?;
                }
                drive.validate().map_err(world_error)?;
                Some(drive)
            } else {
                None
            };
            let upright = setting.upright.map(|u| {
                let axis = (orientation.conjugate() * Vec3::Y).normalize();
                UprightDrive::new(axis, Vec3::Y, u.strength).with_max_torque(u.max_torque)
            });
            if let Some(u) = &upright {
                u.validate().map_err(world_error)?;
            }
            drives.push((body, drive, upright));
        }
        Ok(drives)
    }
}

/// A body with its world drive and upright drive (each `None`: released).
type BodyDrive = (BodyHandle, Option<WorldDrive>, Option<UprightDrive>);

/// Sets drives [`Ragdoll::world_drives`] made and checked.
fn set_world_drives(world: &mut World, drives: Vec<BodyDrive>) -> Result<(), RagdollError> {
    for (body, drive, upright) in drives {
        let set = |w: &mut World| {
            w.set_world_drive(body, drive)?;
            w.set_upright_drive(body, upright)
        };
        set(world).map_err(|e| RagdollError::world("world drive", e))?;
    }
    Ok(())
}
