//! Collision groups per body and per ragdoll, a ragdoll's self-collision,
//! and a ragdoll in and out with its colliders in one call: boxes in
//! disjoint groups pass through each other, in overlapping groups they
//! stack; a ragdoll's own bodies meet or not as set; every setting is
//! saved with the set, checked on restore, and a refusal changes nothing.

use glam::{Quat, Vec3};
use vertebra_collide::{
    Collider, ColliderShape, CollisionGroups, CollisionSnapshot, Collisions,
    MAX_SELF_COLLISION_GROUPS,
};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, RagdollError, SpineMode};
use vertebra_world::{BodyDesc, BodyHandle, Error, Shape, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;
const HALF: f32 = 0.2;

fn step(w: &mut World, c: &Collisions) {
    let contacts = c.find_contacts(w, DT).unwrap();
    w.set_contacts(&contacts).unwrap();
    w.step(DT).unwrap();
}

/// A world with a ground plane (every group) in its set.
fn ground() -> (World, Collisions) {
    let mut w = World::new(SolverConfig::default()).unwrap();
    let mut c = Collisions::new();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    (w, c)
}

fn cube(w: &mut World, c: &mut Collisions, at: Vec3) -> BodyHandle {
    let shape = Shape::Box {
        half_extents: Vec3::splat(HALF),
    };
    let body = w
        .add_body(BodyDesc::dynamic(shape.mass_properties(500.0).unwrap()).with_position(at))
        .unwrap();
    c.add(Collider::new(body, ColliderShape::Solid(shape)))
        .unwrap();
    body
}

/// Where a box dropped onto a box resting on the ground comes to rest
/// (its centre's height, m) when the lower box is in group 1 and the upper
/// one in group 2 and collides with `upper_filter`.
fn dropped_box_height(upper_filter: u32) -> f32 {
    let (mut w, mut c) = ground();
    let lower = cube(&mut w, &mut c, Vec3::Y * HALF);
    let upper = cube(&mut w, &mut c, Vec3::Y * (4.0 * HALF));
    let group = |membership, filter| CollisionGroups { membership, filter };
    c.set_body_groups(lower, group(0b01, u32::MAX)).unwrap();
    c.set_body_groups(upper, group(0b10, upper_filter)).unwrap();
    for _ in 0..120 {
        step(&mut w, &c);
    }
    w.body(upper).unwrap().position.y
}

/// Groups 1 and 2 with the upper box's filter leaving out group 1: no
/// pair of the two is tested (`a.membership & b.filter == 0`), and the
/// upper box falls through the lower to the ground, which is in every
/// group. With a filter that takes group 1 in, it lands on the lower box.
#[test]
fn boxes_in_disjoint_groups_pass_through_each_other_and_in_overlapping_groups_stack() {
    let through = dropped_box_height(!0b01);
    assert!((through - HALF).abs() < 0.01, "on the ground: {through} m");
    let stacked = dropped_box_height(u32::MAX);
    assert!(
        (stacked - 3.0 * HALF).abs() < 0.01,
        "on the box: {stacked} m"
    );
}

/// The reference humanoid standing on the ground (its feet 5 mm above it)
/// with its left forearm pushed into its chest, a pair no joint joins.
fn humanoid(w: &mut World, c: &mut Collisions) -> Ragdoll {
    let desc = RagdollDesc::reference_humanoid();
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, -Vec3::Y * 0.1);
    let ragdoll = c
        .build_ragdoll(w, &desc, BuildOptions::new(SpineMode::Rod), &pose, None)
        .unwrap();
    let index = |name: &str| desc.bodies.iter().position(|b| b.name == name).unwrap();
    let chest = w.body(ragdoll.bodies[index("chest")].unwrap()).unwrap();
    let forearm = ragdoll.bodies[index("forearm_l")].unwrap();
    w.set_body_pose(forearm, chest.position, Quat::IDENTITY)
        .unwrap();
    ragdoll
}

/// How many contacts `c` finds between two bodies of `ragdoll`, and
/// between one of them and anything else.
fn contacts(w: &World, c: &Collisions, ragdoll: &Ragdoll) -> (usize, usize) {
    let own = |b: BodyHandle| ragdoll.bodies.contains(&Some(b));
    let found = c.find_contacts(w, DT).unwrap();
    let inner = found.iter().filter(|k| own(k.body_a) && own(k.body_b));
    let inner = inner.count();
    (inner, found.len() - inner)
}

