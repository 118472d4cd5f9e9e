//! Per-bone blending of two poses, as Unreal's physics blend weight: for
//! each bone, a weight in [0, 1] between the first pose (0: an animation
//! pose, say) and the second (1: the simulated pose). Translations are
//! interpolated linearly, rotations along the shorter arc (slerp), so a
//! bone turns at a steady rate as its weight moves: at weight `w` it is
//! `w` of the way, in metres and in radians. A weight of exactly 0
//! or 1 gives that pose's bone bit for bit.

use glam::{Quat, Vec3};
use vertebra_math::PortableQuat;

use crate::description::RagdollDesc;
use crate::error::RagdollError;
use crate::pose::Pose;

/// Checks one weight per bone, each finite and in [0, 1]; `context(k)`
/// names bone `k` in the error.
pub(crate) fn check_weights(
    weights: &[f32],
    bones: usize,
    context: impl Fn(usize) -> String,
) -> Result<(), RagdollError> {
    if weights.len() != bones {
        return Err(RagdollError::OutOfRange {
            context: "blend".to_owned(),
            field: "weights",
            reason: format!("has {} entries for {bones} bones", weights.len()),
        });
    }
    for (k, &w) in weights.iter().enumerate() {
        if !w.is_finite() {
            return Err(RagdollError::NonFinite {
                context: context(k),
                field: "weight",
            });
        }
        if !(0.0..=1.0).contains(&w) {
            return Err(RagdollError::OutOfRange {
                context: context(k),
                field: "weight",
                reason: format!("is {w}; must be within [0, 1]"),
            });
        }
    }
    Ok(())
}

/// `a` and `b` blended at weight `w` (0: `a`, 1: `b`, exactly):
/// translation `a (1 - w) + b w`, rotation along the shorter arc
/// ([`PortableQuat::slerp_portable`]).
pub(crate) fn blend_bone((pa, qa): (Vec3, Quat), (pb, qb): (Vec3, Quat), w: f32) -> (Vec3, Quat) {
    if w == 0.0 {
        (pa, qa)
    } else if w == 1.0 {
        (pb, qb)
    } else {
        (pa * (1.0 - w) + pb * w, qa.slerp_portable(qb, w))
    }
}

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
