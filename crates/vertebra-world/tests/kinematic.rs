//! Kinematic bodies at run time: a body switched between dynamic and
//! kinematic keeps its mass and its velocity, and a kinematic body moved
//! to a pose over a step arrives there and carries what is jointed to it or
//! rests on it.

mod common;

use common::capsule;
use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, BodyHandle, BodyKind, Contact, JointDesc, MassProperties, Shape, SolverConfig, World,
};

const DT: f32 = 1.0 / 60.0;

fn world(gravity: Vec3, substeps: u32) -> World {
    World::new(SolverConfig {
        gravity,
        substeps,
        iterations: 10,
        ..SolverConfig::default()
    })
    .unwrap()
}

fn ball(mass: f32) -> MassProperties {
    Shape::Sphere { radius: 0.1 }
        .mass_properties_with_mass(mass)
        .unwrap()
}

/// The angle (rad) between two orientations (from the sine of its half,
/// which resolves small angles where the cosine does not).
fn angle(a: Quat, b: Quat) -> f32 {
    let turn = (a * b.conjugate()).normalize();
    2.0 * turn.xyz().length().min(1.0).asin()
}

/// A falling ball made kinematic stops feeling gravity and moves on at the
/// velocity it had, exactly (`x + n v dt`); made dynamic again it has its
/// own mass (its inverse the bits a fresh body of that mass has) and
/// gravity takes it from its velocity (`v + g dt` after one step).
#[test]
fn a_body_made_kinematic_coasts_and_made_dynamic_falls_on_with_its_own_mass() {
    let g = Vec3::new(0.0, -9.81, 0.0);
    let mut w = world(g, 4);
    let v0 = Vec3::new(1.5, 2.0, -0.5);
    let body = w
        .add_body(BodyDesc::dynamic(ball(3.0)).with_velocity(v0, Vec3::new(0.0, 2.0, 0.0)))
        .unwrap();
    let fresh = w.add_body(BodyDesc::dynamic(ball(3.0))).unwrap();
    for _ in 0..10 {
        w.step(DT).unwrap();
    }
    let before = w.body(body).unwrap();
    w.set_body_kind(body, BodyKind::Kinematic).unwrap();
    let i = body.index();
    assert_eq!(w.bodies().kind[i], BodyKind::Kinematic);
    assert_eq!(w.bodies().mass[i], 3.0, "the mass is kept");
    assert_eq!(
        w.bodies().inverse_mass[i],
        0.0,
        "infinite mass while kinematic"
    );
    assert_eq!(w.body(body).unwrap(), before, "the switch moves nothing");
    let steps = 30;
    for _ in 0..steps {
        w.step(DT).unwrap();
    }
    let coasted = w.body(body).unwrap();
    assert_eq!(coasted.linear_velocity, before.linear_velocity);
    assert_eq!(coasted.angular_velocity, before.angular_velocity);
    let expected = before.position + before.linear_velocity * (steps as f32 * DT);
    let off = (coasted.position - expected).length();
    eprintln!("kinematic coast: {off:.2e} m off x + n v dt");
    assert!(off < 1e-5, "{off}");

    w.set_body_kind(body, BodyKind::Dynamic).unwrap();
    let j = fresh.index();
    assert_eq!(
        w.bodies().inverse_mass[i].to_bits(),
        w.bodies().inverse_mass[j].to_bits()
    );
    assert_eq!(w.bodies().inverse_inertia[i], w.bodies().inverse_inertia[j]);
    w.step(DT).unwrap();
    let fell = w.body(body).unwrap();
    let off = (fell.linear_velocity - (coasted.linear_velocity + g * DT)).length();
    eprintln!("made dynamic: velocity {off:.2e} m/s off v + g dt");
    assert!(off < 1e-5, "{off}");
}

/// A body created kinematic with a mass becomes dynamic with that mass.
#[test]
fn a_kinematic_body_created_with_a_mass_becomes_dynamic_with_it() {
    let mut w = world(Vec3::ZERO, 1);
    let body = w
        .add_body(BodyDesc::kinematic().with_mass(ball(2.0)))
        .unwrap();
    assert_eq!(w.bodies().mass[body.index()], 2.0);
    assert_eq!(w.bodies().inverse_mass[body.index()], 0.0);
    w.set_body_kind(body, BodyKind::Dynamic).unwrap();
    assert_eq!(w.bodies().inverse_mass[body.index()], 0.5);
    w.apply_impulse(body, Vec3::X).unwrap();
    assert_eq!(
        w.body(body).unwrap().linear_velocity,
        Vec3::new(0.5, 0.0, 0.0)
    );
}

