//! World drives and upright drives (`WorldDrive`, `UprightDrive`): a body
//! alone follows its drive's oscillator at the stated frequency and ratio,
//! whatever its mass and inertia; a capped drive pushes at its cap and no
//! harder; a moving target is followed without lag; the upright drive
//! rights a body without touching its spin about the held axis; refused
//! calls name the field and change nothing; the targets move on through
//! steps, snapshots and sleep as a joint drive's do.

mod common;

use core::f32::consts::TAU;

use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, BodyHandle, Error, JointDesc, Shape, SleepSettings, SolverConfig, Spring,
    UprightDrive, World, WorldDrive,
};

const DT: f32 = 1.0 / 60.0;
const HZ: f32 = 2.0;
const ZETA: f32 = 0.3;

fn world(gravity: Vec3) -> World {
    World::new(SolverConfig {
        substeps: 10,
        iterations: 4,
        gravity,
        sleep: None,
        ..SolverConfig::default()
    })
    .unwrap()
}

/// A box of `mass` kg with half extents (0.1, 0.2, 0.3) m (inertias about
/// 1:2.5:3.4), at `position`.
fn block(world: &mut World, mass: f32, position: Vec3) -> BodyHandle {
    let shape = Shape::Box {
        half_extents: Vec3::new(0.1, 0.2, 0.3),
    };
    let props = shape.mass_properties_with_mass(mass).unwrap();
    world
        .add_body(BodyDesc::dynamic(props).with_position(position))
        .unwrap()
}

fn spring(frequency: f32, damping_ratio: f32) -> Spring {
    Spring::Frequency {
        frequency,
        damping_ratio,
    }
}

#[test]
fn a_body_follows_its_world_drive_oscillator_whatever_its_mass() {
    for mass in [0.5, 8.0, 80.0] {
        let mut w = world(Vec3::ZERO);
        let body = block(&mut w, mass, Vec3::new(0.1, 0.0, 0.0));
        let drive = WorldDrive::new(Vec3::ZERO, Quat::IDENTITY, spring(HZ, ZETA));
        w.set_world_drive(body, Some(drive)).unwrap();
        let x: Vec<f32> = (0..120)
            .map(|_| {
                w.step(DT).unwrap();
                w.body(body).unwrap().position.x
            })
            .collect();
        let (hz, zeta) = common::frequency_and_ratio(&x, 0.0, DT);
        eprintln!("{mass} kg: {hz:.3} Hz, ratio {zeta:.3}");
        // Implicit Euler adds about omega h / 2 = 0.01 to the ratio.
        assert!((hz / HZ - 1.0).abs() < 0.02, "{mass} kg: {hz} Hz");
        assert!((zeta / ZETA - 1.0).abs() < 0.05, "{mass} kg: ratio {zeta}");
        let worst = (x.iter().enumerate())
            .map(|(k, x)| {
                let closed = 0.1 - common::underdamped((k + 1) as f32 * DT, TAU * HZ, ZETA, 0.1);
                (x - closed).abs()
            })
            .fold(0.0, f32::max);
        assert!(
            worst < 0.05 * 0.1,
            "{mass} kg: {worst} m from the closed form"
        );
    }
}

#[test]
fn an_anisotropic_body_turns_back_about_one_axis_at_the_stated_frequency() {
    let mut w = world(Vec3::ZERO);
    let body = block(&mut w, 3.0, Vec3::ZERO);
    let axis = Vec3::new(1.0, 2.0, 3.0).normalize();
    w.set_body_pose(body, Vec3::ZERO, Quat::from_axis_angle(axis, 0.4))
        .unwrap();
    let drive = WorldDrive::new(Vec3::ZERO, Quat::IDENTITY, spring(HZ, ZETA));
    w.set_world_drive(body, Some(drive)).unwrap();
    let mut angles = Vec::new();
    let mut off_axis: f32 = 0.0;
    for _ in 0..120 {
        w.step(DT).unwrap();
        let v = w.body(body).unwrap().orientation.to_scaled_axis();
        angles.push(v.dot(axis));
        off_axis = off_axis.max(v.reject_from(axis).length());
    }
    let (hz, zeta) = common::frequency_and_ratio(&angles, 0.0, DT);
    eprintln!("{hz:.3} Hz, ratio {zeta:.3}, {off_axis:.2e} rad off the axis");
    assert!((hz / HZ - 1.0).abs() < 0.02, "{hz} Hz");
    assert!((zeta / ZETA - 1.0).abs() < 0.05, "ratio {zeta}");
    // The mass cancels per axis, inertias 1:2.5:3.4 or not: the turn
    // keeps to its axis but for the gyroscopic term of a box turning about
    // an axis that is not principal.
    assert!(off_axis < 0.05 * 0.4, "{off_axis} rad off the axis");
}

