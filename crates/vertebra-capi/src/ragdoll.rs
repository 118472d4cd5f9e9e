//! Ragdolls: descriptions loaded from a file or a string (or the shipped
//! humanoids), built into a world at a pose, driven toward animation, and
//! the calls a game makes on a whole ragdoll (`docs/ragdolls.md`).

use std::path::Path;

use vertebra_collide::{CollisionGroups, Collisions};
use vertebra_ragdoll::{
    BuildOptions, DriveSettings, MAX_FILE_BYTES, Pose, Ragdoll, RagdollDesc, RagdollError,
    SpineMode,
};
use vertebra_world::Spring;

use crate::collide::{VtCollisions, with_layer};
use crate::error::{Failure, VtResult};
use crate::ffi::{
    Object, bounded_text, boxed, call, copy_text, enter, free, index_of, optional, out, read,
    shared, slice, text,
};
use crate::types::{VtBody, VtTransform, VtVec3, flag, pick};
use crate::world::VtWorld;

/// A ragdoll description (opaque; read-only once made; free it with
/// `vt_ragdoll_desc_destroy`).
pub struct VtRagdollDesc {
    pub(crate) desc: RagdollDesc,
}

/// A ragdoll living in a world: its bodies', joints' and rod's handles
/// (opaque; `vt_ragdoll_build`; free it with `vt_ragdoll_destroy`, which
/// leaves its bodies in the world: `vt_ragdoll_remove` takes them out).
pub struct VtRagdoll {
    pub(crate) ragdoll: Ragdoll,
    poisoned: bool,
}

impl Object for VtRagdoll {
    const NAME: &'static str = "ragdoll";
    fn poisoned(&mut self) -> &mut bool {
        &mut self.poisoned
    }
}

/// The shipped humanoids.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtHumanoid {
    /// The paper's reference humanoid: 13 bodies, all sockets.
    Reference = 0,
    /// Hinged knees and elbows, elliptical shoulders and hips.
    Anatomical = 1,
}

/// How the spine is built.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtSpineMode {
    /// A chain of sockets (the standard ragdoll).
    Sockets = 0,
    /// One rod (the paper's simplified ragdoll).
    Rod = 1,
}

/// How a ragdoll is built (`BuildOptions` in Rust).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtBuildOptions {
    /// A `VtSpineMode`.
    pub spine: u32,
    /// Non-zero: for the switch from animation: the rod's rest and the
    /// joints' anchors from the pose built at (else the rod's rest from it
    /// and the anchors from the description).
    pub at_switch: u32,
    /// Non-zero: masses evened out so that no joint's mass ratio exceeds
    /// `stabilise_ratio` (>= 1).
    pub stabilise: u32,
    /// See `stabilise`.
    pub stabilise_ratio: f32,
}

/// How hard a drive holds.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtStrengthKind {
    /// The target is a hard constraint.
    Infinite = 0,
    /// XPBD compliance `a` (rad / (N m)), damped by the settings' damping.
    Compliance = 1,
    /// A spring of frequency `a` (Hz) and damping ratio `b`.
    Spring = 2,
}

/// A drive's strength: `kind` is a `VtStrengthKind`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtStrength {
    /// A `VtStrengthKind`.
    pub kind: u32,
    /// Compliance or frequency.
    pub a: f32,
    /// Damping ratio.
    pub b: f32,
}

/// Drive settings for a whole ragdoll.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtDriveSettings {
    /// Every joint's strength.
    pub strength: VtStrength,
    /// Damping (N m s / rad) of joints driven by compliance.
    pub damping: f32,
    /// The largest torque (N m) each joint's drive exerts; infinity is
    /// unlimited.
    pub max_torque: f32,
}

impl VtStrength {
    /// The strength as the world's spring: infinite is [`Spring::RIGID`], a
    /// compliance takes the settings' `damping`.
    pub(crate) fn spring(self, damping: f32) -> Result<Spring, Failure> {
        Ok(match pick(self.kind, "strength.kind", &[0, 1, 2])? {
            0 => Spring::RIGID,
            1 => Spring::Compliance {
                compliance: self.a,
                damping,
            },
            _ => Spring::Frequency {
                frequency: self.a,
                damping_ratio: self.b,
            },
        })
    }
}