/// `move_kinematic` then one step puts the body on the target pose, from
/// near the origin and far from it, at one and at several substeps, for
/// turns up to nearly half a turn.
#[test]
fn move_kinematic_arrives_at_the_target_pose_after_the_step() {
    let mut worst = (0.0f32, 0.0f32);
    for substeps in [1, 4, 7] {
        for origin in [Vec3::ZERO, Vec3::new(2.0e4, -300.0, 1.0e3)] {
            let mut w = world(Vec3::new(0.0, -9.81, 0.0), substeps);
            let body = w
                .add_body(BodyDesc::kinematic().with_position(origin))
                .unwrap();
            for k in 0..20 {
                let t = k as f32 * 0.37;
                let position =
                    origin + Vec3::new(t.sin(), 0.2 * t, (1.3 * t).cos()) * (1.0 + 0.1 * t);
                let orientation =
                    Quat::from_euler(glam::EulerRot::YXZ, 0.4 * t, 0.9 * t.sin(), 0.1 * t);
                w.move_kinematic(body, position, orientation, DT).unwrap();
                w.step(DT).unwrap();
                let s = w.body(body).unwrap();
                worst.0 = worst.0.max((s.position - position).length());
                worst.1 = worst.1.max(angle(s.orientation, orientation));
            }
        }
    }
    eprintln!(
        "move_kinematic: worst miss {:.2e} m, {:.2e} rad",
        worst.0, worst.1
    );
    assert!(worst.0 < 1e-5 && worst.1 < 1e-5, "{worst:?}");
}

/// A dynamic body held by a fixed joint to a kinematic carrier that moves
/// and turns along a path is carried rigidly: it stays at its place in the
/// carrier's frame and moves at the carrier's `v + w x r`.
#[test]
fn a_body_jointed_to_a_moving_kinematic_body_is_carried() {
    let mut w = world(Vec3::ZERO, 4);
    let carrier = w.add_body(BodyDesc::kinematic()).unwrap();
    let offset = Vec3::new(0.0, -0.5, 0.2);
    let bob = capsule(&mut w, offset + 0.1 * Vec3::Y, offset - 0.1 * Vec3::Y, 2.0);
    let joint = JointDesc::fixed_at(w.bodies(), carrier, bob, Vec3::new(0.0, -0.4, 0.2)).unwrap();
    w.add_joint(joint).unwrap();
    let (mut worst_place, mut worst_speed) = (0.0f32, 0.0f32);
    for k in 1..=240 {
        let t = k as f32 * DT;
        let position = Vec3::new(t, 0.3 * t * t, -0.5 * t);
        let orientation = Quat::from_rotation_y(0.8 * t) * Quat::from_rotation_x(0.3 * t);
        w.move_kinematic(carrier, position, orientation, DT)
            .unwrap();
        w.step(DT).unwrap();
        let (c, b) = (w.body(carrier).unwrap(), w.body(bob).unwrap());
        let r = c.orientation * offset;
        let carried = c.linear_velocity + c.angular_velocity.cross(r);
        if k > 10 {
            worst_place = worst_place.max((b.position - (c.position + r)).length());
            worst_speed =
                worst_speed.max((b.linear_velocity - carried).length() / carried.length());
        }
    }
    eprintln!(
        "carried by a fixed joint: place {worst_place:.2e} m, velocity {:.3}% off v + w x r",
        100.0 * worst_speed
    );
    assert!(worst_place < 1e-4, "{worst_place}");
    assert!(worst_speed < 0.01, "{worst_speed}");
}

/// Contacts between a box and the top face (y = `top`) of a platform: its
/// corners below 1 cm above it.
fn resting_contacts(
    w: &World,
    platform: BodyHandle,
    body: BodyHandle,
    half: Vec3,
    top: f32,
) -> Vec<Contact> {
    let s = w.body(body).unwrap();
    (0..8)
        .map(|k| {
            let corner = Vec3::new(
                if k & 1 == 0 { -half.x } else { half.x },
                if k & 2 == 0 { -half.y } else { half.y },
                if k & 4 == 0 { -half.z } else { half.z },
            );
            s.position + s.orientation * corner
        })
        .filter(|p| p.y - top < 0.01)
        .map(|p| Contact {
            body_a: platform,
            body_b: body,
            point: p - Vec3::Y * (0.5 * (p.y - top)),
            normal: Vec3::Y,
            depth: top - p.y,
            friction: 0.8,
            restitution: 0.0,
        })
        .collect()
}

