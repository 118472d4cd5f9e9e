//! A world and its collision set belong together: restoring one without
//! the other, or the two from different moments, is refused by name
//! instead of leaving bodies without their colliders.

use glam::{Quat, Vec3};
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, RagdollError, SpineMode};
use vertebra_world::{BodyDesc, Error, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

/// A ground plane and a humanoid standing on it, built with its colliders.
fn standing() -> (World, Collisions, Ragdoll) {
    let mut w = World::new(SolverConfig::default()).unwrap();
    let mut c = Collisions::new();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    let desc = RagdollDesc::reference_humanoid();
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::Y * 0.05);
    let r = c
        .build_ragdoll(
            &mut w,
            &desc,
            BuildOptions::new(SpineMode::Rod),
            &pose,
            None,
        )
        .unwrap();
    (w, c, r)
}

/// The lowest point of the ragdoll's bodies after `frames` frames with
/// detection (m), or the first refusal.
fn lowest_after(w: &mut World, c: &Collisions, r: &Ragdoll, frames: usize) -> Result<f32, String> {
    for _ in 0..frames {
        let contacts = c.find_contacts(w, DT).map_err(|e| e.to_string())?;
        w.set_contacts(&contacts).unwrap();
        w.step(DT).unwrap();
    }
    let y = |b| w.body(b).unwrap().position.y;
    Ok(r.bodies
        .iter()
        .flatten()
        .map(|&b| y(b))
        .fold(f32::MAX, f32::min))
}

/// Standing: 10 frames in, its lowest body is above the ground.
fn settled() -> (World, Collisions, Ragdoll) {
    let (mut w, c, r) = standing();
    assert!(lowest_after(&mut w, &c, &r, 10).unwrap() > 0.0);
    (w, c, r)
}

/// Whether `result` is a world mismatch.
fn mismatch<T: std::fmt::Debug>(result: Result<T, Error>) -> bool {
    matches!(result, Err(Error::WorldMismatch(_)))
}

/// The set's colliders, margin and pairs, to see it unchanged where its
/// snapshot cannot be taken (it does not serve the world).
fn contents(c: &Collisions, r: &Ragdoll) -> (Vec<Collider>, f32, Vec<bool>) {
    let pairs = r.non_colliding_pairs();
    let excluded = pairs.iter().map(|&(a, b)| c.is_excluded(a, b)).collect();
    (c.colliders().copied().collect(), c.prediction(), excluded)
}

/// The set kept. A world restored to a moment before its ragdoll was
/// removed has the ragdoll back, and the set kept from after the removal
/// has no colliders for it: served, detection would give the ground's
/// contacts only, and the ragdoll would fall 23 m through the floor in
/// 2 s with no error. So every call of the set that takes the world
/// refuses it (`WorldMismatch`), everything unchanged, until the set's
/// snapshot taken with the world's is restored after it: the ragdoll
/// stands.
#[test]
fn a_world_restored_without_its_collision_set_is_refused_until_the_set_is_restored() {
    let (mut w, mut c, mut r) = settled();
    let (world_then, set_then) = (w.snapshot(), c.snapshot(&w).unwrap());
    let mut contacts = c.find_contacts(&w, DT).unwrap();
    assert!(!contacts.is_empty(), "the feet on the ground");
    let kept = r.clone();
    c.remove_ragdoll(&mut w, &mut r).unwrap();
    w.restore(&world_then).unwrap();
    let (hash, before) = (w.state_hash(), contents(&c, &kept));
    let fell = lowest_after(&mut w, &c, &kept, 120);
    assert!(
        fell.as_ref().is_err_and(|e| e.contains("world mismatch")),
        "{fell:?}"
    );
    assert!(mismatch(c.find_contacts(&w, DT)));
    assert!(mismatch(c.find_contacts_into(&w, DT, &mut contacts)));
    assert!(contacts.is_empty(), "emptied on error, as documented");
    assert!(mismatch(c.snapshot(&w)));
    let desc = RagdollDesc::reference_humanoid();
    let built = c.build_ragdoll(
        &mut w,
        &desc,
        BuildOptions::new(SpineMode::Rod),
        &Pose::bind(&desc),
        None,
    );
    assert!(matches!(
        built,
        Err(RagdollError::World {
            error: Error::WorldMismatch(_),
            ..
        })
    ));
    let mut again = kept.clone();
    let removed = c.remove_ragdoll(&mut w, &mut again);
    assert!(matches!(
        removed,
        Err(RagdollError::World {
            error: Error::WorldMismatch(_),
            ..
        })
    ));
    assert_eq!(
        (w.state_hash(), contents(&c, &kept)),
        (hash, before),
        "refused, unchanged"
    );
    c.restore(&set_then, &w).unwrap();
    assert!(
        lowest_after(&mut w, &c, &kept, 120).unwrap() > 0.0,
        "it stands"
    );
}

