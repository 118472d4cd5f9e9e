//! Contact events per pair of bodies: one `began` when a pair first
//! pushes, one `ended` when it parts, none while it rests or sleeps; with
//! the impulse and the speed of the hit, the ragdoll and bone; saved with
//! the set.

use glam::{Quat, Vec3};
use vertebra_collide::{Collider, ColliderShape, Collisions, ContactEvents};
use vertebra_ragdoll::{BuildOptions, Pose, RagdollDesc, SpineMode};
use vertebra_world::{BodyDesc, BodyHandle, Error, Shape, SleepSettings, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;
const MASS: f32 = 8.0;

fn world(sleep: bool) -> (World, Collisions, BodyHandle) {
    let config = SolverConfig {
        iterations: 8,
        sleep: sleep.then(SleepSettings::default),
        ..SolverConfig::default()
    };
    let mut w = World::new(config).unwrap();
    let mut c = Collisions::new();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    (w, c, ground)
}

fn drop_box(w: &mut World, c: &mut Collisions, height: f32) -> BodyHandle {
    let shape = Shape::Box {
        half_extents: Vec3::new(0.2, 0.1, 0.15),
    };
    let props = shape.mass_properties_with_mass(MASS).unwrap();
    let body = w
        .add_body(BodyDesc::dynamic(props).with_position(Vec3::new(0.0, height, 0.0)))
        .unwrap();
    c.add(Collider::new(body, ColliderShape::Solid(shape)))
        .unwrap();
    body
}

/// (began, ended) counts of the last step.
fn counts(e: &ContactEvents) -> (usize, usize) {
    (e.began().len(), e.ended().len())
}

#[test]
fn a_dropped_box_begins_once_with_its_hit_rests_silently_and_ends_once() {
    let (mut w, mut c, ground) = world(false);
    let body = drop_box(&mut w, &mut c, 1.0);
    let mut began = Vec::new();
    for frame in 0..150 {
        let falling = w.body(body).unwrap().linear_velocity.y;
        c.step(&mut w, DT).unwrap();
        let e = c.events();
        assert!(e.ended().is_empty(), "frame {frame}: {:?}", e.ended());
        for hit in e.began() {
            began.push((frame, *hit, falling));
        }
        if !began.is_empty() {
            assert_eq!(
                e.touching().len(),
                1,
                "frame {frame}: touching while resting"
            );
        }
    }
    assert_eq!(began.len(), 1, "{began:?}");
    let (_, hit, falling) = began[0];
    assert_eq!((hit.body_a, hit.body_b), (ground, body));
    assert_eq!((hit.part_a, hit.part_b), (None, None));
    assert!((hit.normal - Vec3::Y).length() < 1e-4, "out of the ground");
    // It fell 0.9 m: about 4.2 m/s when it struck, and the floor's impulse
    // stopped it (m v, up to a step of gravity and the closing at
    // detection).
    let speed = (2.0 * 9.81 * 0.9f32).sqrt();
    assert!(
        (hit.closing_speed - speed).abs() < 0.3,
        "{} m/s",
        hit.closing_speed
    );
    assert!(
        hit.impulse > 0.8 * MASS * -falling && hit.impulse < 1.2 * MASS * speed,
        "{} N s for {} m/s",
        hit.impulse,
        -falling
    );
    // Lifted away: the pair ends, once.
    w.set_body_pose(body, Vec3::new(0.0, 5.0, 0.0), Quat::IDENTITY)
        .unwrap();
    c.step(&mut w, DT).unwrap();
    assert_eq!(counts(c.events()), (0, 1));
    assert_eq!(c.events().ended()[0].body_b, body);
    c.step(&mut w, DT).unwrap();
    assert_eq!(counts(c.events()), (0, 0));
}

#[test]
fn a_sleeping_pair_stays_touching_and_a_removed_body_ends_its_pairs() {
    let (mut w, mut c, _) = world(true);
    let body = drop_box(&mut w, &mut c, 0.3);
    let mut total = (0, 0);
    for _ in 0..300 {
        c.step(&mut w, DT).unwrap();
        let (b, e) = counts(c.events());
        total = (total.0 + b, total.1 + e);
    }
    assert!(w.is_asleep(body).unwrap(), "it fell asleep");
    assert_eq!(total, (1, 0), "one hit, no end while asleep");
    assert!(
        c.events().touching().is_empty(),
        "nothing solved while asleep"
    );
    c.remove_body(body);
    w.remove_body(body).unwrap();
    c.step(&mut w, DT).unwrap();
    assert_eq!(counts(c.events()), (0, 1));
    assert_eq!(c.events().ended()[0].body_b, body);
}

#[test]
fn a_ragdolls_hits_name_its_bones() {
    let (mut w, mut c, ground) = world(false);
    let desc = RagdollDesc::reference_humanoid();
    // Lying face down half a metre above the ground.
    let lying = Quat::from_rotation_x(core::f32::consts::FRAC_PI_2);
    let pose = Pose::bind(&desc).moved(Vec3::new(0.0, 1.0, 0.0), lying, Vec3::new(0.0, 0.7, 0.0));
    let ragdoll = c
        .build_ragdoll(
            &mut w,
            &desc,
            BuildOptions::new(SpineMode::Rod),
            &pose,
            None,
        )
        .unwrap();
    let mut bones = Vec::new();
    for _ in 0..90 {
        c.step(&mut w, DT).unwrap();
        for hit in c.events().began() {
            if hit.body_a == ground {
                let part = hit.part_b.expect("a ragdoll's body");
                assert_eq!(part.ragdoll, ragdoll.first_body().unwrap());
                assert_eq!(ragdoll.bodies[part.bone as usize], Some(hit.body_b));
                assert!(hit.impulse > 0.0 && hit.closing_speed > 1.0, "{hit:?}");
                bones.push(desc.bodies[part.bone as usize].name.clone());
            }
        }
    }
    for bone in ["chest", "head", "hips"] {
        assert!(
            bones.iter().any(|b| b == bone),
            "{bone} hit the floor: {bones:?}"
        );
    }
}

#[test]
fn restored_sets_give_the_events_the_original_gave() {
    let run = |restore_at: Option<usize>| {
        let (mut w, mut c, _) = world(true);
        for k in 0..4 {
            drop_box(&mut w, &mut c, 0.4 + 0.3 * k as f32);
        }
        let mut saved = None;
        let mut log = Vec::new();
        for frame in 0..120 {
            if frame == 60 {
                saved = Some((w.snapshot(), c.snapshot(&w).unwrap()));
            }
            c.step(&mut w, DT).unwrap();
            let e = c.events();
            log.push(format!(
                "{:?} {:?} {:?}",
                e.began(),
                e.ended(),
                e.touching()
            ));
        }
        if let Some(at) = restore_at {
            let (world, set) = saved.unwrap();
            w.restore(&world).unwrap();
            c.restore(&set, &w).unwrap();
            for (frame, then) in log.iter().enumerate().skip(at) {
                c.step(&mut w, DT).unwrap();
                let e = c.events();
                let now = format!("{:?} {:?} {:?}", e.began(), e.ended(), e.touching());
                assert_eq!(&now, then, "frame {frame}");
            }
        }
        log
    };
    let log = run(Some(60));
    assert!(
        log.iter()
            .any(|l| l.contains("ContactEnded") || l.contains("Touching"))
    );
}

#[test]
fn after_step_refuses_a_step_its_contacts_were_not_found_for() {
    let (mut w, mut c, _) = world(false);
    drop_box(&mut w, &mut c, 0.1);
    c.step(&mut w, DT).unwrap();
    let hash = w.state_hash();
    // Twice for one step.
    assert!(matches!(c.after_step(&mut w), Err(Error::WorldMismatch(_))));
    // After a step fed nothing.
    w.step(DT).unwrap();
    let hash_after = w.state_hash();
    assert_ne!(hash, hash_after);
    assert!(matches!(c.after_step(&mut w), Err(Error::WorldMismatch(_))));
    assert_eq!(w.state_hash(), hash_after, "refused, nothing changed");
    // A time step the world refuses: refused before anything changes.
    let before = w.state_hash();
    assert!(c.step(&mut w, 2.0).is_err());
    assert!(c.step(&mut w, f32::NAN).is_err());
    assert_eq!(w.state_hash(), before);
    assert!(w.contacts().is_empty());
}
