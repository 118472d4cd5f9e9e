//! A step gives the same bits whatever floating-point mode its caller runs
//! in: here a host that set flush-to-zero (with denormals-are-zero on
//! x86-64, as game engines do; FPCR.FZ on AArch64), on its own thread and
//! on the threads it creates.
#![cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]

mod host_mode;

use host_mode::{FLUSH, ROUNDING, read_mode, write_mode};

use glam::Vec3;
use vertebra_world::{
    BodyDesc, BodyHandle, JointDesc, MassProperties, RodDesc, RodStiffness, Shape, SolverConfig,
    World,
};

/// Runs `f` with flush-to-zero set on this thread, as a host would.
fn as_a_host_with_ftz_daz<T>(f: impl FnOnce() -> T) -> T {
    let before = read_mode();
    write_mode(before | FLUSH);
    let out = f();
    let during = read_mode();
    write_mode(before);
    assert_eq!(
        during & FLUSH,
        FLUSH,
        "the step gave the host its mode back"
    );
    out
}

/// 400 balls a few subnormals from a static anchor at the origin, drifting
/// at 1e-38 m/s (damped) and held by sockets: positions, velocities and
/// the sockets' errors are subnormal. All sockets share the anchor, so they
/// are one colour of 50 blocks, which `threads` workers split.
///
/// The descriptions are computed once, in the default mode
/// ([`descriptions`]): this is about the step, not about helpers such as
/// `JointDesc::socket_at_world_anchor`, which compute in their caller's mode.
fn subnormal_scene(threads: usize, (bodies, sockets): &(Vec<BodyDesc>, Vec<JointDesc>)) -> World {
    let mut world = World::new(SolverConfig {
        gravity: Vec3::ZERO,
        threads,
        parallel_min_blocks: 1,
        ..SolverConfig::default()
    })
    .unwrap();
    for body in bodies {
        world.add_body(*body).unwrap();
    }
    // The descriptions name the bodies of the world that made them; this
    // world's bodies sit in the same slots.
    let here = |h: BodyHandle| world.bodies().handle_at(h.index()).unwrap();
    let sockets: Vec<JointDesc> = sockets
        .iter()
        .map(|s| JointDesc {
            body_a: here(s.body_a),
            body_b: here(s.body_b),
            ..*s
        })
        .collect();
    for socket in sockets {
        world.add_joint(socket).unwrap();
    }
    world
}

fn descriptions() -> (Vec<BodyDesc>, Vec<JointDesc>) {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let mut bodies = vec![BodyDesc::fixed()];
    let anchor = world.add_body(bodies[0]).unwrap();
    let mass = Shape::Sphere { radius: 0.05 }
        .mass_properties_with_mass(1.0)
        .unwrap();
    let mut sockets = Vec::new();
    for k in 1..=400 {
        let k = k as f32;
        let ball = BodyDesc::dynamic(mass)
            .with_position(Vec3::new(k * 1.0e-39, -k * 2.0e-40, 0.0))
            .with_velocity(Vec3::new(k * 1.0e-38, 0.0, 0.0), Vec3::ZERO)
            .with_damping(5.0, 5.0);
        bodies.push(ball);
        let ball = world.add_body(ball).unwrap();
        let socket =
            JointDesc::socket_at_world_anchor(world.bodies(), anchor, ball, Vec3::ZERO, Vec3::Y);
        sockets.push(socket.unwrap());
    }
    (bodies, sockets)
}

/// The state hash after each of 20 steps.
fn run(mut world: World) -> (Vec<u64>, World) {
    let hashes = (0..20)
        .map(|_| {
            world.step(1.0 / 60.0).unwrap();
            world.state_hash()
        })
        .collect();
    (hashes, world)
}

#[test]
fn ftz_and_daz_on_the_callers_threads_change_no_bit() {
    let scene = descriptions();
    for threads in [1, 2, 4] {
        let (expected, world) = run(subnormal_scene(threads, &scene));
        // The scene does reach subnormals (else the test proves nothing).
        let subnormal = world
            .bodies()
            .position
            .iter()
            .any(|p| p.to_array().iter().any(|v| v.is_subnormal()));
        assert!(subnormal, "the scene keeps subnormal positions");
        // Built under FTZ/DAZ, so the pool's workers inherit the mode too.
        let (got, _) = as_a_host_with_ftz_daz(|| run(subnormal_scene(threads, &scene)));
        assert_eq!(
            got, expected,
            "{threads} thread(s): FTZ/DAZ changed the step"
        );
    }
}

