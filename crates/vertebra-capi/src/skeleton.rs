//! Animation skeletons and the mapper between a ragdoll's bodies and a
//! skeleton's bones, both ways (the paper's section 6).

use std::path::Path;

use vertebra_ragdoll::{
    LocalPose, ModelPose, RagdollError, Skeleton, SkeletonMapper, SpineMapping, SpineMode,
    Transform,
};

use crate::error::{Failure, VtResult};
use crate::ffi::{
    Out, boxed, call, copy_text, enter, free, index_of, out, shared, slice, slice_mut, text,
};
use crate::ragdoll::{VtRagdoll, VtRagdollDesc, toml_text, write_pose};
use crate::types::{VtTransform, pick};
use crate::world::VtWorld;

/// An animation skeleton (opaque; read-only; `vt_skeleton_destroy`).
pub struct VtSkeleton {
    pub(crate) skeleton: Skeleton,
}

/// A mapper between one ragdoll description's bodies and one skeleton's
/// bones (opaque; read-only; `vt_skeleton_mapper_destroy`).
pub struct VtSkeletonMapper {
    pub(crate) mapper: SkeletonMapper,
}

/// How a chain of bones without bodies (the spine's, under a rod) is
/// placed between its two bodies.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtSpineMapping {
    /// Shares of the top body's rotation; bind offsets.
    Orientation = 0,
    /// As orientation, closing the gap to the top body.
    PositionOrientation = 1,
    /// On the rod's arc (the paper's mapping).
    Arc = 2,
}

impl From<VtTransform> for Transform {
    fn from(t: VtTransform) -> Self {
        Transform::new(t.position.into(), t.rotation.into())
    }
}

impl From<Transform> for VtTransform {
    fn from(t: Transform) -> Self {
        (t.translation, t.rotation).into()
    }
}

/// The mapping a `VtSpineMapping` names.
pub(crate) fn spine_mapping(mapping: u32) -> Result<SpineMapping, Failure> {
    let all = [
        SpineMapping::Orientation,
        SpineMapping::PositionOrientation,
        SpineMapping::Arc,
    ];
    pick(mapping, "mapping", &all)
}

/// Hands a loaded skeleton to C.
fn made(
    skeleton: Result<Skeleton, RagdollError>,
    place: Result<Out<*mut VtSkeleton>, Failure>,
) -> Result<(), Failure> {
    let place = place?;
    place.set(boxed(VtSkeleton {
        skeleton: skeleton?,
    }));
    Ok(())
}

/// The shipped 63-bone reference skeleton, which both humanoids fit.
///
/// # Safety
/// `skeleton` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_reference(skeleton: *mut *mut VtSkeleton) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let place = unsafe { out(skeleton, "skeleton") };
        made(Ok(Skeleton::reference()), place)
    })
}

/// Loads a skeleton from the TOML file at `path` (`[[bone]]` tables).
///
/// # Safety
/// `path` is a NUL-terminated string; `skeleton` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_from_file(
    path: *const core::ffi::c_char,
    skeleton: *mut *mut VtSkeleton,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (path, place) = unsafe { (text(path, "path")?, out(skeleton, "skeleton")) };
        made(Skeleton::from_file(Path::new(path)), place)
    })
}

/// Reads a skeleton from TOML text (NUL-terminated UTF-8, at most
/// `MAX_FILE_BYTES` = 1 MiB: a longer text is refused before it is read).
///
/// # Safety
/// `toml` is a NUL-terminated string; `skeleton` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_from_string(
    toml: *const core::ffi::c_char,
    skeleton: *mut *mut VtSkeleton,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (toml, place) = unsafe { (toml_text(toml, "skeleton")?, out(skeleton, "skeleton")) };
        made(Skeleton::from_toml(toml), place)
    })
}

/// Frees a skeleton (null does nothing); mappers made from it keep their
/// own copy.
///
/// # Safety
/// `skeleton` is null or live, and not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_destroy(skeleton: *mut VtSkeleton) {
    // SAFETY: the function's contract.
    unsafe { free(skeleton) }
}

/// Writes the number of bones into `count`: the length of every skeleton
/// pose.
///
/// # Safety
/// `skeleton` is live; `count` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_bone_count(
    skeleton: *const VtSkeleton,
    count: *mut usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (skeleton, count) = unsafe { (shared(skeleton, "skeleton")?, out(count, "count")?) };
        count.set(skeleton.skeleton.len());
        Ok(())
    })
}

