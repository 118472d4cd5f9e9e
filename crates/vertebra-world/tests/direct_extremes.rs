//! The direct joint solve (`JointSolver::Direct`) at its extremes, through
//! the public API only: trees of every kind, huge trees, extreme mass
//! ratios, degenerate joints, kinds and constraints changed between steps,
//! sleep, snapshots, backends and threads, far from the origin. Every
//! world stays finite, keeps its joints together (no worse than the
//! iterative solver) and keeps the bit-identity the library promises.

mod common;

use common::capsule;
use glam::{Quat, Vec3};
use vertebra_math::Backend;
use vertebra_world::{
    AngularDrive, BackendChoice, BodyDesc, BodyHandle, BodyKind, JointDesc, JointKind, JointSolver,
    LimitSoftness, MassProperties, RodDesc, SleepSettings, SolverConfig, World,
};

const DT: f32 = 1.0 / 60.0;

fn config(joints: JointSolver, iterations: u32) -> SolverConfig {
    SolverConfig {
        iterations,
        sleep: None,
        joints,
        ..SolverConfig::default()
    }
}

fn world(joints: JointSolver, iterations: u32) -> World {
    World::new(config(joints, iterations)).expect("valid config")
}

/// Every live body's state is finite.
fn assert_finite(w: &World) {
    for (i, h) in handles(w).into_iter().enumerate() {
        let s = w.body(h).unwrap();
        let all = [s.position, s.linear_velocity, s.angular_velocity];
        assert!(
            all.iter().all(|v| v.is_finite()) && s.orientation.is_finite(),
            "body {i} not finite: {s:?}"
        );
    }
}

/// Every live body's handle.
fn handles(w: &World) -> Vec<BodyHandle> {
    (0..w.bodies().capacity())
        .filter_map(|i| w.bodies().handle_at(i))
        .collect()
}

/// The summed joint separation (cm) of the current poses.
fn separation(w: &mut World) -> f32 {
    let eps = w.measure_residuals().eps_lin_cm;
    assert!(eps.is_finite(), "non-finite residual");
    eps
}

/// Steps `frames` frames; the worst summed separation (cm) after any.
fn run(w: &mut World, frames: usize) -> f32 {
    let mut worst = 0.0f32;
    for _ in 0..frames {
        w.step(DT).unwrap();
        assert_finite(w);
        worst = worst.max(separation(w));
    }
    worst
}

/// A body of `mass` kg with a diagonal inertia `inertia` kg m^2 at `at`.
fn point_mass(w: &mut World, at: Vec3, mass: f32, inertia: f32) -> BodyHandle {
    let props = MassProperties {
        mass,
        inertia: glam::Mat3::from_diagonal(Vec3::splat(inertia)),
    };
    w.add_body(BodyDesc::dynamic(props).with_position(at))
        .unwrap()
}

/// A horizontal chain from a static anchor at `top` along +X of `links`
/// links of `length` m, cycling socket (with a cone and twist), hinge
/// (hard range), fixed, rod. Returns the bodies (the anchor first).
fn mixed_chain(w: &mut World, top: Vec3, links: usize, length: f32) -> Vec<BodyHandle> {
    let anchor = w.add_body(BodyDesc::fixed().with_position(top)).unwrap();
    let mut bodies = vec![anchor];
    for k in 0..links {
        let a = top + Vec3::X * (length * k as f32);
        let b = a + Vec3::X * length;
        let body = capsule(w, a, b, 1.0 + k as f32 % 3.0);
        let parent = *bodies.last().unwrap();
        let kind = k % 4;
        if kind == 3 && bodies.len() > 1 {
            let rod = RodDesc::from_pose(w.bodies(), parent, body, &[]).unwrap();
            w.add_rod(rod.with_bend_limit(0.6).with_twist_limit(-0.3, 0.3))
                .unwrap();
        } else {
            let desc = match kind {
                0 | 3 => JointDesc::socket_at_world_anchor(w.bodies(), parent, body, a, Vec3::X)
                    .unwrap()
                    .with_swing_limit(0.7)
                    .with_twist_limit(-0.2, 0.2),
                1 => JointDesc::hinge_at_world_anchor(w.bodies(), parent, body, a, Vec3::Z)
                    .unwrap()
                    .with_kind(JointKind::Hinge {
                        range: Some([-1.0, 0.5]),
                        softness: LimitSoftness::Hard,
                    }),
                _ => JointDesc::fixed_at(w.bodies(), parent, body, a).unwrap(),
            };
            w.add_joint(desc).unwrap();
        }
        bodies.push(body);
    }
    bodies
}

