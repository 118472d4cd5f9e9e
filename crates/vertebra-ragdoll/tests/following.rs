//! Driving along a moving animation (`Ragdoll::drive_following`): the
//! drives, the rod spine's included, turn with the animation instead of
//! chasing it.

use glam::{Quat, Vec3};
use vertebra_ragdoll::{
    BuildOptions, DriveSettings, JointDef, Pose, Ragdoll, RagdollDesc, SpineMode,
};
use vertebra_world::{BodyDesc, JointDesc, SolverConfig, Spring, World};

const DT: f32 = 1.0 / 60.0;
/// The animations' rate: the elbow's bend, the spine's total bend (rad/s).
const SPEED: f32 = 1.0;
/// The spine's animation is slower: half a radian in the second, well
/// inside the rod's 60-degree bend limit.
const SPINE_SPEED: f32 = 0.5;
/// Frames each animation runs.
const FRAMES: usize = 60;

/// The anatomical humanoid with each joint turned by `rotation` (world
/// frame at bind pose), the hips at bind pose.
fn pose(desc: &RagdollDesc, rotation: impl Fn(&JointDef) -> Quat) -> Pose {
    let rotations: Vec<Quat> = desc.joints.iter().map(rotation).collect();
    let root = (desc.bodies[desc.root].centre(), Quat::IDENTITY);
    Pose::from_joint_rotations(desc, root, &rotations).unwrap()
}

/// The anatomical humanoid at `elbow` radians of left elbow bend (about
/// the hinge's axis, -X), everything else at bind pose.
fn elbow_pose(desc: &RagdollDesc, elbow: f32) -> Pose {
    pose(desc, |j| {
        if j.name == "elbow_l" {
            Quat::from_axis_angle(j.axis(), elbow)
        } else {
            Quat::IDENTITY
        }
    })
}

/// The anatomical humanoid with its spine bent sideways (about +Z) by
/// `bend` radians from the hips to the chest, a third at each spine
/// joint, everything else at bind pose.
fn spine_pose(desc: &RagdollDesc, bend: f32) -> Pose {
    pose(desc, |j| {
        if j.name.starts_with("spine_") {
            Quat::from_rotation_z(bend / 3.0)
        } else {
            Quat::IDENTITY
        }
    })
}

/// The anatomical humanoid with `spine`, hips held by a static body, no
/// gravity, driven for `FRAMES` frames along `animation` (the pose at each
/// frame's end) with or without the animation's velocity; the world and
/// ragdoll afterwards.
fn follow(
    spine: SpineMode,
    animation: impl Fn(&RagdollDesc, usize) -> Pose,
    following: bool,
    settings: &DriveSettings,
) -> (World, Ragdoll, RagdollDesc) {
    let desc = RagdollDesc::anatomical_humanoid();
    let config = SolverConfig {
        gravity: Vec3::ZERO,
        ..SolverConfig::default()
    };
    let mut world = World::new(config).unwrap();
    let ragdoll = Ragdoll::build(
        &mut world,
        &desc,
        BuildOptions::new(spine),
        &Pose::bind(&desc),
        None,
    )
    .unwrap();
    let hips = ragdoll.bodies[desc.root].unwrap();
    let at = world.body(hips).unwrap().position;
    let anchor = world.add_body(BodyDesc::fixed().with_position(at)).unwrap();
    world
        .add_joint(JointDesc::fixed_at(world.bodies(), anchor, hips, at).unwrap())
        .unwrap();
    for frame in 0..FRAMES {
        let (prev, next) = (animation(&desc, frame), animation(&desc, frame + 1));
        if following {
            ragdoll
                .drive_following(&mut world, &prev, &next, DT, settings)
                .unwrap();
        } else {
            ragdoll.drive_to(&mut world, &next, settings).unwrap();
        }
        world.step(DT).unwrap();
    }
    (world, ragdoll, desc)
}

/// Body `body`'s orientation in `world`.
fn orientation(world: &World, ragdoll: &Ragdoll, body: usize) -> Quat {
    world
        .body(ragdoll.bodies[body].unwrap())
        .unwrap()
        .orientation
}