impl TryFrom<VtDriveSettings> for DriveSettings {
    type Error = Failure;
    /// Refuses a damping that is not finite or is negative whatever the
    /// strength (as before a compliance carried its own damping).
    fn try_from(s: VtDriveSettings) -> Result<Self, Failure> {
        if !(s.damping.is_finite() && s.damping >= 0.0) {
            return Err(RagdollError::OutOfRange {
                context: "drive".to_owned(),
                field: "damping",
                reason: "must be finite and not negative".to_owned(),
            }
            .into());
        }
        Ok(DriveSettings::uniform(s.strength.spring(s.damping)?).with_max_torque(s.max_torque))
    }
}

impl TryFrom<VtBuildOptions> for BuildOptions {
    type Error = Failure;
    fn try_from(o: VtBuildOptions) -> Result<Self, Failure> {
        let spine = pick(
            o.spine,
            "options.spine",
            &[SpineMode::Sockets, SpineMode::Rod],
        )?;
        let mut options = match flag(o.at_switch) {
            true => BuildOptions::at_switch(spine),
            false => BuildOptions::new(spine),
        };
        options.stabilise = flag(o.stabilise).then_some(o.stabilise_ratio);
        Ok(options)
    }
}

/// A pose from `count` transforms at `pose` (one per described body).
///
/// # Safety
/// `pose` points to `count` readable transforms.
pub(crate) unsafe fn pose_from(
    pose: *const VtTransform,
    count: usize,
    what: &str,
) -> Result<Pose, Failure> {
    // SAFETY: the function's contract.
    let transforms = unsafe { slice(pose, count, what) }?;
    Ok(Pose {
        bones: transforms.iter().map(|&t| t.into()).collect(),
    })
}

/// Hands a loaded description to C.
fn made(
    desc: Result<RagdollDesc, Failure>,
    place: Result<crate::ffi::Out<*mut VtRagdollDesc>, Failure>,
) -> Result<(), Failure> {
    let place = place?;
    place.set(boxed(VtRagdollDesc { desc: desc? }));
    Ok(())
}

/// Loads a ragdoll description from the TOML file at `path` (UTF-8); a
/// skeleton it names is read beside it. Refused with the file, line and
/// field of the first problem.
///
/// # Safety
/// `path` is a NUL-terminated string; `desc` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_from_file(
    path: *const core::ffi::c_char,
    desc: *mut *mut VtRagdollDesc,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (path, place) = unsafe { (text(path, "path")?, out(desc, "desc")) };
        made(
            RagdollDesc::from_file(Path::new(path)).map_err(Failure::from),
            place,
        )
    })
}

/// A ragdoll, generator or skeleton text (`file` names which) from C: a
/// NUL-terminated UTF-8 string of at most `MAX_FILE_BYTES`, as a file; a
/// longer one is refused before it is read whole
/// (`RagdollError::TooLarge`, `VT_RESULT_RAGDOLL`).
///
/// # Safety
/// `toml` is null or points to a NUL-terminated string.
pub(crate) unsafe fn toml_text<'a>(
    toml: *const core::ffi::c_char,
    file: &'static str,
) -> Result<&'a str, Failure> {
    let max = usize::try_from(MAX_FILE_BYTES).unwrap_or(usize::MAX);
    // SAFETY: the function's contract.
    unsafe {
        bounded_text(toml, "toml", max, || {
            Failure::from(RagdollError::TooLarge {
                file,
                limit: MAX_FILE_BYTES,
            })
        })
    }
}

/// Reads a ragdoll description from TOML text (UTF-8, NUL-terminated, at
/// most `MAX_FILE_BYTES` = 1 MiB: a longer text is refused before it is
/// read). Refused with the line and field of the first problem.
///
/// # Safety
/// `toml` is a NUL-terminated string; `desc` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_from_string(
    toml: *const core::ffi::c_char,
    desc: *mut *mut VtRagdollDesc,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (toml, place) = unsafe { (toml_text(toml, "ragdoll")?, out(desc, "desc")) };
        made(RagdollDesc::from_toml(toml).map_err(Failure::from), place)
    })
}

