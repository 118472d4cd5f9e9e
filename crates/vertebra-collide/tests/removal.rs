//! Removal and bookkeeping: colliders go with their bodies and ragdolls, a
//! refused call changes nothing, and the set is saved and restored with
//! the world, bit for bit, from bytes that are checked as untrusted input.

use glam::{Quat, Vec3};
use vertebra_collide::{
    Collider, ColliderShape, CollisionSnapshot, Collisions, MAX_COLLIDER_EXTENT, RagdollPart,
};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, RagdollError, SpineMode};
use vertebra_world::{BodyDesc, BodyHandle, Error, JointDesc, Shape, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

fn step(w: &mut World, c: &Collisions) {
    let contacts = c.find_contacts(w, DT).unwrap();
    w.set_contacts(&contacts).unwrap();
    w.step(DT).unwrap();
}

/// A static ground plane, a box on it and a turned one just above it (a
/// restitution of 0.25 on both); the ground and the first box are an
/// excluded pair.
fn boxes() -> (World, Collisions, [BodyHandle; 3]) {
    let mut w = World::new(SolverConfig::default()).unwrap();
    let mut c = Collisions::new();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    let shape = Shape::Box {
        half_extents: Vec3::new(0.3, 0.2, 0.25),
    };
    let mut cube = |at: Vec3, turn: f32| {
        let desc = BodyDesc::dynamic(shape.mass_properties(500.0).unwrap())
            .with_position(at)
            .with_orientation(Quat::from_rotation_y(turn));
        let body = w.add_body(desc).unwrap();
        let mut collider = Collider::new(body, ColliderShape::Solid(shape));
        collider.restitution = 0.25;
        c.add(collider).unwrap();
        body
    };
    let a = cube(Vec3::new(0.0, 0.21, 0.0), 0.0);
    let b = cube(Vec3::new(0.7, 0.3, 0.0), 0.4);
    c.exclude(a, ground);
    (w, c, [ground, a, b])
}

/// The ground and three humanoids dropped lying down, the middle one with
/// a socket spine.
fn pile() -> (World, Collisions, Vec<Ragdoll>) {
    let mut w = World::new(SolverConfig::default()).unwrap();
    let mut c = Collisions::new();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    let desc = RagdollDesc::reference_humanoid();
    let ragdolls = (0..3)
        .map(|k| {
            let spine = [SpineMode::Rod, SpineMode::Sockets][k % 2];
            let lying = Quat::from_rotation_y(0.6 * k as f32)
                * Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
            let pose = Pose::bind(&desc).moved(
                Vec3::new(0.0, 1.0, 0.0),
                lying,
                Vec3::new(0.0, 0.3 + 0.4 * k as f32, 0.0),
            );
            let r = Ragdoll::build(&mut w, &desc, BuildOptions::new(spine), &pose, None).unwrap();
            c.add_ragdoll(&r).unwrap();
            r
        })
        .collect();
    (w, c, ragdolls)
}

/// Every collider's body is in the world.
fn all_live(w: &World, c: &Collisions) -> bool {
    c.colliders().all(|collider| w.body(collider.body).is_ok())
}

#[test]
fn add_jointed_adds_nothing_when_one_shape_is_refused() {
    // Nothing is added, not even the colliders before the refused one.
    let (w, mut c, [_, a, b]) = boxes();
    let before = c.snapshot(&w).unwrap();
    let good = Shape::Sphere { radius: 0.1 };
    let flat = Shape::Sphere { radius: 0.0 };
    let refused = c.add_jointed(&[(a, good), (b, flat)], &[(a, b)]);
    let Err(Error::Collider { index, body, .. }) = &refused else {
        panic!("the collider is named: {refused:?}");
    };
    assert_eq!((*index, *body), (4, b), "the second new collider, on b");
    assert!(refused.unwrap_err().to_string().contains("collider 4"));
    assert_eq!(
        c.snapshot(&w).unwrap(),
        before,
        "nothing was added or excluded"
    );
    assert!(!c.is_excluded(a, b));
}

#[test]
fn colliders_beyond_the_size_limit_are_refused() {
    // Beyond the limit a collider's contacts are not finite (a box of half
    // extent 1e30 m gives NaN points).
    let (mut w, mut c, [_, _, b]) = boxes();
    let before = c.snapshot(&w).unwrap();
    for shape in [
        Shape::Box {
            half_extents: Vec3::new(0.3, 1e30, 0.2),
        },
        Shape::Sphere { radius: 2e4 },
        Shape::Capsule {
            half_segment: Vec3::X * 9e3,
            radius: 2e3,
        },
    ] {
        let refused = c.add(Collider::new(b, ColliderShape::Solid(shape)));
        assert_eq!(
            refused,
            Err(Error::Collider {
                index: 3,
                body: b,
                reason: Box::new(Error::OutOfRange("collider size (at most 1e4 m)")),
            }),
            "{shape:?}"
        );
    }
    // A restitution outside [0, 1], refused in words that read as a
    // sentence.
    let mut bouncy = Collider::new(b, ColliderShape::Solid(Shape::Sphere { radius: 0.1 }));
    bouncy.restitution = 1.5;
    let refused = c.add(bouncy).unwrap_err();
    assert_eq!(
        refused.to_string(),
        format!("collider 3 on body {b:?}: collider restitution (0 to 1) is out of range")
    );
    assert_eq!(c.snapshot(&w).unwrap(), before);
    let floor = Shape::Box {
        half_extents: Vec3::new(MAX_COLLIDER_EXTENT, 1.0, MAX_COLLIDER_EXTENT),
    };
    c.add(Collider::new(b, ColliderShape::Solid(floor)))
        .unwrap();
    let contacts = c.find_contacts(&w, DT).unwrap();
    w.set_contacts(&contacts).unwrap();
}

#[test]
fn a_bad_prediction_margin_is_refused() {
    let (_, mut c, _) = boxes();
    for (margin, refused) in [
        (f32::NAN, Error::NonFinite("collision prediction")),
        (f32::INFINITY, Error::NonFinite("collision prediction")),
        (-0.01, Error::NonPositive("collision prediction")),
    ] {
        assert_eq!(c.set_prediction(margin), Err(refused));
    }
    assert_eq!(c.prediction(), 0.01);
}

#[test]
fn a_collider_whose_body_is_gone_is_named() {
    // Not only "stale or unknown body handle": which collider, on which
    // body.
    let (mut w, c, [_, _, b]) = boxes();
    w.remove_body(b).unwrap();
    let refused = c.find_contacts(&w, DT).unwrap_err();
    assert_eq!(
        refused,
        Error::Collider {
            index: 2,
            body: b,
            reason: Box::new(Error::StaleHandle("body")),
        }
    );
    assert!(refused.to_string().starts_with("collider 2 on body"));
}

#[test]
fn removing_a_ragdoll_takes_its_colliders_and_contacts_keep_coming() {
    // A collider left behind would name a removed body, and every later
    // `find_contacts` would fail.
    let (mut w, mut c, mut ragdolls) = pile();
    for _ in 0..20 {
        step(&mut w, &c);
    }
    let count = c.colliders().count();
    let removed: Vec<BodyHandle> = ragdolls[1].bodies.iter().flatten().copied().collect();
    c.remove_ragdoll(&mut w, &mut ragdolls[1]).unwrap();
    assert_eq!(c.colliders().count(), count - removed.len());
    assert!(all_live(&w, &c));
    assert!(ragdolls[1].bodies.iter().all(Option::is_none));
    for &gone in &removed {
        assert!(c.colliders().all(|col| col.body != gone));
        assert!(removed.iter().all(|&other| !c.is_excluded(gone, other)));
    }
    // A new ragdoll reuses the freed slots and collides as before.
    let desc = RagdollDesc::reference_humanoid();
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::new(0.0, 2.0, 0.0));
    let fresh = Ragdoll::build(
        &mut w,
        &desc,
        BuildOptions::new(SpineMode::Sockets),
        &pose,
        None,
    )
    .unwrap();
    c.add_ragdoll(&fresh).unwrap();
    assert_eq!(c.colliders().count(), count);
    for _ in 0..60 {
        step(&mut w, &c);
    }
    assert!(w.body(fresh.bodies[desc.root].unwrap()).unwrap().position.y < 1.0);
}