/// Trees of every kind, mixed, with limits hit hard (a horizontal chain
/// falls and swings): finite, together, and no worse than iterated.
#[test]
fn mixed_trees_of_every_kind_hold_together() {
    let swing = |joints| {
        let mut w = world(joints, 4);
        let bodies = mixed_chain(&mut w, Vec3::new(0.0, 5.0, 0.0), 12, 0.3);
        w.set_body_velocity(
            bodies[12],
            Vec3::new(0.0, 0.0, 8.0),
            Vec3::new(5.0, 0.0, 0.0),
        )
        .unwrap();
        run(&mut w, 90)
    };
    let direct = swing(JointSolver::Direct);
    let iterative = swing(JointSolver::Iterative);
    assert!(direct < 0.5, "direct: {direct} cm");
    assert!(
        direct <= iterative,
        "direct {direct} cm, iterative {iterative} cm"
    );
}

/// A 2000-link chain and a star of 200 spokes on one hub, solved as two
/// trees: finite, and every joint held to well under a millimetre on
/// average (iterated, the chain stretches by metres).
#[test]
fn a_huge_chain_and_a_huge_star() {
    let mut w = world(JointSolver::Direct, 2);
    let top = Vec3::new(0.0, 500.0, 0.0);
    let (chain, _) = common::hanging_chain(&mut w, top, 2000, 0.1);
    w.set_body_velocity(chain[2000], Vec3::new(5.0, 0.0, 0.0), Vec3::ZERO)
        .unwrap();
    let hub = point_mass(&mut w, Vec3::new(50.0, 5.0, 0.0), 10.0, 1.0);
    for k in 0..200 {
        let angle = k as f32 * core::f32::consts::TAU / 200.0;
        let out = Vec3::new(angle.cos(), 0.0, angle.sin());
        let at = Vec3::new(50.0, 5.0, 0.0) + out * 0.2;
        let spoke = capsule(&mut w, at, at + out * 0.5, 0.5);
        let desc = if k % 2 == 0 {
            JointDesc::socket_at_world_anchor(w.bodies(), hub, spoke, at, out).unwrap()
        } else {
            JointDesc::hinge_at_world_anchor(w.bodies(), hub, spoke, at, Vec3::Y).unwrap()
        };
        w.add_joint(desc).unwrap();
    }
    w.set_body_velocity(hub, Vec3::ZERO, Vec3::new(0.0, 20.0, 3.0))
        .unwrap();
    let worst = run(&mut w, 10);
    let joints = w.joints().count() as f32;
    assert!(worst / joints < 0.01, "{worst} cm over {joints} joints");
}

/// 1e-3 kg links next to 1e5 kg bodies (a ratio of 1e8) and bodies of
/// tiny and huge inertia: finite, and direct no worse than iterated on
/// the joints' separation.
#[test]
fn extreme_mass_ratios_and_inertias() {
    let build = |joints| {
        let mut w = world(joints, 8);
        // Static -> light link -> heavy body -> light link -> heavy body.
        let top = Vec3::new(0.0, 5.0, 0.0);
        let anchor = w.add_body(BodyDesc::fixed().with_position(top)).unwrap();
        let mut parent = anchor;
        let masses = [
            (1e-3, 1e-7),
            (1e5, 1e4),
            (1e-3, 1e-9),
            (1e5, 1e6),
            (1.0, 1e-6),
        ];
        for (k, &(mass, inertia)) in masses.iter().enumerate() {
            let upper = top - Vec3::Y * (0.3 * k as f32);
            let centre = upper - Vec3::Y * 0.15;
            let body = point_mass(&mut w, centre, mass, inertia);
            let desc = if k == 2 {
                JointDesc::hinge_at_world_anchor(w.bodies(), parent, body, upper, Vec3::Z).unwrap()
            } else {
                JointDesc::socket_at_world_anchor(w.bodies(), parent, body, upper, -Vec3::Y)
                    .unwrap()
            };
            w.add_joint(desc).unwrap();
            parent = body;
        }
        w.set_body_velocity(parent, Vec3::new(3.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 9.0))
            .unwrap();
        run(&mut w, 120)
    };
    let direct = build(JointSolver::Direct);
    let iterative = build(JointSolver::Iterative);
    assert!(
        direct <= iterative.max(1.0),
        "direct {direct} cm, iterative {iterative} cm"
    );
}