/// One of the shipped humanoids (`VtHumanoid`).
///
/// # Safety
/// `desc` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_humanoid(
    humanoid: u32,
    desc: *mut *mut VtRagdollDesc,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let place = unsafe { out(desc, "desc") };
        let which = pick(humanoid, "humanoid", &[0, 1]);
        let made_desc = which.map(|h| match h {
            0 => RagdollDesc::reference_humanoid(),
            _ => RagdollDesc::anatomical_humanoid(),
        });
        made(made_desc, place)
    })
}

/// Frees a description (null does nothing). Ragdolls built from it keep
/// their own copy.
///
/// # Safety
/// `desc` is null or live, and not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_destroy(desc: *mut VtRagdollDesc) {
    // SAFETY: the function's contract.
    unsafe { free(desc) }
}

/// Writes the number of described bodies into `count`: the length of
/// every pose.
///
/// # Safety
/// `desc` is live; `count` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_body_count(
    desc: *const VtRagdollDesc,
    count: *mut usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (desc, count) = unsafe { (shared(desc, "desc")?, out(count, "count")?) };
        count.set(desc.desc.bodies.len());
        Ok(())
    })
}

/// Writes the index of the body named `name` into `index`.
///
/// # Safety
/// `desc` is live; `name` is a NUL-terminated string; `index` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_body_index(
    desc: *const VtRagdollDesc,
    name: *const core::ffi::c_char,
    index: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { desc_index_by_name(desc, name, index, "body", RagdollDesc::body_index) }
}

/// Copies the name of body `index` with its NUL into `buffer` (`capacity`
/// bytes) and its length with the NUL into `length`; refused
/// (`VT_RESULT_BUFFER_TOO_SMALL`, only `length` written) when it does not
/// fit.
///
/// # Safety
/// `desc` is live; `buffer` points to `capacity` writable bytes; `length`
/// is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_body_name(
    desc: *const VtRagdollDesc,
    index: usize,
    buffer: *mut core::ffi::c_char,
    capacity: usize,
    length: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { desc_name(desc, index, BODIES, buffer, capacity, length) }
}

/// Writes the bind pose (every body at its description's place, unrotated;
/// m, world) into `pose`, which holds `count` transforms: the body count.
///
/// # Safety
/// `desc` is live; `pose` points to `count` writable transforms.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_bind_pose(
    desc: *const VtRagdollDesc,
    pose: *mut VtTransform,
    count: usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let desc = unsafe { shared(desc, "desc") }?;
        let bind = Pose::bind(&desc.desc);
        // SAFETY: the function's contract.
        let place = unsafe { crate::ffi::slice_mut(pose, count, "pose") }?;
        write_pose(&bind, place)
    })
}

/// Copies a pose into `place`, which must be as long.
pub(crate) fn write_pose(pose: &Pose, place: &mut [VtTransform]) -> Result<(), Failure> {
    if place.len() != pose.bones.len() {
        return Err(Failure::new(
            VtResult::BufferTooSmall,
            format!(
                "the pose holds {} transforms; it takes {}",
                place.len(),
                pose.bones.len()
            ),
        ));
    }
    for (to, &from) in place.iter_mut().zip(&pose.bones) {
        *to = from.into();
    }
    Ok(())
}

