//! Joint forces and torques against statics (a hanging weight, a
//! cantilever), both joint solves; joints that break in the step their
//! load passes the threshold, on every backend and thread count.

use glam::Vec3;
use vertebra_math::Backend;
use vertebra_world::{
    BackendChoice, BodyDesc, BodyHandle, Error, JointDesc, JointHandle, JointSolver, Shape,
    SolverConfig, World,
};

const DT: f32 = 1.0 / 60.0;
const G: f32 = 9.81;

fn config(joints: JointSolver) -> SolverConfig {
    SolverConfig {
        substeps: 2,
        iterations: 8,
        joints,
        sleep: None,
        ..SolverConfig::default()
    }
}

fn capsule(w: &mut World, mass: f32, at: Vec3, along: Vec3) -> BodyHandle {
    let half = along * 0.2;
    let shape = Shape::capsule(-half, half, 0.05);
    let props = shape.mass_properties_with_mass(mass).unwrap();
    w.add_body(BodyDesc::dynamic(props).with_position(at))
        .unwrap()
}

#[test]
fn a_hanging_weights_socket_carries_its_weight() {
    for joints in [JointSolver::Iterative, JointSolver::Direct] {
        let mut w = World::new(config(joints)).unwrap();
        let anchor = w.add_body(BodyDesc::fixed()).unwrap();
        let bob = capsule(&mut w, 3.0, Vec3::new(0.0, -0.25, 0.0), Vec3::Y);
        let joint =
            JointDesc::socket_at_world_anchor(w.bodies(), anchor, bob, Vec3::ZERO, -Vec3::Y)
                .unwrap();
        let joint = w.add_joint(joint).unwrap();
        for _ in 0..60 {
            w.step(DT).unwrap();
        }
        let load = w.joint_force(joint).unwrap();
        let weight = Vec3::new(0.0, 3.0 * G, 0.0);
        assert!(
            (load.force - weight).length() < 0.01 * weight.length(),
            "{joints:?}: {load:?}"
        );
        assert!(load.torque.length() < 1e-3, "{joints:?}: {load:?}");
    }
}

/// A horizontal beam welded to a wall at one end (a fixed joint): the
/// joint holds its weight and the weight's moment about the weld (the
/// weld turns the beam back against gravity's `r x m g`). Its bodies
/// either way round (the load is on `b`: the wall's is the beam's turned
/// about), and 10 km from the origin, where a coordinate's `f32` step is
/// a millimetre; both joint solves.
#[test]
fn a_cantilevers_weld_holds_its_weight_and_its_moment_on_either_body_far_or_near() {
    for joints in [JointSolver::Iterative, JointSolver::Direct] {
        for far in [Vec3::ZERO, Vec3::new(1.0e4, 0.0, -1.0e4)] {
            for beam_is_b in [true, false] {
                let mut w = World::new(config(joints)).unwrap();
                let wall = w.add_body(BodyDesc::fixed().with_position(far)).unwrap();
                let beam = capsule(&mut w, 2.0, far + Vec3::new(0.25, 0.0, 0.0), Vec3::X);
                let (a, b) = if beam_is_b {
                    (wall, beam)
                } else {
                    (beam, wall)
                };
                let joint = JointDesc::fixed_at(w.bodies(), a, b, far).unwrap();
                let joint = w.add_joint(joint).unwrap();
                for _ in 0..60 {
                    w.step(DT).unwrap();
                }
                let load = w.joint_force(joint).unwrap();
                let arm = w.body(beam).unwrap().position - far;
                let side = if beam_is_b { 1.0 } else { -1.0 };
                let weight = side * Vec3::new(0.0, 2.0 * G, 0.0);
                let moment = side * -(arm.cross(Vec3::new(0.0, -2.0 * G, 0.0)));
                let case = format!("{joints:?}, {far}, beam is b: {beam_is_b}: {load:?}");
                assert!(
                    (load.force - weight).length() < 0.01 * weight.length(),
                    "{case}"
                );
                assert!(
                    (load.torque - moment).length() < 0.02 * moment.length(),
                    "{case} against {moment}"
                );
            }
        }
    }
}

