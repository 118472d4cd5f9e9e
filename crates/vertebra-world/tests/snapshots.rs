//! Snapshots between worlds: a snapshot restores into any world of the
//! same build (a fresh one in another process included) and steps on bit
//! for bit; handles stay unique across restores, and another world's
//! handles are refused.

mod common;

use std::process::Command;

use glam::Vec3;
use vertebra_math::Backend;
use vertebra_world::{
    BackendChoice, BodyDesc, Contact, Error, RodDesc, RodStiffness, Snapshot, SolverConfig, World,
};

const DT: f32 = 1.0 / 60.0;

/// A chain of six capsules hanging from a static body, its ends also held
/// by a rod whose rest shape moves (the rest written back after every
/// step is what a snapshot holds), swung sideways.
fn swinging_chain() -> World {
    let mut world = common::world(2, 8);
    let (bodies, _) = common::hanging_chain(&mut world, Vec3::new(0.0, 4.0, 0.0), 6, 0.4);
    let rod = RodDesc::from_pose(world.bodies(), bodies[2], bodies[5], &[])
        .unwrap()
        .with_stiffness(RodStiffness::Kirchhoff(2.0), RodStiffness::Kirchhoff(1.0))
        .with_rest_velocity(Vec3::new(0.1, 0.7, -0.4), 1.3);
    world.add_rod(rod).unwrap();
    world
        .set_body_velocity(bodies[6], Vec3::new(3.0, 0.0, 1.0), Vec3::ZERO)
        .unwrap();
    world
}

/// Steps `world` `steps` times, each with a ground contact (y = 2 m) under
/// every dynamic body that reaches it, from the world's own handles (so any
/// world of the lineage computes the same ones); the state hash after each.
fn run(world: &mut World, steps: usize) -> Vec<u64> {
    let ground = world.bodies().handle_at(0).unwrap();
    (0..steps)
        .map(|_| {
            let store = world.bodies();
            let contacts: Vec<Contact> = (1..store.capacity())
                .filter_map(|i| store.handle_at(i).map(|h| (i, h)))
                .filter(|&(i, _)| store.position[i].y < 2.1)
                .map(|(i, body_b)| Contact {
                    body_a: ground,
                    body_b,
                    point: Vec3::new(store.position[i].x, 2.0, store.position[i].z),
                    normal: Vec3::Y,
                    depth: 2.05 - store.position[i].y,
                    friction: 0.5,
                    restitution: 0.2,
                })
                .collect();
            world.set_contacts(&contacts).unwrap();
            world.step(DT).unwrap();
            world.state_hash()
        })
        .collect()
}

#[test]
fn a_handle_issued_after_a_snapshot_stays_stale_after_restoring_it() {
    let mut world = swinging_chain();
    let snapshot = world.snapshot();
    let late = world.add_body(BodyDesc::fixed()).unwrap();
    let late_rod = world
        .add_rod(
            RodDesc::from_pose(
                world.bodies(),
                late,
                world.bodies().handle_at(1).unwrap(),
                &[],
            )
            .unwrap(),
        )
        .unwrap();
    world.restore(&snapshot).unwrap();
    let again = world.add_body(BodyDesc::fixed()).unwrap();
    assert_eq!(again.index(), late.index(), "the slot is reused");
    assert_ne!(again, late, "but the handle is new");
    assert_eq!(world.body(late), Err(Error::StaleHandle("body")));
    assert_eq!(world.rod(late_rod), Err(Error::StaleHandle("rod")));
    assert!(world.body(again).is_ok());
    // Restoring again (the counter never goes back) issues newer still.
    world.restore(&snapshot).unwrap();
    let third = world.add_body(BodyDesc::fixed()).unwrap();
    assert!(third != late && third != again);
}

