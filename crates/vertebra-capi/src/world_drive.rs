//! World drives and upright drives: a body pulled toward a pose in the
//! world, or one of its axes held near a world direction, with caps
//! (`vertebra_world::WorldDrive`, `UprightDrive`).

use vertebra_world::{BodyHandle, Error, UprightDrive, World, WorldDrive};

use crate::error::{Failure, VtResult};
use crate::ffi::{out, read};
use crate::joint::{VtSoftness, drive_spring};
use crate::types::{VtBody, VtQuat, VtVec3, flag};
use crate::world::{VtWorld, with_world};

/// A body pulled toward a pose in the world: its centre of mass toward
/// `position`, its orientation toward `orientation`, each part a damped
/// spring with a cap.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtWorldDrive {
    /// The target for the centre of mass (m, world) as the next step
    /// begins.
    pub position: VtVec3,
    /// The target orientation (unit, world).
    pub orientation: VtQuat,
    /// The target's velocity (m/s, world).
    pub linear_velocity: VtVec3,
    /// The target's angular velocity (rad/s, world).
    pub angular_velocity: VtVec3,
    /// Non-zero: the position part acts, at `linear`.
    pub has_linear: u32,
    /// The position part's strength (`VT_SOFTNESS_KIND_COMPLIANCE`, 0:
    /// rigid, or `VT_SOFTNESS_KIND_SPRING`).
    pub linear: VtSoftness,
    /// Non-zero: the orientation part acts, at `angular`.
    pub has_angular: u32,
    /// The orientation part's strength.
    pub angular: VtSoftness,
    /// The largest force the position part exerts (N; infinity:
    /// unlimited).
    pub max_force: f32,
    /// The largest torque the orientation part exerts (N m; infinity:
    /// unlimited).
    pub max_torque: f32,
}

/// One axis of a body held near a world direction.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtUprightDrive {
    /// The body's axis (unit, body frame).
    pub axis: VtVec3,
    /// The world direction (unit, world).
    pub up: VtVec3,
    /// Its strength (compliance, 0: rigid, or a spring).
    pub strength: VtSoftness,
    /// The largest torque (N m; infinity: unlimited).
    pub max_torque: f32,
}

impl TryFrom<VtWorldDrive> for WorldDrive {
    type Error = Failure;
    fn try_from(d: VtWorldDrive) -> Result<Self, Failure> {
        let part = |has: u32, s: VtSoftness, field: &str| {
            flag(has).then(|| drive_spring(s, field)).transpose()
        };
        Ok(WorldDrive {
            position: d.position.into(),
            orientation: d.orientation.into(),
            linear_velocity: d.linear_velocity.into(),
            angular_velocity: d.angular_velocity.into(),
            linear: part(d.has_linear, d.linear, "drive.linear")?,
            angular: part(d.has_angular, d.angular, "drive.angular")?,
            max_force: d.max_force,
            max_torque: d.max_torque,
        })
    }
}

impl From<WorldDrive> for VtWorldDrive {
    fn from(d: WorldDrive) -> Self {
        let part = |s: Option<vertebra_world::Spring>| {
            let rigid = vertebra_world::Spring::RIGID;
            (u32::from(s.is_some()), s.unwrap_or(rigid).into())
        };
        let ((has_linear, linear), (has_angular, angular)) = (part(d.linear), part(d.angular));
        Self {
            position: d.position.into(),
            orientation: d.orientation.into(),
            linear_velocity: d.linear_velocity.into(),
            angular_velocity: d.angular_velocity.into(),
            has_linear,
            linear,
            has_angular,
            angular,
            max_force: d.max_force,
            max_torque: d.max_torque,
        }
    }
}

impl TryFrom<VtUprightDrive> for UprightDrive {
    type Error = Failure;
    fn try_from(d: VtUprightDrive) -> Result<Self, Failure> {
        Ok(UprightDrive {
            axis: d.axis.into(),
            up: d.up.into(),
            strength: drive_spring(d.strength, "drive.strength")?,
            max_torque: d.max_torque,
        })
    }
}

impl From<UprightDrive> for VtUprightDrive {
    fn from(d: UprightDrive) -> Self {
        Self {
            axis: d.axis.into(),
            up: d.up.into(),
            strength: d.strength.into(),
            max_torque: d.max_torque,
        }
    }
}

/// Sets or clears (`drive` null) a body's drive of C type `C` through
/// `set`.
///
/// # Safety
/// `world` is a live world; `drive` is null or readable.
unsafe fn set_drive<C: Copy, R: TryFrom<C, Error = Failure>>(
    world: *mut VtWorld,
    body: VtBody,
    drive: *const C,
    set: impl FnOnce(&mut World, BodyHandle, Option<R>) -> Result<(), Error>,
) -> VtResult {
    let drive = match drive.is_null() {
        true => Ok(None),
        // SAFETY: the function's contract.
        false => unsafe { read(drive, "drive") }.map(Some),
    };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let drive = drive?.map(R::try_from).transpose()?;
            Ok(set(w, body.into(), drive)?)
        })
    }
}

/// Writes 1 into `has` and a body's drive (read by `get`) into `drive`,
/// or 0 into `has` if it has none.
///
/// # Safety
/// `world` is a live world; `has` and `drive` are writable.
unsafe fn get_drive<C: From<R>, R>(
    world: *mut VtWorld,
    body: VtBody,
    (has, drive): (*mut u32, *mut C),
    get: impl FnOnce(&World, BodyHandle) -> Result<Option<R>, Error>,
) -> VtResult {
    // SAFETY: the function's contract.
    let (has, drive) = unsafe { (out(has, "has"), out(drive, "drive")) };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (has, drive) = (has?, drive?);
            match get(w, body.into())? {
                Some(d) => {
                    drive.done(d.into())?;
                    has.done(1)
                }
                None => has.done(0),
            }
        })
    }
}

/// Sets a dynamic body's world drive, or clears it (`drive` null). Refused
/// (nothing changed) for a body that is not dynamic or a field out of
/// range; the message names it.
///
/// # Safety
/// `world` is a live world; `drive` is null or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_world_drive(
    world: *mut VtWorld,
    body: VtBody,
    drive: *const VtWorldDrive,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { set_drive(world, body, drive, World::set_world_drive) }
}

/// Writes 1 into `has` and the body's world drive into `drive` (its target
/// as the next step begins), or 0 into `has` if it has none.
///
/// # Safety
/// `world` is a live world; `has` and `drive` are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_world_drive(
    world: *mut VtWorld,
    body: VtBody,
    has: *mut u32,
    drive: *mut VtWorldDrive,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { get_drive(world, body, (has, drive), World::world_drive) }
}

/// Sets a dynamic body's upright drive, or clears it (`drive` null), as
/// `vt_world_set_world_drive`.
///
/// # Safety
/// `world` is a live world; `drive` is null or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_upright_drive(
    world: *mut VtWorld,
    body: VtBody,
    drive: *const VtUprightDrive,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { set_drive(world, body, drive, World::set_upright_drive) }
}

/// Writes 1 into `has` and the body's upright drive into `drive`, or 0
/// into `has` if it has none.
///
/// # Safety
/// `world` is a live world; `has` and `drive` are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_upright_drive(
    world: *mut VtWorld,
    body: VtBody,
    has: *mut u32,
    drive: *mut VtUprightDrive,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { get_drive(world, body, (has, drive), World::upright_drive) }
}
