//! The switch from animation to ragdoll without a pop: the chain bones'
//! offsets from the mapping at the switch, faded out over a time
//! (`Transition` in Rust; `docs/ragdolls.md`), and a skeleton's local
//! poses taken to the model frame.

use vertebra_ragdoll::Transition;

use crate::error::VtResult;
use crate::ffi::{boxed, call, enter, free, out, shared, slice_mut};
use crate::ragdoll::VtRagdoll;
use crate::skeleton::{VtSkeleton, VtSkeletonMapper, local_pose, spine_mapping, write_bones};
use crate::types::VtTransform;
use crate::world::VtWorld;

/// The switch from animation (opaque; read-only;
/// `vt_transition_destroy`).
pub struct VtTransition {
    transition: Transition,
}

/// Takes a local pose (`count` parent-local transforms) to the model frame
/// (`count` transforms into `model`): what
/// `vt_skeleton_mapper_map_to_ragdoll` takes.
///
/// # Safety
/// `skeleton` is live; `local` points to `count` readable transforms,
/// `model` to `count` writable ones.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_to_model(
    skeleton: *const VtSkeleton,
    local: *const VtTransform,
    model: *mut VtTransform,
    count: usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (skeleton, pose) = unsafe {
            (
                shared(skeleton, "skeleton")?,
                local_pose(local, count, "local")?,
            )
        };
        // SAFETY: the function's contract.
        let place = unsafe { slice_mut(model, count, "model") }?;
        let model = pose.to_model(&skeleton.skeleton)?;
        write_bones(&model.bones, place)
    })
}

/// Starts the switch for a ragdoll just built at the animation's pose
/// (`vt_ragdoll_build` with `at_switch`): the offsets between the
/// animation (`count` parent-local transforms, placed by
/// `model_to_world`) and what `mapping` (a `VtSpineMapping`) gives from
/// the bodies, faded out over `fade` seconds (>= 0; infinity: kept).
/// Writes the transition into `transition` (`vt_transition_destroy`).
/// Refused, naming the joint, for a ragdoll whose joints are apart at the
/// pose by more than 1 mm (built without `at_switch` at a pose whose
/// bodiless bones are turned): its first step would pop.
///
/// # Safety
/// `mapper`, `ragdoll` and `world` are live; `animation` points to `count`
/// readable transforms; `transition` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_transition_create(
    mapper: *const VtSkeletonMapper,
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    animation: *const VtTransform,
    count: usize,
    model_to_world: VtTransform,
    mapping: u32,
    fade: f32,
    transition: *mut *mut VtTransition,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (mapper, animation, place) = unsafe {
            (
                shared(mapper, "mapper")?,
                local_pose(animation, count, "animation")?,
                out(transition, "transition")?,
            )
        };
        // SAFETY: the function's contract.
        let (ragdoll, world) = unsafe { (enter(ragdoll)?, enter(world)?) };
        let made = Transition::new(
            &mapper.mapper,
            &ragdoll.ragdoll,
            &world.world,
            &animation,
            model_to_world.into(),
            spine_mapping(mapping)?,
            fade,
        )?;
        place.set(boxed(VtTransition { transition: made }));
        Ok(())
    })
}

/// Frees a transition (null does nothing).
///
/// # Safety
/// `transition` is null or live, and not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_transition_destroy(transition: *mut VtTransition) {
    // SAFETY: the function's contract.
    unsafe { free(transition) }
}

/// Every bone of the skeleton `since_switch` seconds after the switch
/// (>= 0): the mapping of the simulated ragdoll with the switch's offsets
/// faded in; written into `bones` (`count` world transforms; `animation`
/// as `vt_skeleton_mapper_map_to_skeleton` takes it).
///
/// # Safety
/// `transition`, `mapper`, `ragdoll` and `world` are live; `animation`
/// points to `count` readable transforms, `bones` to `count` writable ones.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_transition_skeleton_pose(
    transition: *const VtTransition,
    mapper: *const VtSkeletonMapper,
    ragdoll: *mut VtRagdoll,
    world: *mut VtWorld,
    animation: *const VtTransform,
    model_to_world: VtTransform,
    since_switch: f32,
    bones: *mut VtTransform,
    count: usize,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (transition, mapper, animation) = unsafe {
            (
                shared(transition, "transition")?,
                shared(mapper, "mapper")?,
                local_pose(animation, count, "animation")?,
            )
        };
        // SAFETY: the function's contract.
        let (ragdoll, world) = unsafe { (enter(ragdoll)?, enter(world)?) };
        // SAFETY: the function's contract.
        let place = unsafe { slice_mut(bones, count, "bones") }?;
        let pose = transition.transition.skeleton_pose(
            &mapper.mapper,
            &ragdoll.ragdoll,
            &world.world,
            &animation,
            model_to_world.into(),
            since_switch,
        )?;
        write_bones(&pose.bones, place)
    })
}
