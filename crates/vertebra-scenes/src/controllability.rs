//! Figure 7: the hips held, every joint driven to the bind pose with
//! infinite strength, the chest pushed (frames 30 to 90, see
//! [`SceneWorld::advance`]).

use glam::Vec3;
use vertebra_ragdoll::{DriveSettings, Pose, RagdollDesc, RagdollError};
use vertebra_world::{Spring, World};

use crate::setup::{ragdoll_with_fixed_hips, seeded, spine_top};
use crate::{SceneConfig, SceneWorld};

/// The scene's world: the bind pose, its hips held, driven to itself; the
/// push is 200 N along +Z on the top of the spine (the chest).
pub(crate) fn build(
    mut world: World,
    desc: &RagdollDesc,
    config: &SceneConfig,
) -> Result<SceneWorld, RagdollError> {
    let pose = seeded(Pose::bind(desc), desc, config.seed, 0);
    let ragdoll = ragdoll_with_fixed_hips(&mut world, desc, config.spine, &pose)?;
    ragdoll.drive_to(&mut world, &pose, &DriveSettings::uniform(Spring::RIGID))?;
    let push = ragdoll.bodies[spine_top(desc)].map(|c| (c, Vec3::new(0.0, 0.0, 200.0)));
    Ok(SceneWorld::new(
        world,
        None,
        vec![ragdoll],
        Some(pose),
        push,
    ))
}