#[test]
fn a_refused_ragdoll_removal_leaves_world_set_and_ragdoll_as_they_were() {
    let (mut w, mut c, mut ragdolls) = pile();
    let desc = ragdolls[0].description().clone();
    let hips = ragdolls[0].bodies[desc.root].unwrap();
    let at = w.body(hips).unwrap().position;
    let anchor = w.add_body(BodyDesc::fixed().with_position(at)).unwrap();
    w.add_joint(JointDesc::socket_at_world_anchor(w.bodies(), anchor, hips, at, Vec3::Y).unwrap())
        .unwrap();
    let before = (
        w.state_hash(),
        w.bodies().len(),
        w.joints().count(),
        w.rods().count(),
        c.snapshot(&w).unwrap(),
        ragdolls[0].bodies.clone(),
        ragdolls[0].joints.clone(),
        ragdolls[0].rod,
    );
    let refused = c.remove_ragdoll(&mut w, &mut ragdolls[0]).unwrap_err();
    assert!(
        matches!(&refused, RagdollError::NotRemovable { item, .. } if item.contains("hips")),
        "{refused}"
    );
    let after = (
        w.state_hash(),
        w.bodies().len(),
        w.joints().count(),
        w.rods().count(),
        c.snapshot(&w).unwrap(),
        ragdolls[0].bodies.clone(),
        ragdolls[0].joints.clone(),
        ragdolls[0].rod,
    );
    assert_eq!(after, before);
}

