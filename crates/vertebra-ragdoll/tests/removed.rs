//! A removed ragdoll is refused by every call that takes it, naming the
//! ragdoll, with the world as it was: mapped onto a skeleton it would put
//! every bone of its bodies at the world origin, and driven it would do
//! nothing.

use glam::{Quat, Vec3};
use vertebra_ragdoll::{
    BuildOptions, DriveSettings, Pose, Ragdoll, RagdollDesc, RagdollError, Skeleton,
    SkeletonMapper, SpineMapping, SpineMode, Transform, Transition,
};
use vertebra_world::{SolverConfig, Spring, World};

/// A ragdoll built in `world` at bind pose lifted 1 m, with its mapper
/// onto the reference skeleton and a transition measured at the build.
fn built(world: &mut World, spine: SpineMode) -> (Ragdoll, SkeletonMapper, Transition) {
    let desc = RagdollDesc::reference_humanoid();
    let skeleton = Skeleton::reference();
    let mapper = SkeletonMapper::new(&skeleton, &desc, spine).unwrap();
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::Y);
    let ragdoll = Ragdoll::build(world, &desc, BuildOptions::new(spine), &pose, None).unwrap();
    let transition = Transition::new(
        &mapper,
        &ragdoll,
        world,
        &skeleton.bind_pose(),
        Transform::new(Vec3::Y, Quat::IDENTITY),
        SpineMapping::Arc,
        0.3,
    )
    .unwrap();
    (ragdoll, mapper, transition)
}

/// Asserts `result` refuses a removed ragdoll by its name.
#[track_caller]
fn names_the_removed_ragdoll<T: core::fmt::Debug>(call: &str, result: Result<T, RagdollError>) {
    let error = result.expect_err(call);
    let text = error.to_string();
    assert_eq!(
        error,
        RagdollError::Removed {
            ragdoll: "reference-humanoid".to_owned()
        },
        "{call}: {text}"
    );
    assert_eq!(
        text, "ragdoll `reference-humanoid` has been removed from the world; build it again",
        "{call}"
    );
}

#[test]
fn every_call_on_a_removed_ragdoll_is_refused_naming_it() {
    for spine in [SpineMode::Rod, SpineMode::Sockets] {
        let mut world = World::new(SolverConfig::default()).unwrap();
        let (mut ragdoll, mapper, transition) = built(&mut world, spine);
        let desc = ragdoll.description().clone();
        let skeleton = mapper.skeleton().clone();
        let pose = Pose::bind(&desc);
        let settings = DriveSettings::uniform(Spring::RIGID);
        ragdoll.remove(&mut world).unwrap();
        let hash = world.state_hash();
        let animation = skeleton.bind_pose();
        let place = Transform::IDENTITY;
        // Mapped, a removed ragdoll would put every bone at the origin.
        names_the_removed_ragdoll(
            "map_to_skeleton",
            mapper.map_to_skeleton(&ragdoll, &world, &animation, place, SpineMapping::Arc),
        );
        names_the_removed_ragdoll(
            "Transition::skeleton_pose",
            transition.skeleton_pose(&mapper, &ragdoll, &world, &animation, place, 0.1),
        );
        names_the_removed_ragdoll(
            "Transition::new",
            Transition::new(
                &mapper,
                &ragdoll,
                &world,
                &animation,
                place,
                SpineMapping::Arc,
                0.3,
            ),
        );
        names_the_removed_ragdoll(
            "Ragdoll::skeleton_pose",
            ragdoll.skeleton_pose(&world, SpineMapping::Arc),
        );
        // Driven, it would do nothing and say `Ok`.
        names_the_removed_ragdoll("drive_to", ragdoll.drive_to(&mut world, &pose, &settings));
        names_the_removed_ragdoll(
            "drive_following",
            ragdoll.drive_following(&mut world, &pose, &pose, 1.0 / 60.0, &settings),
        );
        names_the_removed_ragdoll("release_drives", ragdoll.release_drives(&mut world));
        // These would refuse it anyway: they name the ragdoll, not only its
        // root body.
        names_the_removed_ragdoll("root_transform", ragdoll.root_transform(&world));
        names_the_removed_ragdoll("bounds", ragdoll.bounds(&world));
        names_the_removed_ragdoll(
            "set_velocity",
            ragdoll.set_velocity(&mut world, Vec3::X, Vec3::ZERO),
        );
        names_the_removed_ragdoll(
            "apply_impulse",
            ragdoll.apply_impulse(&mut world, "chest", Vec3::X, None),
        );
        names_the_removed_ragdoll(
            "set_body_kinematic",
            ragdoll.set_body_kinematic(&mut world, "hips", true),
        );
        names_the_removed_ragdoll(
            "set_kinematic",
            ragdoll.set_kinematic(&mut world, &vec![false; desc.bodies.len()]),
        );
        names_the_removed_ragdoll("kinematic", ragdoll.kinematic(&world));
        names_the_removed_ragdoll(
            "drive_to_pose_using_kinematics",
            ragdoll.drive_to_pose_using_kinematics(&mut world, &pose, 1.0 / 60.0),
        );
        // Removed again, or re-created in place: nothing of it is left to
        // remove (build a new one instead).
        names_the_removed_ragdoll("remove", ragdoll.remove(&mut world));
        names_the_removed_ragdoll("recreate", ragdoll.recreate(&mut world, &pose, None));
        assert_eq!(
            world.state_hash(),
            hash,
            "{spine:?}: a refusal changed the world"
        );
        assert!(ragdoll.bodies.iter().all(Option::is_none));
        assert_eq!(ragdoll.rod, None);
    }
}

/// A ragdoll whose bodies were taken out by hand (not by
/// `Ragdoll::remove`) is refused too, naming the body gone.
#[test]
fn a_ragdoll_whose_body_was_removed_by_hand_is_refused_naming_the_body() {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let (ragdoll, mapper, _) = built(&mut world, SpineMode::Sockets);
    let hand = ragdoll.bodies[ragdoll.description().body_index("forearm_l").unwrap()].unwrap();
    let joint = world
        .joints()
        .find(|(_, d)| d.body_b == hand)
        .map(|(h, _)| h)
        .unwrap();
    world.remove_joint(joint).unwrap();
    world.remove_body(hand).unwrap();
    let animation = mapper.skeleton().bind_pose();
    let mapped = mapper.map_to_skeleton(
        &ragdoll,
        &world,
        &animation,
        Transform::IDENTITY,
        SpineMapping::Arc,
    );
    let text = mapped.unwrap_err().to_string();
    assert!(text.starts_with("body `forearm_l`: stale"), "{text}");
}
