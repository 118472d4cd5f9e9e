//! The solver against physics: closed forms, conservation laws, and the
//! convergence and limit behaviour a ragdoll needs.

mod common;

use common::{angle_between, capsule, hanging_chain, world, world_with};
use glam::{Mat3, Quat, Vec3};
use vertebra_world::{
    AngularDrive, BodyDesc, JointDesc, JointKind, JointSolver, Shape, SolverConfig, SwingTwist,
    World,
};

const DT: f32 = 1.0 / 60.0;

#[test]
fn compound_pendulum_period_matches_the_closed_form() {
    // A 0.6 m rod hanging from its top end, released 0.1 rad from rest.
    let mut w = world(16, 2);
    let pivot_body = w.add_body(BodyDesc::fixed()).unwrap();
    let (length, mass, radius) = (0.6f32, 2.0f32, 0.05f32);
    let shape = Shape::capsule(Vec3::new(0.0, 0.3, 0.0), Vec3::new(0.0, -0.3, 0.0), radius);
    let props = shape.mass_properties_with_mass(mass).unwrap();
    let d = length / 2.0;
    let theta0 = 0.1f32;
    let rotation = Quat::from_rotation_z(theta0);
    let bob = w
        .add_body(
            BodyDesc::dynamic(props)
                .with_position(rotation * Vec3::new(0.0, -d, 0.0))
                .with_orientation(rotation),
        )
        .unwrap();
    let socket = JointDesc {
        body_a: pivot_body,
        body_b: bob,
        anchor_a: Vec3::ZERO,
        anchor_b: Vec3::new(0.0, d, 0.0),
        frame_a: Quat::IDENTITY,
        frame_b: Quat::IDENTITY,
        kind: JointKind::Socket(SwingTwist::FREE),
        drive: None,
        breaking: None,
    };
    w.add_joint(socket).unwrap();
    // I about the pivot = I_cm + m d^2 (about the z axis, across the rod).
    let i_pivot = props.inertia.z_axis.z + mass * d * d;
    let period = 2.0 * std::f32::consts::PI * (i_pivot / (mass * 9.81 * d)).sqrt();
    // Small-angle correction for 0.1 rad amplitude: T (1 + theta0^2 / 16).
    let period = period * (1.0 + theta0 * theta0 / 16.0);
    // Time the upward zero crossings of the angle over ~5 periods.
    let mut crossings = Vec::new();
    let mut previous = theta0;
    for frame in 1..=(6.0 * period / DT) as usize {
        w.step(DT).unwrap();
        let p = w.body(bob).unwrap().position;
        let theta = p.x.atan2(-p.y);
        if previous < 0.0 && theta >= 0.0 {
            // Linear interpolation inside the frame.
            let t = (frame as f32 - 1.0 + previous / (previous - theta)) * DT;
            crossings.push(t);
        }
        previous = theta;
    }
    assert!(crossings.len() >= 5, "{crossings:?}");
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f32;
    let error = (measured - period).abs() / period;
    eprintln!(
        "period {measured:.4} s, closed form {period:.4} s, error {:.3}%",
        error * 100.0
    );
    assert!(error < 0.005, "period {measured} vs {period}");
}

/// A box with three distinct principal moments, spinning about `axis`
/// (body frame) at 6 rad/s with a 1% perturbation on another axis.
fn spinning_box(axis: Vec3) -> (World, vertebra_world::BodyHandle, Mat3) {
    let mut w = World::new(SolverConfig {
        substeps: 8,
        gravity: Vec3::ZERO,
        ..SolverConfig::default()
    })
    .unwrap();
    let shape = Shape::Box {
        half_extents: Vec3::new(0.05, 0.2, 0.4),
    };
    let props = shape.mass_properties(1000.0).unwrap();
    let spin = axis * 6.0 + Vec3::new(axis.y, axis.z, axis.x) * 0.06;
    let body = w
        .add_body(BodyDesc::dynamic(props).with_velocity(Vec3::ZERO, spin))
        .unwrap();
    (w, body, props.inertia)
}

