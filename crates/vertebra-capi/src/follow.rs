//! A ragdoll held in the world along its animation: every body's world
//! drive, the uprights, and joints and bodies together in one call a
//! frame (`Ragdoll::world_drive_following`, `Ragdoll::follow`).

use vertebra_ragdoll::{DriveSettings, PhysicalAnimation, Upright, WorldDriveSettings};

use crate::error::{Failure, VtResult};
use crate::ffi::{read, slice};
use crate::joint::{VtSoftness, drive_spring};
use crate::ragdoll::{VtDriveSettings, VtRagdoll, pose_from, with_ragdoll};
use crate::types::{VtTransform, flag};
use crate::world::VtWorld;

/// One body kept upright: the body axis that is up in the animation held
/// near world +Y.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtUpright {
    /// The described body (`vt_ragdoll_desc_body_index`).
    pub body: u32,
    /// Its strength (compliance, 0: rigid, or a spring).
    pub strength: VtSoftness,
    /// The largest torque (N m; infinity: unlimited).
    pub max_torque: f32,
}

/// How hard every body of a ragdoll is pulled toward its pose in the
/// world.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtWorldDriveSettings {
    /// Non-zero: the position part acts, at `linear`.
    pub has_linear: u32,
    /// The position part's strength.
    pub linear: VtSoftness,
    /// Non-zero: the orientation part acts, at `angular`.
    pub has_angular: u32,
    /// The orientation part's strength.
    pub angular: VtSoftness,
    /// Each body's force cap per kilogram (N/kg; below 9.81 the drives
    /// cannot carry the ragdoll's weight; infinity: unlimited).
    pub max_acceleration: f32,
    /// Each body's torque cap (N m; infinity: unlimited).
    pub max_torque: f32,
    /// `upright_count` bodies kept upright (any pointer when the count is
    /// 0).
    pub uprights: *const VtUpright,
    /// How many `uprights`.
    pub upright_count: usize,
}

/// The settings `settings` points to, its uprights read.
///
/// # Safety
/// `settings` is readable; its `uprights` points to `upright_count`
/// readable items.
unsafe fn world_settings(
    settings: *const VtWorldDriveSettings,
) -> Result<WorldDriveSettings, Failure> {
    // SAFETY: the function's contract.
    let s = unsafe { read(settings, "settings") }?;
    // SAFETY: the function's contract.
    let uprights = unsafe { slice(s.uprights, s.upright_count, "settings.uprights") }?;
    let part = |has: u32, soft: VtSoftness, field: &str| {
        flag(has).then(|| drive_spring(soft, field)).transpose()
    };
    Ok(WorldDriveSettings {
        linear: part(s.has_linear, s.linear, "settings.linear")?,
        angular: part(s.has_angular, s.angular, "settings.angular")?,
        max_acceleration: s.max_acceleration,
        max_torque: s.max_torque,
        uprights: (uprights.iter().enumerate())
            .map(|(k, u)| {
                Ok(Upright {
                    body: u.body as usize,
                    strength: drive_spring(
                        u.strength,
                        &format!("settings.uprights[{k}].strength"),
                    )?,
                    max_torque: u.max_torque,
                })
            })
            .collect::<Result<_, Failure>>()?,
    })
}

/// Gives every dynamic body a world drive along the animation, from
/// `previous` to `pose` over `dt` seconds (both `count` world transforms,
/// one per described body), and keeps `settings`' bodies upright. Refused,
/// nothing changed, for settings or poses out of range.
///
/// # Safety
/// `ragdoll` and `world` are live; `previous` and `pose` point to `count`
/// readable transforms; `settings` is readable, its `uprights` as it says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_world_drive_following(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    previous: *const VtTransform,
    pose: *const VtTransform,
    count: usize,
    dt: f32,
    settings: *const VtWorldDriveSettings,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe {
        (
            pose_from(previous, count, "previous"),
            pose_from(pose, count, "pose"),
            world_settings(settings),
        )
    };
    // SAFETY: the function's contract.
    unsafe {
        with_ragdoll(ragdoll, world, |r, w| {
            let (previous, pose, settings) = (inputs.0?, inputs.1?, inputs.2?);
            Ok(r.world_drive_following(w, &previous, &pose, dt, &settings)?)
        })
    }
}

/// The joints' drives (`vt_ragdoll_drive_following`) and the bodies'
/// world drives (`vt_ragdoll_world_drive_following`) along the animation
/// in one call a frame, both checked before either changes anything.
///
/// # Safety
/// As `vt_ragdoll_world_drive_following`; `joints` is readable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn vt_ragdoll_follow(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    previous: *const VtTransform,
    pose: *const VtTransform,
    count: usize,
    dt: f32,
    joints: *const VtDriveSettings,
    settings: *const VtWorldDriveSettings,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe {
        (
            pose_from(previous, count, "previous"),
            pose_from(pose, count, "pose"),
            read(joints, "joints"),
            world_settings(settings),
        )
    };
    // SAFETY: the function's contract.
    unsafe {
        with_ragdoll(ragdoll, world, |r, w| {
            let (previous, pose) = (inputs.0?, inputs.1?);
            let animation = PhysicalAnimation {
                joints: DriveSettings::try_from(inputs.2?)?,
                world: inputs.3?,
            };
            Ok(r.follow(w, (&previous, &pose), dt, &animation)?)
        })
    }
}

/// Clears every body's world and upright drive.
///
/// # Safety
/// `ragdoll` and `world` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_release_world_drives(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { with_ragdoll(ragdoll, world, |r, w| Ok(r.release_world_drives(w)?)) }
}