#[test]
fn a_ragdolls_self_collision_is_on_by_default_and_can_be_turned_off_and_on() {
    let (mut w, mut c) = ground();
    let ragdoll = humanoid(&mut w, &mut c);
    assert!(c.ragdoll_self_collision(&ragdoll));
    let (inner, outer) = contacts(&w, &c, &ragdoll);
    assert!(
        inner > 0 && outer > 0,
        "{inner} own, {outer} with the ground"
    );
    c.set_ragdoll_self_collision(&ragdoll, false).unwrap();
    assert!(!c.ragdoll_self_collision(&ragdoll));
    assert_eq!(contacts(&w, &c, &ragdoll), (0, outer), "the ground stays");
    // Its jointed pairs stay excluded either way.
    for (a, b) in ragdoll.non_colliding_pairs() {
        assert!(c.is_excluded(a, b));
    }
    c.set_ragdoll_self_collision(&ragdoll, true).unwrap();
    assert!(c.ragdoll_self_collision(&ragdoll));
    assert_eq!(contacts(&w, &c, &ragdoll), (inner, outer));
}

/// Two humanoids side by side in one team (group 2, not colliding with
/// group 2): they pass through each other and both still meet the ground.
#[test]
fn a_ragdolls_groups_go_on_every_collider_of_its_bodies() {
    let (mut w, mut c) = ground();
    let desc = RagdollDesc::reference_humanoid();
    let options = BuildOptions::new(SpineMode::Sockets);
    let pose =
        |x: f32| Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::new(x, -0.1, 0.0));
    let a = c
        .build_ragdoll(&mut w, &desc, options, &pose(0.0), None)
        .unwrap();
    let b = c
        .build_ragdoll(&mut w, &desc, options, &pose(0.15), None)
        .unwrap();
    let of = |r: &Ragdoll, k: &vertebra_world::Contact| {
        r.bodies.contains(&Some(k.body_a)) || r.bodies.contains(&Some(k.body_b))
    };
    let between = |c: &Collisions, w: &World| {
        let found = c.find_contacts(w, DT).unwrap();
        let count = found.iter().filter(|k| of(&a, k) && of(&b, k)).count();
        (count, found.len() - count)
    };
    let (crossing, _) = between(&c, &w);
    assert!(crossing > 0, "side by side, overlapping");
    let team = CollisionGroups {
        membership: 0b10,
        filter: !0b10,
    };
    c.set_ragdoll_groups(&a, team).unwrap();
    c.set_ragdoll_groups(&b, team).unwrap();
    let on_a_ragdoll = |body| a.bodies.contains(&Some(body)) || b.bodies.contains(&Some(body));
    let theirs: Vec<_> = c.colliders().filter(|k| on_a_ragdoll(k.body)).collect();
    assert_eq!(theirs.len(), 2 * desc.bodies.len());
    assert!(theirs.iter().all(|k| k.groups == team));
    let (crossing, rest) = between(&c, &w);
    assert_eq!(crossing, 0);
    assert!(rest > 0, "the ground and their own bodies stay");
}

/// `Ragdoll::build` then `add_ragdoll`, or `build_ragdoll`: the same world
/// and set, so the same steps; a refused `build_ragdoll` changes neither.
#[test]
fn building_a_ragdoll_with_its_colliders_is_one_call() {
    let desc = RagdollDesc::reference_humanoid();
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::from_rotation_z(0.3), Vec3::Y * 0.4);
    let options = BuildOptions::new(SpineMode::Rod);
    let (mut w1, mut c1) = ground();
    let r1 = c1
        .build_ragdoll(&mut w1, &desc, options, &pose, None)
        .unwrap();
    let (mut w2, mut c2) = ground();
    let r2 = Ragdoll::build(&mut w2, &desc, options, &pose, None).unwrap();
    c2.add_ragdoll(&r2).unwrap();
    assert_eq!(c1.colliders().count(), c2.colliders().count());
    for (a, b) in r1.non_colliding_pairs() {
        assert!(c1.is_excluded(a, b));
    }
    for _ in 0..60 {
        step(&mut w1, &c1);
        step(&mut w2, &c2);
        assert_eq!(w1.state_hash(), w2.state_hash());
    }
    let before = (w1.state_hash(), c1.snapshot(&w1).unwrap());
    let bad = Pose {
        bones: pose.bones[1..].to_vec(),
    };
    let refused = c1.build_ragdoll(&mut w1, &desc, options, &bad, None);
    assert!(
        matches!(refused, Err(RagdollError::BadPose(_))),
        "{refused:?}"
    );
    assert_eq!((w1.state_hash(), c1.snapshot(&w1).unwrap()), before);
    // And out again in one call: the set holds the ground alone.
    let mut r1 = r1;
    c1.remove_ragdoll(&mut w1, &mut r1).unwrap();
    assert_eq!(c1.colliders().count(), 1);
}