/// The left elbow's lag behind its animation (rad) after a second of
/// following it at `SPEED`, with or without the animation's velocity.
fn lag(following: bool, settings: &DriveSettings) -> f32 {
    let animation = |desc: &RagdollDesc, frame: usize| elbow_pose(desc, SPEED * DT * frame as f32);
    let (world, ragdoll, desc) = follow(SpineMode::Sockets, animation, following, settings);
    let elbow = desc.joints.iter().find(|j| j.name == "elbow_l").unwrap();
    let q = |body| orientation(&world, &ragdoll, body);
    let relative = (q(elbow.parent) * elbow.frame).inverse() * (q(elbow.child) * elbow.frame);
    let angle = 2.0 * relative.x.atan2(relative.w);
    SPEED * DT * FRAMES as f32 - angle
}

/// The rod spine's lag behind its animation (rad): the chest's bend about
/// +Z relative to the hips, after a second of following the spine bending
/// at `SPINE_SPEED`, with or without the animation's velocity.
fn spine_lag(following: bool, settings: &DriveSettings) -> f32 {
    let animation =
        |desc: &RagdollDesc, frame: usize| spine_pose(desc, SPINE_SPEED * DT * frame as f32);
    let (world, ragdoll, desc) = follow(SpineMode::Rod, animation, following, settings);
    let spine = desc.spine.as_ref().unwrap();
    let q = |body| orientation(&world, &ragdoll, body);
    let relative = q(spine.bodies[0]).inverse() * q(*spine.bodies.last().unwrap());
    let angle = 2.0 * relative.z.atan2(relative.w);
    SPINE_SPEED * DT * FRAMES as f32 - angle
}

#[test]
fn a_drive_following_the_animation_does_not_lag() {
    // A spring-damper chasing a target that moves at v, damped against
    // rest, settles lagging by e = 2 zeta v / omega (the steady state of
    // e'' + 2 zeta omega e' + omega^2 e = 2 zeta omega v); damped against
    // the target's own motion, it settles on it (e = 0). Measured: 0.0810
    // rad against 0.0796, and -0.001.
    let (frequency, zeta) = (4.0, 1.0);
    let settings = DriveSettings::uniform(Spring::Frequency {
        frequency,
        damping_ratio: zeta,
    });
    let omega = 2.0 * core::f32::consts::PI * frequency;
    let expected = 2.0 * zeta * SPEED / omega;
    let (chasing, following) = (lag(false, &settings), lag(true, &settings));
    eprintln!("lag: chasing {chasing} rad (closed form {expected}), following {following} rad");
    assert!(
        (chasing - expected).abs() < 0.25 * expected,
        "chasing lags {chasing}, closed form {expected}"
    );
    assert!(
        following.abs() < 0.1 * expected,
        "following lags {following}"
    );
}

#[test]
fn a_rod_spine_following_the_animation_does_not_lag() {
    // The rod's rest shape is the spine's drive target. A spring-damper of
    // stiffness K and damping D chasing a target that moves at v settles
    // D v / K behind it; the rod stands for n sockets in series of
    // compliance c and damping D_s (K = 1 / (n c), D = D_s / n), so the
    // rod spine driven to each frame's end pose lags c D_s v, the damping
    // time times the speed, as each socket would. Following, its rest moves
    // at the animation's rates and damping acts on the bend relative to it:
    // no lag. By compliance, not frequency: the hips are held by a joint
    // the rod cannot see, so a rod spring is set on the effective inertia
    // of a free pair, many times below the upper body's about the held
    // hips, and at 4 Hz rings near 0.7 Hz for seconds. Measured: 0.0599
    // rad against 0.0600, and 1.1e-5.
    let (compliance, damping) = (0.001, 120.0);
    let settings = DriveSettings::uniform(Spring::Compliance {
        compliance,
        damping,
    });
    let expected = compliance * damping * SPINE_SPEED;
    let (chasing, following) = (spine_lag(false, &settings), spine_lag(true, &settings));
    eprintln!(
        "rod spine lag: chasing {chasing} rad (closed form {expected}), following {following} rad"
    );
    assert!(
        (chasing - expected).abs() < 0.05 * expected,
        "chasing lags {chasing}, closed form {expected}"
    );
    assert!(
        following.abs() < 0.02 * expected,
        "following lags {following}"
    );
}