/// Degenerate joints: anchors at both centres of mass, a hinge whose
/// axes start exactly opposed (turned 180 degrees), a fixed joint whose
/// frames start half a turn apart, a rod whose ends are then put
/// together: nothing panics, nothing goes non-finite.
#[test]
fn degenerate_joints_stay_finite() {
    let mut w = world(JointSolver::Direct, 4);
    let anchor = w
        .add_body(BodyDesc::fixed().with_position(Vec3::new(0.0, 5.0, 0.0)))
        .unwrap();
    let a = point_mass(&mut w, Vec3::new(0.0, 5.0, 0.0), 1.0, 0.1);
    let b = point_mass(&mut w, Vec3::new(0.0, 4.5, 0.0), 1.0, 0.1);
    let c = point_mass(&mut w, Vec3::new(0.0, 4.0, 0.0), 1.0, 0.1);
    let d = point_mass(&mut w, Vec3::new(0.0, 3.5, 0.0), 1.0, 0.1);
    // Anchor at a's centre of mass and at the static body's origin.
    let socket = JointDesc::socket_at_world_anchor(
        w.bodies(),
        anchor,
        a,
        Vec3::new(0.0, 5.0, 0.0),
        -Vec3::Y,
    )
    .unwrap();
    w.add_joint(socket).unwrap();
    // A hinge turned half a turn about Y: b's axis starts along -Z.
    let mut hinge =
        JointDesc::hinge_at_world_anchor(w.bodies(), a, b, Vec3::new(0.0, 4.75, 0.0), Vec3::Z)
            .unwrap();
    hinge.frame_b = Quat::from_rotation_y(core::f32::consts::PI) * hinge.frame_b;
    w.add_joint(hinge).unwrap();
    let mut fixed = JointDesc::fixed_at(w.bodies(), b, c, Vec3::new(0.0, 4.25, 0.0)).unwrap();
    fixed.frame_b = Quat::from_rotation_x(core::f32::consts::PI) * fixed.frame_b;
    w.add_joint(fixed).unwrap();
    let rod = RodDesc::from_pose(w.bodies(), c, d, &[]).unwrap();
    let rod = w.add_rod(rod).unwrap();
    run(&mut w, 5);
    // The rod's ends together, and the hinge's bodies in one place.
    let at_c = w.body(c).unwrap();
    w.set_body_pose(d, at_c.position, at_c.orientation).unwrap();
    let at_a = w.body(a).unwrap();
    w.set_body_pose(b, at_a.position, at_a.orientation).unwrap();
    run(&mut w, 60);
    // And a rod changed to a (nearly) zero rest length.
    let mut desc = w.rod(rod).unwrap();
    desc.rest_length = 1e-6;
    if w.set_rod(rod, desc).is_ok() {
        run(&mut w, 30);
    }
}