/// Refused settings change nothing: a body without a collider, a ragdoll
/// whose colliders were never added, a removed ragdoll.
#[test]
fn refused_group_settings_change_nothing() {
    let (mut w, mut c) = ground();
    let bare = w.add_body(BodyDesc::fixed()).unwrap();
    let desc = RagdollDesc::reference_humanoid();
    let options = BuildOptions::new(SpineMode::Sockets);
    let outside = Ragdoll::build(&mut w, &desc, options, &Pose::bind(&desc), None).unwrap();
    let mut inside = humanoid(&mut w, &mut c);
    let mut gone = inside.clone();
    let before = c.snapshot(&w).unwrap();
    let no_collider = Err(Error::StaleHandle("collider body"));
    let ragdoll_without = Err(RagdollError::from(Error::StaleHandle("collider body")));
    let groups = CollisionGroups::default();
    assert_eq!(c.set_body_groups(bare, groups), no_collider);
    assert_eq!(c.set_ragdoll_groups(&outside, groups), ragdoll_without);
    assert_eq!(
        c.set_ragdoll_self_collision(&outside, false),
        ragdoll_without
    );
    assert_eq!(c.snapshot(&w).unwrap(), before);
    c.set_ragdoll_self_collision(&inside, false).unwrap();
    c.remove_ragdoll(&mut w, &mut gone).unwrap();
    inside.bodies.iter_mut().for_each(|b| *b = None);
    let before = c.snapshot(&w).unwrap();
    // A removed ragdoll is refused by name: by every
    // call on it, adding its colliders again included (it has none).
    let removed = Err(RagdollError::Removed {
        ragdoll: desc.name.clone(),
    });
    assert_eq!(c.set_ragdoll_self_collision(&inside, true), removed);
    assert_eq!(c.set_ragdoll_groups(&gone, groups), removed);
    assert_eq!(c.add_ragdoll(&gone), removed);
    assert_eq!(c.remove_ragdoll(&mut w, &mut gone), removed);
    assert_eq!(c.snapshot(&w).unwrap(), before);
}

/// `bytes` with its payload checksum made right again (the format is
/// documented: magic 8, version 4 bytes, xxh3 8, payload).
fn resealed(mut bytes: Vec<u8>) -> CollisionSnapshot {
    let sum = xxhash_rust::xxh3::xxh3_64(&bytes[20..]);
    bytes[12..20].copy_from_slice(&sum.to_le_bytes());
    CollisionSnapshot::from_bytes(bytes)
}

/// The self-collision setting is in the snapshot: restored, it is off
/// again, and it follows a recreated ragdoll to its new bodies. A snapshot
/// of another format version, or whose next group is one already given,
/// is refused by name with the set unchanged.
#[test]
fn self_collision_settings_are_saved_restored_and_checked() {
    let (mut w, mut c) = ground();
    let mut ragdoll = humanoid(&mut w, &mut c);
    c.set_ragdoll_self_collision(&ragdoll, false).unwrap();
    let saved = c.snapshot(&w).unwrap();
    c.set_ragdoll_self_collision(&ragdoll, true).unwrap();
    c.restore(&saved, &w).unwrap();
    assert!(!c.ragdoll_self_collision(&ragdoll));
    assert_eq!(c.snapshot(&w).unwrap(), saved);
    assert_eq!(contacts(&w, &c, &ragdoll).0, 0);
    let desc = ragdoll.description().clone();
    c.recreate_ragdoll(&mut w, &mut ragdoll, &Pose::bind(&desc), None)
        .unwrap();
    assert!(!c.ragdoll_self_collision(&ragdoll));
    let good = c.snapshot(&w).unwrap().as_bytes().to_vec();
    let before = c.snapshot(&w).unwrap();
    let mut older = good.clone();
    older[8] = 1;
    assert_eq!(
        c.restore(&CollisionSnapshot::from_bytes(older), &w),
        Err(Error::IncompatibleSnapshot(
            "a collision-set snapshot of another format version"
        ))
    );
    // The payload ends with the next group to give (a one-byte varint, 1):
    // 0 leaves the ragdoll's group 0 not yet given.
    let mut early = good.clone();
    *early.last_mut().unwrap() = 0;
    assert_eq!(
        c.restore(&resealed(early), &w),
        Err(Error::CorruptSnapshot(
            "self-collision entry 0: a group not given yet".into()
        ))
    );
    assert_eq!(c.snapshot(&w).unwrap(), before);
}