#[test]
fn a_recreated_ragdoll_keeps_its_colliders_on_its_new_bodies() {
    let (mut w, mut c, mut ragdolls) = pile();
    for _ in 0..20 {
        step(&mut w, &c);
    }
    let count = c.colliders().count();
    let desc = ragdolls[0].description().clone();
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::new(2.0, 1.0, 0.0));
    c.recreate_ragdoll(&mut w, &mut ragdolls[0], &pose, None)
        .unwrap();
    assert_eq!(c.colliders().count(), count);
    assert!(all_live(&w, &c));
    for (a, b) in ragdolls[0].non_colliding_pairs() {
        assert!(c.is_excluded(a, b), "jointed pairs stay excluded");
    }
    for body in ragdolls[0].bodies.iter().flatten() {
        assert_eq!(c.colliders().filter(|col| col.body == *body).count(), 1);
    }
    for _ in 0..60 {
        step(&mut w, &c);
    }
}

#[test]
fn restoring_the_world_and_the_set_replays_bit_for_bit() {
    let (mut w, mut c, mut ragdolls) = pile();
    for _ in 0..30 {
        step(&mut w, &c);
    }
    let (world_then, set_then) = (w.snapshot(), c.snapshot(&w).unwrap());
    let replay = |w: &mut World, c: &Collisions| -> Vec<u64> {
        (0..60)
            .map(|_| {
                step(w, c);
                w.state_hash()
            })
            .collect()
    };
    let first = replay(&mut w, &c);
    // Change everything the set holds: a ragdoll and its colliders gone, a
    // box added with a collider, a pair excluded, the margin.
    c.remove_ragdoll(&mut w, &mut ragdolls[1]).unwrap();
    let shape = Shape::Sphere { radius: 0.2 };
    let ball = w
        .add_body(
            BodyDesc::dynamic(shape.mass_properties(100.0).unwrap())
                .with_position(Vec3::new(0.0, 3.0, 0.0)),
        )
        .unwrap();
    c.add(Collider::new(ball, ColliderShape::Solid(shape)))
        .unwrap();
    c.exclude(ball, ragdolls[0].bodies[0].unwrap());
    c.set_prediction(0.05).unwrap();
    for _ in 0..10 {
        step(&mut w, &c);
    }
    w.restore(&world_then).unwrap();
    c.restore(&set_then, &w).unwrap();
    assert_eq!(
        c.snapshot(&w).unwrap(),
        set_then,
        "the same set, the same bytes"
    );
    assert_eq!(replay(&mut w, &c), first);
    // Through the bytes, into a fresh set.
    w.restore(&world_then).unwrap();
    let mut fresh = Collisions::new();
    fresh
        .restore(
            &CollisionSnapshot::from_bytes(set_then.as_bytes().to_vec()),
            &w,
        )
        .unwrap();
    assert_eq!(replay(&mut w, &fresh), first);
}

/// `bytes` with its payload checksum made right again (the format is
/// documented: magic 8, version 4, xxh3 8, payload).
fn resealed(mut bytes: Vec<u8>) -> CollisionSnapshot {
    let sum = xxhash_rust::xxh3::xxh3_64(&bytes[20..]);
    bytes[12..20].copy_from_slice(&sum.to_le_bytes());
    CollisionSnapshot::from_bytes(bytes)
}

