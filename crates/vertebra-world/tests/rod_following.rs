//! A rod whose rest shape moves (`RodDesc::bend_rest_velocity`,
//! `twist_rest_velocity`) against the closed form of a damped spring
//! following a ramp, and against the other way of moving a rest shape (set
//! anew before every step, still in between: how `drive_to` moves a rod).
//!
//! The rig: a static base and a ball 0.4 m above it on a straight rod, no
//! gravity, as `rod_drive.rs`. The rest bends the rod about +Z (in a's
//! material frame, which `from_pose` turns from the world's about +Z: the
//! same axis) or twists it about +Y (the rod's axis) at a constant rate
//! `v`. One substep per step, so that a rest set anew before every step is
//! a ramp sampled at the substep (the discrete steady state below is then
//! exact, not only to first order in the frame).

use core::f32::consts::TAU;

use glam::Vec3;
use vertebra_world::{
    BodyDesc, BodyHandle, Error, RodDesc, RodHandle, RodStiffness, Shape, SolverConfig, World,
};

/// One step is one substep (s): the substep of 10 substeps at 60 Hz.
const H: f32 = 1.0 / 600.0;
const LENGTH: f32 = 0.4;
const RADIUS: f32 = 0.08;
const MASS: f32 = 5.0;
/// The rest's rate (rad/s).
const V: f32 = 0.5;

/// How the rest moves.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Rest {
    /// Set before every step to where the ramp is at the step's end, its
    /// rates zero (as before rests had rates).
    Chased,
    /// Given its rates once; the world advances it.
    Following,
}

/// The base, the ball on a rod of `stiffness` in bending and twisting.
fn rig(stiffness: RodStiffness) -> (World, BodyHandle, RodHandle) {
    let mut w = World::new(SolverConfig {
        substeps: 1,
        iterations: 10,
        gravity: Vec3::ZERO,
        // The rod's own response: the ball turning in place at `V` moves
        // its mass at 2.5 cm/s, and it would sleep.
        sleep: None,
        ..SolverConfig::default()
    })
    .unwrap();
    let base = w.add_body(BodyDesc::fixed()).unwrap();
    let props = Shape::Sphere { radius: RADIUS }
        .mass_properties_with_mass(MASS)
        .unwrap();
    let ball = w
        .add_body(BodyDesc::dynamic(props).with_position(Vec3::Y * LENGTH))
        .unwrap();
    let rod = RodDesc::from_pose(w.bodies(), base, ball, &[])
        .unwrap()
        .with_stiffness(stiffness, stiffness);
    let rod = w.add_rod(rod).unwrap();
    (w, ball, rod)
}

/// The ball's turn about `axis` (rad): the bend angle for +Z (the base is
/// held, so `t_b` turns with the ball), the twist for +Y.
fn angle(w: &World, ball: BodyHandle, axis: Vec3) -> f32 {
    let q = w.body(ball).unwrap().orientation;
    2.0 * Vec3::new(q.x, q.y, q.z).dot(axis).atan2(q.w)
}

/// The rod's rest shape at angle `a` (rad) of the ramp: bent by `a` about
/// +Z, or twisted by `a`.
fn shaped(rod: RodDesc, axis: Vec3, a: f32) -> RodDesc {
    let mut rod = rod;
    if axis == Vec3::Z {
        rod.bend_rest = Vec3::new(a.cos(), a.sin(), 0.0);
    } else {
        rod.twist_rest = a;
    }
    rod
}

/// The rest's angle less the rod's (rad, the lag) and the ball's angular
/// speed about `axis` (rad/s) after every step, for `seconds`.
fn run(stiffness: RodStiffness, axis: Vec3, rest: Rest, seconds: f32) -> Vec<(f32, f32)> {
    let (mut w, ball, handle) = rig(stiffness);
    if rest == Rest::Following {
        let rod = w.rod(handle).unwrap();
        let (bend, twist) = if axis == Vec3::Z {
            (Vec3::Z * V, 0.0)
        } else {
            (Vec3::ZERO, V)
        };
        w.set_rod(handle, rod.with_rest_velocity(bend, twist))
            .unwrap();
    }
    (1..=(seconds / H).round() as usize)
        .map(|k| {
            let ramp = V * H * k as f32;
            if rest == Rest::Chased {
                let rod = w.rod(handle).unwrap();
                w.set_rod(handle, shaped(rod, axis, ramp)).unwrap();
            }
            w.step(H).unwrap();
            let spin = w.body(ball).unwrap().angular_velocity.dot(axis);
            (ramp - angle(&w, ball, axis), spin)
        })
        .collect()
}

/// A critically damped spring (`omega` rad/s) whose target starts along
/// the ramp `v t` at `t = 0` from rest on it: the lag `e` obeys
/// `e'' + 2 omega e' + omega^2 e = 2 omega v` when damped against rest
/// (`e(0) = 0`, `e'(0) = v`), so
/// `e = 2 v / omega - (2 v / omega + v t) exp(-omega t)`, settling at
/// `2 zeta v / omega`; damped against the target's motion the right side is
/// 0 and `e = v t exp(-omega t)`, settling at 0.
fn lag(rest: Rest, omega: f32, t: f32) -> f32 {
    let decay = (-omega * t).exp();
    match rest {
        Rest::Chased => 2.0 * V / omega - (2.0 * V / omega + V * t) * decay,
        Rest::Following => V * t * decay,
    }
}

