//! Whole worlds of sockets and rods are bit-identical across backends and
//! thread counts.

mod common;

use common::capsule;
use glam::{Quat, Vec3};
use vertebra_math::Backend;
use vertebra_world::{
    AngularDrive, BackendChoice, BodyDesc, BodyKind, JointDesc, JointSolver, RodDesc, RodStiffness,
    SolverConfig, World,
};

/// 30 branching chains (hundreds of bodies and sockets, several colours),
/// plus a hub body with 30 sockets so that the overflow set is used, some
/// limits and drives, stepped `frames` times.
fn build(backend: Backend, threads: usize) -> World {
    build_solved(backend, threads, JointSolver::Iterative)
}

/// [`build`]'s world with its joints solved by `joints`.
fn build_solved(backend: Backend, threads: usize, joints: JointSolver) -> World {
    build_with(SolverConfig {
        backend: BackendChoice::Forced(backend),
        threads,
        parallel_min_blocks: 1,
        joints,
        ..SolverConfig::default()
    })
}

/// [`build`]'s bodies and joints in a world of `config`.
fn build_with(config: SolverConfig) -> World {
    let mut w = World::new(config).unwrap();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    for tree in 0..30 {
        let base = Vec3::new((tree % 6) as f32 * 1.5, 3.0, (tree / 6) as f32 * 1.5);
        let mut parents = vec![(ground, base)];
        for depth in 0..4 {
            let mut next = Vec::new();
            for (k, &(parent, top)) in parents.iter().enumerate() {
                for branch in 0..if depth % 2 == 0 { 1 } else { 2 } {
                    let dir =
                        Vec3::new(0.3 * branch as f32 - 0.15, -1.0, 0.1 * k as f32).normalize();
                    let bottom = top + dir * 0.3;
                    let body = capsule(&mut w, top + dir * 0.02, bottom, 1.0 + 0.5 * depth as f32);
                    let mut desc =
                        JointDesc::socket_at_world_anchor(w.bodies(), parent, body, top, dir)
                            .unwrap();
                    if (tree + depth) % 3 == 0 {
                        desc = desc.with_swing_limit(0.4).with_twist_limit(-0.2, 0.3);
                    }
                    if (tree + depth) % 4 == 1 {
                        desc = desc.with_drive(
                            AngularDrive::spring(Quat::from_rotation_x(0.3), 3.0, 0.5)
                                .with_target_velocity(Vec3::new(0.0, 0.4, 0.0))
                                .with_max_torque(20.0),
                        );
                    }
                    w.add_joint(desc).unwrap();
                    next.push((body, bottom));
                }
            }
            parents = next;
        }
    }
    // Rods: a spine-like rod from each tree's top body to a new body above
    // it, bent, with limits and stiffness (some as relaxation factors).
    let tops: Vec<_> = (0..w.bodies().capacity())
        .filter_map(|i| w.bodies().handle_at(i))
        .skip(1)
        .step_by(9)
        .collect();
    for (k, &top) in tops.iter().enumerate() {
        let p = w.body(top).unwrap().position;
        let chest = capsule(
            &mut w,
            p + Vec3::new(0.1, 0.45, 0.0),
            p + Vec3::new(0.1, 0.55, 0.0),
            3.0,
        );
        let bones = [p + Vec3::new(0.08, 0.25, 0.02)];
        let stiffness = if k % 2 == 0 {
            RodStiffness::Kirchhoff(2.0)
        } else {
            RodStiffness::Relaxation(0.3)
        };
        let rod = RodDesc::from_pose(w.bodies(), top, chest, &bones)
            .unwrap()
            .with_stiffness(stiffness, RodStiffness::Kirchhoff(2.0))
            .with_bend_limit(1.0)
            .with_twist_limit(-0.5, 0.5);
        w.add_rod(rod).unwrap();
    }
    // The hub: 30 spokes on one dynamic body exceed the 24 colours.
    let hub = capsule(
        &mut w,
        Vec3::new(-3.0, 2.0, 0.0),
        Vec3::new(-3.0, 1.8, 0.0),
        5.0,
    );
    for k in 0..30 {
        let angle = k as f32 * 0.2;
        let dir = Vec3::new(angle.cos(), 0.0, angle.sin());
        let anchor = Vec3::new(-3.0, 1.9, 0.0) + dir * 0.1;
        let spoke = capsule(&mut w, anchor, anchor + dir * 0.3, 0.5);
        let desc = JointDesc::socket_at_world_anchor(w.bodies(), hub, spoke, anchor, dir).unwrap();
        w.add_joint(desc).unwrap();
    }
    w
}