/// Many trees of one shape (two full blocks and a part-filled one, so
/// padding lanes), trees of another shape, single-link trees, a ring
/// (a loop), a body between two kinematic anchors, joints between two
/// static or kinematic bodies: the world the bit-identity tests step.
fn crowd(w: &mut World) -> Vec<BodyHandle> {
    let mut ends = Vec::new();
    for k in 0..19 {
        let top = Vec3::new(k as f32 * 2.0, 6.0, 0.0);
        let links = if k % 5 == 4 { 3 } else { 5 };
        let bodies = mixed_chain(w, top, links, 0.25);
        ends.push(*bodies.last().unwrap());
    }
    // A free-floating tree (no static root): body 0 is its root.
    let a = capsule(w, Vec3::new(0.0, 2.0, 3.0), Vec3::new(0.4, 2.0, 3.0), 2.0);
    let b = capsule(w, Vec3::new(0.4, 2.0, 3.0), Vec3::new(0.8, 2.0, 3.0), 1.0);
    let desc =
        JointDesc::hinge_at_world_anchor(w.bodies(), a, b, Vec3::new(0.4, 2.0, 3.0), Vec3::Y)
            .unwrap();
    w.add_joint(desc).unwrap();
    w.set_body_velocity(a, Vec3::Y, Vec3::new(0.0, 0.0, 4.0))
        .unwrap();
    ends.push(b);
    // Two kinematic anchors holding one bar (a loop through them), and
    // joints made to join two kinematic bodies and a kinematic body to a
    // static one (their dynamic side switched to kinematic).
    let left = w
        .add_body(BodyDesc::kinematic().with_position(Vec3::new(0.0, 4.0, 5.0)))
        .unwrap();
    let right = w
        .add_body(BodyDesc::kinematic().with_position(Vec3::new(1.0, 4.0, 5.0)))
        .unwrap();
    let ground = w
        .add_body(BodyDesc::fixed().with_position(Vec3::new(2.0, 4.0, 5.0)))
        .unwrap();
    let bar = capsule(w, Vec3::new(0.0, 4.0, 5.0), Vec3::new(1.0, 4.0, 5.0), 3.0);
    for (anchor, x) in [(left, 0.0), (right, 1.0)] {
        let at = Vec3::new(x, 4.0, 5.0);
        let desc = JointDesc::socket_at_world_anchor(w.bodies(), anchor, bar, at, Vec3::X).unwrap();
        w.add_joint(desc).unwrap();
    }
    let knob = capsule(w, Vec3::new(0.0, 4.5, 5.0), Vec3::new(0.0, 4.8, 5.0), 1.0);
    let fixed = JointDesc::fixed_at(w.bodies(), left, knob, Vec3::new(0.0, 4.5, 5.0)).unwrap();
    w.add_joint(fixed).unwrap();
    let hinge = JointDesc::hinge_at_world_anchor(
        w.bodies(),
        knob,
        ground,
        Vec3::new(0.0, 4.8, 5.0),
        Vec3::Z,
    )
    .unwrap();
    w.add_joint(hinge).unwrap();
    w.set_body_kind(knob, BodyKind::Kinematic).unwrap();
    w.set_body_velocity(left, Vec3::new(0.5, 0.0, 0.0), Vec3::ZERO)
        .unwrap();
    ends.push(bar);
    ends
}

/// Edits between steps, in a fixed order: kinds switched (a link made
/// kinematic, moved, and made dynamic again), a
/// joint removed and added back, drives added, changed and removed, a
/// rod's rest shape and limits changed, a free body removed.
fn edit(w: &mut World, ends: &[BodyHandle], frame: usize) {
    let end = ends[(frame / 10 * 7) % ends.len()];
    match frame % 10 {
        1 => w.set_body_kind(end, BodyKind::Kinematic).unwrap(),
        2 => {
            let s = w.body(end).unwrap();
            let to = s.position + Vec3::new(0.05, 0.02, 0.0);
            w.move_kinematic(end, to, Quat::from_rotation_z(0.3) * s.orientation, DT)
                .unwrap();
        }
        4 => w.set_body_kind(end, BodyKind::Dynamic).unwrap(),
        5 => {
            let (h, desc) = w.joints().nth(frame % 7).unwrap();
            w.remove_joint(h).unwrap();
            w.add_joint(desc).unwrap();
        }
        6 => {
            let (h, desc) = (w.joints())
                .find(|(_, d)| !matches!(d.kind, JointKind::Fixed) && d.drive.is_none())
                .unwrap();
            let _ = desc;
            w.set_joint_drive(
                h,
                Some(AngularDrive::spring(Quat::from_rotation_z(0.4), 4.0, 0.5)),
            )
            .unwrap();
        }
        7 => {
            let (h, _) = w.joints().find(|(_, d)| d.drive.is_some()).unwrap();
            w.set_joint_drive(h, Some(AngularDrive::spring(Quat::IDENTITY, 2.0, 1.0)))
                .unwrap();
        }
        8 => {
            let (h, _) = w.joints().find(|(_, d)| d.drive.is_some()).unwrap();
            w.set_joint_drive(h, None).unwrap();
        }
        9 => {
            let (h, mut desc) = w.rods().nth(frame % 3).unwrap();
            desc.rest_length *= 1.1;
            desc.bend_limit = Some(0.2);
            desc.twist_limit = None;
            w.set_rod(h, desc).unwrap();
            let free = w
                .add_body(BodyDesc::dynamic(MassProperties {
                    mass: 1.0,
                    inertia: glam::Mat3::IDENTITY,
                }))
                .unwrap();
            w.step(DT).unwrap();
            w.remove_body(free).unwrap();
        }
        _ => {}
    }
}