#[test]
fn a_capped_drive_pushes_at_its_cap_and_no_harder() {
    // Held at its place against gravity by a drive capped at half its
    // weight: it falls at g / 2. Capped above its weight, it hangs.
    let g = 9.81;
    for (cap, fall) in [(0.5, 0.5 * 0.5 * g), (2.0, 0.0)] {
        let mut w = world(Vec3::new(0.0, -g, 0.0));
        let body = block(&mut w, 4.0, Vec3::ZERO);
        let drive = WorldDrive::new(Vec3::ZERO, Quat::IDENTITY, Spring::RIGID)
            .with_caps(cap * 4.0 * g, f32::INFINITY);
        w.set_world_drive(body, Some(drive)).unwrap();
        for _ in 0..60 {
            w.step(DT).unwrap();
        }
        let y = w.body(body).unwrap().position.y;
        eprintln!("cap {cap} of its weight: {y} m after 1 s");
        assert!((y + fall).abs() < 0.01 * fall.max(0.1), "cap {cap}: {y} m");
    }
}

#[test]
fn a_capped_orientation_part_turns_the_body_at_its_cap() {
    // A torque cap of 1 N m on a rigid orientation drive 1 rad away: the
    // body turns as a constant 1 N m turns it (about its principal x
    // axis: angle = t^2 / (2 I)).
    let mut w = world(Vec3::ZERO);
    let body = block(&mut w, 3.0, Vec3::ZERO);
    let target = Quat::from_rotation_x(1.0);
    let drive = WorldDrive::new(Vec3::ZERO, target, Spring::RIGID).with_caps(f32::INFINITY, 1.0);
    w.set_world_drive(body, Some(drive)).unwrap();
    let inertia = 3.0 * (0.4 * 0.4 + 0.6 * 0.6) / 12.0;
    for _ in 0..20 {
        w.step(DT).unwrap();
    }
    let t = 20.0 * DT;
    let angle = w.body(body).unwrap().orientation.to_scaled_axis().x;
    let expected = t * t / (2.0 * inertia);
    eprintln!("{angle} rad after {t} s (a constant 1 N m: {expected})");
    assert!(
        (angle / expected - 1.0).abs() < 0.02,
        "{angle} against {expected}"
    );
}

#[test]
fn a_moving_target_is_followed_without_lag_and_moves_on_in_the_description() {
    let mut w = world(Vec3::ZERO);
    let body = block(&mut w, 2.0, Vec3::ZERO);
    let velocity = Vec3::new(1.0, 0.0, 0.5);
    let spin = Vec3::new(0.0, 1.0, 0.0);
    let mut drive = WorldDrive::new(Vec3::ZERO, Quat::IDENTITY, spring(4.0, 1.0));
    drive.linear_velocity = velocity;
    drive.angular_velocity = spin;
    w.set_world_drive(body, Some(drive)).unwrap();
    let steps = 180;
    for _ in 0..steps {
        w.step(DT).unwrap();
    }
    let t = steps as f32 * DT;
    let state = w.body(body).unwrap();
    let kept = w.world_drive(body).unwrap().unwrap();
    assert!(
        (kept.position - velocity * t).length() < 1e-4,
        "{}",
        kept.position
    );
    let turn = Quat::from_scaled_axis(spin * t);
    assert!(common::angle_between(kept.orientation, turn) < 1e-4);
    let lag = (state.position - kept.position).length();
    let turn_lag = common::angle_between(state.orientation, kept.orientation);
    eprintln!("after {t} s: {lag:.2e} m and {turn_lag:.2e} rad behind");
    assert!(lag < 1e-3 && turn_lag < 1e-3, "{lag} m, {turn_lag} rad");
}