/// Writes the index of the bone named `name` into `index`.
///
/// # Safety
/// `skeleton` is live; `name` is a NUL-terminated string; `index` is
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_bone_index(
    skeleton: *const VtSkeleton,
    name: *const core::ffi::c_char,
    index: *mut usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let skeleton = unsafe { shared(skeleton, "skeleton") }?;
        let find = |name: &str| {
            let found = skeleton.skeleton.bone_index(name);
            let why = || format!("the skeleton has no bone `{name}`");
            found.ok_or_else(|| Failure::new(VtResult::Ragdoll, why()))
        };
        // SAFETY: the function's contract.
        unsafe { index_of(name, index, find) }
    })
}

/// Copies the name of bone `index` with its NUL into `buffer` (`capacity`
/// bytes) and its length with the NUL into `length` (as
/// `vt_ragdoll_desc_body_name`).
///
/// # Safety
/// `skeleton` is live; `buffer` points to `capacity` writable bytes;
/// `length` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_bone_name(
    skeleton: *const VtSkeleton,
    index: usize,
    buffer: *mut core::ffi::c_char,
    capacity: usize,
    length: *mut usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let skeleton = unsafe { shared(skeleton, "skeleton") }?;
        let bones = skeleton.skeleton.bones();
        let bone = bones.get(index).ok_or_else(|| {
            let n = bones.len();
            Failure::new(
                VtResult::OutOfRange,
                format!("bone {index} of a skeleton of {n}"),
            )
        })?;
        // SAFETY: the function's contract.
        unsafe { copy_text(&bone.name, buffer, capacity, length) }
    })
}

/// Writes the bind pose, each bone relative to its parent (m), into
/// `local`, which holds `count` transforms: the bone count.
///
/// # Safety
/// `skeleton` is live; `local` points to `count` writable transforms.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_bind_pose(
    skeleton: *const VtSkeleton,
    local: *mut VtTransform,
    count: usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let skeleton = unsafe { shared(skeleton, "skeleton") }?;
        // SAFETY: the function's contract.
        let place = unsafe { slice_mut(local, count, "local") }?;
        write_bones(&skeleton.skeleton.bind_pose().bones, place)
    })
}

/// The `count` parent-local transforms at `local` as a skeleton's local
/// pose (one per bone; `write_bones` writes one back).
///
/// # Safety
/// `local` points to `count` readable transforms.
pub(crate) unsafe fn local_pose(
    local: *const VtTransform,
    count: usize,
    what: &str,
) -> Result<LocalPose, Failure> {
    // SAFETY: the function's contract.
    let bones = unsafe { slice(local, count, what) }?;
    Ok(LocalPose {
        bones: bones.iter().map(|&t| t.into()).collect(),
    })
}

/// Copies bones into `place`, which must be as long.
pub(crate) fn write_bones(bones: &[Transform], place: &mut [VtTransform]) -> Result<(), Failure> {
    if place.len() != bones.len() {
        return Err(Failure::new(
            VtResult::BufferTooSmall,
            format!(
                "the pose holds {} bones; it takes {}",
                place.len(),
                bones.len()
            ),
        ));
    }
    for (to, &from) in place.iter_mut().zip(bones) {
        *to = from.into();
    }
    Ok(())
}

/// Makes the mapper between `desc`'s bodies (built with `spine`, a
/// `VtSpineMode`) and `skeleton`'s bones: each body follows the bone its
/// description binds it to, or else the bone of its own name. Refused,
/// naming the body, when the skeleton lacks the bone.
///
/// # Safety
/// `skeleton` and `desc` are live; `mapper` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_mapper_create(
    skeleton: *const VtSkeleton,
    desc: *const VtRagdollDesc,
    spine: u32,
    mapper: *mut *mut VtSkeletonMapper,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (skeleton, desc, place) = unsafe {
            (
                shared(skeleton, "skeleton")?,
                shared(desc, "desc")?,
                out(mapper, "mapper")?,
            )
        };
        let spine = pick(spine, "spine", &[SpineMode::Sockets, SpineMode::Rod])?;
        let made = SkeletonMapper::new(&skeleton.skeleton, &desc.desc, spine)?;
        place.set(boxed(VtSkeletonMapper { mapper: made }));
        Ok(())
    })
}