/// Builds a ragdoll from `desc` into `world` at `pose` (`count` world
/// transforms, one per described body: centre of mass and rotation from
/// bind), at rest, or with the velocities that carry `previous` (null: at
/// rest) to `pose` over `dt` seconds. With a collision layer (`collisions`
/// not null) its bodies get colliders and its jointed pairs never collide.
/// Writes the new ragdoll into `ragdoll` (free it with
/// `vt_ragdoll_destroy`). Refused with nothing added.
///
/// # Safety
/// `world` is live; `collisions` is null or live; `desc` is live;
/// `options` is readable; `pose` (and `previous`, unless null) point to
/// `count` readable transforms; `ragdoll` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_build(
    world: *mut VtWorld,
    collisions: *mut VtCollisions,
    desc: *const VtRagdollDesc,
    options: *const VtBuildOptions,
    pose: *const VtTransform,
    previous: *const VtTransform,
    count: usize,
    dt: f32,
    ragdoll: *mut *mut VtRagdoll,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (desc, options, place) = unsafe {
            (
                shared(desc, "desc")?,
                read(options, "options")?,
                out(ragdoll, "ragdoll")?,
            )
        };
        let options = BuildOptions::try_from(options)?;
        // SAFETY: the function's contract.
        let pose = unsafe { pose_from(pose, count, "pose") }?;
        let previous = match previous.is_null() {
            true => None,
            // SAFETY: the function's contract.
            false => Some(unsafe { pose_from(previous, count, "previous") }?),
        };
        let previous = previous.as_ref().map(|p| (p, dt));
        // SAFETY: the function's contract.
        let mut world = unsafe { enter(world) }?;
        let built = match collisions.is_null() {
            true => Ragdoll::build(&mut world.world, &desc.desc, options, &pose, previous)?,
            false => {
                // SAFETY: the function's contract.
                let mut layer = unsafe { enter(collisions) }?;
                let layer: &mut Collisions = &mut layer.collisions;
                layer.build_ragdoll(&mut world.world, &desc.desc, options, &pose, previous)?
            }
        };
        place.set(boxed(VtRagdoll {
            ragdoll: built,
            poisoned: false,
        }));
        Ok(())
    })
}

/// Frees a ragdoll object (null does nothing); its bodies, joints and rod
/// stay in the world (`vt_ragdoll_remove` first to take them out).
///
/// # Safety
/// `ragdoll` is null or live, and not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_destroy(ragdoll: *mut VtRagdoll) {
    // SAFETY: the function's contract.
    unsafe { free(ragdoll) }
}

/// Takes a ragdoll's bodies, joints and rod out of `world` (and their
/// colliders out of `collisions`, unless null). Refused, with nothing
/// removed, if any of them is already gone. A removed ragdoll is refused
/// by every call on it but `vt_ragdoll_destroy` (`VT_RESULT_STALE_HANDLE`,
/// naming the ragdoll): build a new one.
///
/// # Safety
/// `ragdoll` and `world` are live; `collisions` is null or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_remove(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    collisions: *mut VtCollisions,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (mut ragdoll, mut world) = unsafe { (enter(ragdoll)?, enter(world)?) };
        let (ragdoll, world) = (&mut ragdoll.ragdoll, &mut world.world);
        match collisions.is_null() {
            true => ragdoll.remove(world)?,
            false => {
                // SAFETY: the function's contract.
                let mut layer = unsafe { enter(collisions) }?;
                layer.collisions.remove_ragdoll(world, ragdoll)?
            }
        }
        Ok(())
    })
}

/// Runs `body` on a ragdoll and its world inside [`call`].
///
/// # Safety
/// `ragdoll` and `world` are null or live, used by no other call at once.
pub(crate) unsafe fn with_ragdoll(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    body: impl FnOnce(&Ragdoll, &mut vertebra_world::World) -> Result<(), Failure>,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (ragdoll, mut world) = unsafe { (enter(ragdoll)?, enter(world)?) };
        body(&ragdoll.ragdoll, &mut world.world)
    })
}