/// A chain of three links from an anchor with a weight at its end, the
/// middle link breakable below the load: it breaks in the first step, on
/// every backend and thread count, and the rest falls.
fn chain(config: SolverConfig, threshold: f32) -> (World, Vec<JointHandle>, BodyHandle) {
    let mut w = World::new(config).unwrap();
    let mut parent = w.add_body(BodyDesc::fixed()).unwrap();
    let mut joints = Vec::new();
    let mut last = parent;
    for k in 0..3 {
        let top = -0.5 * k as f32;
        let mass = if k == 2 { 20.0 } else { 1.0 };
        let link = capsule(&mut w, mass, Vec3::new(0.0, top - 0.25, 0.0), Vec3::Y);
        let mut joint = JointDesc::socket_at_world_anchor(
            w.bodies(),
            parent,
            link,
            Vec3::new(0.0, top, 0.0),
            -Vec3::Y,
        )
        .unwrap();
        if k == 1 {
            joint = joint.with_breaking(threshold, f32::INFINITY);
        }
        joints.push(w.add_joint(joint).unwrap());
        parent = link;
        last = link;
    }
    (w, joints, last)
}

#[test]
fn a_joint_past_its_threshold_breaks_in_the_same_step_everywhere() {
    // The middle link holds 21 kg (206 N); it breaks past 150 N.
    let mut outcomes = Vec::new();
    for joints in [JointSolver::Iterative, JointSolver::Direct] {
        for backend in Backend::available() {
            for threads in [1, 2] {
                let config = SolverConfig {
                    backend: BackendChoice::Forced(backend),
                    threads,
                    ..config(joints)
                };
                let (mut w, handles, weight) = chain(config, 150.0);
                let mut broke = None;
                for frame in 0..30 {
                    w.step(DT).unwrap();
                    if let Some(b) = w.broken_joints().first() {
                        assert_eq!(b.joint, handles[1]);
                        assert!(b.load.force.length() > 150.0, "{b:?}");
                        broke.get_or_insert(frame);
                        assert!(matches!(w.joint(handles[1]), Err(Error::StaleHandle(_))));
                    }
                }
                // The load reaches the weight's within the first steps.
                assert!(
                    broke.is_some_and(|f| f <= 2),
                    "{joints:?} on {backend} at {threads}: {broke:?}"
                );
                assert!(w.body(weight).unwrap().position.y < -2.0, "the end fell");
                outcomes.push((joints, broke, w.state_hash()));
            }
        }
    }
    for pair in outcomes.windows(2) {
        if pair[0].0 == pair[1].0 {
            assert_eq!(pair[0], pair[1], "the same step and bits everywhere");
        }
    }
    // Above the load it holds, for good.
    let (mut w, handles, _) = chain(config(JointSolver::Iterative), 400.0);
    for _ in 0..120 {
        w.step(DT).unwrap();
        assert!(w.broken_joints().is_empty());
    }
    assert!(w.joint(handles[1]).is_ok());
}

#[test]
fn thresholds_are_checked_saved_and_change_no_bit_of_a_joint_without_them() {
    let (mut w, _, _) = chain(config(JointSolver::Iterative), 1e9);
    let (a, b) = (
        w.bodies().handle_at(0).unwrap(),
        w.bodies().handle_at(1).unwrap(),
    );
    let desc = JointDesc::socket_at_world_anchor(w.bodies(), a, b, Vec3::ZERO, -Vec3::Y).unwrap();
    let before = w.state_hash();
    for (force, torque) in [(0.0, 1.0), (1.0, -1.0), (f32::NAN, 1.0), (1.0, f32::NAN)] {
        assert!(w.add_joint(desc.with_breaking(force, torque)).is_err());
    }
    assert_eq!(w.state_hash(), before, "refused, nothing changed");
    // Saved with the joint, and stepped on alike.
    let snapshot = w.snapshot();
    let mut restored = World::new(config(JointSolver::Iterative)).unwrap();
    restored.restore(&snapshot).unwrap();
    let breakable: Vec<_> = restored
        .joints()
        .filter(|(_, d)| d.breaking.is_some())
        .collect();
    assert_eq!(breakable.len(), 1);
    for _ in 0..10 {
        w.step(DT).unwrap();
        restored.step(DT).unwrap();
    }
    assert_eq!(w.state_hash(), restored.state_hash());
    // The thresholds are state: the same world without them hashes
    // otherwise (a joint without them hashes as it did before they
    // existed: the golden hashes, crates/vertebra-scenes/tests/golden.rs).
    let (plain, _, _) = chain(config(JointSolver::Iterative), 1e9);
    let mut unbreakable = World::new(config(JointSolver::Iterative)).unwrap();
    unbreakable.restore(&plain.snapshot()).unwrap();
    let (slot, desc) = unbreakable.joints().nth(1).unwrap();
    let kept = JointDesc {
        breaking: None,
        ..desc
    };
    unbreakable.remove_joint(slot).unwrap();
    unbreakable.add_joint(kept).unwrap();
    let without = unbreakable.state_hash();
    let mut with = World::new(config(JointSolver::Iterative)).unwrap();
    with.restore(&plain.snapshot()).unwrap();
    let (slot, desc) = with.joints().nth(1).unwrap();
    with.remove_joint(slot).unwrap();
    with.add_joint(desc).unwrap();
    assert_ne!(with.state_hash(), without, "the thresholds are hashed");
}