/// Restores `bad` into the boxes' set: refused with `expected` (any
/// refusal when `None`) and the set unchanged.
fn assert_refused(bad: &CollisionSnapshot, expected: Option<Error>) {
    let (w, mut c, _) = boxes();
    let before = c.snapshot(&w).unwrap();
    let result = c.restore(bad, &w);
    match (&result, expected) {
        (Err(e), Some(expected)) => assert_eq!(*e, expected),
        (Err(_), None) => {}
        (Ok(()), _) => panic!("accepted"),
    }
    assert_eq!(
        c.snapshot(&w).unwrap(),
        before,
        "a refused restore changes nothing"
    );
}

#[test]
fn damaged_and_foreign_collision_snapshots_are_refused_with_nothing_changed() {
    let (mut own, c, [_, _, b]) = boxes();
    let saved = c.snapshot(&own).unwrap();
    let good = saved.as_bytes().to_vec();
    let corrupt = |why: &str| Some(Error::CorruptSnapshot(why.into()));
    assert_refused(
        &CollisionSnapshot::from_bytes(b"VTBSNAP1 and more bytes".to_vec()),
        corrupt("not a collision-set snapshot"),
    );
    assert_refused(
        &CollisionSnapshot::from_bytes(good[..19].to_vec()),
        corrupt("not a collision-set snapshot"),
    );
    let mut newer = good.clone();
    newer[8] = 5;
    assert_refused(
        &CollisionSnapshot::from_bytes(newer),
        Some(Error::IncompatibleSnapshot(
            "a collision-set snapshot of another format version",
        )),
    );
    let mut flipped = good.clone();
    *flipped.last_mut().unwrap() ^= 0x10;
    assert_refused(
        &CollisionSnapshot::from_bytes(flipped),
        corrupt("checksum mismatch"),
    );
    assert_refused(
        &resealed(good[..good.len() - 1].to_vec()),
        corrupt("undecodable collision set"),
    );
    assert_refused(
        &resealed([&good[..], &[0]].concat()),
        corrupt("bytes after the collision set"),
    );
    // Another world's bodies are foreign (its handles carry another
    // lineage): the first collider is named.
    let mut other = World::new(SolverConfig::default()).unwrap();
    other.add_body(BodyDesc::fixed()).unwrap();
    other.add_body(BodyDesc::fixed()).unwrap();
    let mut set = Collisions::new();
    let result = set.restore(&saved, &other);
    assert!(
        matches!(&result, Err(Error::Collider { index: 0, reason, .. })
            if **reason == Error::ForeignHandle("body")),
        "{result:?}"
    );
    assert_eq!(set.colliders().count(), 0);
    // The boxes' own world without the third box: its collider is named.
    own.remove_body(b).unwrap();
    assert_eq!(
        set.restore(&saved, &own),
        Err(Error::Collider {
            index: 2,
            body: b,
            reason: Box::new(Error::StaleHandle("body")),
        })
    );
    assert_eq!(set.colliders().count(), 0);
}

#[test]
fn crafted_collision_snapshots_never_panic_nor_admit_a_bad_value() {
    // Every 4-byte window of the payload overwritten with a float or word
    // that breaks something (NaN, infinities, negatives, zero, huge, all
    // ones), and every byte with a few values, resealed with a correct
    // checksum: each is refused with the set unchanged, or accepted as a
    // set whose contacts the world takes.
    let (mut w, c, _) = boxes();
    let good = c.snapshot(&w).unwrap().as_bytes().to_vec();
    let words: Vec<[u8; 4]> = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 0.0, 1e30]
        .iter()
        .map(|x| x.to_le_bytes())
        .chain([[0xff; 4]])
        .collect();
    let mut crafted = Vec::new();
    for at in 20..good.len() {
        for word in &words {
            let mut bytes = good.clone();
            let end = (at + 4).min(bytes.len());
            bytes[at..end].copy_from_slice(&word[..end - at]);
            crafted.push(bytes);
        }
        for value in [0x00, 0x01, 0x7f, 0x80, 0xff] {
            let mut bytes = good.clone();
            bytes[at] = value;
            crafted.push(bytes);
        }
    }
    let (mut accepted, mut refusals) = (0, 0);
    for bytes in crafted {
        let mut set = c.clone();
        match set.restore(&resealed(bytes), &w) {
            Ok(()) => {
                accepted += 1;
                assert!(set.prediction().is_finite() && set.prediction() >= 0.0);
                // Its contacts pass the world's own checks.
                let contacts = set.find_contacts(&w, DT).unwrap();
                w.set_contacts(&contacts).unwrap();
            }
            Err(_) => {
                refusals += 1;
                assert_eq!(
                    set.snapshot(&w).unwrap(),
                    c.snapshot(&w).unwrap(),
                    "refused, unchanged"
                );
            }
        }
    }
    eprintln!("crafted collision snapshots: {accepted} accepted, {refusals} refused");
    assert!(accepted > 0 && refusals > 0);
}

