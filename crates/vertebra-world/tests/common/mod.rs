//! Builders shared by the world's tests.
#![allow(dead_code)]

use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, BodyHandle, JointDesc, JointHandle, JointSolver, Shape, SolverConfig, World,
};

/// A capsule body of `mass` kg whose core segment runs from `top` to
/// `bottom` (world, m), radius 0.05 m, at rest with identity orientation.
pub fn capsule(world: &mut World, top: Vec3, bottom: Vec3, mass: f32) -> BodyHandle {
    let centre = (top + bottom) * 0.5;
    let shape = Shape::capsule(top - centre, bottom - centre, 0.05);
    let props = shape
        .mass_properties_with_mass(mass)
        .expect("valid capsule");
    world
        .add_body(BodyDesc::dynamic(props).with_position(centre))
        .expect("valid body")
}

/// A vertical chain of `links` capsules of `length` m hanging from a static
/// body at `top`, each joined by a socket with the twist axis down.
pub fn hanging_chain(
    world: &mut World,
    top: Vec3,
    links: usize,
    length: f32,
) -> (Vec<BodyHandle>, Vec<JointHandle>) {
    let anchor_body = world
        .add_body(BodyDesc::fixed().with_position(top))
        .expect("static body");
    let mut bodies = vec![anchor_body];
    let mut sockets = Vec::new();
    for k in 0..links {
        let upper = top - Vec3::Y * (length * k as f32);
        let lower = upper - Vec3::Y * length;
        let body = capsule(world, upper, lower, 1.0);
        let parent = *bodies.last().expect("a parent");
        let desc = JointDesc::socket_at_world_anchor(world.bodies(), parent, body, upper, -Vec3::Y)
            .expect("socket");
        sockets.push(world.add_joint(desc).expect("valid socket"));
        bodies.push(body);
    }
    (bodies, sockets)
}

/// A world with `substeps` and `iterations`, otherwise default, that
/// never sleeps: these tests measure responses to their end, and a small
/// slow oscillation or a slow return would fall asleep short of it.
pub fn world(substeps: u32, iterations: u32) -> World {
    world_with(substeps, iterations, JointSolver::default())
}

/// [`world`] with the joints solved by `joints`: the iterated solver for
/// the promises of its parts one at a time (`SolverConfig::paper`'s).
pub fn world_with(substeps: u32, iterations: u32, joints: JointSolver) -> World {
    World::new(SolverConfig {
        substeps,
        iterations,
        sleep: None,
        joints,
        ..SolverConfig::default()
    })
    .expect("valid config")
}

/// The angle (rad) between two orientations, accurate near zero (atan2 of
/// the relative quaternion; `acos` of a dot product is not).
pub fn angle_between(a: Quat, b: Quat) -> f32 {
    let r = a * b.conjugate();
    2.0 * Vec3::new(r.x, r.y, r.z).length().atan2(r.w.abs())
}
