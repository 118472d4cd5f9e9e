//! Soft limits with damping against their closed forms. A 1 kg, 0.5 m
//! capsule turns about its centre of mass (the joint's anchor, so the point
//! part carries no load and the limit's effective inertia is the body's),
//! without gravity, at `V` rad/s into a limit given as a spring at `F` Hz:
//! the excess `e` past the limit obeys `e'' = -omega^2 e - 2 zeta omega e'`
//! from `e = 0`, `e' = V`. Critically damped (`zeta = 1`),
//! `e = V t exp(-omega t)`: it peaks at `V / (e omega)` and returns to the
//! limit without crossing it (the limb comes to rest against the limit).
//! Undamped, `e = V / omega sin(omega t)`: it peaks at `V / omega` and
//! leaves the limit at `V` (a rebound).

mod common;

use common::{capsule, world};
use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, BodyHandle, JointDesc, JointKind, LimitSoftness, SolverConfig, Spring, Swing,
    SwingTwist, World,
};

const DT: f32 = 1.0 / 60.0;
/// The speed into the limit (rad/s).
const V: f32 = 2.0;
/// The limit's frequency (Hz).
const F: f32 = 5.0;

/// What a run shows: the largest excess (rad), the largest angle back
/// inside the limit after first touching it (rad), and the final angular
/// speed about the joint axis (rad/s, positive away from the limit).
#[derive(Debug)]
struct Run {
    peak: f32,
    back_inside: f32,
    final_speed: f32,
    /// The speed away from the limit as the capsule first leaves it (rad/s).
    exit_speed: f32,
}

/// A weightless world with the capsule centred at the origin along +X and
/// a static body, the joint built by `joint`; the capsule starts at the
/// limit turning at `V` into it about `spin` (+Z or -Z); `excess` measures
/// how far past the limit it is (rad, negative inside).
fn run(
    spin: Vec3,
    joint: impl Fn(&World, BodyHandle, BodyHandle) -> JointDesc,
    excess: impl Fn(Quat) -> f32,
) -> Run {
    let mut w = World::new(SolverConfig {
        gravity: Vec3::ZERO,
        ..*world(8, 20).config()
    })
    .unwrap();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    let bob = capsule(
        &mut w,
        Vec3::new(-0.25, 0.0, 0.0),
        Vec3::new(0.25, 0.0, 0.0),
        1.0,
    );
    let desc = joint(&w, ground, bob);
    w.add_joint(desc).unwrap();
    w.set_body_velocity(bob, Vec3::ZERO, spin * V).unwrap();
    let (mut peak, mut back_inside, mut touched) = (0.0f32, 0.0f32, false);
    let mut exit_speed = 0.0f32;
    for _ in 0..60 {
        w.step(DT).unwrap();
        let e = excess(w.body(bob).unwrap().orientation);
        touched |= e > 0.0;
        peak = peak.max(e);
        if touched {
            if e < 0.0 && back_inside == 0.0 {
                exit_speed = -w.body(bob).unwrap().angular_velocity.dot(spin);
            }
            back_inside = back_inside.max(-e);
        }
    }
    let final_speed = -w.body(bob).unwrap().angular_velocity.dot(spin);
    Run {
        peak,
        back_inside,
        final_speed,
        exit_speed,
    }
}

/// A hinge about +Z with the range `[0, 2]` rad, at 0 now.
fn hinge_run(softness: LimitSoftness) -> Run {
    run(
        -Vec3::Z,
        |w, a, b| {
            JointDesc::hinge_at_world_anchor(w.bodies(), a, b, Vec3::ZERO, Vec3::Z)
                .unwrap()
                .with_kind(JointKind::Hinge {
                    range: Some([0.0, 2.0]),
                    softness,
                })
        },
        |q| {
            let (axis, angle) = q.to_axis_angle();
            -angle * axis.z.signum()
        },
    )
}

/// A socket with the twist axis along the capsule (+X) and a cone of
/// half-angle 0.3 rad: the capsule reaches the cone's edge after 0.15 s.
fn cone_run(softness: LimitSoftness) -> Run {
    let half = 0.3f32;
    let axis = Vec3::X;
    run(
        Vec3::Z,
        move |w, a, b| {
            JointDesc::socket_at_world_anchor(w.bodies(), a, b, Vec3::ZERO, axis)
                .unwrap()
                .with_kind(JointKind::Socket(SwingTwist {
                    swing: Swing::Cone(half),
                    twist: None,
                    softness,
                }))
        },
        move |q| (q * Vec3::X).angle_between(axis) - half,
    )
}

fn spring(damping_ratio: f32) -> LimitSoftness {
    LimitSoftness::Soft(Spring::Frequency {
        frequency: F,
        damping_ratio,
    })
}

/// Critically damped: peaks at `V / (e omega)` and never leaves the limit.
fn check_critical(r: &Run) {
    let omega = core::f32::consts::TAU * F;
    let expected = V / (core::f32::consts::E * omega);
    eprintln!("critical: {r:?}, closed-form peak {expected:.4} rad");
    assert!(
        (r.peak - expected).abs() < 0.1 * expected,
        "peak {} against {expected}",
        r.peak
    );
    assert!(
        r.back_inside < 1e-3,
        "rebounded {} rad inside",
        r.back_inside
    );
    assert!(
        r.final_speed.abs() < 0.01 * V,
        "still turning {}",
        r.final_speed
    );
}

/// Undamped: peaks at `V / omega` and leaves the limit at nearly `V`.
fn check_undamped(r: &Run) {
    let omega = core::f32::consts::TAU * F;
    let expected = V / omega;
    eprintln!("undamped: {r:?}, closed-form peak {expected:.4} rad");
    assert!(
        (r.peak - expected).abs() < 0.1 * expected,
        "peak {} against {expected}",
        r.peak
    );
    assert!(r.back_inside > 0.25, "no rebound: {r:?}");
    assert!(r.exit_speed > 0.8 * V, "rebound speed {}", r.exit_speed);
}

#[test]
fn a_critically_damped_hinge_limit_holds_without_rebound() {
    check_critical(&hinge_run(spring(1.0)));
}

#[test]
fn an_undamped_hinge_limit_rebounds() {
    check_undamped(&hinge_run(spring(0.0)));
}

#[test]
fn a_critically_damped_cone_holds_without_rebound() {
    check_critical(&cone_run(spring(1.0)));
}

#[test]
fn an_undamped_cone_rebounds() {
    check_undamped(&cone_run(spring(0.0)));
}

/// The same spring given as compliance and damping on the capsule's own
/// inertia about Z (`K = I omega^2`, `D = 2 I omega`) gives the same peak.
#[test]
fn compliance_and_damping_match_the_spring_on_the_bodys_inertia() {
    let shape =
        vertebra_world::Shape::capsule(Vec3::new(-0.25, 0.0, 0.0), Vec3::new(0.25, 0.0, 0.0), 0.05);
    let props = shape.mass_properties_with_mass(1.0).unwrap();
    let inertia = props.inertia.z_axis.z;
    let omega = core::f32::consts::TAU * F;
    let r = hinge_run(LimitSoftness::Soft(Spring::Compliance {
        compliance: 1.0 / (inertia * omega * omega),
        damping: 2.0 * inertia * omega,
    }));
    check_critical(&r);
}