#[test]
fn following_an_animation_reaches_its_pose_at_the_end_of_the_step() {
    let mut w = world(Vec3::ZERO);
    let body = block(&mut w, 2.0, Vec3::ZERO);
    let base = WorldDrive::new(Vec3::ZERO, Quat::IDENTITY, Spring::RIGID);
    let mut prev = (Vec3::ZERO, Quat::IDENTITY);
    for k in 1..=30 {
        let t = k as f32 * DT;
        let pose = (Vec3::new(t.sin(), 0.0, 0.0), Quat::from_rotation_z(0.5 * t));
        let drive = base.following(prev, pose, DT).unwrap();
        w.set_world_drive(body, Some(drive)).unwrap();
        w.step(DT).unwrap();
        let state = w.body(body).unwrap();
        assert!((state.position - pose.0).length() < 1e-5, "frame {k}");
        let off = common::angle_between(state.orientation, pose.1);
        assert!(off < 1e-5, "frame {k}: {off} rad");
        prev = pose;
    }
}

#[test]
fn the_upright_drive_rights_a_body_and_leaves_its_spin_about_the_axis() {
    // A free body tipped 0.6 rad from +Y and spinning about its own axis:
    // critically damped at 3 Hz it comes upright without overshoot, and
    // its spin about the axis is untouched (the drive has no row there).
    let mut w = world(Vec3::ZERO);
    let shape = Shape::Capsule {
        half_segment: Vec3::new(0.0, 0.3, 0.0),
        radius: 0.1,
    };
    let props = shape.mass_properties_with_mass(5.0).unwrap();
    let tip = Quat::from_rotation_z(0.6);
    let body = w
        .add_body(BodyDesc::dynamic(props).with_orientation(tip))
        .unwrap();
    let drive = UprightDrive::new(Vec3::Y, Vec3::Y, spring(3.0, 1.0));
    w.set_upright_drive(body, Some(drive)).unwrap();
    let spin = 2.0;
    w.set_body_velocity(body, Vec3::ZERO, tip * Vec3::Y * spin)
        .unwrap();
    let mut tilt = Vec::new();
    for _ in 0..90 {
        w.step(DT).unwrap();
        let state = w.body(body).unwrap();
        let axis = state.orientation * Vec3::Y;
        tilt.push(axis.angle_between(Vec3::Y));
        let about = state.angular_velocity.dot(axis);
        assert!((about - spin).abs() < 0.01 * spin, "spin {about}");
    }
    eprintln!(
        "tilt after 0.5 s {:.3}, 1.5 s {:.2e} rad",
        tilt[29], tilt[89]
    );
    assert!(
        tilt.windows(2).all(|p| p[1] <= p[0] + 1e-4),
        "it overshoots"
    );
    assert!(tilt[89] < 1e-5, "{} rad", tilt[89]);
}

#[test]
fn a_capped_upright_drive_holds_a_pole_only_while_its_cap_exceeds_the_load() {
    // A 1 m pole of 4 kg on a socket at its foot, tipped 0.2 rad: gravity's
    // torque about the foot is m g (l / 2) sin 0.2 = 3.9 N m. A cap of 10
    // N m rights it, one of 2 N m lets it fall.
    for (cap, stands) in [(10.0, true), (2.0, false)] {
        let mut w = world(Vec3::new(0.0, -9.81, 0.0));
        let ground = w.add_body(BodyDesc::fixed()).unwrap();
        let tip = Quat::from_rotation_z(0.2);
        let foot = Vec3::ZERO;
        let pole = common::capsule(&mut w, foot + tip * Vec3::Y, foot, 4.0);
        let joint =
            JointDesc::socket_at_world_anchor(w.bodies(), ground, pole, foot, Vec3::Y).unwrap();
        w.add_joint(joint).unwrap();
        // The capsule's body frame is the world's: its axis is `tip Y`.
        let axis = tip * Vec3::Y;
        let drive = UprightDrive::new(axis, Vec3::Y, spring(2.0, 1.0)).with_max_torque(cap);
        w.set_upright_drive(pole, Some(drive)).unwrap();
        for _ in 0..120 {
            w.step(DT).unwrap();
        }
        let axis = w.body(pole).unwrap().orientation * axis;
        let tilt = axis.angle_between(Vec3::Y);
        eprintln!("cap {cap} N m: tilt {tilt} rad after 2 s");
        assert_eq!(tilt < 0.05, stands, "cap {cap}: {tilt} rad");
    }
}