/// `value` as a postcard varint (LEB128), appended to `bytes`.
fn varint(mut value: u64, bytes: &mut Vec<u8>) {
    while value >= 0x80 {
        bytes.push(value as u8 | 0x80);
        value >>= 7;
    }
    bytes.push(value as u8);
}

/// A collision snapshot's group counter (the next group to give, the
/// payload's last varint) set to `u64::MAX` with the checksum made right
/// is refused: accepted, turning one more ragdoll's self-collision off
/// would overflow it (a panic in debug builds, 0 in release: two ragdolls
/// in one group, which pass through each other, and a set whose own next
/// snapshot is refused). The counter is refused beyond
/// `MAX_SELF_COLLISION_GROUPS` with the set unchanged; at the limit it is
/// accepted, and the call that would give a group past it is refused
/// naming the ragdoll's first body and collider, with nothing changed: the
/// two overlapping ragdolls still meet.
#[test]
fn a_crafted_group_counter_is_refused_and_a_group_is_never_given_twice() {
    let (mut w, mut c) = ground();
    let desc = RagdollDesc::reference_humanoid();
    let options = BuildOptions::new(SpineMode::Sockets);
    let pose =
        |x: f32| Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::new(x, -0.1, 0.0));
    let a = c
        .build_ragdoll(&mut w, &desc, options, &pose(0.0), None)
        .unwrap();
    let b = c
        .build_ragdoll(&mut w, &desc, options, &pose(0.15), None)
        .unwrap();
    c.set_ragdoll_self_collision(&a, false).unwrap();
    let of = |r: &Ragdoll, body: BodyHandle| r.bodies.contains(&Some(body));
    let crossing = |c: &Collisions, w: &World| {
        let found = c.find_contacts(w, DT).unwrap();
        let between = |k: &&vertebra_world::Contact| {
            (of(&a, k.body_a) && of(&b, k.body_b)) || (of(&b, k.body_a) && of(&a, k.body_b))
        };
        found.iter().filter(between).count()
    };
    let meeting = crossing(&c, &w);
    assert!(meeting > 0, "side by side, overlapping");
    let good = c.snapshot(&w).unwrap().as_bytes().to_vec();
    assert_eq!(good.last(), Some(&1), "one group given");
    let with_counter = |given: u64| {
        let mut bytes = good[..good.len() - 1].to_vec();
        varint(given, &mut bytes);
        resealed(bytes)
    };
    let before = c.snapshot(&w).unwrap();
    for given in [u64::MAX, MAX_SELF_COLLISION_GROUPS + 1] {
        let refused = c.restore(&with_counter(given), &w);
        assert_eq!(
            refused,
            Err(Error::CorruptSnapshot(format!(
                "self-collision groups: {given} given, more than the 2^48 a set gives"
            )))
        );
        assert_eq!(c.snapshot(&w).unwrap(), before, "refused, unchanged");
    }
    // At the limit: accepted, and no group past it is given.
    c.restore(&with_counter(MAX_SELF_COLLISION_GROUPS), &w)
        .unwrap();
    let at_limit = c.snapshot(&w).unwrap();
    let first = b.bodies[0].unwrap();
    let index = c.colliders().position(|k| k.body == first).unwrap();
    assert_eq!(
        c.set_ragdoll_self_collision(&b, false),
        Err(Error::Collider {
            index,
            body: first,
            reason: Box::new(Error::OutOfRange(
                "ragdoll self-collision group (all 2^48 given)"
            )),
        }
        .into())
    );
    assert_eq!(c.snapshot(&w).unwrap(), at_limit, "refused, unchanged");
    assert!(c.ragdoll_self_collision(&b));
    assert_eq!(crossing(&c, &w), meeting);
    // One below: the last group goes to the second ragdoll, which still
    // meets the first, and the set's own snapshot restores.
    c.restore(&with_counter(MAX_SELF_COLLISION_GROUPS - 1), &w)
        .unwrap();
    c.set_ragdoll_self_collision(&b, false).unwrap();
    assert!(!c.ragdoll_self_collision(&a) && !c.ragdoll_self_collision(&b));
    assert_eq!(crossing(&c, &w), meeting, "two groups: they still meet");
    let last = c.snapshot(&w).unwrap();
    c.restore(&last, &w).unwrap();
    assert_eq!(c.snapshot(&w).unwrap(), last);
}