/// Writes the handle of described body `index` into `body` and 1 into
/// `present`; or 0 into `present` for a body the ragdoll has no body for
/// (a spine interior body of a rod-spine ragdoll: an animation-only bone).
/// A removed ragdoll is refused (`VT_RESULT_STALE_HANDLE`), as by every
/// call on it.
///
/// # Safety
/// `ragdoll` is live; `body` and `present` are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_body(
    ragdoll: *mut VtRagdoll,
    index: usize,
    body: *mut VtBody,
    present: *mut u32,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (ragdoll, body, present) = unsafe {
            (
                enter(ragdoll)?,
                out(body, "body")?,
                out(present, "present")?,
            )
        };
        ragdoll.ragdoll.check_not_removed()?;
        let bodies = &ragdoll.ragdoll.bodies;
        let slot = bodies.get(index).ok_or_else(|| {
            let n = bodies.len();
            Failure::new(
                VtResult::OutOfRange,
                format!("body {index} of a ragdoll of {n}"),
            )
        })?;
        present.set(u32::from(slot.is_some()));
        if let Some(handle) = *slot {
            body.set(handle.into());
        }
        Ok(())
    })
}

/// Drives every joint (and the rod) toward `pose` (`count` world
/// transforms, one per described body) with `settings`, until driven
/// again or released.
///
/// # Safety
/// `ragdoll` and `world` are live; `pose` points to `count` readable
/// transforms; `settings` is readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_drive_to(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    pose: *const VtTransform,
    count: usize,
    settings: *const VtDriveSettings,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe { (pose_from(pose, count, "pose"), read(settings, "settings")) };
    // SAFETY: the function's contract.
    unsafe {
        with_ragdoll(ragdoll, world, |r, w| {
            let (pose, settings) = (inputs.0?, DriveSettings::try_from(inputs.1?)?);
            Ok(r.drive_to(w, &pose, &settings)?)
        })
    }
}

/// Drives toward a moving animation: the targets start at `previous` and
/// turn toward `pose` over `dt` seconds (both `count` world transforms).
///
/// # Safety
/// As `vt_ragdoll_drive_to`; `previous` points to `count` readable
/// transforms.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_drive_following(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    previous: *const VtTransform,
    pose: *const VtTransform,
    count: usize,
    dt: f32,
    settings: *const VtDriveSettings,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe {
        (
            pose_from(previous, count, "previous"),
            pose_from(pose, count, "pose"),
            read(settings, "settings"),
        )
    };
    // SAFETY: the function's contract.
    unsafe {
        with_ragdoll(ragdoll, world, |r, w| {
            let (previous, pose) = (inputs.0?, inputs.1?);
            let settings = DriveSettings::try_from(inputs.2?)?;
            Ok(r.drive_following(w, &previous, &pose, dt, &settings)?)
        })
    }
}

/// Releases every drive: the ragdoll goes limp.
///
/// # Safety
/// `ragdoll` and `world` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_release_drives(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { with_ragdoll(ragdoll, world, |r, w| Ok(r.release_drives(w)?)) }
}

/// Applies an impulse (N s, world) to the body named `body`, at the world
/// point `point` (m), or at its centre of mass when `point` is null.
///
/// # Safety
/// `ragdoll` and `world` are live; `body` is a NUL-terminated string;
/// `point` is null or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_apply_impulse(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    body: *const core::ffi::c_char,
    impulse: VtVec3,
    point: *const VtVec3,
) -> VtResult {
    // SAFETY: the function's contract.
    let name = unsafe { text(body, "body") };
    let point = match point.is_null() {
        true => Ok(None),
        // SAFETY: the function's contract.
        false => unsafe { read(point, "point") }.map(|p| Some(p.into())),
    };
    // SAFETY: the function's contract.
    unsafe {
        with_ragdoll(ragdoll, world, |r, w| {
            Ok(r.apply_impulse(w, name?, impulse.into(), point?)?)
        })
    }
}

/// Sets every body's velocity (m/s and rad/s, world) as one rigid body.
///
/// # Safety
/// `ragdoll` and `world` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_set_velocity(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    linear: VtVec3,
    angular: VtVec3,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_ragdoll(ragdoll, world, |r, w| {
            Ok(r.set_velocity(w, linear.into(), angular.into())?)
        })
    }
}

