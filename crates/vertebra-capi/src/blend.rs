//! Blending between animation and simulation: two poses bone by bone at
//! per-bone weights (Unreal's physics blend weight), and the blend back
//! from the ragdoll's last pose to the animation (getting up;
//! `BlendBack` in Rust, `docs/ragdolls.md`). Either on a ragdoll's body
//! poses (world transforms, one per described body) or on a skeleton's
//! local poses (parent-local transforms, one per bone).

use vertebra_ragdoll::{
    Blend, BlendBack, GetUp, LocalPose, Pose, RagdollDesc, RagdollError, Skeleton,
};

use crate::error::{Failure, VtResult};
use crate::ffi::{Object, boxed, call, enter, free, out, shared, slice, slice_mut};
use crate::ragdoll::{VtRagdollDesc, pose_from, write_pose};
use crate::skeleton::{VtSkeleton, local_pose, write_bones};
use crate::types::{VtTransform, VtVec3};

/// A blend back under way (opaque; `vt_blend_back_create_ragdoll` or
/// `vt_blend_back_create_skeleton`; free it with `vt_blend_back_destroy`).
pub struct VtBlendBack {
    blend: Blending,
    poisoned: bool,
}

impl Object for VtBlendBack {
    const NAME: &'static str = "blend back";
    fn poisoned(&mut self) -> &mut bool {
        &mut self.poisoned
    }
}

/// What a blend back blends, with the rig its poses are checked against
/// (boxed: the two differ much in size).
enum Blending {
    Ragdoll(BlendBack<Pose>, Box<RagdollDesc>),
    Skeleton(BlendBack<LocalPose>, Box<Skeleton>),
}

/// A pose kind C passes as an array of transforms: a ragdoll's (world
/// transforms, one per described body) or a skeleton's local pose
/// (parent-local transforms, one per bone). The blends below are written
/// once over it.
trait Transforms: Blend {
    /// `count` transforms at `at` as a pose (`what` names the array).
    ///
    /// # Safety
    /// `at` points to `count` readable transforms.
    unsafe fn read(at: *const VtTransform, count: usize, what: &str) -> Result<Self, Failure>;

    /// Writes the pose into `place`, which must be as long.
    fn write(&self, place: &mut [VtTransform]) -> Result<(), Failure>;

    /// This pose blended bone by bone with `other` at `weights`
    /// (`Pose::blend`, `LocalPose::blend`).
    fn blend_bones(
        &self,
        rig: &Self::Rig,
        other: &Self,
        weights: &[f32],
    ) -> Result<Self, RagdollError>;
}

impl Transforms for Pose {
    /// # Safety
    /// As the trait's.
    unsafe fn read(at: *const VtTransform, count: usize, what: &str) -> Result<Self, Failure> {
        // SAFETY: the function's contract.
        unsafe { pose_from(at, count, what) }
    }

    fn write(&self, place: &mut [VtTransform]) -> Result<(), Failure> {
        write_pose(self, place)
    }

    fn blend_bones(
        &self,
        desc: &RagdollDesc,
        other: &Self,
        weights: &[f32],
    ) -> Result<Self, RagdollError> {
        self.blend(desc, other, weights)
    }
}

impl Transforms for LocalPose {
    /// # Safety
    /// As the trait's.
    unsafe fn read(at: *const VtTransform, count: usize, what: &str) -> Result<Self, Failure> {
        // SAFETY: the function's contract.
        unsafe { local_pose(at, count, what) }
    }

    fn write(&self, place: &mut [VtTransform]) -> Result<(), Failure> {
        write_bones(&self.bones, place)
    }

    fn blend_bones(
        &self,
        skeleton: &Skeleton,
        other: &Self,
        weights: &[f32],
    ) -> Result<Self, RagdollError> {
        self.blend(skeleton, other, weights)
    }
}