/// The crowd's hash after `frames` frames of edits and steps.
fn crowd_hash(backend: Backend, threads: usize, frames: usize, sleep: bool) -> u64 {
    let mut w = World::new(SolverConfig {
        backend: BackendChoice::Forced(backend),
        threads,
        sleep: sleep.then(SleepSettings::default),
        ..config(JointSolver::Direct, 3)
    })
    .unwrap();
    let ends = crowd(&mut w);
    for frame in 0..frames {
        edit(&mut w, &ends, frame);
        w.step(DT).unwrap();
        assert_finite(&w);
    }
    w.state_hash()
}

/// Whole worlds, edited between steps, bit-identical across every
/// backend and 1 to 4 threads.
#[test]
fn every_backend_and_thread_count_agrees_on_an_edited_crowd() {
    let reference = crowd_hash(Backend::Scalar, 1, 40, false);
    for backend in Backend::available() {
        for threads in 1..=4 {
            if (backend, threads) == (Backend::Scalar, 1) {
                continue;
            }
            let hash = crowd_hash(backend, threads, 40, false);
            assert_eq!(hash, reference, "{backend} with {threads} threads");
        }
    }
}

/// The edited crowd stays together: with the direct solve its joints
/// are no further apart than iterated ones.
#[test]
fn the_edited_crowd_holds_together() {
    let worst = |joints| {
        let mut w = world(joints, 3);
        let ends = crowd(&mut w);
        let mut worst = 0.0f32;
        for frame in 0..60 {
            edit(&mut w, &ends, frame);
            w.step(DT).unwrap();
            assert_finite(&w);
            worst = worst.max(separation(&mut w));
        }
        worst
    };
    let direct = worst(JointSolver::Direct);
    let iterative = worst(JointSolver::Iterative);
    assert!(
        direct <= iterative,
        "direct {direct} cm, iterative {iterative} cm"
    );
}