/// Frees a mapper (null does nothing).
///
/// # Safety
/// `mapper` is null or live, and not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_mapper_destroy(mapper: *mut VtSkeletonMapper) {
    // SAFETY: the function's contract.
    unsafe { free(mapper) }
}

/// The ragdoll's pose for an animation: `model` (`bone_count` model-frame
/// bone transforms) placed in the world by `model_to_world`, mapped onto
/// the bodies, written into `pose` (`body_count` world transforms): what
/// `vt_ragdoll_build` takes at the switch from animation.
///
/// # Safety
/// `mapper` is live; `model` points to `bone_count` readable transforms;
/// `pose` points to `body_count` writable transforms (the two may
/// overlap).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_mapper_map_to_ragdoll(
    mapper: *const VtSkeletonMapper,
    model: *const VtTransform,
    bone_count: usize,
    model_to_world: VtTransform,
    pose: *mut VtTransform,
    body_count: usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (mapper, model) = unsafe {
            (
                shared(mapper, "mapper")?,
                slice(model, bone_count, "model")?,
            )
        };
        // The input is copied before the output is lent: the two arrays
        // may overlap (mapped in place).
        let animation = ModelPose {
            bones: model.iter().map(|&t| t.into()).collect(),
        };
        let mapped = mapper
            .mapper
            .map_to_ragdoll(&animation, model_to_world.into())?;
        // SAFETY: the function's contract; `model` is no longer used.
        let place = unsafe { slice_mut(pose, body_count, "pose") }?;
        write_pose(&mapped, place)
    })
}

/// Every bone of the skeleton from the simulated ragdoll: bones on bodies
/// follow them, chains between bodies are placed by `mapping` (a
/// `VtSpineMapping`), bones past the bodies (fingers) keep the animation's
/// local transforms from `animation` (`count` parent-local transforms);
/// written into `bones` (`count` world transforms).
///
/// # Safety
/// `mapper`, `ragdoll` and `world` are live; `animation` points to `count`
/// readable transforms; `bones` to `count` writable ones (it may be
/// `animation`: mapped in place).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_mapper_map_to_skeleton(
    mapper: *const VtSkeletonMapper,
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    animation: *const VtTransform,
    model_to_world: VtTransform,
    mapping: u32,
    bones: *mut VtTransform,
    count: usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (mapper, animation) = unsafe {
            (
                shared(mapper, "mapper")?,
                local_pose(animation, count, "animation")?,
            )
        };
        // SAFETY: the function's contract.
        let (ragdoll, world) = unsafe { (enter(ragdoll)?, enter(world)?) };
        let mapping = spine_mapping(mapping)?;
        let mapped = mapper.mapper.map_to_skeleton(
            &ragdoll.ragdoll,
            &world.world,
            &animation,
            model_to_world.into(),
            mapping,
        )?;
        // SAFETY: the function's contract; `animation`'s slice is no longer
        // used (it was copied above), so `bones` may be the same array.
        let place = unsafe { slice_mut(bones, count, "bones") }?;
        write_bones(&mapped.bones, place)
    })
}

/// Writes the pose of every described body into `pose` (`count` writable
/// transforms, one per described body: world, at its centre of mass,
/// rotation relative to bind), read from the bodies in `world`; a rod
/// spine's interior bodies are placed by `mapping` (a `VtSpineMapping`).
/// What `vt_blend_back_create_ragdoll` and `vt_get_up_choose` take as the
/// ragdoll's last pose (`Ragdoll::skeleton_pose` in Rust). Refused for a
/// `count` that is not the description's body count.
///
/// # Safety
/// `ragdoll` and `world` are live; `pose` points to `count` writable
/// transforms.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_pose(
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    mapping: u32,
    pose: *mut VtTransform,
    count: usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (ragdoll, world, place) = unsafe {
            (
                enter(ragdoll)?,
                enter(world)?,
                slice_mut(pose, count, "pose")?,
            )
        };
        let read = ragdoll
            .ragdoll
            .skeleton_pose(&world.world, spine_mapping(mapping)?)?;
        write_pose(&read, place)
    })
}