fn angular_momentum(w: &World, body: vertebra_world::BodyHandle, inertia: Mat3) -> Vec3 {
    let s = w.body(body).unwrap();
    let r = Mat3::from_quat(s.orientation);
    r * inertia * r.transpose() * s.angular_velocity
}

#[test]
fn a_free_body_flips_about_its_intermediate_axis_only() {
    // Moments: x largest (0.2^2 + 0.4^2), y intermediate, z smallest.
    for (axis, flips) in [(Vec3::X, false), (Vec3::Y, true), (Vec3::Z, false)] {
        let (mut w, body, inertia) = spinning_box(axis);
        let l0 = angular_momentum(&w, body, inertia);
        let mut lowest = 1.0f32;
        let mut drift = 0.0f32;
        for _ in 0..(8.0 / DT) as usize {
            w.step(DT).unwrap();
            let q = w.body(body).unwrap().orientation;
            // Alignment of the spin axis (body frame) with its start, in world.
            lowest = lowest.min((q * axis).dot(axis));
            drift = drift.max((angular_momentum(&w, body, inertia) - l0).length() / l0.length());
        }
        eprintln!(
            "axis {axis}: lowest alignment {lowest:.3}, momentum drift {:.2}%",
            drift * 100.0
        );
        // Bounds at h = 1/480 s: the exact exponential map keeps a steady
        // spin's momentum; through the flips the one-step implicit
        // gyroscopic update loses a little (2.6% measured over 8 s).
        let bound = if flips {
            assert!(lowest < -0.9, "the intermediate axis should flip over");
            0.03
        } else {
            assert!(lowest > 0.95, "a major or minor axis spin should stay put");
            0.002
        };
        assert!(
            drift < bound,
            "angular momentum drifted {:.2}%",
            drift * 100.0
        );
    }
}

#[test]
fn iterated_joint_error_falls_as_iterations_grow() {
    let mean_error = |iterations: u32| {
        let mut w = world_with(1, iterations, JointSolver::Iterative);
        hanging_chain(&mut w, Vec3::new(0.0, 2.0, 0.0), 12, 0.15);
        // Swing the chain sideways so the joints work.
        for frame in 0..120 {
            if frame < 10 {
                let last = w.bodies().handle_at(w.bodies().capacity() - 1).unwrap();
                w.add_force(last, Vec3::new(40.0, 0.0, 0.0)).unwrap();
            }
            w.step(DT).unwrap();
        }
        let mut total = 0.0;
        for _ in 0..60 {
            w.step(DT).unwrap();
            total += w.measure_residuals().eps_lin_cm;
        }
        total / 60.0
    };
    let errors: Vec<f32> = [1, 2, 5, 10, 20, 40].into_iter().map(mean_error).collect();
    eprintln!("mean eps_lin (cm) at 1, 2, 5, 10, 20, 40 iterations: {errors:?}");
    for pair in errors.windows(2) {
        assert!(
            pair[1] < pair[0],
            "error must fall with iterations: {errors:?}"
        );
    }
    assert!(errors[5] < errors[0] / 10.0, "{errors:?}");
}