/// Sleeping trees: a damped hanging crowd falls asleep, is woken by an
/// impulse and holds together after; the same on every thread count.
#[test]
fn trees_sleep_and_wake() {
    let run_sleep = |threads| {
        let mut w = World::new(SolverConfig {
            threads,
            sleep: Some(SleepSettings::default()),
            ..config(JointSolver::Direct, 3)
        })
        .unwrap();
        let mut ends = Vec::new();
        for k in 0..10 {
            let top = Vec3::new(k as f32, 5.0, 0.0);
            let (bodies, _) = common::hanging_chain(&mut w, top, 4, 0.3);
            ends.push(bodies[4]);
        }
        let mut slept = false;
        for _ in 0..600 {
            w.step(DT).unwrap();
            if w.is_asleep(ends[0]).unwrap() {
                slept = true;
                break;
            }
        }
        assert!(slept, "the hanging chains never slept");
        let before = separation(&mut w);
        // A snapshot of the sleeping world, restored into a fresh one,
        // wakes and steps on as the original.
        let mut restored = World::new(*w.config()).unwrap();
        restored.restore(&w.snapshot()).unwrap();
        w.apply_impulse(ends[3], Vec3::new(5.0, 0.0, 0.0)).unwrap();
        restored
            .apply_impulse(
                restored.bodies().handle_at(ends[3].index()).unwrap(),
                Vec3::new(5.0, 0.0, 0.0),
            )
            .unwrap();
        w.step(DT).unwrap();
        assert!(!w.is_asleep(ends[3]).unwrap(), "an impulse did not wake");
        let worst = run(&mut w, 60);
        assert!(
            worst < before + 0.05,
            "woken: {worst} cm, asleep {before} cm"
        );
        for _ in 0..61 {
            restored.step(DT).unwrap();
        }
        assert_eq!(restored.state_hash(), w.state_hash(), "restored");
        w.state_hash()
    };
    let one = run_sleep(1);
    for threads in 2..=3 {
        assert_eq!(run_sleep(threads), one, "{threads} threads");
    }
}

/// Snapshots of an edited crowd (kinematic links, drives, a ring)
/// restore into fresh direct worlds, on other backends and thread
/// counts, and step on bit for bit.
#[test]
fn snapshots_restore_into_fresh_direct_worlds() {
    let mut w = world(JointSolver::Direct, 3);
    let ends = crowd(&mut w);
    for frame in 0..23 {
        edit(&mut w, &ends, frame);
        w.step(DT).unwrap();
    }
    let snapshot = w.snapshot();
    for _ in 0..20 {
        w.step(DT).unwrap();
    }
    for backend in Backend::available() {
        let mut fresh = World::new(SolverConfig {
            backend: BackendChoice::Forced(backend),
            threads: 2,
            ..config(JointSolver::Direct, 3)
        })
        .unwrap();
        fresh.restore(&snapshot).unwrap();
        for _ in 0..20 {
            fresh.step(DT).unwrap();
        }
        assert_eq!(fresh.state_hash(), w.state_hash(), "{backend}");
    }
}

/// The same chain far from the origin (1e5 m) holds as tightly as near
/// it (links of 0.25 m: every coordinate is exact in `f32` there too, so
/// the two worlds are built alike; the joints' errors are at round-off,
/// where the start of step's double-precision gaps differ in their last
/// bits, so the two swings need not agree bit for bit), and far tighter
/// than iterated.
#[test]
fn far_from_the_origin() {
    let swing = |origin: Vec3, joints| {
        let mut w = world(joints, 2);
        let bodies = mixed_chain(&mut w, origin, 8, 0.25);
        w.set_body_velocity(bodies[8], Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO)
            .unwrap();
        run(&mut w, 90)
    };
    let far_origin = Vec3::new(1e5, 5.0, -1e5);
    let near = swing(Vec3::new(0.0, 5.0, 0.0), JointSolver::Direct);
    let far = swing(far_origin, JointSolver::Direct);
    let iterative = swing(far_origin, JointSolver::Iterative);
    assert!(near < 0.5 && far < 0.5, "far {far} cm, near {near} cm");
    assert!(
        far < iterative / 10.0,
        "far {far} cm, iterated {iterative} cm"
    );
}