fn hash_after(backend: Backend, threads: usize, frames: usize) -> (u64, f32) {
    hash_after_solved(backend, threads, frames, JointSolver::Iterative)
}

fn hash_after_solved(
    backend: Backend,
    threads: usize,
    frames: usize,
    joints: JointSolver,
) -> (u64, f32) {
    let mut w = build_solved(backend, threads, joints);
    let bodies: Vec<_> = (0..w.bodies().capacity())
        .filter_map(|i| w.bodies().handle_at(i))
        .collect();
    for frame in 0..frames {
        // Some forces so that the motion is rich.
        let b = bodies[(frame * 7) % bodies.len()];
        w.add_force(b, Vec3::new(20.0, 0.0, -10.0)).unwrap();
        w.step(1.0 / 60.0).unwrap();
    }
    (w.state_hash(), w.measure_residuals().eps_lin_cm)
}

#[test]
fn the_world_uses_many_colours_and_the_overflow_set() {
    let w = build(Backend::Scalar, 1);
    assert!(w.bodies().len() > 200, "{} bodies", w.bodies().len());
    let mut w = w;
    w.step(1.0 / 60.0).unwrap();
    assert!(w.measure_residuals().joints.len() > 200);
    assert!(
        w.measure_residuals().rods.len() >= 10,
        "rods: {}",
        w.measure_residuals().rods.len()
    );
    assert!(w.colour_count() >= 3, "colours: {}", w.colour_count());
    assert!(w.overflow_count() >= 6, "overflow: {}", w.overflow_count());
}

#[test]
fn every_backend_and_thread_count_gives_the_same_bits() {
    let (reference, eps) = hash_after(Backend::Scalar, 1, 100);
    assert!(eps.is_finite());
    for backend in Backend::available() {
        for threads in [1, 2] {
            let (hash, _) = hash_after(backend, threads, 100);
            assert_eq!(
                hash, reference,
                "{backend} with {threads} thread(s) differs from scalar"
            );
        }
    }
}

/// The direct solve's trees (the hub's 30 spokes in one tree, rods with
/// limits, drives, the overflow set) give the scalar reference's bits on
/// every backend and thread count too, and hold the joints far tighter.
#[test]
fn direct_joints_give_the_same_bits_everywhere_and_tighter_joints() {
    let direct = JointSolver::Direct;
    let (reference, eps) = hash_after_solved(Backend::Scalar, 1, 100, direct);
    let (iterative, iterative_eps) = hash_after(Backend::Scalar, 1, 100);
    assert_ne!(reference, iterative, "the direct solve changed nothing");
    assert!(
        eps < iterative_eps / 10.0,
        "direct {eps} cm against iterative {iterative_eps} cm"
    );
    for backend in Backend::available() {
        for threads in [1, 2, 3] {
            let (hash, _) = hash_after_solved(backend, threads, 100, direct);
            assert_eq!(
                hash, reference,
                "{backend} with {threads} thread(s) differs from scalar"
            );
        }
    }
}

#[test]
fn repeated_runs_give_the_same_bits() {
    let best = Backend::best();
    assert_eq!(hash_after(best, 2, 30), hash_after(best, 2, 30));
}

