//! Every value the API accepts gives a finite, bounded step with the
//! last-line NaN guard silent; values beyond the documented ranges are
//! refused with the field named.

mod common;

use common::capsule;
use glam::{Quat, Vec3};
use vertebra_world::{
    AngularDrive, BodyHandle, Contact, Error, MAX_ANGULAR_SPEED_LIMIT, MAX_COORDINATE,
    MAX_DRIVE_DAMPING_RATIO, MAX_DRIVE_DAMPING_TIME, MAX_LINEAR_SPEED_LIMIT, MAX_ROD_LENGTH,
    MAX_SOLVER_SWEEPS, MAX_THREADS, MIN_DRIVE_FREQUENCY, RodDesc, RodStiffness, SolverConfig,
    World,
};

/// Steps `world` a second at 60 Hz; every body stays finite, within
/// `bound` m of the origin and within the speed limits after every step,
/// and the NaN guard never fires.
fn steps_clean(world: &mut World, bound: f32) {
    for _ in 0..60 {
        world.step(1.0 / 60.0).expect("a valid step");
        within_speed_limits(world);
    }
    let store = world.bodies();
    for i in (0..store.capacity()).filter(|&i| store.is_live(i)) {
        assert!(store.is_finite(i), "body {i} went non-finite");
        let s = store.state(store.handle_at(i).unwrap()).unwrap();
        assert!(
            s.position.abs().max_element() <= bound,
            "body {i} at {}",
            s.position
        );
    }
    assert_eq!(world.repaired_bodies(), 0, "the NaN guard fired");
}

/// Every body's speed and spin within the configured limits (to rounding).
fn within_speed_limits(world: &World) {
    let (config, store) = (world.config(), world.bodies());
    for i in (0..store.capacity()).filter(|&i| store.is_live(i)) {
        let v = store.linear_velocity[i].length();
        let w = store.angular_velocity[i].length();
        assert!(
            v <= config.max_linear_speed * (1.0 + 1e-6),
            "body {i}: {v} m/s"
        );
        assert!(
            w <= config.max_angular_speed * (1.0 + 1e-6),
            "body {i}: {w} rad/s"
        );
    }
}

/// A hard correction that moves a body 100 m in one step (a socket whose
/// anchors start 100 m apart) reports at most the speed limit, not the
/// 2,000 m/s its motion implies.
#[test]
fn hard_corrections_report_within_the_speed_limits() {
    let mut world = World::new(SolverConfig::default()).expect("default config");
    let (a, b) = two_bodies(&mut world);
    let socket = vertebra_world::JointDesc::socket_at_world_anchor(
        world.bodies(),
        a,
        b,
        Vec3::new(0.0, -0.45, 0.0),
        -Vec3::Y,
    )
    .expect("socket");
    world.add_joint(socket).expect("socket");
    world
        .set_body_pose(b, Vec3::new(100.0, 0.0, 0.0), Quat::IDENTITY)
        .expect("pose");
    world.step(1.0 / 60.0).expect("step");
    within_speed_limits(&world);
}

/// An accepted spin of 1.8e38 rad/s on a body in contact steps finite and
/// within the limits (the world holds it to the limit before the
/// contact measures its approach speed, where `w x r` can overflow).
#[test]
fn accepted_spins_are_held_before_contacts_measure_them() {
    // A slow spin limit, so that the body barely turns and its contact
    // stays closed through the step.
    let config = SolverConfig {
        max_angular_speed: 1.0,
        ..SolverConfig::default()
    };
    let mut world = World::new(config).expect("valid config");
    let (a, b) = two_bodies(&mut world);
    world
        .set_body_velocity(a, Vec3::ZERO, Vec3::new(1.8e38, 0.0, 0.0))
        .expect("finite, so accepted");
    let far_point = Contact {
        point: Vec3::new(0.0, -0.45, 5.0),
        ..contact(a, b, 0.01)
    };
    world.set_contacts(&[far_point]).expect("contact");
    world.step(1.0 / 60.0).expect("step");
    within_speed_limits(&world);
    assert_eq!(world.repaired_bodies(), 0, "the NaN guard fired");
}

fn two_bodies(world: &mut World) -> (BodyHandle, BodyHandle) {
    let a = capsule(world, Vec3::ZERO, Vec3::new(0.0, -0.4, 0.0), 2.0);
    let b = capsule(
        world,
        Vec3::new(0.0, -0.5, 0.0),
        Vec3::new(0.0, -0.9, 0.0),
        1.0,
    );
    (a, b)
}

fn config_error(config: SolverConfig) -> Error {
    World::new(config).err().expect("refused")
}