/// A chain whose root joint is to a kinematic body moved fast (a 20 m/s
/// circle, turning): the chain follows, finite, no worse than iterated.
#[test]
fn a_fast_kinematic_root() {
    let follow = |joints| {
        let mut w = world(joints, 4);
        let hand = w
            .add_body(BodyDesc::kinematic().with_position(Vec3::new(1.0, 5.0, 0.0)))
            .unwrap();
        let mut parent = hand;
        for k in 0..6 {
            let upper = Vec3::new(1.0, 5.0 - 0.3 * k as f32, 0.0);
            let body = capsule(&mut w, upper, upper - Vec3::Y * 0.3, 1.0);
            let desc = match k % 3 {
                0 => JointDesc::socket_at_world_anchor(w.bodies(), parent, body, upper, -Vec3::Y)
                    .unwrap(),
                1 => JointDesc::hinge_at_world_anchor(w.bodies(), parent, body, upper, Vec3::Z)
                    .unwrap(),
                _ => JointDesc::fixed_at(w.bodies(), parent, body, upper).unwrap(),
            };
            w.add_joint(desc).unwrap();
            parent = body;
        }
        let mut worst = 0.0f32;
        for frame in 1..=120 {
            let t = frame as f32 * DT;
            let to = Vec3::new((20.0 * t).cos(), 5.0, (20.0 * t).sin());
            w.move_kinematic(hand, to, Quat::from_rotation_y(-20.0 * t), DT)
                .unwrap();
            w.step(DT).unwrap();
            assert_finite(&w);
            worst = worst.max(separation(&mut w));
        }
        worst
    };
    let direct = follow(JointSolver::Direct);
    let iterative = follow(JointSolver::Iterative);
    assert!(
        direct <= iterative,
        "direct {direct} cm, iterative {iterative} cm"
    );
    assert!(direct < 1.0, "direct {direct} cm");
}

/// A refused call changes nothing: a direct world that was refused
/// (a static body made kinematic, a dynamic body made static, a joint
/// naming one body twice, a rod's bodies changed) steps on as one never
/// asked.
#[test]
fn refused_calls_change_nothing() {
    let build = || {
        let mut w = world(JointSolver::Direct, 3);
        let bodies = mixed_chain(&mut w, Vec3::new(0.0, 5.0, 0.0), 8, 0.3);
        w.step(DT).unwrap();
        (w, bodies)
    };
    let (mut asked, bodies) = build();
    let (mut never, _) = build();
    assert!(asked.set_body_kind(bodies[0], BodyKind::Kinematic).is_err());
    assert!(asked.set_body_kind(bodies[3], BodyKind::Static).is_err());
    let (_, joint) = asked.joints().next().unwrap();
    let mut same = joint;
    same.body_b = same.body_a;
    assert!(asked.add_joint(same).is_err());
    let (rod, mut desc) = asked.rods().next().unwrap();
    desc.body_b = bodies[1];
    assert!(asked.set_rod(rod, desc).is_err());
    assert!(asked.remove_body(bodies[2]).is_err());
    for _ in 0..30 {
        asked.step(DT).unwrap();
        never.step(DT).unwrap();
    }
    assert_eq!(asked.state_hash(), never.state_hash());
}

/// The parts a tree's joint gets must not depend on which joints share
/// its block. Two mixed chains and a fixed joint between two kinematic
/// bodies (no tree holds it): on one worker every joint is in bin 0 and
/// the chains' fixed joints shared its block, so their points and locks
/// were iterated as well as solved directly; on two, the chains went to
/// bins of their own and theirs were not, and the worlds parted in the
/// first step.
#[test]
fn a_joint_no_tree_holds_does_not_change_its_block_mates() {
    let hash = |threads| {
        let mut w = World::new(SolverConfig {
            backend: BackendChoice::Forced(Backend::Scalar),
            threads,
            ..config(JointSolver::Direct, 3)
        })
        .unwrap();
        for k in 0..2 {
            mixed_chain(&mut w, Vec3::new(k as f32 * 2.0, 6.0, 0.0), 3, 0.25);
        }
        let hand = w
            .add_body(BodyDesc::kinematic().with_position(Vec3::new(0.0, 4.0, 5.0)))
            .unwrap();
        let knob = capsule(
            &mut w,
            Vec3::new(0.0, 4.5, 5.0),
            Vec3::new(0.0, 4.8, 5.0),
            1.0,
        );
        let at = Vec3::new(0.0, 4.5, 5.0);
        let fixed = JointDesc::fixed_at(w.bodies(), hand, knob, at).unwrap();
        w.add_joint(fixed).unwrap();
        w.set_body_kind(knob, BodyKind::Kinematic).unwrap();
        for _ in 0..3 {
            w.step(DT).unwrap();
        }
        w.state_hash()
    };
    let one = hash(1);
    for threads in 2..=3 {
        assert_eq!(hash(threads), one, "{threads} threads");
    }
}