/// The payload's layout, as `docs/contacts.md` documents it (format 4).
#[derive(serde::Serialize, serde::Deserialize)]
struct Payload {
    census: u64,
    prediction: f32,
    colliders: Vec<Collider>,
    excluded: Vec<(BodyHandle, BodyHandle)>,
    parts: Vec<(BodyHandle, RagdollPart)>,
    touching: Vec<(BodyHandle, BodyHandle)>,
    apart: Vec<(BodyHandle, u64)>,
    next_apart: u64,
}

/// A change to a decoded payload.
type Change = Box<dyn FnOnce(&mut Payload)>;

/// `good` decoded, changed by `change`, encoded and sealed again.
fn crafted(good: &CollisionSnapshot, change: impl FnOnce(&mut Payload)) -> CollisionSnapshot {
    let bytes = good.as_bytes();
    let mut payload: Payload = postcard::from_bytes(&bytes[20..]).unwrap();
    change(&mut payload);
    let body = postcard::to_allocvec(&payload).unwrap();
    resealed([&bytes[..20], &body[..]].concat())
}

/// Every value a collision snapshot carries is checked as the set would
/// have written it: the lists the set writes in a canonical order (so
/// equal sets give equal bytes) are not normalised on the way in. A set
/// writes each excluded pair once, its bodies in slot order, and both
/// lists ascending by their encoding: anything else (an entry repeated, a
/// pair's bodies swapped, two entries exchanged) is refused by name with
/// the set unchanged.
#[test]
fn lists_the_set_could_not_have_written_are_refused_by_name() {
    let (w, mut c, ragdolls) = pile();
    c.set_ragdoll_self_collision(&ragdolls[1], false).unwrap();
    let good = c.snapshot(&w).unwrap();
    assert_eq!(crafted(&good, |_| {}), good, "the layout is the set's");
    let corrupt = |why: &str| Err(Error::CorruptSnapshot(why.into()));
    let cases: [(&str, Change); 9] = [
        (
            "excluded pair 1: out of order or repeated",
            Box::new(|p| p.excluded.insert(0, p.excluded[0])),
        ),
        (
            "excluded pair 1: out of order or repeated",
            Box::new(|p| p.excluded.swap(0, 1)),
        ),
        (
            "excluded pair 0: its bodies out of order",
            Box::new(|p| {
                let (a, b) = p.excluded[0];
                p.excluded[0] = (b, a);
            }),
        ),
        (
            "self-collision entry 1: out of order or repeated",
            Box::new(|p| p.apart.swap(0, 1)),
        ),
        (
            "self-collision entry 1: out of order or repeated",
            Box::new(|p| p.apart.insert(0, p.apart[0])),
        ),
        (
            "ragdoll part 1: out of order or repeated",
            Box::new(|p| p.parts.swap(0, 1)),
        ),
        (
            "ragdoll part 1: out of order or repeated",
            Box::new(|p| p.parts.insert(0, p.parts[0])),
        ),
        (
            "touching pair 0: its bodies out of order or the same",
            Box::new(|p| {
                let (a, b) = p.excluded[0];
                p.touching = vec![(b, a)];
            }),
        ),
        (
            "touching pair 1: out of order or repeated",
            Box::new(|p| p.touching = vec![p.excluded[0], p.excluded[0]]),
        ),
    ];
    for (why, change) in cases {
        let bad = crafted(&good, change);
        assert_eq!(c.restore(&bad, &w), corrupt(why));
        assert_eq!(c.snapshot(&w).unwrap(), good, "{why}: refused, unchanged");
    }
}
