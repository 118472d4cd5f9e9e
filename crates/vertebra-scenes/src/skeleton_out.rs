//! A scene's ragdolls on the reference animation skeleton
//! (`Skeleton::reference()`, 63 bones), frame by frame: what `vertebra
//! scene --skeleton-out` writes. Both humanoids bind to it by name.

use glam::Quat;
use vertebra_ragdoll::{
    LocalPose, ModelPose, RagdollError, Skeleton, SkeletonMapper, SpineMapping, Transform,
};

use crate::SceneWorld;
use vertebra_math::DefaultFloatMode;

/// One mapper per ragdoll of a scene, onto the reference skeleton.
pub struct SkeletonOut {
    skeleton: Skeleton,
    /// The animation pose for the bones without a body (fingers, twist
    /// bones, toes, the root): the bind pose.
    animation: LocalPose,
    mappers: Vec<SkeletonMapper>,
}

impl SkeletonOut {
    /// A mapper per ragdoll of `scene` (its description and spine) onto
    /// the reference skeleton; refused, naming the body, when a ragdoll
    /// has a body without a bone of its name (a `--ragdoll` file of other
    /// names).
    pub fn new(scene: &SceneWorld) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let skeleton = Skeleton::reference();
        let mappers = scene
            .ragdolls
            .iter()
            .map(|r| SkeletonMapper::new(&skeleton, r.description(), r.options().spine))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            animation: skeleton.bind_pose(),
            skeleton,
            mappers,
        })
    }

    /// The skeleton mapped onto.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Per ragdoll, every bone's world transform now (arc spine mapping).
    /// The model frame (which places the free root bone) rides on the
    /// ragdoll's root body as at bind pose: the root body's transform
    /// times its bind centre, inverted.
    pub fn poses(&self, scene: &SceneWorld) -> Result<Vec<ModelPose>, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        scene
            .ragdolls
            .iter()
            .zip(&self.mappers)
            .map(|(ragdoll, mapper)| {
                let desc = ragdoll.description();
                let root = ragdoll.bodies[desc.root].expect("the root body is always built");
                let state = scene
                    .world
                    .body(root)
                    .map_err(|error| RagdollError::World {
                        context: format!("body `{}`", desc.bodies[desc.root].name),
                        error,
                    })?;
                let model_to_world = Transform::new(state.position, state.orientation)
                    * Transform::new(-desc.bodies[desc.root].centre(), Quat::IDENTITY);
                mapper.map_to_skeleton(
                    ragdoll,
                    &scene.world,
                    &self.animation,
                    model_to_world,
                    SpineMapping::Arc,
                )
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::{Scene, SceneConfig, build};
    use vertebra_ragdoll::SpineMode;

    /// Built, before any step, passive bending's ragdoll is its bind pose
    /// turned 30 degrees about +X through the hips' centre: every bone is
    /// its bind model transform moved by that turn.
    #[test]
    fn the_start_of_passive_bending_is_the_bind_skeleton_turned() {
        for spine in [SpineMode::Rod, SpineMode::Sockets] {
            let scene = build(&SceneConfig::new(Scene::PassiveBending, spine)).unwrap();
            let out = SkeletonOut::new(&scene).unwrap();
            let poses = out.poses(&scene).unwrap();
            assert_eq!(poses.len(), 1);
            let bind = out.skeleton().bind_pose().to_model(out.skeleton()).unwrap();
            let hips = Vec3::new(0.0, 1.0, 0.0);
            let turn = Transform::new(hips, Quat::from_rotation_x(30f32.to_radians()))
                * Transform::new(-hips, Quat::IDENTITY);
            for (j, (got, b)) in poses[0].bones.iter().zip(&bind.bones).enumerate() {
                let want = turn * *b;
                // The angle from the relative rotation's vector part: f32
                // `acos` near 1 (`angle_between`) resolves only ~3e-4 rad.
                let angle = 2.0 * (got.rotation.inverse() * want.rotation).xyz().length();
                assert!(
                    got.translation.distance(want.translation) < 1e-5 && angle < 1e-4,
                    "{spine:?}: bone `{}`: {got:?} against {want:?}",
                    out.skeleton().bones()[j].name
                );
            }
        }
    }
}