/// Near the extremes: masses of `1 / heavy` and `heavy` kg side by side
/// (a ratio of 1e6), inertias from `heavy^-2` to `heavy` kg m^2, anchors
/// 10 m from their centres of mass, zero-width limits (a cone of 0,
/// twist and hinge ranges of [0, 0], a rod's bend and twist limits of
/// 0): finite, and no further apart than iterated.
#[test]
fn a_million_to_one_with_long_arms_and_zero_width_limits() {
    let build = |joints, (heavy, side, mask): (f32, f32, u8)| {
        let mut w = world(joints, 4);
        let top = Vec3::new(0.0, 20.0, 0.0);
        let anchor = w.add_body(BodyDesc::fixed().with_position(top)).unwrap();
        let mut parent = anchor;
        let bodies = [
            (1.0 / heavy, 1.0 / heavy / heavy),
            (heavy, heavy),
            (1.0 / heavy, heavy),
            (heavy, 1.0 / heavy / heavy),
            (1.0, 1.0),
        ];
        for (k, &(mass, inertia)) in bodies.iter().enumerate() {
            let at = top - Vec3::Y * k as f32;
            // The centre of mass 10 m to the side of the joint.
            let body = point_mass(&mut w, at + Vec3::X * side, mass, inertia);
            let desc = match k % 3 {
                0 => JointDesc::socket_at_world_anchor(w.bodies(), parent, body, at, -Vec3::Y)
                    .unwrap()
                    .with_swing_limit(if mask & 1 != 0 { 0.0 } else { 1.0 })
                    .with_twist_limit(
                        if mask & 8 != 0 { 0.0 } else { -1.0 },
                        if mask & 8 != 0 { 0.0 } else { 1.0 },
                    ),
                1 => JointDesc::hinge_at_world_anchor(w.bodies(), parent, body, at, Vec3::Z)
                    .unwrap()
                    .with_kind(JointKind::Hinge {
                        range: Some(if mask & 2 != 0 {
                            [0.0, 0.0]
                        } else {
                            [-1.0, 1.0]
                        }),
                        softness: LimitSoftness::Hard,
                    }),
                _ => JointDesc::fixed_at(w.bodies(), parent, body, at).unwrap(),
            };
            w.add_joint(desc).unwrap();
            parent = body;
        }
        let last = capsule(
            &mut w,
            Vec3::new(side, 15.0, 0.0),
            Vec3::new(side, 14.0, 0.0),
            1.0,
        );
        let rod = RodDesc::from_pose(w.bodies(), parent, last, &[]).unwrap();
        if mask & 4 != 0 {
            w.add_rod(rod.with_bend_limit(0.0).with_twist_limit(0.0, 0.0))
                .unwrap();
        } else {
            w.add_rod(rod).unwrap();
        }
        w.set_body_velocity(last, Vec3::new(30.0, 0.0, 0.0), Vec3::new(0.0, 50.0, 0.0))
            .unwrap();
        run(&mut w, 60)
    };
    // (heavy, lever arm, zero-width limits: 1 cone, 2 hinge range,
    // 4 rod bend and twist, 8 socket twist).
    for case in [
        (1e3f32, 10.0f32, 1u8),
        (1e3, 10.0, 2),
        (1e3, 10.0, 4),
        (1e3, 10.0, 8),
        (1e3, 10.0, 13),
        (1e3, 0.0, 9),
        (1.0, 10.0, 15),
        // Zero-width cone, twist and hinge range together: near-dependent
        // rows across a 1e9 inertia ratio. Before the solve's trust region
        // (a turn of at most a radian per body per solve) the direct solve
        // ran to 5e8 cm where iterating reached 2,949 cm.
        (1e3, 10.0, 11),
        (1e3, 10.0, 15),
        (1e3, 10.0, 3),
        (1e3, 10.0, 7),
    ] {
        let direct = build(JointSolver::Direct, case);
        let iterative = build(JointSolver::Iterative, case);
        assert!(
            direct <= iterative.max(1.0),
            "{case:?}: direct {direct} cm, iterative {iterative} cm"
        );
    }
}
