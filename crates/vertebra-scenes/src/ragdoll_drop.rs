//! Figures 1 and 8 (right): 30 ragdolls dropped into a pit.

use glam::{Quat, Vec3};
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_math::{PortableQuat, trig};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, RagdollError, SpineMode};
use vertebra_world::{BodyDesc, Shape, World};

use crate::setup::seeded;
use crate::{SceneConfig, SceneWorld};

/// The scene's world: [`ragdoll_drop`] with `config`'s ragdolls and seed.
pub(crate) fn build(
    world: World,
    desc: &RagdollDesc,
    config: &SceneConfig,
) -> Result<SceneWorld, RagdollError> {
    let (world, collisions, ragdolls) =
        ragdoll_drop(world, desc, config.spine, config.ragdolls, config.seed)?;
    Ok(SceneWorld::new(
        world,
        Some(collisions),
        ragdolls,
        None,
        None,
    ))
}

/// Ragdolls per pit in [`ragdoll_drop`]: the paper's figure.
pub const RAGDOLLS_PER_PIT: usize = 30;

/// Distance (m) between the centres of neighbouring pits along +X.
const PIT_SPACING: f32 = 4.0;

/// The paper's ragdoll-drop world for `count` ragdolls: ground with its top
/// at y = 0 and, per 30 ragdolls, a pit (the first centred on the origin,
/// the next 4 m further along +X each): four static walls (inner faces at
/// x, z = +-1.5 about the pit's centre, 1 m tall, 0.1 m thick) and three
/// static boxes of half-extents (0.3, 0.15, 0.3). A pit's ragdolls lie face
/// down in 10 layers of 3, layer `j` turned by 37 j degrees about +Y, hips
/// at (0, 1 + 0.5 j, 0) + (i - 1) 0.6 u_j from its centre. A ragdoll's
/// jointed pairs never collide. With 30 and seed 0 this is exactly the
/// paper's scene; another seed moves each ragdoll by at most 1 mm and 0.1
/// degree ([`crate::seed`]).
pub fn ragdoll_drop(
    mut world: World,
    desc: &RagdollDesc,
    spine: SpineMode,
    count: usize,
    seed: u64,
) -> Result<(World, Collisions, Vec<Ragdoll>), RagdollError> {
    let mut collisions = Collisions::new();
    let mut fixed = |world: &mut World,
                     at: Vec3,
                     turn: Quat,
                     shape: ColliderShape|
     -> Result<(), RagdollError> {
        let body = world.add_body(BodyDesc::fixed().with_position(at).with_orientation(turn))?;
        collisions.add(Collider::new(body, shape))?;
        Ok(())
    };
    fixed(
        &mut world,
        Vec3::ZERO,
        Quat::IDENTITY,
        ColliderShape::Plane(Vec3::Y),
    )?;
    let pits = count.div_ceil(RAGDOLLS_PER_PIT);
    let centre = |pit: usize| Vec3::X * (PIT_SPACING * pit as f32);
    for pit in 0..pits {
        let half_box = Vec3::new(0.3, 0.15, 0.3);
        let walls = [
            (Vec3::new(1.55, 0.5, 0.0), Vec3::new(0.05, 0.5, 1.6), 0.0),
            (Vec3::new(-1.55, 0.5, 0.0), Vec3::new(0.05, 0.5, 1.6), 0.0),
            (Vec3::new(0.0, 0.5, 1.55), Vec3::new(1.6, 0.5, 0.05), 0.0),
            (Vec3::new(0.0, 0.5, -1.55), Vec3::new(1.6, 0.5, 0.05), 0.0),
        ];
        let boxes = [
            (Vec3::new(0.6, 0.15, 0.6), half_box, 0.0f32),
            (Vec3::new(-0.7, 0.25, -0.2), half_box, 30f32.to_radians()),
            (Vec3::new(0.2, 0.1, -0.8), half_box, 0.0),
        ];
        for (at, half, turn) in walls.into_iter().chain(boxes) {
            fixed(
                &mut world,
                centre(pit) + at,
                Quat::from_rotation_y_portable(turn),
                ColliderShape::Solid(Shape::Box { half_extents: half }),
            )?;
        }
    }
    let hips = desc.bodies[desc.root].centre();
    let mut ragdolls = Vec::new();
    for index in 0..count {
        let (pit, k) = (index / RAGDOLLS_PER_PIT, index % RAGDOLLS_PER_PIT);
        let (layer, slot) = (k / 3, k % 3);
        let yaw = (37.0 * layer as f32).to_radians();
        let turn = Quat::from_rotation_y_portable(yaw)
            .mul_portable(Quat::from_rotation_x_portable(std::f32::consts::FRAC_PI_2));
        let u = Vec3::new(trig::cos(yaw), 0.0, -trig::sin(yaw));
        let at = centre(pit)
            + Vec3::new(0.0, 1.0 + 0.5 * layer as f32, 0.0)
            + u * (0.6 * (slot as f32 - 1.0));
        let pose = seeded(
            Pose::bind(desc).moved(hips, turn, at - hips),
            desc,
            seed,
            index,
        );
        let ragdoll = Ragdoll::build(&mut world, desc, BuildOptions::new(spine), &pose, None)?;
        collisions.add_ragdoll(&ragdoll)?;
        ragdolls.push(ragdoll);
    }
    Ok((world, collisions, ragdolls))
}