#[test]
fn solver_settings_beyond_their_ranges_are_refused() {
    let sweeps = Error::InvalidConfig("substeps x iterations must be at most 10000");
    for (substeps, iterations) in [
        (1, u32::MAX),
        (u32::MAX, 1),
        (u32::MAX, u32::MAX),
        (101, 100),
    ] {
        let config = SolverConfig {
            substeps,
            iterations,
            ..SolverConfig::default()
        };
        assert_eq!(config_error(config), sweeps, "{substeps} x {iterations}");
    }
    for threads in [MAX_THREADS + 1, usize::MAX] {
        assert_eq!(
            config_error(SolverConfig {
                threads,
                ..SolverConfig::default()
            }),
            Error::InvalidConfig("threads must be at most 256")
        );
    }
    for speed in [
        f32::MAX,
        f32::INFINITY,
        f32::NAN,
        0.0,
        -1.0,
        MAX_LINEAR_SPEED_LIMIT * 1.01,
    ] {
        let config = SolverConfig {
            max_linear_speed: speed,
            ..SolverConfig::default()
        };
        assert_eq!(
            config_error(config),
            Error::InvalidConfig("max_linear_speed must be positive and at most 1e6 m/s")
        );
    }
    for speed in [
        f32::MAX,
        f32::INFINITY,
        f32::NAN,
        0.0,
        MAX_ANGULAR_SPEED_LIMIT * 1.01,
    ] {
        let config = SolverConfig {
            max_angular_speed: speed,
            ..SolverConfig::default()
        };
        assert_eq!(
            config_error(config),
            Error::InvalidConfig("max_angular_speed must be positive and at most 1e6 rad/s")
        );
    }
}

/// Every setting at the edge of its range: speed limits at their ceilings,
/// gravity at `f32::MAX`, bodies thrown at 1e30 m/s and rad/s, a socket
/// driven with compliance and damping of `f32::MAX`: the step stays finite
/// and within one step's motion per step.
#[test]
fn settings_at_their_limits_step_finite_and_bounded() {
    for gravity in [0.0, f32::MAX] {
        let mut world = World::new(SolverConfig {
            max_linear_speed: MAX_LINEAR_SPEED_LIMIT,
            max_angular_speed: MAX_ANGULAR_SPEED_LIMIT,
            gravity: Vec3::new(0.0, -gravity, 0.0),
            ..SolverConfig::default()
        })
        .unwrap();
        let (a, b) = two_bodies(&mut world);
        world
            .set_body_velocity(a, Vec3::splat(1e30), Vec3::splat(1e30))
            .unwrap();
        let socket = vertebra_world::JointDesc::socket_at_world_anchor(
            world.bodies(),
            a,
            b,
            Vec3::new(0.0, -0.45, 0.0),
            -Vec3::Y,
        )
        .unwrap();
        let drive = AngularDrive::compliant(Quat::from_rotation_z(1.0), f32::MAX, 0.0)
            .with_target_velocity(Vec3::X * MAX_ANGULAR_SPEED_LIMIT);
        let slow = AngularDrive::spring(
            Quat::from_rotation_z(1.0),
            MIN_DRIVE_FREQUENCY,
            MAX_DRIVE_DAMPING_RATIO,
        );
        let sticky = AngularDrive::compliant(Quat::IDENTITY, 1e-30, MAX_DRIVE_DAMPING_TIME / 1e-30)
            .with_max_torque(f32::MAX);
        world.add_joint(socket.with_drive(drive)).unwrap();
        for d in [slow, sticky] {
            let extra = world
                .add_body(vertebra_world::BodyDesc::dynamic(
                    vertebra_world::Shape::Sphere { radius: 0.1 }
                        .mass_properties_with_mass(1.0)
                        .unwrap(),
                ))
                .unwrap();
            let s = vertebra_world::JointDesc::socket_at_world_anchor(
                world.bodies(),
                a,
                extra,
                Vec3::ZERO,
                Vec3::X,
            )
            .unwrap();
            world.add_joint(s.with_drive(d)).unwrap();
        }
        // 60 steps of at most MAX_LINEAR_SPEED_LIMIT / 60 m each.
        steps_clean(&mut world, MAX_LINEAR_SPEED_LIMIT * 1.01);
    }
    for (substeps, iterations) in [(1, MAX_SOLVER_SWEEPS), (MAX_SOLVER_SWEEPS, 1), (100, 100)] {
        let mut world = World::new(SolverConfig {
            substeps,
            iterations,
            ..SolverConfig::default()
        })
        .unwrap();
        two_bodies(&mut world);
        world.step(1.0 / 60.0).expect("a step at the most sweeps");
    }
    assert!(
        World::new(SolverConfig {
            threads: MAX_THREADS,
            ..SolverConfig::default()
        })
        .is_ok()
    );
}

