//! Everything that computes what enters the world, or what a game reads
//! back from it, gives the same bits whatever floating-point mode its
//! caller runs in: a ragdoll read from its file, built, dropped on a floor
//! with its contacts found each frame, pushed and driven, and mapped onto
//! its skeleton through a transition, under each rounding mode and under
//! flush-to-zero with denormals-are-zero, against the default mode.
#![cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]

#[path = "../../vertebra-world/tests/host_mode/mod.rs"]
mod host_mode;

use host_mode::{DEFAULT, FLUSH, ROUNDING, STATUS, read_mode, write_mode};

use glam::{Quat, Vec3};
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{
    ANATOMICAL_HUMANOID, BuildOptions, DriveSettings, Pose, REFERENCE_HUMANOID, Ragdoll,
    RagdollDesc, Skeleton, SkeletonMapper, SpineMapping, SpineMode, Transform, Transition,
};
use vertebra_world::{BodyDesc, SolverConfig, Spring, World};

const DT: f32 = 1.0 / 60.0;

/// The modes a host may set: each rounding direction, and flush-to-zero
/// (with denormals-are-zero on x86-64).
const MODES: [(&str, u64); 4] = [
    (ROUNDING[0].0, DEFAULT | ROUNDING[0].1),
    (ROUNDING[1].0, DEFAULT | ROUNDING[1].1),
    (ROUNDING[2].0, DEFAULT | ROUNDING[2].1),
    ("flush to zero", DEFAULT | FLUSH),
];

/// Runs `f` in `mode`, as a host would, and checks it got its mode back.
fn in_mode<T>(mode: u64, f: impl FnOnce() -> T) -> T {
    let before = read_mode();
    write_mode(mode);
    let out = f();
    let during = read_mode() & !STATUS;
    write_mode(before);
    assert_eq!(during, mode, "a call did not give the host its mode back");
    out
}

/// The bits of everything the session computed: the world's state hash
/// after each frame, and each frame's skeleton pose.
#[derive(Debug, PartialEq)]
struct Session {
    hashes: Vec<u64>,
    poses: Vec<Vec<u32>>,
}

fn pose_bits(bones: &[Transform]) -> Vec<u32> {
    bones
        .iter()
        .flat_map(|t| {
            t.translation
                .to_array()
                .into_iter()
                .chain(t.rotation.to_array())
        })
        .map(f32::to_bits)
        .collect()
}

/// A shipped humanoid read from its file's text, built turned and
/// moving (both spines), dropped on a floor with its contacts found every
/// frame, pushed and driven to its bind pose, and mapped onto the
/// reference skeleton through a transition, for 40 frames.
fn session(text: &str, spine: SpineMode) -> Session {
    let desc = RagdollDesc::from_toml(text).expect("the reference humanoid");
    let skeleton = Skeleton::reference();
    let mut world = World::new(SolverConfig::default()).unwrap();
    let mut collisions = Collisions::new();
    let ground = world.add_body(BodyDesc::fixed()).unwrap();
    collisions
        .add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    let turn = Quat::from_rotation_y(0.7) * Quat::from_rotation_x(0.3);
    let pose = Pose::bind(&desc).moved(desc.bodies[0].centre(), turn, Vec3::new(0.1, 0.6, 0.3));
    let before = Pose::bind(&desc).moved(
        desc.bodies[0].centre(),
        turn * Quat::from_rotation_z(0.05),
        Vec3::new(0.1, 0.62, 0.3),
    );
    let options = BuildOptions::at_switch(spine);
    let ragdoll =
        Ragdoll::build(&mut world, &desc, options, &pose, Some((&before, DT))).expect("built");
    collisions.add_ragdoll(&ragdoll).unwrap();
    let mapper = SkeletonMapper::new(&skeleton, &desc, spine).unwrap();
    let animation = skeleton.bind_pose();
    let place = Transform::new(Vec3::new(0.1, 0.6, 0.3), turn);
    let transition = Transition::new(
        &mapper,
        &ragdoll,
        &world,
        &animation,
        place,
        SpineMapping::Arc,
        0.3,
    )
    .unwrap();
    let mut session = Session {
        hashes: Vec::new(),
        poses: Vec::new(),
    };
    for frame in 0..40 {
        if frame == 5 {
            ragdoll
                .apply_impulse(
                    &mut world,
                    &desc.bodies[3].name,
                    Vec3::new(3.0, 1.0, -2.0),
                    None,
                )
                .unwrap();
        }
        if frame == 10 {
            let settings = DriveSettings::uniform(Spring::Frequency {
                frequency: 4.0,
                damping_ratio: 1.0,
            });
            ragdoll
                .drive_to(&mut world, &Pose::bind(&desc), &settings)
                .unwrap();
        }
        let contacts = collisions.find_contacts(&world, DT).unwrap();
        world.set_contacts(&contacts).unwrap();
        world.step(DT).unwrap();
        session.hashes.push(world.state_hash());
        // Exact in every mode (a power of two): the test's own arithmetic
        // is the caller's.
        let since = frame as f32 / 64.0;
        let mapped = transition
            .skeleton_pose(&mapper, &ragdoll, &world, &animation, place, since)
            .unwrap();
        session.poses.push(pose_bits(&mapped.bones));
    }
    session
}

#[test]
fn a_ragdoll_session_gives_the_default_modes_bits_in_every_mode() {
    for (model, text) in [
        ("reference", REFERENCE_HUMANOID),
        ("anatomical", ANATOMICAL_HUMANOID),
    ] {
        for spine in [SpineMode::Rod, SpineMode::Sockets] {
            let reference = in_mode(DEFAULT, || session(text, spine));
            for (name, mode) in MODES {
                let here = in_mode(mode, || session(text, spine));
                let frame = reference
                    .hashes
                    .iter()
                    .zip(&here.hashes)
                    .position(|(a, b)| a != b);
                assert_eq!(
                    frame, None,
                    "{model}, {spine:?}, {name}: the world differs from frame"
                );
                let frame = reference
                    .poses
                    .iter()
                    .zip(&here.poses)
                    .position(|(a, b)| a != b);
                assert_eq!(
                    frame, None,
                    "{model}, {spine:?}, {name}: the skeleton differs from frame"
                );
            }
        }
    }
}
