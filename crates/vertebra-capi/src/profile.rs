//! Physical-animation profiles from C: a description's named profiles
//! blended over time (`ProfileBlend` in Rust) and followed each frame
//! (`Ragdoll::follow_profile`; `docs/ragdolls.md`, "Profiles").

use core::ffi::c_char;

use vertebra_ragdoll::{Profile, ProfileBlend, RagdollDesc};

use crate::error::{Failure, VtResult};
use crate::ffi::{Object, boxed, call, enter, free, out, shared, text};
use crate::ragdoll::{VtRagdoll, VtRagdollDesc, pose_from};
use crate::types::{VtTransform, flag};
use crate::world::VtWorld;

/// A profile blend under way for one ragdoll (opaque;
/// `vt_profile_blend_create`; free it with `vt_profile_blend_destroy`).
pub struct VtProfileBlend {
    blend: ProfileBlend,
    /// The description the profiles are named in and made for.
    desc: Box<RagdollDesc>,
    poisoned: bool,
}

impl Object for VtProfileBlend {
    const NAME: &'static str = "profile blend";
    fn poisoned(&mut self) -> &mut bool {
        &mut self.poisoned
    }
}

/// The profile named by the NUL-terminated string at `name` in `desc`.
///
/// # Safety
/// `name` is null or a NUL-terminated string.
unsafe fn named(desc: &RagdollDesc, name: *const c_char) -> Result<Profile, Failure> {
    // SAFETY: the function's contract.
    let name = unsafe { text(name, "name") }?;
    desc.profile(name).cloned().ok_or_else(|| {
        let why = format!("the ragdoll `{}` has no profile `{name}`", desc.name);
        Failure::new(VtResult::Ragdoll, why)
    })
}

/// Starts at `desc`'s profile `name` (not blending), written into `blend`
/// (free it with `vt_profile_blend_destroy`). The blend keeps its own copy
/// of `desc`. Refused for a name the description has no profile of.
///
/// # Safety
/// `desc` is live; `name` is a NUL-terminated string; `blend` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_profile_blend_create(
    desc: *const VtRagdollDesc,
    name: *const c_char,
    blend: *mut *mut VtProfileBlend,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (desc, place) = unsafe { (shared(desc, "desc")?, out(blend, "blend")?) };
        // SAFETY: the function's contract.
        let profile = unsafe { named(&desc.desc, name) }?;
        place.set(boxed(VtProfileBlend {
            blend: ProfileBlend::new(profile),
            desc: Box::new(desc.desc.clone()),
            poisoned: false,
        }));
        Ok(())
    })
}

/// Frees a profile blend (null does nothing).
///
/// # Safety
/// `blend` is null or live, and not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_profile_blend_destroy(blend: *mut VtProfileBlend) {
    // SAFETY: the function's contract.
    unsafe { free(blend) }
}

/// Blends to the description's profile `name` over `duration` seconds
/// (0: at once), from wherever the blend stands now. Refused, unchanged,
/// for an unknown name or a duration negative or not finite.
///
/// # Safety
/// `blend` is live; `name` is a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_profile_blend_switch(
    blend: *mut VtProfileBlend,
    name: *const c_char,
    duration: f32,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let mut blend = unsafe { enter(blend) }?;
        // SAFETY: the function's contract.
        let profile = unsafe { named(&blend.desc, name) }?;
        Ok(blend.blend.switch_to(profile, duration)?)
    })
}

/// Blends over `duration` seconds to the profile the blend is heading for
/// with described body `body`'s drives (and, if `below` is non-zero,
/// every body's below it) scaled by `multiplier` (0..1): a limb fading
/// out as a hit lands (scaling the same body again compounds: 0.5 twice is
/// 0.25). Refused, unchanged, for a body out of range or a multiplier or
/// duration out of range.
///
/// # Safety
/// `blend` is live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_profile_blend_scale(
    blend: *mut VtProfileBlend,
    body: usize,
    below: u32,
    multiplier: f32,
    duration: f32,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let mut blend = unsafe { enter(blend) }?;
        let target = blend.blend.target().clone();
        let scaled = target.scaled(&blend.desc, body, flag(below), multiplier)?;
        Ok(blend.blend.switch_to(scaled, duration)?)
    })
}

/// Moves the blend on by `dt` seconds (a frame's time; anything not
/// finite or not positive leaves it).
///
/// # Safety
/// `blend` is live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_profile_blend_advance(blend: *mut VtProfileBlend, dt: f32) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let mut blend = unsafe { enter(blend) }?;
        blend.blend.advance(dt);
        Ok(())
    })
}

/// Writes how far the blend is into `progress` (0..1; 1 at its target).
///
/// # Safety
/// `blend` is live; `progress` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_profile_blend_progress(
    blend: *mut VtProfileBlend,
    progress: *mut f32,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (blend, progress) = unsafe { (enter(blend)?, out(progress, "progress")?) };
        progress.set(blend.blend.progress());
        Ok(())
    })
}

/// Drives every joint and body of the ragdoll along the animation, from
/// `previous` to `pose` over `dt` seconds (both `count` world transforms,
/// one per described body), with the profile as `blend` stands now. Call
/// it every frame, after `vt_profile_blend_advance`. Refused, nothing
/// changed, for poses out of range or a blend made for another ragdoll's
/// description (one of other counts).
///
/// # Safety
/// `ragdoll`, `world` and `blend` are live; `previous` and `pose` point
/// to `count` readable transforms.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_follow_profile(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    previous: *const VtTransform,
    pose: *const VtTransform,
    count: usize,
    dt: f32,
    blend: *mut VtProfileBlend,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (previous, pose, blend) = unsafe {
            (
                pose_from(previous, count, "previous")?,
                pose_from(pose, count, "pose")?,
                enter(blend)?,
            )
        };
        let profile = blend.blend.current()?;
        // SAFETY: the function's contract.
        let (ragdoll, mut world) = unsafe { (enter(ragdoll)?, enter(world)?) };
        let poses = (&previous, &pose);
        Ok((ragdoll.ragdoll).follow_profile(&mut world.world, poses, dt, &profile)?)
    })
}
