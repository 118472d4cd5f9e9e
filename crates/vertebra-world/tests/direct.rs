//! The direct joint solve (`JointSolver::Direct`), through the public
//! API: chains held together in few iterations, mass ratios that tear
//! iterated chains apart, loops, snapshots.

mod common;

use common::{capsule, hanging_chain};
use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, JointDesc, JointSolver, MAX_LIMIT_RETURN_SPEED, SolverConfig, World,
};

fn world(iterations: u32, joints: JointSolver) -> World {
    World::new(SolverConfig {
        iterations,
        sleep: None,
        measure_residuals: true,
        joints,
        ..SolverConfig::default()
    })
    .expect("valid config")
}

/// The largest summed separation (cm) over `frames` steps at 60 Hz.
fn worst_separation(w: &mut World, frames: usize) -> f32 {
    let mut worst = 0.0f32;
    for _ in 0..frames {
        w.step(1.0 / 60.0).unwrap();
        let eps = w.residuals().unwrap().eps_lin_cm;
        assert!(eps.is_finite());
        worst = worst.max(eps);
    }
    worst
}

/// An 8-link chain swung hard: one direct iteration (and the closing
/// solves) keeps it together to a hundredth of a millimetre, where 4
/// iterations of Gauss-Seidel leave centimetres.
#[test]
fn a_swung_chain_stays_together_with_one_iteration() {
    let swung = |iterations, joints| {
        let mut w = world(iterations, joints);
        let (bodies, _) = hanging_chain(&mut w, Vec3::new(0.0, 5.0, 0.0), 8, 0.3);
        w.set_body_velocity(bodies[8], Vec3::new(3.0, 0.0, 0.0), Vec3::ZERO)
            .unwrap();
        worst_separation(&mut w, 120)
    };
    let direct = swung(1, JointSolver::Direct);
    let iterative = swung(4, JointSolver::Iterative);
    assert!(direct < 1e-3, "direct, 1 iteration: {direct} cm");
    assert!(iterative > 1.0, "iterative, 4 iterations: {iterative} cm");
}

/// A 1000 kg body hanging from a static anchor by five 1 kg links (a
/// 1:1000 mass ratio across the last joint), 1 substep x 20 iterations:
/// iterated, the light links give way by decimetres; solved directly, the
/// chain holds to under a millimetre.
#[test]
fn a_heavy_body_on_light_links_does_not_stretch_them() {
    let hang = |joints| {
        let mut w = world(20, joints);
        let (bodies, _) = hanging_chain(&mut w, Vec3::new(0.0, 5.0, 0.0), 5, 0.3);
        let last = *bodies.last().unwrap();
        let bottom = w.body(last).unwrap().position - Vec3::Y * 0.15;
        let heavy = capsule(&mut w, bottom, bottom - Vec3::Y * 0.4, 1000.0);
        let joint =
            JointDesc::socket_at_world_anchor(w.bodies(), last, heavy, bottom, -Vec3::Y).unwrap();
        w.add_joint(joint).unwrap();
        // Swing it, so that the links carry more than its weight.
        w.set_body_velocity(heavy, Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO)
            .unwrap();
        worst_separation(&mut w, 180)
    };
    let direct = hang(JointSolver::Direct);
    let iterative = hang(JointSolver::Iterative);
    assert!(direct < 0.1, "direct: {direct} cm");
    assert!(iterative > 10.0, "iterative: {iterative} cm");
}

/// A ring of four bodies (the fourth joint closes a loop) and a body held
/// between two static anchors (a loop through them): the closing joints
/// stay iterated, the rest is solved directly, and everything stays
/// finite and together.
#[test]
fn loops_close_with_an_iterated_joint() {
    let mut w = world(20, JointSolver::Direct);
    let corners = [
        Vec3::new(0.0, 3.0, 0.0),
        Vec3::new(0.5, 3.0, 0.0),
        Vec3::new(0.5, 2.5, 0.0),
        Vec3::new(0.0, 2.5, 0.0),
    ];
    let mut links = Vec::new();
    for k in 0..4 {
        links.push(capsule(&mut w, corners[k], corners[(k + 1) % 4], 1.0));
    }
    for k in 0..4 {
        let (a, b) = (links[k], links[(k + 1) % 4]);
        let at = corners[(k + 1) % 4];
        let joint = JointDesc::socket_at_world_anchor(w.bodies(), a, b, at, Vec3::Y).unwrap();
        w.add_joint(joint).unwrap();
    }
    let left = w
        .add_body(BodyDesc::fixed().with_position(Vec3::new(2.0, 3.0, 0.0)))
        .unwrap();
    let right = w
        .add_body(BodyDesc::fixed().with_position(Vec3::new(3.0, 3.0, 0.0)))
        .unwrap();
    let bar = capsule(
        &mut w,
        Vec3::new(2.0, 3.0, 0.0),
        Vec3::new(3.0, 3.0, 0.0),
        2.0,
    );
    for (anchor, at) in [(left, 2.0), (right, 3.0)] {
        let at = Vec3::new(at, 3.0, 0.0);
        let joint =
            JointDesc::socket_at_world_anchor(w.bodies(), anchor, bar, at, Vec3::X).unwrap();
        w.add_joint(joint).unwrap();
    }
    let worst = worst_separation(&mut w, 120);
    assert!(worst < 0.5, "loops: {worst} cm");
}

