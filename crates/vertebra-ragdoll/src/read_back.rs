//! A built ragdoll read back onto a skeleton: its bodies and rod read
//! from the world (`SkeletonMapper::map_to_skeleton`), and its own
//! one-bone-per-body pose (`Ragdoll::skeleton_pose`). Above both the
//! mapper and the runtime ragdoll, which it joins.

use glam::{Quat, Vec3};
use vertebra_math::DefaultFloatMode;
use vertebra_world::World;

use crate::error::RagdollError;
use crate::mapper::{Bodies, SkeletonMapper};
use crate::mapping::SpineMapping;
use crate::model::rod_name;
use crate::pose::Pose;
use crate::ragdoll::Ragdoll;
use crate::skeleton::{LocalPose, ModelPose, Transform};

impl SkeletonMapper {
    /// Every bone's world transform from the ragdoll's bodies in `world`
    /// and the animation's current local pose (for the bones without a
    /// body that follow their parents or the model frame). `ragdoll` must
    /// be built from the mapper's description and spine mode, and still be
    /// in `world`: a removed ragdoll is refused
    /// ([`RagdollError::Removed`], naming it), and so is one whose body or
    /// rod is no longer in `world` (naming the body or rod).
    pub fn map_to_skeleton(
        &self,
        ragdoll: &Ragdoll,
        world: &World,
        animation: &LocalPose,
        model_to_world: Transform,
        mapping: SpineMapping,
    ) -> Result<ModelPose, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let (bodies, rod_frames) = self.read(ragdoll, world)?;
        self.map(
            &bodies,
            rod_frames,
            animation,
            model_to_world,
            mapping,
            None,
        )
    }

    /// The bodies' world poses and the rod's frames, read from `world`.
    pub(crate) fn read(&self, ragdoll: &Ragdoll, world: &World) -> Result<Bodies, RagdollError> {
        // A removed ragdoll has no bodies to read: refused by name (mapped,
        // every body would be at the world origin).
        ragdoll.check_not_removed()?;
        if ragdoll.options.spine != self.spine
            || ragdoll.desc.name != self.desc.name
            || ragdoll.desc.bodies.len() != self.desc.bodies.len()
        {
            return Err(RagdollError::OutOfRange {
                context: "skeleton mapper".to_owned(),
                field: "ragdoll",
                reason: format!(
                    "is `{}` ({} bodies, {:?} spine); the mapper was made for `{}` ({} bodies, {:?} spine)",
                    ragdoll.desc.name,
                    ragdoll.desc.bodies.len(),
                    ragdoll.options.spine,
                    self.desc.name,
                    self.desc.bodies.len(),
                    self.spine
                ),
            });
        }
        let mut bodies = vec![(Vec3::ZERO, Quat::IDENTITY); ragdoll.bodies.len()];
        for ((out, handle), def) in bodies
            .iter_mut()
            .zip(&ragdoll.bodies)
            .zip(&ragdoll.desc.bodies)
        {
            if let Some(h) = handle {
                let s = world
                    .body(*h)
                    .map_err(|e| RagdollError::world(&format!("body `{}`", def.name), e))?;
                *out = (s.position, s.orientation);
            }
        }
        let rod_frames = match ragdoll.rod {
            Some(rod) => {
                let rod = world
                    .rod(rod)
                    .map_err(|e| RagdollError::world(&rod_name(&ragdoll.desc), e))?;
                Some((rod.frame_a, rod.frame_b))
            }
            None => None,
        };
        Ok((bodies, rod_frames))
    }
}

impl Ragdoll {
    /// The pose of every body as an animation bone (one bone per described
    /// body, at its centre of mass, rotation relative to bind), from the
    /// bodies in `world`; a simplified ragdoll's interior spine bodies are
    /// placed by `mapping`. It is [`SkeletonMapper`](crate::SkeletonMapper) on a skeleton of one
    /// bone per body (each at its centre of mass, unrotated at bind); for
    /// an engine's own skeleton use the mapper.
    pub fn skeleton_pose(
        &self,
        world: &World,
        mapping: SpineMapping,
    ) -> Result<Pose, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let mapper = &self.as_bones;
        let model = mapper.map_to_skeleton(
            self,
            world,
            &mapper.skeleton().bind_pose(),
            Transform::IDENTITY,
            mapping,
        )?;
        let bones = mapper
            .binding()
            .iter()
            .map(|&bone| {
                let t = model.bones[bone];
                (t.translation, t.rotation)
            })
            .collect();
        Ok(Pose { bones })
    }
}
