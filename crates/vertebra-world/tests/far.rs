//! Precision far from the origin: motion, joints and contacts are as exact
//! kilometres away as at the origin, and the world's edge holds bodies in.
//!
//! Before bodies kept double-precision coordinates and the solver worked on
//! displacements, velocities were `(p - p0) / h` of absolute `f32`
//! positions: at 8 substeps a body released at y = 1.5 km never fell, and
//! a body sliding at 0.2 m/s at x = 100 km stood still.

mod common;

use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, BodyHandle, Contact, JointDesc, MAX_COORDINATE, Shape, SolverConfig, World,
};

const DT: f32 = 1.0 / 60.0;

fn world(substeps: u32, gravity: Vec3) -> World {
    World::new(SolverConfig {
        substeps,
        gravity,
        ..SolverConfig::default()
    })
    .expect("valid config")
}

fn ball(world: &mut World, position: Vec3, velocity: Vec3) -> BodyHandle {
    let mass = Shape::Sphere { radius: 0.1 }
        .mass_properties_with_mass(1.0)
        .expect("valid sphere");
    world
        .add_body(
            BodyDesc::dynamic(mass)
                .with_position(position)
                .with_velocity(velocity, Vec3::ZERO),
        )
        .expect("valid body")
}

/// From rest at every height up to the edge, at 1 and 8 substeps, a body's
/// speed after 2 s is `g t` within 0.1%, and it has fallen `g t^2 / 2`
/// (the symplectic Euler sum, within 0.1%).
#[test]
fn free_fall_is_exact_at_every_height() {
    for height in [0.0, 1.0e3, 1.0e5, 1.0e6] {
        for substeps in [1, 8] {
            let mut w = world(substeps, Vec3::new(0.0, -9.81, 0.0));
            let body = ball(&mut w, Vec3::new(0.0, height, 0.0), Vec3::ZERO);
            let steps = 120;
            for _ in 0..steps {
                w.step(DT).expect("step");
            }
            let t = steps as f32 * DT;
            let v = -w.body(body).expect("live").linear_velocity.y;
            assert!(
                (v - 9.81 * t).abs() <= 1e-3 * 9.81 * t,
                "at {height} m, {substeps} substeps: {v} m/s after {t} s"
            );
            let n = (steps * substeps) as f64;
            let h = f64::from(DT) / f64::from(substeps);
            let expected = 9.81 * h * h * n * (n + 1.0) / 2.0;
            let fallen = f64::from(height) - w.bodies().precise_position(body.index()).y;
            assert!(
                (fallen - expected).abs() <= 1e-3 * expected,
                "at {height} m, {substeps} substeps: fell {fallen} m, expected {expected}"
            );
        }
    }
}

/// At x = 100 km an `f32` resolves 7.8 mm; a body sliding 3.3 mm a step
/// keeps sliding: its velocity stays 0.2 m/s and it covers 2 m in 10 s.
#[test]
fn a_slow_body_keeps_sliding_far_away() {
    for substeps in [1, 8] {
        let mut w = world(substeps, Vec3::ZERO);
        let start = Vec3::new(1.0e5, 0.0, 0.0);
        let body = ball(&mut w, start, Vec3::new(0.2, 0.0, 0.0));
        for _ in 0..600 {
            w.step(DT).expect("step");
        }
        let state = w.body(body).expect("live");
        assert!((state.linear_velocity.x - 0.2).abs() < 1e-5, "{state:?}");
        let covered = w.bodies().precise_position(body.index()).x - 1.0e5;
        assert!((covered - 2.0).abs() < 1e-3, "covered {covered} m");
        // The f32 coordinate the API reports follows to within its own
        // resolution.
        assert!((state.position.x - 100_002.0).abs() <= 0.004, "{state:?}");
    }
}

/// A box on frictionless ground at x = 100 km, the ground body at the
/// origin (its contact point 100 km from its centre): the box rests at the
/// same height as at the origin and keeps sliding.
#[test]
fn a_box_slides_on_frictionless_ground_far_from_the_grounds_centre() {
    let rest = |x: f32| {
        let mut w = world(1, Vec3::new(0.0, -9.81, 0.0));
        let ground = w.add_body(BodyDesc::fixed()).expect("ground");
        let half = 0.25;
        let mass = Shape::Box {
            half_extents: Vec3::splat(half),
        }
        .mass_properties_with_mass(5.0)
        .expect("valid box");
        let body = w
            .add_body(
                BodyDesc::dynamic(mass)
                    .with_position(Vec3::new(x, half, 0.0))
                    .with_velocity(Vec3::new(0.2, 0.0, 0.0), Vec3::ZERO),
            )
            .expect("box");
        for _ in 0..600 {
            let state = w.body(body).expect("live");
            let bottom = state.position - Vec3::Y * half;
            w.set_contacts(&[Contact {
                body_a: ground,
                body_b: body,
                point: Vec3::new(bottom.x, 0.5 * bottom.y, bottom.z),
                normal: Vec3::Y,
                depth: -bottom.y,
                friction: 0.0,
                restitution: 0.0,
            }])
            .expect("valid contact");
            w.step(DT).expect("step");
        }
        let precise = w.bodies().precise_position(body.index());
        let state = w.body(body).expect("live");
        (precise.x - f64::from(x), precise.y, state.linear_velocity)
    };
    let (near_x, near_y, near_v) = rest(0.0);
    let (far_x, far_y, far_v) = rest(1.0e5);
    assert!((near_x - 2.0).abs() < 1e-3, "{near_x}");
    assert!((far_x - near_x).abs() < 1e-3, "{far_x} vs {near_x}");
    assert!((far_y - near_y).abs() < 1e-4, "{far_y} vs {near_y}");
    assert!((far_v - near_v).length() < 1e-4, "{far_v} vs {near_v}");
}

