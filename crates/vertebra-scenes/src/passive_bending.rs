//! Figures 2 and 8 (left): the hips held, the upper body leaned 30
//! degrees and left to slump.

use glam::{Quat, Vec3};
use vertebra_math::PortableQuat;
use vertebra_ragdoll::{Pose, RagdollDesc, RagdollError};
use vertebra_world::World;

use crate::setup::{ragdoll_with_fixed_hips, seeded};
use crate::{SceneConfig, SceneWorld};

/// The scene's world: the bind pose leaned 30 degrees about +X through the
/// hips centre (0, 1, 0), the upper body toward +Z; the hips held.
pub(crate) fn build(
    mut world: World,
    desc: &RagdollDesc,
    config: &SceneConfig,
) -> Result<SceneWorld, RagdollError> {
    let pose = Pose::bind(desc).moved(
        Vec3::new(0.0, 1.0, 0.0),
        Quat::from_rotation_x_portable(30f32.to_radians()),
        Vec3::ZERO,
    );
    let pose = seeded(pose, desc, config.seed, 0);
    let ragdoll = ragdoll_with_fixed_hips(&mut world, desc, config.spine, &pose)?;
    Ok(SceneWorld::new(world, None, vec![ragdoll], None, None))
}