/// `a` and `b` (each `count` transforms of kind `P`) blended bone by bone
/// at `weights` against `rig`, into `out`: what `vt_ragdoll_pose_blend`
/// and `vt_skeleton_pose_blend` do.
///
/// # Safety
/// `a`, `b` and `weights` point to `count` readable items, `out` to
/// `count` writable transforms (it may be `a` or `b`).
unsafe fn blend_poses<P: Transforms>(
    rig: &P::Rig,
    a: *const VtTransform,
    b: *const VtTransform,
    weights: *const f32,
    count: usize,
    out: *mut VtTransform,
) -> Result<(), Failure> {
    // SAFETY: the function's contract.
    let (a, b, weights) = unsafe {
        (
            P::read(a, count, "a")?,
            P::read(b, count, "b")?,
            slice(weights, count, "weights")?,
        )
    };
    let blended = a.blend_bones(rig, &b, weights)?;
    // SAFETY: the function's contract; the inputs were copied above.
    let place = unsafe { slice_mut(out, count, "out") }?;
    blended.write(place)
}

/// Blends two ragdoll poses bone by bone: body `k` of the output (`out`)
/// is `a`'s at `weights[k] = 0`, `b`'s at 1 (exactly), positions
/// interpolated linearly and rotations along the shorter arc between
/// (each array `count` long, one per described body; `a` the animation's
/// and `b` the simulation's for Unreal's physics blend weight). Refused,
/// naming the body, for a pose that does not fit `desc` or a weight not
/// finite or outside [0, 1].
///
/// # Safety
/// `desc` is live; `a`, `b` and `weights` point to `count` readable
/// items, `out` to `count` writable transforms (it may be `a` or `b`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_ragdoll_pose_blend(
    desc: *const VtRagdollDesc,
    a: *const VtTransform,
    b: *const VtTransform,
    weights: *const f32,
    count: usize,
    out: *mut VtTransform,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let desc = unsafe { shared(desc, "desc") }?;
        // SAFETY: the function's contract.
        unsafe { blend_poses::<Pose>(&desc.desc, a, b, weights, count, out) }
    })
}

/// Blends two skeleton poses bone by bone in local space (each array
/// `count` parent-local transforms, one per bone), as
/// `vt_ragdoll_pose_blend` blends a ragdoll's. Refused, naming the bone,
/// for a pose that does not fit `skeleton` or a weight not finite or
/// outside [0, 1].
///
/// # Safety
/// `skeleton` is live; `a`, `b` and `weights` point to `count` readable
/// items, `out` to `count` writable transforms (it may be `a` or `b`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_skeleton_pose_blend(
    skeleton: *const VtSkeleton,
    a: *const VtTransform,
    b: *const VtTransform,
    weights: *const f32,
    count: usize,
    out: *mut VtTransform,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let skeleton = unsafe { shared(skeleton, "skeleton") }?;
        // SAFETY: the function's contract.
        unsafe { blend_poses::<LocalPose>(&skeleton.skeleton, a, b, weights, count, out) }
    })
}

/// A blend back from `simulated` (`count` transforms of kind `P`, held
/// from now on) to the animation over `duration` seconds, checked against
/// `rig`, written into `blend` as the object C frees with
/// `vt_blend_back_destroy`; `kind` holds it with its own copy of the rig
/// to check each frame's animation against. What both
/// `vt_blend_back_create_*` do.
///
/// # Safety
/// `simulated` points to `count` readable transforms; `blend` is writable.
unsafe fn start<P: Transforms>(
    rig: &P::Rig,
    simulated: *const VtTransform,
    count: usize,
    duration: f32,
    blend: *mut *mut VtBlendBack,
    kind: fn(BlendBack<P>, Box<P::Rig>) -> Blending,
) -> Result<(), Failure>
where
    P::Rig: Clone,
{
    // SAFETY: the function's contract.
    let (simulated, place) = unsafe {
        (
            P::read(simulated, count, "simulated")?,
            out(blend, "blend")?,
        )
    };
    let made = BlendBack::new(rig, simulated, duration)?;
    place.set(boxed(VtBlendBack {
        blend: kind(made, Box::new(rig.clone())),
        poisoned: false,
    }));
    Ok(())
}