/// A snapshot of a world solved directly restores into a fresh one and
/// steps on bit for bit (the trees are laid out again from the joints).
#[test]
fn a_restored_snapshot_steps_on_bit_for_bit() {
    let mut w = world(4, JointSolver::Direct);
    let (bodies, _) = hanging_chain(&mut w, Vec3::new(0.0, 5.0, 0.0), 6, 0.3);
    w.set_body_velocity(bodies[6], Vec3::new(1.0, 0.0, 2.0), Vec3::ZERO)
        .unwrap();
    for _ in 0..30 {
        w.step(1.0 / 60.0).unwrap();
    }
    let snapshot = w.snapshot();
    let mut restored = world(4, JointSolver::Direct);
    restored.restore(&snapshot).unwrap();
    for _ in 0..30 {
        w.step(1.0 / 60.0).unwrap();
        restored.step(1.0 / 60.0).unwrap();
    }
    assert_eq!(w.state_hash(), restored.state_hash());
}

/// A hanging arm put a radian past its 0.3 rad swing cone (its pose set
/// after the joint was made, as a ragdoll built from an animation that
/// bends a joint past its limit): solved directly, the limit takes it
/// back at `MAX_LIMIT_RETURN_SPEED`, the same angle every step while it is
/// far, and holds it on the limit once there. The return is measured from
/// the world's state alone: a snapshot taken halfway steps on bit for bit.
#[test]
fn a_limit_found_far_past_comes_back_at_a_bounded_speed() {
    let dt = 1.0 / 60.0;
    let config = SolverConfig {
        iterations: 4,
        gravity: Vec3::ZERO,
        sleep: None,
        joints: JointSolver::Direct,
        ..SolverConfig::default()
    };
    let mut w = World::new(config).unwrap();
    let anchor = w.add_body(BodyDesc::fixed()).unwrap();
    let arm = capsule(&mut w, Vec3::ZERO, -Vec3::Y * 0.5, 2.0);
    let joint = JointDesc::socket_at_world_anchor(w.bodies(), anchor, arm, Vec3::ZERO, -Vec3::Y)
        .unwrap()
        .with_swing_limit(0.3);
    w.add_joint(joint).unwrap();
    let turn = Quat::from_rotation_z(1.3);
    w.set_body_pose(arm, turn * (-Vec3::Y * 0.25), turn)
        .unwrap();
    let swing = |w: &World| (w.body(arm).unwrap().orientation * -Vec3::Y).angle_between(-Vec3::Y);
    let step = MAX_LIMIT_RETURN_SPEED * dt;
    let mut before = swing(&w);
    let mut steps = Vec::new();
    let mut restored = World::new(config).unwrap();
    for k in 0..30 {
        if k == 7 {
            restored.restore(&w.snapshot()).unwrap();
        }
        w.step(dt).unwrap();
        if k >= 7 {
            restored.step(dt).unwrap();
        }
        let now = swing(&w);
        steps.push(before - now);
        before = now;
    }
    assert_eq!(w.state_hash(), restored.state_hash(), "restored halfway");
    eprintln!("swing {before:.5} rad after 0.5 s; taken back each step: {steps:?}");
    // 1 rad at 0.067 rad a step: 15 steps, each a whole step's return.
    for (k, &back) in steps.iter().enumerate() {
        assert!(back <= step * 1.001, "step {k}: {back} rad, above {step}");
        if k < 14 {
            assert!(back >= step * 0.999, "step {k}: {back} rad, below {step}");
        }
    }
    assert!((before - 0.3).abs() < 1e-4, "on the limit: {before} rad");
}