/// Runs `f` with `bits` set in the control register on this thread
/// (flush-to-zero, or round toward zero), then gives the thread its mode
/// back.
fn in_mode<T>(bits: u64, f: impl FnOnce() -> T) -> T {
    let before = read_mode();
    write_mode(before | bits);
    let out = f();
    write_mode(before);
    out
}

/// A body whose inverse inertia has a subnormal cofactor (normal inputs:
/// off-diagonal 1e-20), and one under round-toward-zero: `add_body`
/// computes in the default mode too, so the worlds hash alike and each
/// one's snapshot restores into the other's kind of host. (Found by an
/// adversarial session: both hashes differed, and the snapshots were
/// refused, "inverse mass is not 1/mass".)
#[test]
fn adding_a_body_does_not_depend_on_the_callers_mode() {
    let world = || {
        let mut w = World::new(SolverConfig::default()).unwrap();
        let t = std::hint::black_box(1.0e-20f32);
        let inertia = glam::Mat3::from_cols(
            Vec3::new(1.0, 0.0, t),
            Vec3::new(0.0, 1.0, t),
            Vec3::new(t, t, 1.0),
        );
        let tilted = MassProperties::new(1.0, inertia).unwrap();
        let plain =
            MassProperties::new(3.0, glam::Mat3::from_diagonal(Vec3::new(0.3, 0.7, 1.1))).unwrap();
        for mass in [tilted, plain] {
            w.add_body(BodyDesc::dynamic(mass).with_velocity(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)))
                .unwrap();
        }
        w
    };
    let reference = world();
    for bits in [FLUSH, ROUNDING[2].1] {
        let host = in_mode(bits, world);
        assert_eq!(host.state_hash(), reference.state_hash(), "mode {bits:#x}");
        let mut fresh = World::new(SolverConfig::default()).unwrap();
        fresh
            .restore(&host.snapshot())
            .expect("the host's snapshot restores");
        let mut fresh = World::new(SolverConfig::default()).unwrap();
        in_mode(bits, || fresh.restore(&reference.snapshot())).expect("restores on the host");
    }
}

/// A rod given subnormal stiffness and rest length in place under DAZ:
/// accepted as in the default mode, and the worlds step on alike.
#[test]
fn setting_a_rod_does_not_depend_on_the_callers_mode() {
    let build = || {
        let mut w = World::new(SolverConfig::default()).unwrap();
        let m = Shape::Sphere { radius: 0.1 }
            .mass_properties_with_mass(1.0)
            .unwrap();
        let a = w.add_body(BodyDesc::fixed()).unwrap();
        let b = w
            .add_body(BodyDesc::dynamic(m).with_position(Vec3::new(1.0, 0.0, 0.0)))
            .unwrap();
        let rod = RodDesc::from_pose(w.bodies(), a, b, &[]).unwrap();
        let rod = w.add_rod(rod).unwrap();
        w.step(1.0 / 60.0).unwrap();
        (w, rod)
    };
    let tiny = |w: &World, rod| {
        let mut d = w.rod(rod).unwrap();
        let k = std::hint::black_box(1.0e-40f32);
        d.bending = RodStiffness::Kirchhoff(k);
        d.twisting = RodStiffness::Kirchhoff(k);
        d.rest_length = std::hint::black_box(2.0e-38);
        d
    };
    let ((mut w1, r1), (mut w2, r2)) = (build(), build());
    w1.set_rod(r1, tiny(&w1, r1)).unwrap();
    let d2 = tiny(&w2, r2);
    in_mode(FLUSH, || w2.set_rod(r2, d2)).expect("accepted as in the default mode");
    for _ in 0..60 {
        w1.step(1.0 / 60.0).unwrap();
        w2.step(1.0 / 60.0).unwrap();
        assert_eq!(w1.state_hash(), w2.state_hash());
    }
}
