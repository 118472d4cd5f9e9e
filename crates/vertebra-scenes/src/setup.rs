//! What the scenes' builders share: a ragdoll with held hips, seeded
//! poses, the top of the spine.

use glam::{Quat, Vec3};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, RagdollError, SpineMode};
use vertebra_world::{AngularDrive, BodyDesc, BodyHandle, JointDesc, World};

/// A ragdoll at `pose` whose root body (the hips) is held where it is.
pub(crate) fn ragdoll_with_fixed_hips(
    world: &mut World,
    desc: &RagdollDesc,
    spine: SpineMode,
    pose: &Pose,
) -> Result<Ragdoll, RagdollError> {
    let ragdoll = Ragdoll::build(world, desc, BuildOptions::new(spine), pose, None)?;
    fix(
        world,
        ragdoll.bodies[desc.root].expect("the root body exists"),
    )?;
    Ok(ragdoll)
}

/// Holds `body` where it is: a static anchor and a socket with a stiff
/// drive (its error is not counted in the ragdoll's residuals).
fn fix(world: &mut World, body: BodyHandle) -> Result<(), RagdollError> {
    let at = world.body(body)?.position;
    let anchor = world.add_body(
        BodyDesc::fixed()
            .with_position(at)
            .with_orientation(world.body(body)?.orientation),
    )?;
    let pin = JointDesc::socket_at_world_anchor(world.bodies(), anchor, body, at, Vec3::Y)?
        .with_drive(AngularDrive::rigid(Quat::IDENTITY));
    world.add_joint(pin)?;
    Ok(())
}

/// `pose` moved and turned about its root by ragdoll `index`'s seeded
/// perturbation; `pose` itself, bit for bit, for seed 0.
pub(crate) fn seeded(pose: Pose, desc: &RagdollDesc, seed: u64, index: usize) -> Pose {
    if seed == 0 {
        return pose;
    }
    let (offset, turn) = crate::seed::perturbation(seed, index);
    let root = pose.bones[desc.root].0;
    pose.moved(root, turn, offset)
}

/// The top of the spine chain (the chest), or the root when there is none.
pub(crate) fn spine_top(desc: &RagdollDesc) -> usize {
    desc.spine
        .as_ref()
        .and_then(|s| s.bodies.last().copied())
        .unwrap_or(desc.root)
}