/// Switches the body named `body` to kinematic (non-zero: it follows the
/// animation) or back to dynamic (0).
///
/// # Safety
/// `ragdoll` and `world` are live; `body` is a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_set_body_kinematic(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    body: *const core::ffi::c_char,
    kinematic: u32,
) -> VtResult {
    // SAFETY: the function's contract.
    let name = unsafe { text(body, "body") };
    // SAFETY: the function's contract.
    unsafe {
        with_ragdoll(ragdoll, world, |r, w| {
            Ok(r.set_body_kinematic(w, name?, flag(kinematic))?)
        })
    }
}

/// Writes the root body's (the hips') pose into `root` and the ragdoll's
/// world bounds (m) into `min` and `max` (either output may be null).
///
/// # Safety
/// `ragdoll` and `world` are live; `root`, `min` and `max` are null or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_placement(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    root: *mut VtTransform,
    min: *mut VtVec3,
    max: *mut VtVec3,
) -> VtResult {
    // Every place is checked before any is written: a refused call
    // writes none.
    // SAFETY: the function's contract.
    let places = unsafe {
        (
            optional(root, "root"),
            optional(min, "min"),
            optional(max, "max"),
        )
    };
    // SAFETY: the function's contract.
    unsafe {
        with_ragdoll(ragdoll, world, |r, w| {
            let (root, min, max) = (places.0?, places.1?, places.2?);
            let transform = r.root_transform(w)?;
            let (low, high) = r.bounds(w)?;
            for (place, value) in [(min, low), (max, high)] {
                if let Some(place) = place {
                    place.set(value.into());
                }
            }
            if let Some(root) = root {
                root.set(transform.into());
            }
            Ok(())
        })
    }
}

/// Writes the number of described joints into `count`.
///
/// # Safety
/// `desc` is live; `count` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_joint_count(
    desc: *const VtRagdollDesc,
    count: *mut usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (desc, count) = unsafe { (shared(desc, "desc")?, out(count, "count")?) };
        count.done(desc.desc.joints.len())
    })
}

/// Writes the index of the joint named `name` into `index`.
///
/// # Safety
/// `desc` is live; `name` is a NUL-terminated string; `index` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_joint_index(
    desc: *const VtRagdollDesc,
    name: *const core::ffi::c_char,
    index: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { desc_index_by_name(desc, name, index, "joint", RagdollDesc::joint_index) }
}

/// Copies the name of joint `index` with its NUL into `buffer` (`capacity`
/// bytes) and its length with the NUL into `length`, as
/// `vt_ragdoll_desc_body_name`.
///
/// # Safety
/// `desc` is live; `buffer` points to `capacity` writable bytes; `length`
/// is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_desc_joint_name(
    desc: *const VtRagdollDesc,
    index: usize,
    buffer: *mut core::ffi::c_char,
    capacity: usize,
    length: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { desc_name(desc, index, JOINTS, buffer, capacity, length) }
}

/// Writes the handle of described joint `index` into `joint` and 1 into
/// `present`; or 0 into `present` for a joint the ragdoll has no joint
/// for (a spine joint of a rod-spine ragdoll: the rod holds the spine). Its
/// drive, limits, force (`vt_world_joint_force`) and residual
/// (`vt_world_joint_residual`) are the world's, by this handle. A removed
/// ragdoll is refused (`VT_RESULT_STALE_HANDLE`).
///
/// # Safety
/// `ragdoll` is live; `joint` and `present` are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_joint(
    ragdoll: *mut VtRagdoll,
    index: usize,
    joint: *mut crate::types::VtJoint,
    present: *mut u32,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (ragdoll, joint, present) = unsafe {
            (
                enter(ragdoll)?,
                out(joint, "joint")?,
                out(present, "present")?,
            )
        };
        ragdoll.ragdoll.check_not_removed()?;
        let joints = &ragdoll.ragdoll.joints;
        let slot = joints.get(index).ok_or_else(|| {
            let n = joints.len();
            Failure::new(
                VtResult::OutOfRange,
                format!("joint {index} of a ragdoll of {n}"),
            )
        })?;
        if let Some(handle) = *slot {
            joint.set(handle.into());
        }
        present.done(u32::from(slot.is_some()))
    })
}