#[test]
fn a_moving_rest_is_followed_without_the_damping_lag() {
    // 4 Hz, ratio 1: settled well within the 2 s (exp(-omega t) = 1e-22).
    let (frequency, zeta) = (4.0f32, 1.0f32);
    let omega = TAU * frequency;
    let spring = RodStiffness::Spring {
        frequency,
        damping_ratio: zeta,
    };
    let steady = 2.0 * zeta * V / omega;
    for axis in [Vec3::Z, Vec3::Y] {
        for rest in [Rest::Chased, Rest::Following] {
            let lags = run(spring, axis, rest, 2.0);
            let (end, _) = lags[lags.len() - 1];
            let expected = lag(rest, omega, 2.0);
            // The transient's largest lag, against the closed form's (the
            // implicit integration damps it a little).
            let peak = lags.iter().map(|l| l.0).fold(f32::MIN, f32::max);
            let closed_peak = (1..=(2.0 / H) as usize)
                .map(|k| lag(rest, omega, H * k as f32))
                .fold(f32::MIN, f32::max);
            eprintln!(
                "{axis} {rest:?}: lag after 2 s {end:.6} rad (closed form {expected:.6}), \
                 peak {peak:.5} (closed form {closed_peak:.5})"
            );
            // Settled: the last second's lag is constant.
            let settled = &lags[lags.len() / 2..];
            let spread = settled
                .iter()
                .map(|l| (l.0 - end).abs())
                .fold(0.0, f32::max);
            assert!(spread < 1e-3 * steady, "{axis} {rest:?}: spread {spread}");
            assert!(
                (end - expected).abs() < 0.01 * steady,
                "{axis} {rest:?}: lag {end}, closed form {expected}"
            );
        }
    }
}

#[test]
fn damping_acts_relative_to_the_rest_not_to_standing_still() {
    // Nearly no spring (k = 1e-3 N m^2) and strong damping (d = 10 N m^2 s:
    // D = d / l0 = 25 N m s, some 100 times the ball's inertia per second):
    // damped against standing still the ball stays put, the tiny spring
    // pulling it at `K e / D` (a ramp's 1 rad of lag moves it at 1e-4
    // rad/s); damped against the rest's motion it turns with the rest,
    // lagging by `v J / D` once `D / J` has passed (J the effective inertia).
    let damped = RodStiffness::Damped {
        stiffness: 1e-3,
        damping: 10.0,
    };
    for axis in [Vec3::Z, Vec3::Y] {
        let chased = run(damped, axis, Rest::Chased, 1.0);
        let following = run(damped, axis, Rest::Following, 1.0);
        let (spin_chased, spin_following) =
            (chased[chased.len() - 1].1, following[following.len() - 1].1);
        eprintln!(
            "{axis}: after 1 s the ball turns at {spin_chased:.2e} rad/s chased, \
             {spin_following:.6} following a rest turning at {V}"
        );
        assert!(spin_chased.abs() < 1e-2 * V, "{axis}: chased {spin_chased}");
        assert!(
            (spin_following - V).abs() < 1e-3 * V,
            "{axis}: following {spin_following}"
        );
    }
}

#[test]
fn the_advanced_rest_is_written_back() {
    // After a second at 0.5 rad/s the rest has turned by 0.5 rad and twisted
    // by -0.5 rad, and `World::rod` says so; a twist past pi wraps. (To
    // 1e-3: each is a sum of 600 substeps' turns in `f32`.)
    let spring = RodStiffness::Spring {
        frequency: 4.0,
        damping_ratio: 1.0,
    };
    let (mut w, _, handle) = rig(spring);
    let rod = w.rod(handle).unwrap();
    let rod = RodDesc {
        twist_rest: 3.0,
        ..rod
    };
    w.set_rod(handle, rod.with_rest_velocity(Vec3::Z * V, -V))
        .unwrap();
    for _ in 0..600 {
        w.step(H).unwrap();
    }
    let rod = w.rod(handle).unwrap();
    let expected = Vec3::new(V.cos(), V.sin(), 0.0);
    assert!(
        rod.bend_rest.distance(expected) < 1e-3,
        "{} for {expected}",
        rod.bend_rest
    );
    assert!(
        (rod.twist_rest - (3.0 - V)).abs() < 1e-3,
        "{}",
        rod.twist_rest
    );
    let rod = w.rod(handle).unwrap().with_rest_velocity(Vec3::ZERO, 1.0);
    w.set_rod(handle, rod).unwrap();
    for _ in 0..600 {
        w.step(H).unwrap();
    }
    let twist = w.rod(handle).unwrap().twist_rest;
    let expected = 3.5 - TAU;
    assert!((twist - expected).abs() < 1e-3, "{twist} for {expected}");
}

#[test]
fn following_refuses_a_time_step_that_is_not_one() {
    // A negative dt would give rates that move the rest away from the
    // pose, which the world would accept.
    let (w, _, handle) = rig(RodStiffness::Kirchhoff(1.0));
    let rod = w.rod(handle).unwrap();
    let (prev, pose) = ((Vec3::X, 0.0), (Vec3::new(0.8, 0.6, 0.0), 0.2));
    for (dt, error) in [
        (-H, Error::NonPositive("following time step")),
        (0.0, Error::NonPositive("following time step")),
        (f32::NAN, Error::NonFinite("following time step")),
        (
            1e-7,
            Error::OutOfRange("following time step (at least 1e-6 s)"),
        ),
    ] {
        assert_eq!(rod.following(prev, pose, dt), Err(error), "dt {dt}");
    }
    let followed = rod.following(prev, pose, 0.5).unwrap();
    assert!((followed.twist_rest_velocity - 0.4).abs() < 1e-6);
}
