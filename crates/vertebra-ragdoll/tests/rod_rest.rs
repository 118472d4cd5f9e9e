//! Where a simplified ragdoll's rod takes its rest shape and limits from
//! (`RodRest`): the switch pose (the paper's, the default) or the bind
//! pose (as the sockets').

use core::f32::consts::PI;

use glam::{Quat, Vec3};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, RodRest, SpineMode};
use vertebra_world::{SolverConfig, World};

/// The reference humanoid switched on with its spine twisted by `tau`
/// (each of its three joints by a third, about +Y), no gravity.
fn twisted(tau: f32, rod_rest: RodRest) -> (World, Ragdoll) {
    let desc = RagdollDesc::reference_humanoid();
    let mut rotations = vec![Quat::IDENTITY; desc.joints.len()];
    for &k in &desc.spine.as_ref().unwrap().joints {
        rotations[k] = Quat::from_rotation_y(tau / 3.0);
    }
    let pose = Pose::from_joint_rotations(
        &desc,
        (Vec3::new(0.0, 1.0, 0.0), Quat::IDENTITY),
        &rotations,
    )
    .unwrap();
    let mut world = World::new(SolverConfig {
        gravity: Vec3::ZERO,
        ..SolverConfig::default()
    })
    .unwrap();
    let options = BuildOptions {
        rod_rest,
        ..BuildOptions::new(SpineMode::Rod)
    };
    let ragdoll = Ragdoll::build(&mut world, &desc, options, &pose, None).unwrap();
    (world, ragdoll)
}

/// The chest's twist about the hips' +Y (rad).
fn spine_twist(world: &World, ragdoll: &Ragdoll) -> f32 {
    let at = |b: usize| world.body(ragdoll.bodies[b].unwrap()).unwrap().orientation;
    let relative = at(0).conjugate() * at(3);
    2.0 * relative.y.atan2(relative.w)
}

/// Closed forms: twisted by `tau` at the switch, a rod made there measures
/// a twist of 0 there, so from the switch its rest twist is 0 and its range
/// the file's +-30 degrees; from bind pose (twisted back by `tau`) its rest
/// twist is `-tau` and its range `[-tau - 30, -tau + 30]` degrees. The
/// spine is straight either way: the rest bend is none and the bend limit
/// the file's 60 degrees.
#[test]
fn the_rest_twist_and_range_come_from_the_switch_or_from_bind() {
    let tau = 0.5;
    let limit = 30f32.to_radians();
    for (rest, twist) in [(RodRest::Transition, 0.0), (RodRest::Bind, -tau)] {
        let (world, ragdoll) = twisted(tau, rest);
        let rod = world.rod(ragdoll.rod.unwrap()).unwrap();
        assert!(
            (rod.twist_rest - twist).abs() < 1e-5,
            "{rest:?}: {}",
            rod.twist_rest
        );
        let [lo, hi] = rod.twist_limit.unwrap();
        assert!((lo - (twist - limit)).abs() < 1e-5 && (hi - (twist + limit)).abs() < 1e-5);
        assert!(
            rod.bend_rest.distance(Vec3::X) < 1e-5,
            "{rest:?}: {}",
            rod.bend_rest
        );
        assert!((rod.bend_limit.unwrap() - 60f32.to_radians()).abs() < 1e-4);
    }
    // A range that would pass pi is held at it.
    let (world, ragdoll) = twisted(-2.9, RodRest::Bind);
    let [_, hi] = world
        .rod(ragdoll.rod.unwrap())
        .unwrap()
        .twist_limit
        .unwrap();
    assert_eq!(hi, PI);
}

/// Left alone after the switch: from the switch, the spine has no twisting
/// energy and keeps the twist the animation gave it; from bind pose, its
/// stiffness (undamped) swings it back through bind, to the other side.
#[test]
fn from_bind_pose_the_spine_untwists_and_from_the_switch_it_stays() {
    let tau = 0.5;
    for rest in [RodRest::Transition, RodRest::Bind] {
        let (mut world, ragdoll) = twisted(tau, rest);
        let (mut least, mut most) = (f32::INFINITY, f32::NEG_INFINITY);
        for _ in 0..120 {
            world.step(1.0 / 60.0).unwrap();
            let twist = spine_twist(&world, &ragdoll);
            least = least.min(twist);
            most = most.max(twist);
        }
        match rest {
            RodRest::Transition => {
                assert!(
                    (least - tau).abs() < 1e-3 && (most - tau).abs() < 1e-3,
                    "{least}..{most}"
                )
            }
            RodRest::Bind => assert!(least < -0.5 * tau && most <= tau + 1e-3, "{least}..{most}"),
        }
    }
}