/// Writes the ragdoll's first body into `body`: the name the collision
/// layer's hits and events give the ragdoll (`VtRagdollPart::ragdoll`). A
/// removed ragdoll is refused (`VT_RESULT_STALE_HANDLE`).
///
/// # Safety
/// `ragdoll` is live; `body` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_first_body(
    ragdoll: *mut VtRagdoll,
    body: *mut VtBody,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (ragdoll, body) = unsafe { (enter(ragdoll)?, out(body, "body")?) };
        ragdoll.ragdoll.check_not_removed()?;
        let first = ragdoll.ragdoll.first_body().ok_or_else(|| {
            Failure::new(VtResult::StaleHandle, "the ragdoll has no body".to_owned())
        })?;
        body.done(first.into())
    })
}

/// Sets the groups of every collider of a ragdoll.
///
/// # Safety
/// `collisions` and `ragdoll` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_set_ragdoll_groups(
    collisions: *mut VtCollisions,
    ragdoll: *mut VtRagdoll,
    membership: u32,
    filter: u32,
) -> VtResult {
    let groups = CollisionGroups { membership, filter };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let ragdoll = enter(ragdoll)?;
            Ok(layer
                .collisions
                .set_ragdoll_groups(&ragdoll.ragdoll, groups)?)
        })
    }
}

/// Lets a ragdoll's bodies collide with each other (non-zero; its jointed
/// pairs never do) or not (0).
///
/// # Safety
/// `collisions` and `ragdoll` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_set_ragdoll_self_collision(
    collisions: *mut VtCollisions,
    ragdoll: *mut VtRagdoll,
    collide: u32,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let ragdoll = enter(ragdoll)?;
            let layer = &mut layer.collisions;
            Ok(layer.set_ragdoll_self_collision(&ragdoll.ragdoll, flag(collide))?)
        })
    }
}

/// Writes the index of `desc`'s `what` (a body or joint) named `name`,
/// found by `find`, into `index`.
///
/// # Safety
/// `desc` is live; `name` is a NUL-terminated string; `index` is writable.
unsafe fn desc_index_by_name(
    desc: *const VtRagdollDesc,
    name: *const core::ffi::c_char,
    index: *mut usize,
    what: &str,
    find: fn(&RagdollDesc, &str) -> Option<usize>,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let desc = unsafe { shared(desc, "desc") }?;
        let find = |name: &str| {
            let why = || format!("the ragdoll has no {what} `{name}`");
            find(&desc.desc, name).ok_or_else(|| Failure::new(VtResult::Ragdoll, why()))
        };
        // SAFETY: the function's contract.
        unsafe { index_of(name, index, find) }
    })
}

/// A kind of item a description lists (`"body"` or `"joint"`), how
/// many it has and the name of one.
type DescItem = (
    &'static str,
    fn(&RagdollDesc) -> usize,
    fn(&RagdollDesc, usize) -> &str,
);

/// A description's bodies.
const BODIES: DescItem = ("body", |d| d.bodies.len(), |d, k| &d.bodies[k].name);

/// A description's joints.
const JOINTS: DescItem = ("joint", |d| d.joints.len(), |d, k| &d.joints[k].name);

/// Copies the name of `desc`'s item `index` of a kind (`BODIES`,
/// `JOINTS`) with its NUL into `buffer` (`capacity` bytes) and its length
/// with the NUL into `length`.
///
/// # Safety
/// `desc` is live; `buffer` points to `capacity` writable bytes; `length`
/// is writable.
unsafe fn desc_name(
    desc: *const VtRagdollDesc,
    index: usize,
    (what, count, name): DescItem,
    buffer: *mut core::ffi::c_char,
    capacity: usize,
    length: *mut usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let desc = unsafe { shared(desc, "desc") }?;
        let n = count(&desc.desc);
        if index >= n {
            let why = format!("{what} {index} of a ragdoll of {n}");
            return Err(Failure::new(VtResult::OutOfRange, why));
        }
        // SAFETY: the function's contract.
        unsafe { copy_text(name(&desc.desc, index), buffer, capacity, length) }
    })
}