/// A swinging chain of sockets keeps its joints as tight at 100 km on
/// every axis as at the origin.
#[test]
fn joints_hold_as_tight_far_away_as_at_the_origin() {
    let error = |origin: Vec3| {
        let mut w = world(1, Vec3::new(0.0, -9.81, 0.0));
        let (bodies, _) = common::hanging_chain(&mut w, origin, 4, 0.4);
        let last = *bodies.last().expect("links");
        w.set_body_velocity(last, Vec3::new(3.0, 0.0, 1.0), Vec3::ZERO)
            .expect("push");
        let mut worst = 0.0f32;
        for _ in 0..120 {
            w.step(DT).expect("step");
            worst = worst.max(w.measure_residuals().eps_lin_cm);
        }
        worst
    };
    let near = error(Vec3::ZERO);
    let far = error(Vec3::splat(1.0e5));
    assert!(near < 0.5, "{near} cm at the origin");
    assert!(far < 1.1 * near, "{far} cm far away, {near} cm near");
}

/// The world's edge is a wall: a body flying out stops at
/// `MAX_COORDINATE`, its outward velocity gone and the rest kept, and the
/// API still accepts its pose and the contacts on its surface.
#[test]
fn the_edge_holds_bodies_inside_and_keeps_them_usable() {
    let mut w = world(1, Vec3::ZERO);
    let edge = MAX_COORDINATE;
    let body = ball(
        &mut w,
        Vec3::new(edge - 1.0, 0.0, 0.0),
        Vec3::new(100.0, 3.0, 0.0),
    );
    let other = ball(&mut w, Vec3::new(edge - 0.5, 1.0, 0.0), Vec3::ZERO);
    for _ in 0..60 {
        w.step(DT).expect("step");
    }
    let state = w.body(body).expect("live");
    assert_eq!(state.position.x, edge);
    assert_eq!(state.linear_velocity.x, 0.0);
    assert_eq!(state.linear_velocity.y, 3.0);
    w.set_body_pose(body, state.position, Quat::IDENTITY)
        .expect("a pose at the edge is accepted");
    w.set_contacts(&[Contact {
        body_a: other,
        body_b: body,
        point: state.position + Vec3::X * 0.1,
        normal: Vec3::X,
        depth: 0.0,
        friction: 0.5,
        restitution: 0.0,
    }])
    .expect("a contact on its surface, past the edge, is accepted");
    w.step(DT).expect("step");
    assert!(w.bodies().is_finite(body.index()));
}

/// A socket to a static body whose anchor lies 100 km from the static
/// body's centre holds as tightly as one whose anchor is at the centre.
#[test]
fn a_far_anchor_on_a_static_body_holds() {
    let error = |ground_at: Vec3| {
        let mut w = world(1, Vec3::new(0.0, -9.81, 0.0));
        let top = Vec3::new(1.0e5, 10.0, 0.0);
        let ground = w
            .add_body(BodyDesc::fixed().with_position(ground_at))
            .expect("ground");
        let bob = common::capsule(&mut w, top, top - Vec3::Y * 0.5, 1.0);
        w.set_body_velocity(bob, Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO)
            .expect("push");
        let socket = JointDesc::socket_at_world_anchor(w.bodies(), ground, bob, top, -Vec3::Y)
            .expect("socket");
        w.add_joint(socket).expect("valid socket");
        let mut worst = 0.0f32;
        for _ in 0..120 {
            w.step(DT).expect("step");
            worst = worst.max(w.measure_residuals().eps_lin_cm);
        }
        worst
    };
    let near = error(Vec3::new(1.0e5, 10.0, 0.0));
    let far = error(Vec3::ZERO);
    assert!(near < 0.01, "{near} cm");
    assert!(
        far < 1.1 * near + 1e-6,
        "{far} cm with the anchor far from its body"
    );
}

/// A box released 1.56 mm over the ground (the contact fed exactly, from
/// the box's double-precision coordinate) settles onto it at 100 km and at
/// the edge as at the origin: the contact's gap is not rounded to the
/// coordinates' last digit (it hovered 1.6 mm up at 100 km, 2.5 cm up at
/// 1,000 km).
#[test]
fn a_small_gap_closes_far_away() {
    let settle = |origin: Vec3| {
        let mut w = world(1, Vec3::new(0.0, -9.81, 0.0));
        let ground = w
            .add_body(BodyDesc::fixed().with_position(origin))
            .expect("ground");
        let mass = Shape::Box {
            half_extents: Vec3::splat(0.1),
        }
        .mass_properties_with_mass(1.0)
        .expect("valid box");
        let start = origin + Vec3::new(0.0, 0.1015625, 0.0);
        let body = w
            .add_body(BodyDesc::dynamic(mass).with_position(start))
            .expect("box");
        for _ in 0..120 {
            let y = w.bodies().precise_position(body.index()).y;
            w.set_contacts(&[Contact {
                body_a: ground,
                body_b: body,
                point: origin,
                normal: Vec3::Y,
                depth: (f64::from(origin.y) - (y - 0.1)) as f32,
                friction: 0.0,
                restitution: 0.0,
            }])
            .expect("valid contact");
            w.step(DT).expect("step");
        }
        w.bodies().precise_position(body.index()).y - f64::from(origin.y)
    };
    let near = settle(Vec3::ZERO);
    assert!((near - 0.1).abs() < 1e-4, "{near} m at the origin");
    for origin in [Vec3::new(0.0, 1.0e5, 0.0), Vec3::new(0.0, -999_999.0, 0.0)] {
        let far = settle(origin);
        assert!(
            (far - near).abs() < 1e-4,
            "{far} m at {origin}, {near} m at the origin"
        );
    }
}
