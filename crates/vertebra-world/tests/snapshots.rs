//! Snapshots between worlds: a snapshot restores into any world of the
//! same build (a fresh one in another process included) and steps on bit
//! for bit; handles stay unique across restores, and another world's
//! handles are refused.

mod common;

use std::process::Command;

use glam::{Quat, Vec3};
use vertebra_math::Backend;
use vertebra_world::{
    AngularDrive, BackendChoice, BodyDesc, Contact, Error, JointDesc, RodDesc, RodStiffness,
    Snapshot, SolverConfig, World,
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
    // Two worlds built by the same calls: their handles would be equal
    // without the world's lineage in them.
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
        Err(Error::Contact {
            index: 0,
            reason: Box::new(Error::ForeignHandle("body"))
        })
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
            sleep: None,
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

/// A unit quaternion whose normalised bits, normalised again, change.
fn still_target() -> Quat {
    Quat::from_rotation_y(1.085) * Quat::from_rotation_x(0.40145)
}

/// A chain of five capsules under a static anchor, driven: its top held by
/// a rigid pin (a static body and a socket with a rigid drive, as passive
/// bending holds the hips), then sockets and hinges whose drives' targets
/// turn (spring and compliance drives, one torque-limited) and, between
/// them, a socket and a hinge whose drives hold still targets that are not
/// the identity.
fn driven_chain() -> World {
    let mut world = common::world(4, 6);
    let (bodies, _) = common::hanging_chain(&mut world, Vec3::new(0.0, 4.0, 0.0), 5, 0.35);
    let top = bodies[1];
    let at = world.body(top).unwrap().position;
    let pin_body = world.add_body(BodyDesc::fixed().with_position(at)).unwrap();
    let pin = JointDesc::socket_at_world_anchor(world.bodies(), pin_body, top, at, Vec3::Y)
        .unwrap()
        .with_drive(AngularDrive::rigid(Quat::IDENTITY));
    world.add_joint(pin).unwrap();
    let joint = |world: &World, k: usize, hinge: bool| {
        let upper = Vec3::new(0.0, 4.0 - 0.35 * k as f32, 0.0);
        let (a, b) = (bodies[k], bodies[k + 1]);
        match hinge {
            true => JointDesc::hinge_at_world_anchor(world.bodies(), a, b, upper, Vec3::Z),
            false => JointDesc::socket_at_world_anchor(world.bodies(), a, b, upper, -Vec3::Y),
        }
        .unwrap()
    };
    let drives = [
        (
            1,
            false,
            AngularDrive::spring(Quat::IDENTITY, 6.0, 0.8)
                .with_target_velocity(Vec3::new(0.3, 1.1, -0.7)),
        ),
        (
            2,
            true,
            AngularDrive::spring(Quat::from_rotation_x(0.2), 4.0, 1.0)
                .with_target_velocity(Vec3::new(1.7, 0.0, 0.0))
                .with_max_torque(2.0),
        ),
        (
            3,
            false,
            // Its glam-normalised target, normalised again, is other bits.
            AngularDrive::compliant(still_target(), 1e-3, 0.5),
        ),
        (
            4,
            true,
            AngularDrive::compliant(Quat::from_rotation_x(-0.4), 2e-3, 0.2)
                .with_target_velocity(Vec3::new(-0.9, 0.2, 0.0)),
        ),
    ];
    for (k, hinge, drive) in drives {
        let desc = joint(&world, k, hinge).with_drive(drive);
        world.add_joint(desc).unwrap();
    }
    let still = JointDesc::hinge_at_world_anchor(
        world.bodies(),
        pin_body,
        bodies[5],
        Vec3::new(0.0, 4.0 - 0.35 * 4.5, 0.0),
        Vec3::X,
    )
    .unwrap()
    .with_drive(AngularDrive::spring(Quat::from_rotation_x(0.7), 2.0, 0.5));
    world.add_joint(still).unwrap();
    world
        .set_body_velocity(
            bodies[5],
            Vec3::new(1.0, 0.0, 0.5),
            Vec3::new(0.0, 2.0, 0.0),
        )
        .unwrap();
    world
}

/// Every body slot's pose (each coordinate's low part too) and
/// velocities, as bits.
fn body_bits(world: &World) -> Vec<u32> {
    let b = world.bodies();
    let vecs = [
        &b.position[..],
        b.position_low(),
        &b.linear_velocity,
        &b.angular_velocity,
    ];
    let vecs = vecs
        .into_iter()
        .flat_map(|v| v.iter().flat_map(|v| v.to_array()));
    let quats = b.orientation.iter().flat_map(|q| q.to_array());
    vecs.chain(quats).map(f32::to_bits).collect()
}

#[test]
fn driven_joints_step_on_bit_for_bit_after_restoring() {
    // A restored world lays each drive out again from its description
    // (the target written back after each step): that must be what the
    // original's lane holds, for moving and still targets alike. Snapshots
    // after each of the first steps, restored into a fresh world.
    let bits = |q: Quat| q.to_array().map(f32::to_bits);
    let once = still_target().normalize();
    assert_ne!(
        bits(once.normalize()),
        bits(once),
        "the still target's premise"
    );
    let mut failed = Vec::new();
    for steps in 1..=12 {
        let mut original = driven_chain();
        for _ in 0..steps {
            original.step(DT).unwrap();
        }
        let mut copy = common::world(4, 6);
        copy.restore(&original.snapshot()).unwrap();
        assert_eq!(copy.state_hash(), original.state_hash());
        let mut same = true;
        for _ in 0..30 {
            original.step(DT).unwrap();
            copy.step(DT).unwrap();
            same &= copy.state_hash() == original.state_hash();
            same &= body_bits(&copy) == body_bits(&original);
        }
        if !same {
            failed.push(steps);
        }
    }
    assert!(
        failed.is_empty(),
        "diverged after restoring at steps {failed:?}"
    );
}

/// Steps `a` and `b` `steps` times each: both must give the same hashes
/// and body bits after every step.
fn step_alike(a: &mut World, b: &mut World, steps: usize, what: &str) {
    for k in 0..steps {
        a.step(DT).unwrap();
        b.step(DT).unwrap();
        assert_eq!(a.state_hash(), b.state_hash(), "{what}: step {k}");
        assert!(body_bits(a) == body_bits(b), "{what}: step {k}");
    }
}

#[test]
fn a_drive_set_back_as_read_changes_nothing_and_dirty_layouts_restore_alike() {
    for steps in 1..=8 {
        let mut original = driven_chain();
        for _ in 0..steps {
            original.step(DT).unwrap();
        }
        // Every drive set back to what `joint` reads: no bit changes.
        let mut twin = common::world(4, 6);
        twin.restore(&original.snapshot()).unwrap();
        twin.step(DT).unwrap();
        original.step(DT).unwrap();
        let joints: Vec<_> = twin.joints().collect();
        for (handle, desc) in joints {
            twin.set_joint_drive(handle, desc.drive).unwrap();
        }
        step_alike(
            &mut original,
            &mut twin,
            10,
            &format!("set back after {steps}"),
        );
        // A joint removed (the layout dirty when the snapshot is taken):
        // the original lays its drives out again from their descriptions,
        // as the restored world does.
        let still = original.joints().last().unwrap().0;
        original.remove_joint(still).unwrap();
        let mut copy = common::world(4, 6);
        copy.restore(&original.snapshot()).unwrap();
        step_alike(
            &mut original,
            &mut copy,
            10,
            &format!("removed after {steps}"),
        );
        // A joint added back, then a snapshot before any step.
        let (handle, mut desc) = original.joints().nth(2).unwrap();
        original.remove_joint(handle).unwrap();
        desc.drive = desc
            .drive
            .map(|d| d.with_target_velocity(Vec3::new(0.0, -2.0, 0.5)));
        original.add_joint(desc).unwrap();
        copy.restore(&original.snapshot()).unwrap();
        step_alike(
            &mut original,
            &mut copy,
            10,
            &format!("re-added after {steps}"),
        );
    }
}

#[test]
fn a_still_target_reads_back_as_given() {
    let mut world = driven_chain();
    for _ in 0..5 {
        world.step(DT).unwrap();
    }
    let targets: Vec<_> = world
        .joints()
        .filter_map(|(_, d)| d.drive)
        .filter(|d| d.target_velocity == Vec3::ZERO)
        .map(|d| d.target.to_array().map(f32::to_bits))
        .collect();
    let given = [Quat::IDENTITY, still_target(), Quat::from_rotation_x(0.7)]
        .map(|q| q.to_array().map(f32::to_bits));
    assert_eq!(targets, given);
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
