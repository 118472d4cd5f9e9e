//! Getting up: which of a game's get-up clips fits a settled ragdoll (face
//! up, face down, or any other lie a clip starts from), and where in the
//! world to play it so that the blend back
//! ([`BlendBack`](crate::BlendBack)) starts from the ragdoll without a
//! slide or a spin.
//!
//! A clip is given by its first frame as a [`Pose`] in its own model frame
//! (the mapper's [`map_to_ragdoll`](crate::SkeletonMapper::map_to_ragdoll)
//! of the clip's first frame at the identity). The clip is placed by a
//! turn about the world's up and a move: the turn is the twist about up
//! of the turn taking the clip's root body to the ragdoll's (a swing-twist
//! split, the twist being the part of a rotation about one axis), so the
//! clip faces the way the ragdoll lies; the move puts the clip's root body
//! on the ragdoll's. What is left, the swing, is how far the clip's lie is
//! from the ragdoll's: the clip with the smallest is the one to play (a
//! ragdoll face down is half a turn of swing from a face-up clip,
//! whatever its heading).

use glam::{Quat, Vec3};

use crate::error::RagdollError;
use crate::model::RagdollDesc;
use crate::pose::Pose;
use vertebra_math::{DefaultFloatMode, PortableQuat};

/// The get-up clip that fits a lying ragdoll, and where to play it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GetUp {
    /// The clip's index in the list given.
    pub clip: usize,
    /// The turn about up (world) of the clip's model frame.
    pub turn: Quat,
    /// The move (m, world) after the turn.
    pub translation: Vec3,
    /// The turn (rad) left between the placed clip's root body and the
    /// ragdoll's: how far the clip's lie is from the ragdoll's.
    pub misfit: f32,
}

impl GetUp {
    /// Of the get-up clips whose first frames are `first_frames` (each a
    /// pose of `desc` in its clip's model frame), the one whose root body
    /// lies most as the ragdoll's does in `lying` (its pose in the world,
    /// [`Ragdoll::skeleton_pose`](crate::Ragdoll::skeleton_pose)), placed
    /// by a turn about `up` (the world's up, unit: against gravity) and a
    /// move that put its root body on the ragdoll's. The first of equally
    /// fitting clips is chosen. Refused, naming the pose, for a pose that
    /// does not fit `desc`, no clip, and an `up` that is not unit.
    pub fn choose(
        desc: &RagdollDesc,
        lying: &Pose,
        first_frames: &[Pose],
        up: Vec3,
    ) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let bad = |what: &str, e: RagdollError| RagdollError::BadPose(format!("{what}: {e}"));
        lying.validate(desc).map_err(|e| bad("the lying pose", e))?;
        if !(up.is_finite() && (up.length() - 1.0).abs() < 1e-3) {
            return Err(RagdollError::OutOfRange {
                context: "get up".to_owned(),
                field: "up",
                reason: format!("is {up}; must be a unit vector"),
            });
        }
        let up = up.normalize();
        let (at, facing) = lying.bones[desc.root];
        let mut best: Option<Self> = None;
        for (clip, first) in first_frames.iter().enumerate() {
            first
                .validate(desc)
                .map_err(|e| bad(&format!("clip {clip}'s first frame"), e))?;
            let (from, orientation) = first.bones[desc.root];
            let turn = twist_about(facing.mul_portable(orientation.conjugate()), up);
            let misfit = turn
                .mul_portable(orientation)
                .angle_between_portable(facing);
            if best.is_none_or(|b| misfit < b.misfit) {
                best = Some(Self {
                    clip,
                    turn,
                    translation: at - turn * from,
                    misfit,
                });
            }
        }
        best.ok_or_else(|| RagdollError::OutOfRange {
            context: "get up".to_owned(),
            field: "first_frames",
            reason: "is empty; give at least one clip's first frame".to_owned(),
        })
    }

    /// `pose` (a frame of the chosen clip, in its model frame) placed in
    /// the world.
    pub fn placed(&self, pose: &Pose) -> Pose {
        pose.moved(Vec3::ZERO, self.turn, self.translation)
    }
}

/// The part of `rotation` about the unit `axis` (its twist in a
/// swing-twist split), the identity where there is none (a half turn of
/// swing).
fn twist_about(rotation: Quat, axis: Vec3) -> Quat {
    let (v, w) = (Vec3::new(rotation.x, rotation.y, rotation.z), rotation.w);
    let along = axis * v.dot(axis);
    let twist = Quat::from_xyzw(along.x, along.y, along.z, w);
    if twist.length_squared() < 1e-12 {
        Quat::IDENTITY
    } else {
        twist.normalize_portable()
    }
}
