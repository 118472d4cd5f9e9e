//! Per-joint drive strengths: a ragdoll driven with some joints held
//! harder or softer than the rest (a stiff neck, loose wrists), as
//! `DriveSettings::joints` does in Rust.

use vertebra_ragdoll::{DriveSettings, Ragdoll, RagdollDesc};

use crate::error::{Failure, VtResult};
use crate::ffi::{enter, read, slice};
use crate::ragdoll::{VtDriveSettings, VtRagdoll, VtStrength, pose_from};
use crate::types::VtTransform;
use crate::world::VtWorld;

/// One joint's own strength, overriding the settings' for it.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtJointStrength {
    /// The described joint (`vt_ragdoll_desc_joint_index`).
    pub joint: u32,
    /// Its strength.
    pub strength: VtStrength,
}

/// `settings` with `overrides` (`count` of them, each joint at most once)
/// for a ragdoll described by `desc`.
///
/// # Safety
/// `settings` is readable; `overrides` points to `count` readable items.
unsafe fn with_overrides(
    settings: *const VtDriveSettings,
    overrides: *const VtJointStrength,
    count: usize,
    desc: &RagdollDesc,
) -> Result<DriveSettings, Failure> {
    // SAFETY: the function's contract.
    let (settings, overrides) = unsafe {
        (
            read(settings, "settings")?,
            slice(overrides, count, "overrides")?,
        )
    };
    let damping = settings.damping;
    let mut settings = DriveSettings::try_from(settings)?;
    let joints = desc.joints.len();
    settings.joints = vec![None; joints];
    for (k, o) in overrides.iter().enumerate() {
        let Some(slot) = settings.joints.get_mut(o.joint as usize) else {
            return Err(Failure::new(
                VtResult::OutOfRange,
                format!(
                    "overrides[{k}].joint is {}; the ragdoll has {joints} joints",
                    o.joint
                ),
            ));
        };
        if slot.is_some() {
            let name = &desc.joints[o.joint as usize].name;
            return Err(Failure::new(
                VtResult::OutOfRange,
                format!("overrides[{k}] names joint `{name}` again"),
            ));
        }
        *slot = Some(o.strength.spring(damping)?);
    }
    Ok(settings)
}

/// Runs `body` on a live ragdoll and world with the settings and overrides
/// read.
///
/// # Safety
/// As [`with_overrides`]; `ragdoll` and `world` are live.
unsafe fn driven(
    (ragdoll, world): (*mut VtRagdoll, *mut VtWorld),
    settings: *const VtDriveSettings,
    (overrides, count): (*const VtJointStrength, usize),
    body: impl FnOnce(&Ragdoll, &mut vertebra_world::World, &DriveSettings) -> Result<(), Failure>,
) -> VtResult {
    crate::ffi::call(|| {
        // SAFETY: the function's contract.
        let (ragdoll, mut world) = unsafe { (enter(ragdoll)?, enter(world)?) };
        let desc = ragdoll.ragdoll.description();
        // SAFETY: the function's contract.
        let settings = unsafe { with_overrides(settings, overrides, count, desc) }?;
        body(&ragdoll.ragdoll, &mut world.world, &settings)
    })
}

/// `vt_ragdoll_drive_to` with some joints at strengths of their own:
/// `overrides` (`override_count` of them; each described joint at most
/// once) replace the settings' strength for their joints; the settings'
/// damping and torque limit hold for every joint. A rod spine takes the
/// override of the spine's first joint. Refused, changing nothing, for a
/// joint index past the description's joints or named twice, or a
/// strength out of range (naming the override).
///
/// # Safety
/// As `vt_ragdoll_drive_to`; `overrides` points to `override_count`
/// readable items (or the count is 0).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_drive_to_with(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    pose: *const VtTransform,
    count: usize,
    settings: *const VtDriveSettings,
    overrides: *const VtJointStrength,
    override_count: usize,
) -> VtResult {
    // SAFETY: the function's contract.
    let pose = unsafe { pose_from(pose, count, "pose") };
    // SAFETY: the function's contract.
    unsafe {
        driven(
            (ragdoll, world),
            settings,
            (overrides, override_count),
            |r, w, settings| Ok(r.drive_to(w, &pose?, settings)?),
        )
    }
}

/// `vt_ragdoll_drive_following` with some joints at strengths of their
/// own, as `vt_ragdoll_drive_to_with` takes them.
///
/// # Safety
/// As `vt_ragdoll_drive_following`; `overrides` points to
/// `override_count` readable items (or the count is 0).
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn vt_ragdoll_drive_following_with(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    previous: *const VtTransform,
    pose: *const VtTransform,
    count: usize,
    dt: f32,
    settings: *const VtDriveSettings,
    overrides: *const VtJointStrength,
    override_count: usize,
) -> VtResult {
    // SAFETY: the function's contract.
    let poses = unsafe {
        (
            pose_from(previous, count, "previous"),
            pose_from(pose, count, "pose"),
        )
    };
    // SAFETY: the function's contract.
    unsafe {
        driven(
            (ragdoll, world),
            settings,
            (overrides, override_count),
            |r, w, settings| Ok(r.drive_following(w, &poses.0?, &poses.1?, dt, settings)?),
        )
    }
}
