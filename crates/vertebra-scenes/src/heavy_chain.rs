//! A mass ratio of 1:1000 across a joint: a chain of light links hanging
//! from a fixed anchor with a heavy body at its end, held straight down
//! under gravity. Gauss-Seidel over the joints converges slowly across
//! large mass ratios (each light link is pulled back and forth between
//! its neighbours), so the iterative solve lets the chain stretch; a direct
//! solve of the whole chain does not.

use glam::Vec3;
use vertebra_ragdoll::{
    BodySpec, BuildOptions, JointSpec, Pose, Ragdoll, RagdollDesc, RagdollError,
};
use vertebra_world::{BodyDesc, JointDesc, SwingTwist, World};

use crate::setup::seeded;
use crate::{SceneConfig, SceneWorld};

/// Light links in the chain.
pub const LINKS: usize = 8;

/// Mass of each light link (kg).
pub const LINK_MASS: f32 = 1.0;

/// Mass of the body at the chain's end (kg): 1000 times a link's.
pub const HEAVY_MASS: f32 = 1000.0;

/// Length of a link's core segment (m); links are capsules of radius
/// 0.03 m, joined end to end.
const LINK_LENGTH: f32 = 0.25;

/// The heavy body: a capsule of this core length and radius (m).
const HEAVY_LENGTH: f32 = 0.3;
const HEAVY_RADIUS: f32 = 0.15;

/// Where the chain hangs from (m, world): the top of the first link.
const ANCHOR: Vec3 = Vec3::new(0.0, 3.0, 0.0);

/// The chain as a ragdoll description: links `link0` .. `link7` from the
/// top down along -Y, then `heavy`, each joined to the one above by a
/// socket without limits at their shared end.
pub fn heavy_chain() -> Result<RagdollDesc, RagdollError> {
    let end = |k: usize| ANCHOR - Vec3::Y * (LINK_LENGTH * k as f32);
    let link = |k: usize| format!("link{k}");
    let mut builder = RagdollDesc::builder("heavy chain");
    for k in 0..LINKS {
        builder = builder.body(BodySpec::capsule(
            &link(k),
            [end(k), end(k + 1)],
            0.03,
            LINK_MASS,
        ));
    }
    let top = end(LINKS);
    builder = builder.body(BodySpec::capsule(
        "heavy",
        [top, top - Vec3::Y * HEAVY_LENGTH],
        HEAVY_RADIUS,
        HEAVY_MASS,
    ));
    let children = (1..LINKS).map(link).chain(["heavy".to_owned()]);
    for (k, child) in children.enumerate() {
        builder = builder.joint(JointSpec::socket(
            &format!("joint{k}"),
            &link(k),
            &child,
            end(k + 1),
            Vec3::NEG_Y,
            SwingTwist::FREE,
        ));
    }
    builder.build()
}

/// The scene's world: `desc` (the [`heavy_chain`]) at rest, straight down,
/// its root's top end joined to a fixed anchor by a socket that counts in
/// the residual error like the chain's own joints.
pub(crate) fn build(
    mut world: World,
    desc: &RagdollDesc,
    config: &SceneConfig,
) -> Result<SceneWorld, RagdollError> {
    let pose = seeded(Pose::bind(desc), desc, config.seed, 0);
    let ragdoll = Ragdoll::build(
        &mut world,
        desc,
        BuildOptions::new(config.spine),
        &pose,
        None,
    )?;
    let root = ragdoll.bodies[desc.root].expect("the root body exists");
    let state = world.body(root)?;
    // The root's top end (its segment's first), where the seeded pose put it.
    let body = &desc.bodies[desc.root];
    let at = state.position + state.orientation * (body.segment[0] - body.centre());
    let anchor = world.add_body(BodyDesc::fixed().with_position(at))?;
    let hang = world.add_joint(JointDesc::socket_at_world_anchor(
        world.bodies(),
        anchor,
        root,
        at,
        Vec3::NEG_Y,
    )?)?;
    Ok(SceneWorld::new(world, None, vec![ragdoll], None, None).with_joints([hang]))
}