/// A fresh set. A world restored from a save (here a fresh world) and a
/// new, empty set would find no contacts, and the ragdoll would fall
/// through the floor. A set that never served a world refuses a restored
/// one; the set's snapshot restored after the world's serves it, and a
/// set built by hand for it is declared with `attach` (refused, naming
/// the collider, while a collider's body is not in the world).
#[test]
fn a_fresh_collision_set_is_refused_for_a_restored_world() {
    let (w, c, r) = settled();
    let (world_then, set_then) = (w.snapshot(), c.snapshot(&w).unwrap());
    let mut loaded = World::new(SolverConfig::default()).unwrap();
    loaded.restore(&world_then).unwrap();
    let fresh = Collisions::new();
    assert!(mismatch(fresh.find_contacts(&loaded, DT)));
    let mut restored = Collisions::new();
    restored.restore(&set_then, &loaded).unwrap();
    let mut copy = World::new(SolverConfig::default()).unwrap();
    copy.restore(&world_then).unwrap();
    assert!(
        lowest_after(&mut loaded, &restored, &r, 120).unwrap() > 0.0,
        "it stands"
    );
    // By hand: the ground and the ragdoll's colliders, declared.
    let mut by_hand = Collisions::new();
    let ground = copy.bodies().handle_at(0).unwrap();
    by_hand
        .add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    by_hand.add_ragdoll(&r).unwrap();
    let mut stray = by_hand.clone();
    let gone = w.bodies().handle_at(0).map(|h| {
        let (i, l, g) = h.to_raw();
        vertebra_world::BodyHandle::from_raw(i, l, g + 1000)
    });
    stray
        .add(Collider::new(gone.unwrap(), ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    let refused = stray.attach(&copy);
    assert!(
        matches!(refused, Err(Error::Collider { index, .. }) if index == 1 + r.bodies.iter().flatten().count()),
        "{refused:?}"
    );
    assert!(mismatch(stray.find_contacts(&copy, DT)), "not attached");
    by_hand.attach(&copy).unwrap();
    assert!(
        lowest_after(&mut copy, &by_hand, &r, 120).unwrap() > 0.0,
        "it stands"
    );
}

/// Both restored, from different moments. The world's snapshot from
/// before the ragdoll was removed, the set's from after: accepted, the
/// ragdoll would fall through the floor. A set's snapshot records the
/// world's bodies it was taken with and is refused for a world with
/// others, the set unchanged; one of another moment with the same bodies
/// (frames later) restores, as it is right.
#[test]
fn a_collision_snapshot_of_another_moment_of_the_world_is_refused() {
    let (mut w, mut c, mut r) = settled();
    let (world_then, set_then) = (w.snapshot(), c.snapshot(&w).unwrap());
    lowest_after(&mut w, &c, &r, 5).unwrap();
    let set_later_same_bodies = c.snapshot(&w).unwrap();
    let kept = r.clone();
    c.remove_ragdoll(&mut w, &mut r).unwrap();
    let set_without = c.snapshot(&w).unwrap();
    w.restore(&world_then).unwrap();
    let before = contents(&c, &kept);
    assert!(mismatch(c.restore(&set_without, &w)));
    assert_eq!(contents(&c, &kept), before, "refused, unchanged");
    assert!(mismatch(c.find_contacts(&w, DT)), "still not serving it");
    c.restore(&set_later_same_bodies, &w).unwrap();
    assert_eq!(c.snapshot(&w).unwrap(), set_then, "the same set");
    assert!(
        lowest_after(&mut w, &c, &kept, 120).unwrap() > 0.0,
        "it stands"
    );
}
