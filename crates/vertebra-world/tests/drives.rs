//! Drives against the damped oscillator they claim to be: a step response
//! on the closed form, critical damping without overshoot, whatever the
//! mass; a moving target tracked without lag; a torque limit that yields
//! to a hit and recovers.
//!
//! The rig: a sphere turning about its own centre (the anchor), on a
//! static body, no gravity. The point part then never acts and the drive
//! alone turns the body, about one world axis: the closed forms apply.

use core::f32::consts::TAU;

use glam::{Quat, Vec3};
use vertebra_world::{
    AngularDrive, BodyDesc, BodyHandle, Error, JointDesc, JointHandle, MIN_TIME_STEP, Shape,
    SolverConfig, World,
};

const DT: f32 = 1.0 / 60.0;
const SUBSTEPS: u32 = 10;

/// A sphere of `mass` kg on a static body, joined at its centre.
fn rig(mass: f32, drive: AngularDrive) -> (World, BodyHandle, JointHandle) {
    let mut w = World::new(SolverConfig {
        substeps: SUBSTEPS,
        iterations: 4,
        gravity: Vec3::ZERO,
        // The drive's own response: a slow drive would sleep within
        // `speed / omega` of its target.
        sleep: None,
        ..SolverConfig::default()
    })
    .unwrap();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    let props = Shape::Sphere { radius: 0.1 }
        .mass_properties_with_mass(mass)
        .unwrap();
    let ball = w.add_body(BodyDesc::dynamic(props)).unwrap();
    let desc =
        JointDesc::socket_at_world_anchor(w.bodies(), ground, ball, Vec3::ZERO, Vec3::X).unwrap();
    let socket = w.add_joint(desc.with_drive(drive)).unwrap();
    (w, ball, socket)
}

/// The body's turn about +Z (rad).
fn angle(w: &World, ball: BodyHandle) -> f32 {
    let q = w.body(ball).unwrap().orientation;
    2.0 * q.z.atan2(q.w)
}

/// The angle over `frames` frames of a drive at `hz`, `zeta`, stepped from
/// rest at 0 to a target of `step` rad about +Z.
fn step_response(mass: f32, hz: f32, zeta: f32, step: f32, frames: usize) -> Vec<f32> {
    let drive = AngularDrive::spring(Quat::from_rotation_z(step), hz, zeta);
    let (mut w, ball, _) = rig(mass, drive);
    (0..frames)
        .map(|_| {
            w.step(DT).unwrap();
            angle(&w, ball)
        })
        .collect()
}

/// `x(t)` of `x'' = -omega^2 (x - s) - 2 zeta omega x'` from rest at 0,
/// for `zeta < 1`.
fn underdamped(t: f32, omega: f32, zeta: f32, s: f32) -> f32 {
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    let decay = (-zeta * omega * t).exp();
    s - s * decay * ((wd * t).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * t).sin())
}

#[test]
fn a_spring_drive_follows_the_damped_oscillator_whatever_the_mass() {
    let (hz, zeta, step) = (2.0, 0.3, 0.5);
    let omega = TAU * hz;
    for mass in [0.1, 1.0, 100.0] {
        let response = step_response(mass, hz, zeta, step, 90);
        let worst = response
            .iter()
            .enumerate()
            .map(|(k, x)| (x - underdamped((k + 1) as f32 * DT, omega, zeta, step)).abs())
            .fold(0.0, f32::max);
        eprintln!("mass {mass} kg: largest difference {worst:.2e} rad of a {step} rad step");
        // Implicit Euler adds about omega h / 2 = 0.0105 to zeta (h = 1/600
        // s); on an envelope `s exp(-zeta omega t)` that moves the response
        // by at most (omega h / 2) / (zeta e) s = 1.3% of the step, and the
        // period by (omega h)^2 / 3: 3% of the step bounds both.
        assert!(worst < 0.03 * step, "mass {mass}: {worst}");
    }
}

#[test]
fn a_critically_damped_drive_settles_without_overshoot() {
    for (hz, step) in [(1.0, 0.3), (5.0, 1.0), (20.0, 2.0)] {
        let response = step_response(1.0, hz, 1.0, step, 180);
        let peak = response.iter().copied().fold(f32::MIN, f32::max);
        let last = *response.last().unwrap();
        eprintln!("{hz} Hz: peak {peak:.5} of a {step} rad step, at 3 s {last:.5}");
        assert!(peak <= 1.02 * step, "{hz} Hz: overshoot {}", peak - step);
        assert!(
            (last - step).abs() < 1e-3 * step,
            "{hz} Hz: settled at {last}"
        );
    }
}

/// The angle between the body's joint frame and the drive's current
/// target (which the world advances): the drive's error (rad).
fn lag(w: &World, ball: BodyHandle, socket: JointHandle) -> f32 {
    let desc = w.joint(socket).unwrap();
    let target = desc.frame_a * desc.drive.unwrap().target;
    let frame = w.body(ball).unwrap().orientation * desc.frame_b;
    (frame * target.conjugate()).to_axis_angle().1.min(TAU)
}

#[test]
fn a_drive_tracks_a_rotating_target_without_lag() {
    // The target turns at 2 rad/s about the joint's +Z; a damping on the
    // absolute spin would leave a lag of 2 zeta speed / omega = 0.064 rad.
    let speed = 2.0;
    let drive = AngularDrive::spring(Quat::IDENTITY, 5.0, 1.0)
        .with_target_velocity(Vec3::new(0.0, 0.0, speed));
    let (mut w, ball, socket) = rig(1.0, drive);
    for _ in 0..180 {
        w.step(DT).unwrap();
    }
    let lag = lag(&w, ball, socket);
    let turned = 2.0 * w.joint(socket).unwrap().drive.unwrap().target.z.asin();
    eprintln!("after 3 s: lag {lag:.2e} rad, target at {turned:.4} rad");
    assert!(lag < 1e-3, "{lag}");
    assert!((w.body(ball).unwrap().angular_velocity.z - speed).abs() < 1e-3);
}

