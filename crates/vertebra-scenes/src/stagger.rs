//! The stagger: the anatomical humanoid standing on flat ground with
//! nothing kinematic, following first a standing animation and then a
//! walk with its joints' drives and capped world drives
//! ([`stagger_profile`]); hit on the chest, it staggers and recovers, or
//! falls. [`crate::StaggerSweep`] hits it harder and harder from every
//! side; the scene's own run (`run`) walks and takes one hit.

use glam::Vec3;
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{BuildOptions, Profile, Ragdoll, RagdollDesc, RagdollError};
use vertebra_world::{BodyDesc, World};

use crate::setup::spine_top;
use crate::{Following, Gait, SceneConfig, SceneWorld, Walk};

/// The walk's speed once its ramp is over (m/s).
pub const WALK_SPEED: f32 = 1.5;

/// When the walk starts (s): standing before.
pub const WALK_START: f32 = 1.0;

/// The scene's own run: the frame whose step its one hit precedes (5 s:
/// 2.5 s into full speed) and the hit (N s, world): from the front.
pub const STAGGER_HIT: (usize, Vec3) = (300, Vec3::new(0.0, 0.0, -40.0));

/// How the stagger's ragdoll follows its animation, standing and walking:
/// the description's `standing` profile (the anatomical humanoid's: the
/// legs and spine, which carry the weight, at 120 Hz, stiff enough under
/// either joint solve that only their 450 N m caps let a hit bend them;
/// the neck and arms at 8 Hz; every body pulled toward its pose at 2 Hz
/// with a force cap of half its weight, so it stands and walks on its
/// legs, and 20 N m; hips and chest kept upright at 2 Hz, 100 N m).
/// Refused for a description without one.
pub fn stagger_profile(desc: &RagdollDesc) -> Result<Profile, RagdollError> {
    desc.profile("standing")
        .cloned()
        .ok_or_else(|| RagdollError::OutOfRange {
            context: format!("ragdoll `{}`", desc.name),
            field: "profile",
            reason: "`standing` is missing; the stagger follows it".to_owned(),
        })
}

/// How far (m, up) `desc`'s bind pose is raised to stand with its lowest
/// point 1 mm above a ground at y = 0.
pub fn standing_lift(desc: &RagdollDesc) -> Vec3 {
    let low = (desc.bodies.iter())
        .map(|b| b.segment[0].y.min(b.segment[1].y) - b.radius)
        .fold(f32::MAX, f32::min);
    Vec3::new(0.0, 0.001 - low, 0.0)
}

/// The stagger's animation on `desc`: standing until `start` (s), then
/// walking at [`WALK_SPEED`] (infinity: standing throughout), placed as
/// the scene places its ragdoll for `seed`: its lowest point 1 mm above
/// the ground, moved and turned by the seed's perturbation.
pub fn stagger_walk(desc: &RagdollDesc, seed: u64, start: f32) -> Result<Walk, RagdollError> {
    let lift = standing_lift(desc);
    let (offset, turn) = crate::seed::perturbation(seed, 0);
    Ok(Walk::new(desc, Gait::walk(WALK_SPEED), start)?.placed(turn, lift + offset))
}

/// The scene's world: a static ground plane at y = 0 and the ragdoll at
/// its animation's first pose, following `walk` with `animation`'s
/// drives.
pub(crate) fn stagger_world(
    mut world: World,
    desc: &RagdollDesc,
    config: &SceneConfig,
    walk: Walk,
    animation: Profile,
) -> Result<SceneWorld, RagdollError> {
    let mut collisions = Collisions::new();
    let ground = world.add_body(BodyDesc::fixed())?;
    collisions.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))?;
    let pose = walk.pose(desc, 0.0)?;
    let ragdoll = Ragdoll::build(
        &mut world,
        desc,
        BuildOptions::new(config.spine),
        &pose,
        None,
    )?;
    collisions.add_ragdoll(&ragdoll)?;
    let following = Following {
        desc: desc.clone(),
        walk,
        animation,
    };
    Ok(
        SceneWorld::new(world, Some(collisions), vec![ragdoll], None, None)
            .with_following(following),
    )
}

/// The scene's own run: standing for [`WALK_START`], then walking; the
/// chest hit by [`STAGGER_HIT`].
pub(crate) fn build(
    world: World,
    desc: &RagdollDesc,
    config: &SceneConfig,
) -> Result<SceneWorld, RagdollError> {
    let walk = stagger_walk(desc, config.seed, WALK_START)?;
    let scene = stagger_world(world, desc, config, walk, stagger_profile(desc)?)?;
    let chest =
        scene.ragdolls[0].bodies[spine_top(desc)].ok_or_else(|| RagdollError::UnknownBody {
            context: "scene stagger (the body hit)".to_owned(),
            field: "body",
            name: "chest".to_owned(),
        })?;
    let (frame, impulse) = STAGGER_HIT;
    Ok(scene.with_hits(vec![(frame, chest, impulse)]))
}