#[test]
fn refused_drives_name_the_field_and_change_nothing() {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0));
    let body = block(&mut w, 2.0, Vec3::ZERO);
    let fixed = w.add_body(BodyDesc::fixed()).unwrap();
    let good = WorldDrive::new(Vec3::ZERO, Quat::IDENTITY, spring(2.0, 1.0));
    w.set_world_drive(body, Some(good)).unwrap();
    let hash = w.state_hash();
    let nan = f32::NAN;
    let cases: Vec<(WorldDrive, Error)> = vec![
        (
            WorldDrive {
                position: Vec3::new(nan, 0.0, 0.0),
                ..good
            },
            Error::NonFinite("world drive position"),
        ),
        (
            WorldDrive {
                position: Vec3::splat(2e6),
                ..good
            },
            Error::OutOfRange("world drive position"),
        ),
        (
            WorldDrive {
                orientation: Quat::from_xyzw(0.0, 0.0, 0.0, 2.0),
                ..good
            },
            Error::NotNormalized("world drive orientation"),
        ),
        (
            WorldDrive {
                linear_velocity: Vec3::splat(1e9),
                ..good
            },
            Error::OutOfRange("world drive linear velocity (at most MAX_LINEAR_SPEED_LIMIT)"),
        ),
        (
            WorldDrive {
                max_force: -1.0,
                ..good
            },
            Error::NonPositive("world drive max force"),
        ),
        (
            WorldDrive {
                max_torque: nan,
                ..good
            },
            Error::NonFinite("world drive max torque"),
        ),
        (
            good.with_strengths(Some(spring(0.0, 1.0)), None),
            Error::OutOfRange("world drive position frequency (at least 1e-3 Hz)"),
        ),
        (
            good.with_strengths(None, Some(spring(1.0, -1.0))),
            Error::NonPositive("world drive orientation damping ratio"),
        ),
    ];
    for (drive, error) in cases {
        assert_eq!(w.set_world_drive(body, Some(drive)), Err(error));
    }
    let upright = UprightDrive::new(Vec3::Y, Vec3::Y, spring(2.0, 1.0));
    let uprights = [
        (
            UprightDrive {
                axis: Vec3::ZERO,
                ..upright
            },
            Error::NotNormalized("upright drive axis"),
        ),
        (
            UprightDrive {
                up: Vec3::splat(nan),
                ..upright
            },
            Error::NonFinite("upright drive up"),
        ),
        (
            UprightDrive {
                max_torque: -2.0,
                ..upright
            },
            Error::NonPositive("upright drive max torque"),
        ),
        (
            UprightDrive {
                strength: spring(1.0, 2e3),
                ..upright
            },
            Error::OutOfRange("upright drive damping ratio (at most 1e3)"),
        ),
    ];
    for (drive, error) in uprights {
        assert_eq!(w.set_upright_drive(body, Some(drive)), Err(error));
    }
    let not_dynamic = Err(Error::NotDynamic("a driven body"));
    assert_eq!(w.set_world_drive(fixed, Some(good)), not_dynamic);
    assert_eq!(w.set_upright_drive(fixed, Some(upright)), not_dynamic);
    assert_eq!(w.state_hash(), hash);
    assert_eq!(w.world_drive(body).unwrap(), Some(good));
    assert_eq!(w.upright_drive(body).unwrap(), None);
}