#[test]
fn following_two_poses_reaches_the_second_at_the_end_of_the_step() {
    let (prev, pose) = (Quat::from_rotation_z(0.1), Quat::from_rotation_z(0.15));
    let drive = AngularDrive::rigid(prev).following(prev, pose, DT).unwrap();
    let (mut w, ball, socket) = rig(1.0, drive);
    w.step(DT).unwrap();
    let target = w.joint(socket).unwrap().drive.unwrap().target;
    assert!(target.angle_between(pose) < 1e-5);
    assert!((angle(&w, ball) - 0.15).abs() < 1e-5);
}

#[test]
fn following_refuses_a_time_step_that_is_not_one() {
    // A negative dt would give the velocity that turns the target away
    // from the pose, which the world would accept.
    let (prev, pose) = (Quat::from_rotation_z(0.1), Quat::from_rotation_z(0.15));
    let drive = AngularDrive::spring(prev, 4.0, 1.0);
    let cases = [
        (-DT, Error::NonPositive("following time step")),
        (0.0, Error::NonPositive("following time step")),
        (-0.0, Error::NonPositive("following time step")),
        (f32::NAN, Error::NonFinite("following time step")),
        (f32::INFINITY, Error::NonFinite("following time step")),
        (
            1e-7,
            Error::OutOfRange("following time step (at least 1e-6 s)"),
        ),
    ];
    for (dt, error) in cases {
        assert_eq!(drive.following(prev, pose, dt), Err(error), "dt {dt}");
    }
    let followed = drive.following(prev, pose, MIN_TIME_STEP).unwrap();
    let speed = 0.05 / MIN_TIME_STEP;
    assert!((followed.target_velocity.z - speed).abs() < 1e-4 * speed);
}

/// The largest and the final error (rad) of a drive at rest on target,
/// hit by `torque` N m about +Z for 0.2 s, then left for 3 s.
fn hit(max_torque: f32, torque: f32) -> (f32, f32) {
    let drive = AngularDrive::spring(Quat::IDENTITY, 4.0, 1.0).with_max_torque(max_torque);
    let (mut w, ball, _) = rig(20.0, drive);
    let mut peak = 0.0f32;
    for frame in 0..200 {
        if frame < 12 {
            w.add_torque(ball, Vec3::new(0.0, 0.0, torque)).unwrap();
        }
        w.step(DT).unwrap();
        peak = peak.max(angle(&w, ball).abs());
    }
    (peak, angle(&w, ball).abs())
}

#[test]
fn a_torque_limited_drive_yields_to_a_hit_and_recovers() {
    // The 4 Hz drive on a 20 kg, 0.1 m sphere (I = 0.08 kg m^2) resists
    // with I omega^2 = 50 N m per rad: a 2 N m hit turns it by ~0.04 rad.
    // Limited to 1 N m, the hit's other 1 N m spins it up for 0.2 s
    // (2.5 rad/s), and 1 N m takes ~0.25 rad more to stop it.
    let (free_peak, free_end) = hit(f32::INFINITY, 2.0);
    let (held_peak, held_end) = hit(1.0, 2.0);
    eprintln!(
        "unlimited: peak {free_peak:.4}, end {free_end:.1e}; 1 N m: peak {held_peak:.4}, end {held_end:.1e} rad"
    );
    // Limited to half the hit, the drive gives way: the joint is driven
    // far past where the unlimited drive stopped it.
    assert!(held_peak > 5.0 * free_peak, "{held_peak} {free_peak}");
    // And comes back.
    assert!(held_end < 1e-3 && free_end < 1e-3, "{held_end} {free_end}");
    // A limit the hit stays below changes nothing.
    assert_eq!(hit(100.0, 2.0), (free_peak, free_end));
}

#[test]
fn damping_measurably_damps_a_compliant_drive() {
    // Compliance 0.02 rad/(N m) on I = 8e-3 kg m^2: omega = 79 rad/s;
    // critical damping is 2 sqrt(I / c) = 1.26 N m s/rad.
    let run = |damping: f32| {
        let drive = AngularDrive::compliant(Quat::from_rotation_z(0.3), 0.02, damping);
        let (mut w, ball, _) = rig(2.0, drive);
        let response: Vec<f32> = (0..60)
            .map(|_| {
                w.step(DT).unwrap();
                angle(&w, ball)
            })
            .collect();
        let peak = response.iter().copied().fold(f32::MIN, f32::max);
        let late = response[30..]
            .iter()
            .map(|x| (x - 0.3).abs())
            .fold(0.0, f32::max);
        (peak, late)
    };
    let (undamped_peak, undamped_late) = run(0.0);
    let (damped_peak, damped_late) = run(1.26);
    eprintln!(
        "damping 0: peak {undamped_peak:.4} late {undamped_late:.2e}; critical: peak {damped_peak:.4} late {damped_late:.2e}"
    );
    assert!(undamped_peak > 0.5, "{undamped_peak}");
    assert!(damped_peak < 0.306, "{damped_peak}");
    // Undamped it still rings after half a second (what rings less is the
    // implicit integration's own damping, omega h / 2 = 0.07 here).
    assert!(damped_late < 1e-3 && undamped_late > 100.0 * damped_late);
}