/// Starts a blend back from a ragdoll's last simulated pose `simulated`
/// (`count` world transforms, one per described body; held from now on)
/// to the animation over `duration` seconds (finite, positive): each
/// frame `vt_blend_back_pose` with the frame's animation pose, then
/// `vt_blend_back_advance`. Writes it into `blend` (free it with
/// `vt_blend_back_destroy`). Refused for a pose that does not fit `desc`
/// (naming the body) or a duration out of range.
///
/// # Safety
/// `desc` is live; `simulated` points to `count` readable transforms;
/// `blend` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_blend_back_create_ragdoll(
    desc: *const VtRagdollDesc,
    simulated: *const VtTransform,
    count: usize,
    duration: f32,
    blend: *mut *mut VtBlendBack,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let desc = unsafe { shared(desc, "desc") }?;
        let rig = &desc.desc;
        // SAFETY: the function's contract.
        unsafe { start(rig, simulated, count, duration, blend, Blending::Ragdoll) }
    })
}

/// As `vt_blend_back_create_ragdoll`, on a skeleton's local poses:
/// `simulated` is `count` parent-local transforms, one per bone of
/// `skeleton` (the skeleton the simulated ragdoll was mapped onto).
///
/// # Safety
/// `skeleton` is live; `simulated` points to `count` readable transforms;
/// `blend` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_blend_back_create_skeleton(
    skeleton: *const VtSkeleton,
    simulated: *const VtTransform,
    count: usize,
    duration: f32,
    blend: *mut *mut VtBlendBack,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let skeleton = unsafe { shared(skeleton, "skeleton") }?;
        let rig = &skeleton.skeleton;
        // SAFETY: the function's contract.
        unsafe { start(rig, simulated, count, duration, blend, Blending::Skeleton) }
    })
}

/// Frees a blend back (null does nothing).
///
/// # Safety
/// `blend` is null or live, and not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_blend_back_destroy(blend: *mut VtBlendBack) {
    // SAFETY: the function's contract.
    unsafe { free(blend) }
}

/// This frame's output of `back` (checked against `rig`) for `animation`
/// (`count` transforms of its kind), into `pose`: what
/// `vt_blend_back_pose` does for either kind.
///
/// # Safety
/// `animation` points to `count` readable transforms, `pose` to `count`
/// writable ones (it may be `animation`).
unsafe fn frame<P: Transforms>(
    back: &BlendBack<P>,
    rig: &P::Rig,
    animation: *const VtTransform,
    count: usize,
    pose: *mut VtTransform,
) -> Result<(), Failure> {
    // SAFETY: the function's contract.
    let animation = unsafe { P::read(animation, count, "animation") }?;
    let output = back.pose(rig, &animation)?;
    // SAFETY: the function's contract; the input was copied.
    output.write(unsafe { slice_mut(pose, count, "pose") }?)
}

/// This frame's output: `animation` (this frame's animation pose, `count`
/// transforms of the kind the blend was made for) blended toward the held
/// simulated pose at the blend's weight, into `pose` (`count` writable
/// transforms; it may be `animation`). The first frame's is the simulated
/// pose, every frame's from the duration on the animation's, exactly.
/// Refused for an animation that does not fit (naming the bone).
///
/// # Safety
/// `blend` is live; `animation` points to `count` readable transforms,
/// `pose` to `count` writable ones.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_blend_back_pose(
    blend: *mut VtBlendBack,
    animation: *const VtTransform,
    count: usize,
    pose: *mut VtTransform,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let blend = unsafe { enter(blend) }?;
        // SAFETY: the function's contract.
        unsafe {
            match &blend.blend {
                Blending::Ragdoll(back, desc) => frame(back, desc, animation, count, pose),
                Blending::Skeleton(back, skeleton) => frame(back, skeleton, animation, count, pose),
            }
        }
    })
}