#[test]
fn a_drive_set_and_cleared_leaves_the_world_as_if_never_set() {
    let mut plain = world(Vec3::new(0.0, -9.81, 0.0));
    let a = block(&mut plain, 2.0, Vec3::ZERO);
    let mut other = world(Vec3::new(0.0, -9.81, 0.0));
    let b = block(&mut other, 2.0, Vec3::ZERO);
    let drive = WorldDrive::new(Vec3::ONE, Quat::IDENTITY, spring(2.0, 1.0));
    other.set_world_drive(b, Some(drive)).unwrap();
    other
        .set_upright_drive(b, Some(UprightDrive::new(Vec3::Y, Vec3::Y, Spring::RIGID)))
        .unwrap();
    other.set_world_drive(b, None).unwrap();
    other.set_upright_drive(b, None).unwrap();
    assert_eq!(plain.state_hash(), other.state_hash());
    for _ in 0..10 {
        plain.step(DT).unwrap();
        other.step(DT).unwrap();
    }
    assert_eq!(plain.state_hash(), other.state_hash());
    assert_eq!(plain.body(a).unwrap(), other.body(b).unwrap());
}

#[test]
fn a_restored_snapshot_steps_on_with_its_drives_bit_for_bit() {
    let mut w = world(Vec3::new(0.0, -9.81, 0.0));
    let body = block(&mut w, 2.0, Vec3::ZERO);
    let mut drive = WorldDrive::new(Vec3::ZERO, Quat::IDENTITY, spring(2.0, 0.5));
    drive.linear_velocity = Vec3::X;
    w.set_world_drive(body, Some(drive)).unwrap();
    let upright = UprightDrive::new(Vec3::Z, Vec3::Y, spring(1.0, 0.2)).with_max_torque(3.0);
    w.set_upright_drive(body, Some(upright)).unwrap();
    for _ in 0..5 {
        w.step(DT).unwrap();
    }
    let snapshot = w.snapshot();
    let mut restored = world(Vec3::new(0.0, -9.81, 0.0));
    restored.restore(&snapshot).unwrap();
    assert_eq!(restored.state_hash(), w.state_hash());
    for _ in 0..20 {
        w.step(DT).unwrap();
        restored.step(DT).unwrap();
    }
    assert_eq!(restored.state_hash(), w.state_hash());
    assert_eq!(restored.world_drive(body), w.world_drive(body));
}

#[test]
fn a_body_whose_target_moves_stays_awake_and_a_still_one_sleeps() {
    for (velocity, sleeps) in [(Vec3::ZERO, true), (Vec3::new(0.01, 0.0, 0.0), false)] {
        let mut w = World::new(SolverConfig {
            gravity: Vec3::ZERO,
            sleep: Some(SleepSettings::default()),
            ..SolverConfig::default()
        })
        .unwrap();
        let body = block(&mut w, 2.0, Vec3::ZERO);
        let mut drive = WorldDrive::new(Vec3::ZERO, Quat::IDENTITY, spring(2.0, 1.0));
        drive.linear_velocity = velocity;
        w.set_world_drive(body, Some(drive)).unwrap();
        for _ in 0..600 {
            w.step(DT).unwrap();
        }
        assert_eq!(
            w.is_asleep(body).unwrap(),
            sleeps,
            "target velocity {velocity}"
        );
    }
}

#[test]
fn driven_worlds_are_the_same_bits_on_every_thread_count() {
    let run = |threads: usize| {
        let mut w = World::new(SolverConfig {
            threads,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            sleep: None,
            ..SolverConfig::default()
        })
        .unwrap();
        let (chain, _) = common::hanging_chain(&mut w, Vec3::ZERO, 12, 0.2);
        for (k, &body) in chain.iter().skip(1).enumerate() {
            let k = k as f32;
            let target = Vec3::new(0.1 * k, -0.2 * k, 0.05 * k.sin());
            let drive = WorldDrive::new(target, Quat::from_rotation_x(0.1 * k), spring(3.0, 0.4))
                .with_caps(20.0, 2.0);
            w.set_world_drive(body, Some(drive)).unwrap();
            let upright =
                UprightDrive::new(Vec3::X, Vec3::Y, spring(2.0, 1.0)).with_max_torque(1.0);
            w.set_upright_drive(body, Some(upright)).unwrap();
        }
        for _ in 0..60 {
            w.step(DT).unwrap();
        }
        w.state_hash()
    };
    let one = run(1);
    assert_eq!(run(2), one);
    assert_eq!(run(4), one);
}