/// [`hash_after`]'s world with bodies switching kind mid-run: at frame 10
/// every fifth dynamic body (the hub among them: its 30 spokes leave the
/// overflow set) turns kinematic and is moved along a circle by
/// `move_kinematic` from then on; at frame 35 every other one of those is
/// dynamic again. Returns the hash and how many joints overflow with the
/// hub kinematic.
fn hash_after_switching(backend: Backend, threads: usize, frames: usize) -> (u64, usize) {
    let mut w = build(backend, threads);
    let dynamic: Vec<_> = (0..w.bodies().capacity())
        .filter_map(|i| w.bodies().handle_at(i))
        .filter(|&b| w.bodies().is_dynamic(b).unwrap())
        .collect();
    let hub = dynamic
        .iter()
        .copied()
        .find(|&b| w.bodies().mass[b.index()] == 5.0)
        .unwrap();
    let mut switched: Vec<_> = dynamic.iter().copied().step_by(5).collect();
    switched.push(hub);
    let mut overflow = usize::MAX;
    for frame in 0..frames {
        if frame == 10 {
            for &b in &switched {
                w.set_body_kind(b, BodyKind::Kinematic).unwrap();
            }
        }
        if frame == 35 {
            for &b in switched.iter().step_by(2) {
                w.set_body_kind(b, BodyKind::Dynamic).unwrap();
            }
        }
        for &b in &switched {
            if w.bodies().kind[b.index()] == BodyKind::Kinematic {
                let s = w.body(b).unwrap();
                let t = frame as f32 / 60.0;
                let to = s.position + 0.01 * Vec3::new(t.cos(), 0.5, t.sin());
                let turn = Quat::from_rotation_y(0.02) * s.orientation;
                w.move_kinematic(b, to, turn, 1.0 / 60.0).unwrap();
            }
        }
        w.step(1.0 / 60.0).unwrap();
        if frame == 20 {
            overflow = w.overflow_count();
        }
    }
    (w.state_hash(), overflow)
}

#[test]
fn worlds_switching_kinds_mid_run_give_the_same_bits_everywhere() {
    let (reference, overflow) = hash_after_switching(Backend::Scalar, 1, 60);
    assert_eq!(overflow, 0, "a kinematic hub's spokes need no overflow");
    for backend in Backend::available() {
        for threads in [1, 2] {
            let (hash, _) = hash_after_switching(backend, threads, 60);
            assert_eq!(
                hash, reference,
                "{backend} with {threads} thread(s) differs from scalar"
            );
        }
    }
    assert_ne!(reference, hash_after(Backend::Scalar, 1, 60).0);
}

/// `count` chains of three links hanging from static bodies: a socket with
/// limits and a drive, a hinge, and a rod from the second link to the
/// third, stepped `frames` times with a push now and then. Each colour
/// then holds `count` joints of a kind, so 1 to 9 chains fill a kind's
/// block from one lane to all eight (and one more block of one lane).
fn small_world_hash(backend: Backend, count: usize, frames: usize) -> u64 {
    let config = SolverConfig {
        backend: BackendChoice::Forced(backend),
        threads: 1,
        ..SolverConfig::default()
    };
    let mut w = World::new(config).unwrap();
    let mut links = Vec::new();
    for chain in 0..count {
        let top = Vec3::new(chain as f32 * 0.7, 2.0, 0.0);
        let base = w.add_body(BodyDesc::fixed().with_position(top)).unwrap();
        let tilt = Vec3::new(0.2, -1.0, 0.1 * chain as f32).normalize();
        let knee = top + tilt * 0.4;
        let upper = capsule(&mut w, top, knee, 2.0);
        let lower = capsule(&mut w, knee, knee - Vec3::Y * 0.4, 1.0);
        let foot = capsule(&mut w, knee - Vec3::Y * 0.45, knee - Vec3::Y * 0.6, 0.5);
        let socket = JointDesc::socket_at_world_anchor(w.bodies(), base, upper, top, tilt)
            .unwrap()
            .with_swing_limit(0.3)
            .with_twist_limit(-0.2, 0.2)
            .with_drive(AngularDrive::spring(Quat::from_rotation_z(0.4), 2.0, 0.5));
        w.add_joint(socket).unwrap();
        let hinge =
            JointDesc::hinge_at_world_anchor(w.bodies(), upper, lower, knee, Vec3::Z).unwrap();
        w.add_joint(hinge).unwrap();
        let bones = [knee - Vec3::new(0.01, 0.42, 0.0)];
        let rod = RodDesc::from_pose(w.bodies(), lower, foot, &bones)
            .unwrap()
            .with_bend_limit(0.5);
        w.add_rod(rod).unwrap();
        links.extend([upper, lower, foot]);
    }
    for frame in 0..frames {
        let body = links[(frame * 5) % links.len()];
        w.add_force(body, Vec3::new(30.0, 10.0, -20.0)).unwrap();
        w.step(1.0 / 60.0).unwrap();
    }
    w.state_hash()
}