/// A box resting on a kinematic platform that speeds up to 1 m/s (at
/// 2 m/s^2, below the friction's `mu g` = 7.8 m/s^2) moves with it: its
/// velocity matches the platform's and it keeps its place on it.
#[test]
fn a_box_resting_on_a_moving_kinematic_platform_is_carried() {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0), 4);
    let plate_half = Vec3::new(2.0, 0.1, 2.0);
    let platform = w
        .add_body(BodyDesc::kinematic().with_position(Vec3::new(0.0, -0.1, 0.0)))
        .unwrap();
    let half = Vec3::new(0.3, 0.2, 0.25);
    let props = Shape::Box { half_extents: half }
        .mass_properties(500.0)
        .unwrap();
    let body = w
        .add_body(BodyDesc::dynamic(props).with_position(Vec3::new(0.0, half.y, 0.0)))
        .unwrap();
    let (mut x, mut v) = (0.0f32, 0.0f32);
    let mut places = Vec::new();
    let mut worst_speed = 0.0f32;
    for frame in 0..180 {
        v = (v + 2.0 * DT).min(1.0);
        x += v * DT;
        let p = w.body(platform).unwrap().position;
        let contacts = resting_contacts(&w, platform, body, half, p.y + plate_half.y);
        w.set_contacts(&contacts).unwrap();
        w.move_kinematic(platform, Vec3::new(x, -0.1, 0.0), Quat::IDENTITY, DT)
            .unwrap();
        w.step(DT).unwrap();
        let (b, p) = (w.body(body).unwrap(), w.body(platform).unwrap());
        if frame >= 30 {
            places.push(b.position.x - p.position.x);
            worst_speed = worst_speed.max((b.linear_velocity.x - p.linear_velocity.x).abs());
        }
    }
    let slip = places
        .iter()
        .fold(0.0f32, |m, &d| m.max((d - places[0]).abs()));
    eprintln!(
        "box on a platform: slip {:.3} mm, velocity off by at most {worst_speed:.2e} m/s",
        slip * 1e3
    );
    assert!(slip < 1e-3, "{slip}");
    assert!(worst_speed < 0.02, "{worst_speed}");
}

/// A swinging chain hanging from a static base whose links are switched
/// to kinematic (and held) and back mid-run (two neighbouring links
/// kinematic at once, so one socket joins two kinematic bodies, and a
/// pending contact loses its dynamic body): every joint holds, the
/// snapshot carries the kinds and is restored, and the restored copy
/// steps on to the same bits.
#[test]
fn kinds_switched_mid_run_survive_a_snapshot_and_keep_the_joints() {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0), 4);
    let (links, _) = common::hanging_chain(&mut w, Vec3::new(0.0, 3.0, 0.0), 5, 0.3);
    let mut restored = world(Vec3::new(0.0, -9.81, 0.0), 4);
    w.apply_impulse(links[5], Vec3::new(2.0, 0.0, 1.0)).unwrap();
    let mut worst = 0.0f32;
    for frame in 0..120 {
        match frame {
            20 => {
                // A contact set while the link was dynamic, pending as it
                // turns kinematic: the snapshot must take it too.
                let gap = Contact {
                    body_a: links[0],
                    body_b: links[2],
                    point: Vec3::new(0.0, 2.0, 0.0),
                    normal: Vec3::Y,
                    depth: -0.5,
                    friction: 0.5,
                    restitution: 0.0,
                };
                w.set_contacts(&[gap]).unwrap();
                // Held where they are: a kinematic body coasting on at its
                // velocity would tear the chain.
                for link in [links[2], links[3]] {
                    w.set_body_kind(link, BodyKind::Kinematic).unwrap();
                    w.set_body_velocity(link, Vec3::ZERO, Vec3::ZERO).unwrap();
                }
                restored.restore(&w.snapshot()).unwrap();
                assert_eq!(restored.state_hash(), w.state_hash());
                assert_eq!(restored.contacts().len(), 1);
                let kind = restored.bodies().kind[links[3].index()];
                assert_eq!(kind, BodyKind::Kinematic);
            }
            80 => w.set_body_kind(links[2], BodyKind::Dynamic).unwrap(),
            _ => {}
        }
        if frame == 80 {
            restored.set_body_kind(links[2], BodyKind::Dynamic).unwrap();
        }
        w.step(DT).unwrap();
        if frame >= 20 {
            restored.step(DT).unwrap();
            assert_eq!(restored.state_hash(), w.state_hash(), "frame {frame}");
        }
        worst = worst.max(w.measure_residuals().eps_lin_cm);
    }
    eprintln!("chain with kinds switched: worst joint error {worst:.3} cm");
    assert!(worst < 0.2, "{worst}");
    assert_eq!(w.bodies().kind[links[3].index()], BodyKind::Kinematic);
    assert_eq!(w.bodies().inverse_mass[links[3].index()], 0.0);
}