#[test]
fn another_worlds_handles_are_refused() {
    // Two worlds built by the same calls: their handles used to be equal.
    let mut ours = swinging_chain();
    let mut theirs = swinging_chain();
    let body = theirs.bodies().handle_at(3).unwrap();
    let socket = theirs.joints().next().unwrap().0;
    let rod = theirs.rods().next().unwrap().0;
    let before = ours.snapshot();
    assert_eq!(ours.body(body), Err(Error::ForeignHandle("body")));
    assert_eq!(
        ours.set_body_velocity(body, Vec3::X, Vec3::ZERO),
        Err(Error::ForeignHandle("body"))
    );
    assert_eq!(
        ours.add_force(body, Vec3::X),
        Err(Error::ForeignHandle("body"))
    );
    assert_eq!(
        ours.remove_joint(socket),
        Err(Error::ForeignHandle("joint"))
    );
    assert_eq!(ours.remove_rod(rod), Err(Error::ForeignHandle("rod")));
    let contact = Contact {
        body_a: ours.bodies().handle_at(0).unwrap(),
        body_b: body,
        point: Vec3::ZERO,
        normal: Vec3::Y,
        depth: 0.0,
        friction: 0.0,
        restitution: 0.0,
    };
    assert_eq!(
        ours.set_contacts(&[contact]),
        Err(Error::ForeignHandle("body"))
    );
    assert_eq!(ours.snapshot(), before, "nothing changed");
    theirs.step(DT).unwrap();
}

#[test]
fn another_world_restores_a_snapshot_takes_on_its_handles_and_steps_on_bit_for_bit() {
    // Snapshots taken after several step counts: a restored world lays its
    // rods out again from their descriptions, and the moving rest written
    // back to a description could differ from the lane by a rounding
    // (renormalised) after one step and not another.
    for steps in 28..34 {
        let mut original = swinging_chain();
        run(&mut original, steps);
        // Settings that do not change results may differ.
        let mut copy = World::new(SolverConfig {
            substeps: 2,
            iterations: 8,
            threads: 2,
            backend: BackendChoice::Forced(Backend::Scalar),
            ..SolverConfig::default()
        })
        .unwrap();
        let own = copy.add_body(BodyDesc::fixed()).unwrap();
        copy.restore(&original.snapshot()).unwrap();
        let tip = original.bodies().handle_at(6).unwrap();
        assert_eq!(
            copy.body(tip),
            original.body(tip),
            "the original's handles work"
        );
        assert_eq!(copy.body(own), Err(Error::ForeignHandle("body")));
        assert_eq!(run(&mut copy, 60), run(&mut original, 60), "after {steps}");
    }
}

/// The child half of the test below: restores the snapshot in the file the
/// parent names into a fresh world and prints the hashes of 60 steps.
fn child(path: &str) {
    let snapshot = Snapshot::from_bytes(std::fs::read(path).unwrap());
    let mut world = common::world(2, 8);
    world.restore(&snapshot).unwrap();
    println!("hashes {:?}", run(&mut world, 60));
}

#[test]
fn a_fresh_world_in_another_process_steps_on_bit_for_bit() {
    if let Ok(path) = std::env::var("VERTEBRA_SNAPSHOT_CHILD") {
        return child(&path);
    }
    let mut world = swinging_chain();
    run(&mut world, 30);
    let path = std::env::temp_dir().join(format!("vertebra-snapshot-{}.bin", std::process::id()));
    std::fs::write(&path, world.snapshot().as_bytes()).unwrap();
    let output = Command::new(std::env::current_exe().unwrap())
        .args([
            "a_fresh_world_in_another_process_steps_on_bit_for_bit",
            "--exact",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("VERTEBRA_SNAPSHOT_CHILD", &path)
        .output()
        .unwrap();
    std::fs::remove_file(&path).unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "the child failed: {stdout}");
    // The test harness prints the test's name on the same line.
    let hashes = stdout
        .split_once("hashes ")
        .and_then(|(_, rest)| rest.lines().next())
        .unwrap_or_else(|| panic!("no hashes from the child: {stdout}"));
    assert_eq!(hashes, format!("{:?}", run(&mut world, 60)));
}