fn rod_world(configure: impl FnOnce(RodDesc) -> RodDesc) -> (World, Result<(), Error>) {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let (a, b) = two_bodies(&mut world);
    let rod = RodDesc::from_pose(world.bodies(), a, b, &[]).unwrap();
    let result = world.add_rod(configure(rod)).map(|_| ());
    (world, result)
}

#[test]
fn rod_rest_lengths_beyond_any_body_pair_are_refused() {
    for length in [1e30, MAX_ROD_LENGTH * 1.01, f32::MAX] {
        let (world, result) = rod_world(|r| RodDesc {
            rest_length: length,
            ..r
        });
        assert_eq!(
            result,
            Err(Error::OutOfRange("rod rest length (at most 6e6 m)"))
        );
        assert_eq!(world.rods().count(), 0);
    }
    // set_rod checks the same.
    let (mut world, result) = rod_world(|r| r);
    result.unwrap();
    let (handle, rod) = world.rods().next().unwrap();
    assert_eq!(
        world.set_rod(
            handle,
            RodDesc {
                rest_length: 1e30,
                ..rod
            }
        ),
        Err(Error::OutOfRange("rod rest length (at most 6e6 m)"))
    );
}

/// The longest and shortest rest lengths, stiff and soft, limited, a rest
/// twist of 1e30 rad, with the bodies spinning: finite, and the NaN guard
/// (which fired every substep at a rest length of 1e30 m) silent.
#[test]
fn rods_at_the_ends_of_their_ranges_step_finite() {
    for length in [MAX_ROD_LENGTH, 1e-30] {
        for k in [0.0, 1e-30, 1e30, f32::INFINITY] {
            let (mut world, result) = rod_world(|r| {
                RodDesc {
                    rest_length: length,
                    twist_rest: 1e30,
                    ..r
                }
                .with_stiffness(RodStiffness::Kirchhoff(k), RodStiffness::Kirchhoff(k))
                .with_bend_limit(0.2)
                .with_twist_limit(-0.1, 0.1)
            });
            result.unwrap();
            let b = world.bodies().handle_at(1).unwrap();
            world
                .set_body_velocity(b, Vec3::new(3.0, 0.0, 0.0), Vec3::new(0.0, 30.0, 5.0))
                .unwrap();
            // The rod may throw its ends apart by its own length.
            steps_clean(&mut world, MAX_ROD_LENGTH + MAX_COORDINATE);
        }
    }
}

fn contact(a: BodyHandle, b: BodyHandle, depth: f32) -> Contact {
    Contact {
        body_a: a,
        body_b: b,
        point: Vec3::new(0.0, -0.45, 0.0),
        normal: -Vec3::Y,
        depth,
        friction: 0.5,
        restitution: 1.0,
    }
}

/// A restitution outside [0, 1] is refused as out of range, in words (it
/// read "invalid restitution (must be in [0, 1]) limit").
#[test]
fn contact_restitution_beyond_zero_to_one_is_refused_in_words() {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let (a, b) = two_bodies(&mut world);
    for restitution in [1.5, -0.1, f32::NAN] {
        let bouncy = Contact {
            restitution,
            ..contact(a, b, 0.01)
        };
        let e = world.set_contacts(&[bouncy]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "contact 0: contact restitution (0 to 1) is out of range"
        );
    }
}

#[test]
fn contact_depths_beyond_the_coordinate_range_are_refused() {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let (a, b) = two_bodies(&mut world);
    for depth in [1e30, -1e30, MAX_COORDINATE * 1.01] {
        assert_eq!(
            world.set_contacts(&[contact(a, b, depth)]),
            Err(Error::Contact {
                index: 0,
                reason: Box::new(Error::OutOfRange("contact depth (at most 1e6 m)"))
            })
        );
    }
    // The deepest accepted overlap pushes the bodies apart by at most it.
    for depth in [MAX_COORDINATE, -MAX_COORDINATE] {
        let mut world = World::new(SolverConfig::default()).unwrap();
        let (a, b) = two_bodies(&mut world);
        world.set_body_pose(a, Vec3::ZERO, Quat::IDENTITY).unwrap();
        world.set_contacts(&[contact(a, b, depth)]).unwrap();
        steps_clean(&mut world, 2.0 * MAX_COORDINATE);
    }
}