/// The anatomical humanoid (rod spine) built at its bind pose in a world
/// of its own, and that pose.
fn anatomical_at_bind() -> (RagdollDesc, World, Pose, Ragdoll) {
    let desc = RagdollDesc::anatomical_humanoid();
    let mut world = World::new(SolverConfig::default()).unwrap();
    let bind = Pose::bind(&desc);
    let ragdoll = Ragdoll::build(
        &mut world,
        &desc,
        BuildOptions::new(SpineMode::Rod),
        &bind,
        None,
    )
    .unwrap();
    (desc, world, bind, ragdoll)
}

#[test]
fn a_step_that_is_no_time_is_refused() {
    let (_, mut world, bind, ragdoll) = anatomical_at_bind();
    let settings = DriveSettings::uniform(Spring::RIGID);
    for dt in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let before = world.state_hash();
        let e = ragdoll
            .drive_following(&mut world, &bind, &bind, dt, &settings)
            .unwrap_err();
        assert!(e.to_string().contains("dt"), "{e}");
        assert_eq!(world.state_hash(), before);
    }
}

/// A strength the world refuses is refused by `drive_to` and
/// `drive_following` before anything is set, naming the settings' field or
/// the joint whose override it is, with the world's reason (which names
/// the number).
#[test]
fn bad_strengths_are_refused_naming_the_joint_and_change_nothing() {
    let (desc, mut world, bind, ragdoll) = anatomical_at_bind();
    let bad = Spring::Frequency {
        frequency: 0.0,
        damping_ratio: 1.0,
    };
    let knee = desc.joints.iter().position(|j| j.name == "knee_l").unwrap();
    let mut overridden = DriveSettings::uniform(Spring::RIGID);
    overridden.joints = vec![None; desc.joints.len()];
    overridden.joints[knee] = Some(Spring::Compliance {
        compliance: 0.01,
        damping: f32::NAN,
    });
    let cases = [
        (
            DriveSettings::uniform(bad),
            "drive: strength is refused: drive frequency (at least 1e-3 Hz) is out of range",
        ),
        (
            overridden,
            "joint `knee_l`: drive is refused: drive damping is not finite",
        ),
    ];
    for (settings, expected) in cases {
        let before = world.state_hash();
        let e = ragdoll.drive_to(&mut world, &bind, &settings).unwrap_err();
        assert_eq!(e.to_string(), expected);
        let e = ragdoll
            .drive_following(&mut world, &bind, &bind, 1.0 / 60.0, &settings)
            .unwrap_err();
        assert_eq!(e.to_string(), expected);
        assert_eq!(
            world.state_hash(),
            before,
            "a refused drive changed the world"
        );
    }
}

/// An animation turning one joint too fast for the world to drive is
/// refused naming that joint, and no joint's drive changes: the ones
/// before it in the description included.
#[test]
fn a_joint_turning_too_fast_is_refused_and_no_drive_changes() {
    let (desc, mut world, bind, ragdoll) = anatomical_at_bind();
    let settings = DriveSettings::uniform(Spring::RIGID);
    ragdoll.drive_to(&mut world, &bind, &settings).unwrap();
    let drives = |world: &World| -> Vec<Option<vertebra_world::AngularDrive>> {
        (ragdoll.joints.iter().flatten())
            .map(|&j| world.joint(j).unwrap().drive)
            .collect()
    };
    let before = drives(&world);
    // The last joint in the description turns 2.5 rad in a microsecond.
    let last = desc.joints.last().unwrap().name.clone();
    let fast = pose(&desc, |j| {
        if j.name == last {
            Quat::from_axis_angle(j.axis(), 2.5)
        } else {
            Quat::IDENTITY
        }
    });
    // Softer drives than the ones set: any joint set would show.
    let softer = DriveSettings::uniform(Spring::Frequency {
        frequency: 5.0,
        damping_ratio: 1.0,
    });
    let e = ragdoll
        .drive_following(&mut world, &bind, &fast, 1e-6, &softer)
        .unwrap_err();
    assert!(e.to_string().contains(&format!("joint `{last}`")), "{e}");
    assert_eq!(drives(&world), before, "a refused call changed a drive");
}