#[test]
fn internal_corrections_conserve_linear_momentum() {
    let mut w = World::new(SolverConfig {
        gravity: Vec3::ZERO,
        ..SolverConfig::default()
    })
    .unwrap();
    // A free-floating chain, joints violated at the start, bodies moving.
    let mut bodies = Vec::new();
    for k in 0..8 {
        let top = Vec3::new(0.0, -0.25 * k as f32, 0.0);
        bodies.push(capsule(&mut w, top, top - Vec3::Y * 0.2, 1.0 + k as f32));
    }
    for k in 1..8 {
        let anchor = Vec3::new(0.0, -0.25 * k as f32 + 0.025, 0.0);
        let desc = JointDesc::socket_at_world_anchor(
            w.bodies(),
            bodies[k - 1],
            bodies[k],
            anchor,
            -Vec3::Y,
        )
        .unwrap();
        w.add_joint(desc).unwrap();
    }
    for (k, &b) in bodies.iter().enumerate() {
        let v = Vec3::new(
            (k as f32 * 1.3).sin(),
            (k as f32 * 0.7).cos(),
            0.5 * k as f32 - 2.0,
        );
        w.set_body_velocity(b, v, Vec3::new(0.3 * k as f32, -1.0, 0.5))
            .unwrap();
    }
    let momentum = |w: &World| -> Vec3 {
        bodies
            .iter()
            .map(|&b| w.body(b).unwrap().linear_velocity * w.bodies().mass[b.index()])
            .sum()
    };
    let p0 = momentum(&w);
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    let p1 = momentum(&w);
    let scale: f32 = bodies
        .iter()
        .map(|&b| w.bodies().mass[b.index()])
        .sum::<f32>()
        * 2.0;
    eprintln!("momentum before {p0}, after {p1}");
    assert!((p1 - p0).length() < 1e-3 * scale, "{p0} -> {p1}");
    // The joints closed their initial gaps.
    assert!(
        w.measure_residuals().eps_lin_cm < 0.05,
        "{}",
        w.measure_residuals().eps_lin_cm
    );
}

/// A static parent at the origin and a 0.4 m capsule child along `dir`
/// from it, joined at the origin with the twist axis along `dir`.
fn arm(
    w: &mut World,
    dir: Vec3,
) -> (
    vertebra_world::BodyHandle,
    vertebra_world::BodyHandle,
    JointDesc,
) {
    let parent = w.add_body(BodyDesc::fixed()).unwrap();
    let child = capsule(w, dir * 0.05, dir * 0.45, 2.0);
    let desc =
        JointDesc::socket_at_world_anchor(w.bodies(), parent, child, Vec3::ZERO, dir).unwrap();
    (parent, child, desc)
}

#[test]
fn the_swing_cone_holds_a_horizontal_arm_at_its_limit() {
    let mut w = world(1, 20);
    let (_, child, desc) = arm(&mut w, Vec3::X);
    let limit = 30f32.to_radians();
    w.add_joint(desc.with_swing_limit(limit)).unwrap();
    let mut worst = 0.0f32;
    for frame in 0..240 {
        w.step(DT).unwrap();
        if frame > 60 {
            worst = worst.max(w.measure_residuals().eps_ang_rad);
        }
    }
    let axis = w.body(child).unwrap().orientation * Vec3::X;
    let swing = axis.angle_between(Vec3::X);
    eprintln!(
        "swing {:.3} deg (limit 30), worst overshoot {worst:.2e} rad",
        swing.to_degrees()
    );
    assert!(axis.y < 0.0, "gravity pulled the arm down");
    assert!(
        (swing - limit).abs() < 0.2f32.to_radians(),
        "rests at the limit: {}",
        swing.to_degrees()
    );
    assert!(worst < 1e-3, "overshoot {worst}");
}

#[test]
fn the_twist_range_holds_against_a_steady_torque() {
    let mut w = world(1, 20);
    let (_, child, desc) = arm(&mut w, -Vec3::Y);
    w.add_joint(desc.with_twist_limit(-0.3, 0.3)).unwrap();
    for _ in 0..180 {
        w.add_torque(child, Vec3::new(0.0, -2.0, 0.0)).unwrap();
        w.step(DT).unwrap();
    }
    let q = w.body(child).unwrap().orientation;
    let twist = 2.0 * (q.y * q.w.signum()).atan2(q.w.abs());
    eprintln!(
        "twist {twist:.4} rad (range [-0.3, 0.3]), overshoot {:.2e}",
        w.measure_residuals().eps_ang_rad
    );
    // Torque about -Y twists the child negatively about its twist axis -Y... in
    // world terms a rotation about +Y of -angle; either way it stops at 0.3.
    assert!((twist.abs() - 0.3).abs() < 2e-3, "twist {twist}");
    assert!(w.measure_residuals().eps_ang_rad < 2e-3);
}

