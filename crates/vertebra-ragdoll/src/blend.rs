//! Per-bone blending of two poses, as Unreal's physics blend weight: for
//! each bone, a weight in [0, 1] between the first pose (0: an animation
//! pose, say) and the second (1: the simulated pose). Translations are
//! interpolated linearly, rotations along the shorter arc (slerp), so a
//! bone turns at a steady rate as its weight moves: at weight `w` it is
//! `w` of the way, in metres and in radians. A weight of exactly 0
//! or 1 gives that pose's bone bit for bit.

use crate::error::RagdollError;
use crate::model::RagdollDesc;
use crate::pose::Pose;
use crate::skeleton::{blend_bone, check_weights};

impl Pose {
    /// This pose blended bone by bone with `other`: bone `k` at
    /// `weights[k]` (0: this pose's bone, 1: `other`'s, exactly; in
    /// between, positions (m, world) interpolated linearly and orientations
    /// along the shorter arc). For the output skeleton, with this pose the
    /// animation's and `other` the simulation's (`Ragdoll::skeleton_pose`),
    /// the weights are Unreal's physics blend weights. Refused, naming the
    /// bone and the field, when either pose does not fit `desc` or a
    /// weight is not finite or outside [0, 1] (one weight per bone).
    pub fn blend(
        &self,
        desc: &RagdollDesc,
        other: &Pose,
        weights: &[f32],
    ) -> Result<Pose, RagdollError> {
        self.validate(desc)?;
        other.validate(desc)?;
        check_weights(weights, desc.bodies.len(), |k| {
            format!("bone `{}`", desc.bodies[k].name)
        })?;
        let bones = self
            .bones
            .iter()
            .zip(&other.bones)
            .zip(weights)
            .map(|((&a, &b), &w)| blend_bone(a, b, w))
            .collect();
        Ok(Pose { bones })
    }
}
