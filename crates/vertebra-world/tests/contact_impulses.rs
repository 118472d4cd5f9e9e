//! What each contact did in a step: the impulses the world reports after
//! it (`World::solved_contacts`, `World::contact_impulses`), checked
//! against momentum: a resting box's contacts carry its weight, a landing
//! box's stop its fall, a sliding box's friction is `mu` times its normal
//! push.

use glam::{Quat, Vec3};
use vertebra_world::{BodyDesc, BodyHandle, Contact, Shape, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;
const MASS: f32 = 12.0;

fn world(substeps: u32) -> (World, BodyHandle, BodyHandle, Vec3) {
    let mut w = World::new(SolverConfig {
        substeps,
        iterations: 10,
        sleep: None,
        ..SolverConfig::default()
    })
    .unwrap();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    let half = Vec3::new(0.3, 0.2, 0.25);
    let props = Shape::Box { half_extents: half }
        .mass_properties_with_mass(MASS)
        .unwrap();
    let body = w
        .add_body(BodyDesc::dynamic(props).with_position(Vec3::new(0.0, half.y, 0.0)))
        .unwrap();
    (w, ground, body, half)
}

/// The box's four lowest corners against the plane through the origin
/// with normal `up`, within 5 cm.
fn corners(w: &World, ground: BodyHandle, body: BodyHandle, half: Vec3, up: Vec3) -> Vec<Contact> {
    let s = w.body(body).unwrap();
    (0..8)
        .map(|k| {
            let c = Vec3::new(
                if k & 1 == 0 { -half.x } else { half.x },
                if k & 2 == 0 { -half.y } else { half.y },
                if k & 4 == 0 { -half.z } else { half.z },
            );
            s.position + s.orientation * c
        })
        .filter(|p| p.dot(up) < 0.05)
        .map(|p| Contact {
            body_a: ground,
            body_b: body,
            point: p - up * (0.5 * p.dot(up)),
            normal: up,
            depth: -p.dot(up),
            friction: 0.4,
            restitution: 0.0,
        })
        .collect()
}

#[test]
fn a_resting_boxs_contacts_carry_its_weight_at_any_substep_count() {
    for substeps in [1, 4] {
        let (mut w, ground, body, half) = world(substeps);
        for frame in 0..120 {
            let contacts = corners(&w, ground, body, half, Vec3::Y);
            w.set_contacts(&contacts).unwrap();
            w.step(DT).unwrap();
            assert_eq!(w.solved_contacts(), &contacts[..], "the list set, in order");
            assert_eq!(w.contact_impulses().len(), contacts.len());
            if frame < 60 {
                continue;
            }
            let normal: f32 = w.contact_impulses().iter().map(|i| i.normal).sum();
            let weight = MASS * 9.81 * DT;
            assert!(
                (normal - weight).abs() < 0.01 * weight,
                "{substeps} substeps, frame {frame}: {normal} N s against {weight}"
            );
            // The corners may hold the box in tangential tension between
            // them (solved one after another), but on a level floor their
            // friction sums to nothing.
            assert!(w.contact_impulses().iter().all(|i| i.normal >= 0.0));
            let friction: Vec3 = w.contact_impulses().iter().map(|i| i.friction).sum();
            assert!(friction.length() < 1e-3 * weight, "{friction:?}");
        }
    }
}

#[test]
fn a_landing_boxs_contacts_stop_its_fall() {
    let (mut w, ground, body, half) = world(1);
    w.set_body_pose(body, Vec3::new(0.0, half.y + 0.04, 0.0), Quat::IDENTITY)
        .unwrap();
    w.set_body_velocity(body, Vec3::new(0.0, -3.0, 0.0), Vec3::ZERO)
        .unwrap();
    let before = w.body(body).unwrap().linear_velocity.y;
    let contacts = corners(&w, ground, body, half, Vec3::Y);
    assert_eq!(contacts.len(), 4);
    w.set_contacts(&contacts).unwrap();
    w.step(DT).unwrap();
    let after = w.body(body).unwrap().linear_velocity.y;
    let normal: f32 = w.contact_impulses().iter().map(|i| i.normal).sum();
    // Momentum: m (v1 - v0) = J - m g dt.
    let expected = MASS * (after - before) + MASS * 9.81 * DT;
    assert!(
        after > before + 2.0,
        "the contacts slowed the fall: {after} m/s"
    );
    assert!(
        (normal - expected).abs() < 1e-3 * expected,
        "{normal} N s against {expected}"
    );
}

#[test]
fn a_sliding_boxs_friction_is_mu_times_its_push() {
    // A 35 degree slope: beyond the cone of mu = 0.4, the box slides.
    let up = Quat::from_rotation_z(35f32.to_radians()) * Vec3::Y;
    let (mut w, ground, body, half) = world(1);
    let tilt = Quat::from_rotation_z(35f32.to_radians());
    w.set_body_pose(body, up * half.y, tilt).unwrap();
    for frame in 0..90 {
        let contacts = corners(&w, ground, body, half, up);
        w.set_contacts(&contacts).unwrap();
        w.step(DT).unwrap();
        if frame < 30 {
            continue;
        }
        let normal: f32 = w.contact_impulses().iter().map(|i| i.normal).sum();
        let friction: Vec3 = w.contact_impulses().iter().map(|i| i.friction).sum();
        assert!(
            friction.dot(up).abs() < 1e-4 * normal,
            "in the tangent plane"
        );
        let ratio = friction.length() / normal;
        assert!((ratio - 0.4).abs() < 0.01, "frame {frame}: mu = {ratio}");
        let weight_normal = MASS * 9.81 * DT * 35f32.to_radians().cos();
        assert!((normal - weight_normal).abs() < 0.01 * weight_normal);
        let slide = w.body(body).unwrap().linear_velocity;
        assert!(friction.dot(slide) < 0.0, "friction opposes the slide");
    }
}

#[test]
fn a_gap_that_never_closes_pushes_nothing_and_a_restore_forgets_the_step() {
    let (mut w, ground, body, _) = world(1);
    let snapshot = w.snapshot();
    w.set_body_pose(body, Vec3::new(0.0, 2.0, 0.0), Quat::IDENTITY)
        .unwrap();
    let far = Contact {
        body_a: ground,
        body_b: body,
        point: Vec3::new(0.0, 0.9, 0.0),
        normal: Vec3::Y,
        depth: -1.5,
        friction: 0.4,
        restitution: 0.0,
    };
    w.set_contacts(&[far]).unwrap();
    w.step(DT).unwrap();
    assert_eq!(w.solved_contacts().len(), 1);
    assert_eq!(w.contact_impulses()[0].normal, 0.0);
    assert_eq!(w.contact_impulses()[0].friction, Vec3::ZERO);
    let steps = w.step_count();
    w.restore(&snapshot).unwrap();
    assert!(w.solved_contacts().is_empty() && w.contact_impulses().is_empty());
    assert_eq!(w.step_count(), steps, "a restore is no step");
    w.step(DT).unwrap();
    assert!(w.solved_contacts().is_empty(), "no contacts were set");
    assert_eq!(w.step_count(), steps + 1);
}