/// A hub hanging from an anchor with four arms of two links each, under
/// the direct solve: a tree the SIMD backends cut into pieces (the arms
/// side by side in lanes, the hub and its anchor joint in a trunk block).
/// At rest every joint carries the weight below it: the anchor's the
/// whole tree's, each arm's shoulder its arm's, on every backend, and
/// to the bit the same on all of them, cut or whole (what breaking in
/// the same step everywhere rests on).
#[test]
fn a_cut_trees_joints_carry_the_weight_below_them_in_every_piece() {
    let mut loads = Vec::new();
    for backend in Backend::available() {
        let config = SolverConfig {
            backend: BackendChoice::Forced(backend),
            ..config(JointSolver::Direct)
        };
        let mut w = World::new(config).unwrap();
        let anchor = w.add_body(BodyDesc::fixed()).unwrap();
        let hub = capsule(&mut w, 4.0, Vec3::new(0.0, -0.25, 0.0), Vec3::Y);
        let top = JointDesc::socket_at_world_anchor(w.bodies(), anchor, hub, Vec3::ZERO, -Vec3::Y);
        let top = w.add_joint(top.unwrap()).unwrap();
        let mut shoulders = Vec::new();
        for k in 0..4 {
            let side = 0.05 * Vec3::new([1.0, -1.0, 0.0, 0.0][k], 0.0, [0.0, 0.0, 1.0, -1.0][k]);
            let mut parent = hub;
            for link in 0..2 {
                let y = -0.5 - 0.5 * link as f32;
                let body = capsule(&mut w, 1.0, side + Vec3::new(0.0, y - 0.25, 0.0), Vec3::Y);
                let at = side + Vec3::new(0.0, y, 0.0);
                let joint =
                    JointDesc::socket_at_world_anchor(w.bodies(), parent, body, at, -Vec3::Y);
                let joint = w.add_joint(joint.unwrap()).unwrap();
                if link == 0 {
                    shoulders.push(joint);
                }
                parent = body;
            }
        }
        for _ in 0..60 {
            w.step(DT).unwrap();
        }
        let weight = |kg: f32| Vec3::new(0.0, kg * G, 0.0);
        let load = w.joint_force(top).unwrap();
        assert!(
            (load.force - weight(12.0)).length() < 0.01 * weight(12.0).length(),
            "{backend}: the anchor's {load:?}"
        );
        for shoulder in &shoulders {
            let load = w.joint_force(*shoulder).unwrap();
            assert!(
                (load.force - weight(2.0)).length() < 0.01 * weight(2.0).length(),
                "{backend}: a shoulder's {load:?}"
            );
        }
        let bits = (core::iter::once(&top).chain(&shoulders))
            .map(|&joint| w.joint_force(joint).unwrap())
            .flat_map(|l| [l.force, l.torque].map(|v| v.to_array().map(f32::to_bits)))
            .collect::<Vec<_>>();
        loads.push((backend, bits));
    }
    for pair in loads.windows(2) {
        assert_eq!(pair[0].1, pair[1].1, "{} and {}", pair[0].0, pair[1].0);
    }
}