#[test]
fn worlds_of_one_to_nine_chains_give_the_same_bits_on_every_backend() {
    for count in 1..=9 {
        let reference = small_world_hash(Backend::Scalar, count, 40);
        for backend in Backend::available() {
            assert_eq!(
                small_world_hash(backend, count, 40),
                reference,
                "{backend} differs from scalar with {count} chain(s)"
            );
        }
    }
}

/// Measured after a step (`World::measure_residuals`, as the scenes do,
/// outside the frame's own cost), the residuals are the step's own: each
/// joint's equals what a world measuring in every step reports, up to
/// the rounding of the committed poses (the step measures its rows as
/// they left the solve; after it they are built again from the bodies:
/// a few ulps of a position, 1e-4 cm or rad),
/// and measuring changes nothing the next step does.
#[test]
fn residuals_measured_after_a_step_are_the_steps_own() {
    for joints in [JointSolver::Iterative, JointSolver::Direct] {
        let config = |measure_residuals| SolverConfig {
            joints,
            measure_residuals,
            ..SolverConfig::default()
        };
        let (mut during, mut after) = (build_with(config(true)), build_with(config(false)));
        for frame in 0..90 {
            if frame < 30 {
                for w in [&mut during, &mut after] {
                    let bodies: Vec<_> = (0..w.bodies().capacity())
                        .filter_map(|i| w.bodies().handle_at(i))
                        .collect();
                    let b = bodies[(frame * 7) % bodies.len()];
                    w.add_force(b, Vec3::new(20.0, 0.0, -10.0)).unwrap();
                }
            }
            during.step(1.0 / 60.0).unwrap();
            after.step(1.0 / 60.0).unwrap();
            let stepped = during.residuals().expect("measured in the step").clone();
            let asked = after.measure_residuals();
            let values = |r: &vertebra_world::Residuals| -> Vec<f32> {
                let joints = r
                    .joints
                    .iter()
                    .map(|j| [j.linear_cm, j.angular_rad, j.limit_rad]);
                let rods = r
                    .rods
                    .iter()
                    .map(|j| [j.linear_cm, j.angular_rad, j.limit_rad]);
                joints.chain(rods).flatten().collect()
            };
            let (stepped, asked) = (values(&stepped), values(asked));
            assert_eq!(stepped.len(), asked.len());
            for (k, (s, a)) in stepped.iter().zip(&asked).enumerate() {
                assert!(
                    (s - a).abs() <= 1e-4 * s.abs().max(a.abs()) + 1e-4,
                    "{joints:?}, frame {frame}, value {k}: {s:e} in the step, {a:e} after"
                );
            }
        }
        assert_eq!(during.state_hash(), after.state_hash(), "{joints:?}");
    }
}