/// Drives a hanging arm toward a 0.6 rad swing, its joint solved by
/// `joints`; pushes it for half a second; returns (settled, pushed,
/// returned) errors from the target (rad).
fn push_driven_arm(compliance: f32, joints: JointSolver) -> (f32, f32, f32) {
    let mut w = world_with(1, 20, joints);
    let (_, child, desc) = arm(&mut w, -Vec3::Y);
    let target = Quat::from_rotation_z(0.6);
    let drive = AngularDrive::compliant(target, compliance, 0.5);
    w.add_joint(desc.with_drive(drive)).unwrap();
    let error = |w: &World| {
        angle_between(
            w.body(child).unwrap().orientation * desc.frame_b,
            desc.frame_a * target,
        )
    };
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    let settled = error(&w);
    for _ in 0..30 {
        w.add_force(child, Vec3::new(0.0, 0.0, 200.0)).unwrap();
        w.step(DT).unwrap();
    }
    let pushed = error(&w);
    for _ in 0..180 {
        w.step(DT).unwrap();
    }
    (settled, pushed, error(&w))
}

#[test]
fn a_stiff_drive_holds_its_pose_through_a_push() {
    // Iterated, at rest it holds to rounding; under a 200 N push at 20
    // iterations a little is left (5.6e-4 rad), gone once the push ends.
    // Under the direct solve the drive is rows of the tree, rigid to
    // round-off through the push (docs/direct.md, "Drives are rows of the
    // solve").
    let cases = [
        (JointSolver::Iterative, 1e-5, 2e-3),
        (JointSolver::Direct, 1e-5, 1e-5),
    ];
    for (joints, at_rest, under_push) in cases {
        let (settled, pushed, returned) = push_driven_arm(0.0, joints);
        eprintln!(
            "{joints:?}: stiff drive error: settled {settled:.2e}, pushed {pushed:.2e}, after {returned:.2e} rad"
        );
        assert!(
            settled < at_rest && returned < at_rest,
            "{joints:?}: {settled} {returned}"
        );
        assert!(pushed < under_push, "{joints:?}: {pushed}");
    }
}

#[test]
fn a_compliant_drive_gives_way_and_returns() {
    let (settled, pushed, returned) = push_driven_arm(0.02, JointSolver::default());
    eprintln!(
        "compliant drive error: settled {settled:.2e}, pushed {pushed:.2e}, after {returned:.2e} rad"
    );
    // Gravity's torque (about 2 kg * 9.81 * 0.25 m * sin 0.6) times the
    // compliance is the steady sag: about 0.055 rad.
    let sag = 0.02 * 2.0 * 9.81 * 0.25 * 0.6f32.sin();
    assert!((settled - sag).abs() < 0.2 * sag, "sag {settled} vs {sag}");
    assert!(pushed > settled + 0.1, "the push bends it: {pushed}");
    assert!(
        (returned - settled).abs() < 1e-3,
        "returns to its sag: {returned} vs {settled}"
    );
}

#[test]
fn a_kinematic_body_carries_its_joints_and_ignores_them() {
    let mut w = world(1, 20);
    let carrier = w
        .add_body(BodyDesc::kinematic().with_velocity(Vec3::new(1.0, 0.0, 0.0), Vec3::ZERO))
        .unwrap();
    let bob = capsule(&mut w, Vec3::ZERO, -Vec3::Y * 0.4, 1.0);
    let desc =
        JointDesc::socket_at_world_anchor(w.bodies(), carrier, bob, Vec3::ZERO, -Vec3::Y).unwrap();
    w.add_joint(desc).unwrap();
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    let c = w.body(carrier).unwrap();
    // The carrier moved exactly by its own velocity, whatever hangs on it.
    assert!(
        (c.position - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-4,
        "{}",
        c.position
    );
    assert_eq!(c.linear_velocity, Vec3::new(1.0, 0.0, 0.0));
    // The bob hangs from it, trailing, and the joint holds.
    let b = w.body(bob).unwrap();
    assert!(b.position.x > 1.5, "{}", b.position);
    assert!(
        w.measure_residuals().eps_lin_cm < 0.01,
        "{}",
        w.measure_residuals().eps_lin_cm
    );
}
