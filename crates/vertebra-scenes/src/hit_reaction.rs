//! The hit reaction: the anatomical humanoid with its hips held (it has no
//! feet to stand on), every joint driven to the bind pose by a damped
//! spring (`SceneConfig::drive_frequency`, `drive_damping_ratio`,
//! `max_torque`), hit on the chest and then on the head.

use glam::Vec3;
use vertebra_ragdoll::{DriveSettings, Pose, RagdollDesc, RagdollError};
use vertebra_world::{BodyHandle, World};

use crate::setup::{ragdoll_with_fixed_hips, seeded, spine_top};
use crate::{SceneConfig, SceneWorld};

/// The frames whose step each hit precedes: the chest at 0.5 s, the head
/// at 2 s.
pub const HIT_FRAMES: [usize; 2] = [30, 120];

/// The chest's hit (N s): from behind, toward +Z (the controllability
/// push's direction).
const CHEST_HIT: Vec3 = Vec3::new(0.0, 0.0, 10.0);

/// The head's hit (N s): from the side, toward +X.
const HEAD_HIT: Vec3 = Vec3::new(3.0, 0.0, 0.0);

/// The scene's world: the bind pose, its hips held, driven to itself by
/// `drive`; the chest (the top of the spine) hit at [`HIT_FRAMES`]`[0]`,
/// the body named `head` at [`HIT_FRAMES`]`[1]`.
pub(crate) fn build(
    mut world: World,
    desc: &RagdollDesc,
    config: &SceneConfig,
    drive: &DriveSettings,
) -> Result<SceneWorld, RagdollError> {
    let pose = seeded(Pose::bind(desc), desc, config.seed, 0);
    let ragdoll = ragdoll_with_fixed_hips(&mut world, desc, config.spine, &pose)?;
    ragdoll.drive_to(&mut world, &pose, drive)?;
    let head = desc.bodies.iter().position(|b| b.name == "head");
    let hit = |index: Option<usize>, name: &str| -> Result<BodyHandle, RagdollError> {
        index
            .and_then(|k| ragdoll.bodies[k])
            .ok_or_else(|| RagdollError::UnknownBody {
                context: "scene hit-reaction (the body hit)".to_owned(),
                field: "body",
                name: name.to_owned(),
            })
    };
    let hits = vec![
        (
            HIT_FRAMES[0],
            hit(Some(spine_top(desc)), "chest")?,
            CHEST_HIT,
        ),
        (HIT_FRAMES[1], hit(head, "head")?, HEAD_HIT),
    ];
    Ok(SceneWorld::new(world, None, vec![ragdoll], Some(pose), None).with_hits(hits))
}
