//! Builders shared by the world's tests.
#![allow(dead_code)]

use core::f32::consts::{PI, TAU};

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

/// `x(t)` of `x'' = -omega^2 (x - s) - 2 zeta omega x'` from rest at 0.
pub fn underdamped(t: f32, omega: f32, zeta: f32, s: f32) -> f32 {
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    let decay = (-zeta * omega * t).exp();
    s - s * decay * ((wd * t).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * t).sin())
}

/// The frequency (Hz) and damping ratio of a step response toward `s`
/// sampled every `dt` (s): the damped frequency from the spacing of its first
/// two crossings of `s` (linearly interpolated), the ratio from its first
/// two extremes' logarithmic decrement (each extreme a parabola through
/// three samples).
pub fn frequency_and_ratio(x: &[f32], s: f32, dt: f32) -> (f32, f32) {
    let e: Vec<f32> = x.iter().map(|x| x - s).collect();
    let mut crossings = Vec::new();
    for k in 1..e.len() {
        if e[k - 1].signum() != e[k].signum() && e[k - 1] != 0.0 {
            crossings.push((k as f32 + e[k - 1] / (e[k - 1] - e[k])) * dt);
        }
    }
    let mut extremes = Vec::new();
    for k in 1..e.len() - 1 {
        let (a, b, c) = (e[k - 1].abs(), e[k].abs(), e[k + 1].abs());
        if b > a && b >= c && e[k - 1].signum() == e[k + 1].signum() {
            let curvature = a - 2.0 * b + c;
            extremes.push(b - (a - c) * (a - c) / (8.0 * curvature));
        }
    }
    assert!(crossings.len() >= 2 && extremes.len() >= 2, "{e:?}");
    let damped = PI / (crossings[1] - crossings[0]);
    let decrement = (extremes[0] / extremes[1]).ln();
    let zeta = decrement / (PI * PI + decrement * decrement).sqrt();
    let omega = damped / (1.0 - zeta * zeta).sqrt();
    (omega / TAU, zeta)
}