/// Moves the blend on by `dt` seconds (finite, not negative).
///
/// # Safety
/// `blend` is live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_blend_back_advance(blend: *mut VtBlendBack, dt: f32) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let mut blend = unsafe { enter(blend) }?;
        match &mut blend.blend {
            Blending::Ragdoll(back, _) => back.advance(dt)?,
            Blending::Skeleton(back, _) => back.advance(dt)?,
        }
        Ok(())
    })
}

/// Writes the ragdoll's weight now into `weight` (1 as the blend starts,
/// 0 from its duration on, smoothstep between) and whether the blend has
/// reached the animation into `done` (1 or 0).
///
/// # Safety
/// `blend` is live; `weight` and `done` are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_blend_back_weight(
    blend: *mut VtBlendBack,
    weight: *mut f32,
    done: *mut u32,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (blend, weight, done) =
            unsafe { (enter(blend)?, out(weight, "weight")?, out(done, "done")?) };
        let (w, d) = match &blend.blend {
            Blending::Ragdoll(back, _) => (back.weight(), back.is_done()),
            Blending::Skeleton(back, _) => (back.weight(), back.is_done()),
        };
        weight.set(w);
        done.set(u32::from(d));
        Ok(())
    })
}

/// The get-up clip that fits a lying ragdoll, and where to play it
/// (`vt_get_up_choose`; `GetUp` in Rust, `docs/ragdolls.md`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VtGetUp {
    /// The clip's index among the first frames given.
    pub clip: usize,
    /// Where to play it: its model frame in the world, a turn about up
    /// then a move (m).
    pub place: VtTransform,
    /// The turn (rad) left between the placed clip's root body and the
    /// ragdoll's: how far the clip's lie is from the ragdoll's.
    pub misfit: f32,
}

/// Of `clips` get-up clips whose first frames are `first_frames` (`clips`
/// poses of `count` transforms each, one per described body, in each
/// clip's model frame, one after another), the one whose root body lies
/// most as the ragdoll's does in `lying` (`count` world transforms: its
/// pose as `vt_ragdoll_pose` gives it), placed by a turn about
/// `up` (the world's up, unit: against gravity) and a move that put its
/// root body on the ragdoll's; into `get_up`. Blend back to the placed
/// clip with `vt_blend_back_create_ragdoll` from `lying`. Refused, naming
/// the pose, for a pose that does not fit `desc`, no clip, and an `up`
/// that is not unit.
///
/// # Safety
/// `desc` is live; `lying` points to `count` readable transforms,
/// `first_frames` to `count * clips`; `get_up` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_get_up_choose(
    desc: *const VtRagdollDesc,
    lying: *const VtTransform,
    count: usize,
    first_frames: *const VtTransform,
    clips: usize,
    up: VtVec3,
    get_up: *mut VtGetUp,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (desc, lying, place) = unsafe {
            (
                shared(desc, "desc")?,
                pose_from(lying, count, "lying")?,
                out(get_up, "get_up")?,
            )
        };
        let total = count.checked_mul(clips).ok_or_else(|| {
            Failure::new(
                VtResult::OutOfRange,
                format!("first_frames: {clips} clips of {count} transforms overflow"),
            )
        })?;
        // SAFETY: the function's contract.
        let frames = unsafe { slice(first_frames, total, "first_frames") }?;
        let first_frames: Vec<Pose> = frames
            .chunks(count.max(1))
            .take(clips)
            .map(|clip| Pose {
                bones: clip.iter().map(|&t| t.into()).collect(),
            })
            .collect();
        let chosen = GetUp::choose(&desc.desc, &lying, &first_frames, up.into())?;
        place.set(VtGetUp {
            clip: chosen.clip,
            place: (chosen.translation, chosen.turn).into(),
            misfit: chosen.misfit,
        });
        Ok(())
    })
}
