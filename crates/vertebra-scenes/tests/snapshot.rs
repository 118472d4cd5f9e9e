//! Snapshots: stepping on from a restored world is bit-identical to
//! stepping on from the original (rollback networking depends on it), in
//! this world, another one or another process; a damaged snapshot is
//! refused with the world untouched.

use glam::Vec3;
use vertebra_collide::CollisionSnapshot;
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneConfig, SceneWorld, build};
use vertebra_world::{BodyDesc, Error, Shape, Snapshot};

const DT: f32 = 1.0 / 60.0;

fn drop_scene(spine: SpineMode, ragdolls: usize) -> SceneWorld {
    let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
    config.ragdolls = ragdolls;
    build(&config).unwrap()
}

/// The scene's world and its collision set (the drop's), saved together.
fn save(scene: &SceneWorld) -> (Snapshot, Option<CollisionSnapshot>) {
    let set = scene.collisions.as_ref();
    let set = set.map(|c| c.snapshot(&scene.world).unwrap());
    (scene.world.snapshot(), set)
}

/// Both put back: the world first, then its set (which serves a restored
/// world only once its own snapshot taken with the world's is restored).
fn load(scene: &mut SceneWorld, (world, set): &(Snapshot, Option<CollisionSnapshot>)) {
    scene.world.restore(world).unwrap();
    if let (Some(c), Some(set)) = (scene.collisions.as_mut(), set) {
        c.restore(set, &scene.world).unwrap();
    }
}

fn run(scene: &mut SceneWorld, frames: std::ops::Range<usize>) -> u64 {
    for frame in frames {
        scene.advance(Scene::RagdollDrop, frame, DT).unwrap();
    }
    scene.world.state_hash()
}

#[test]
fn stepping_on_from_a_restored_drop_is_bit_identical() {
    for spine in [SpineMode::Rod, SpineMode::Sockets] {
        let mut scene = drop_scene(spine, 30);
        run(&mut scene, 0..40);
        let snapshot = save(&scene);
        let at_snapshot = scene.world.state_hash();
        let ahead = run(&mut scene, 40..80);
        assert_ne!(ahead, at_snapshot, "the world moved on");
        // Change the world's structure too: a body added, a ragdoll's joint
        // removed. Restoring undoes both.
        let extra = scene
            .world
            .add_body(
                BodyDesc::dynamic(
                    Shape::Sphere { radius: 0.1 }
                        .mass_properties(1000.0)
                        .unwrap(),
                )
                .with_position(Vec3::new(0.0, 5.0, 0.0)),
            )
            .unwrap();
        let socket = scene.ragdolls[0]
            .joints
            .iter()
            .flatten()
            .next()
            .copied()
            .unwrap();
        scene.world.remove_joint(socket).unwrap();
        load(&mut scene, &snapshot);
        assert_eq!(scene.world.state_hash(), at_snapshot);
        assert!(scene.world.body(extra).is_err(), "the added body is gone");
        assert!(
            scene.world.joint(socket).is_ok(),
            "the removed socket is back"
        );
        assert_eq!(run(&mut scene, 40..80), ahead, "{spine:?}: replay differs");
    }
}

#[test]
fn a_snapshot_survives_its_bytes() {
    let mut scene = drop_scene(SpineMode::Rod, 3);
    run(&mut scene, 0..20);
    let (world, set) = save(&scene);
    let bytes = world.as_bytes().to_vec();
    let set = set.map(|s| CollisionSnapshot::from_bytes(s.as_bytes().to_vec()));
    let ahead = run(&mut scene, 20..40);
    load(&mut scene, &(Snapshot::from_bytes(bytes), set));
    assert_eq!(run(&mut scene, 20..40), ahead);
}

#[test]
fn damaged_snapshots_are_refused_and_change_nothing() {
    let mut scene = drop_scene(SpineMode::Rod, 3);
    run(&mut scene, 0..10);
    let good = scene.world.snapshot().as_bytes().to_vec();
    let before = scene.world.state_hash();
    let refuse = |scene: &mut SceneWorld, bytes: Vec<u8>| {
        let error = scene
            .world
            .restore(&Snapshot::from_bytes(bytes))
            .unwrap_err();
        assert_eq!(
            scene.world.state_hash(),
            before,
            "{error} changed the world"
        );
        error
    };
    let mut other_build = good.clone();
    other_build[8] ^= 0x01;
    assert!(matches!(
        refuse(&mut scene, other_build),
        Error::IncompatibleSnapshot(_)
    ));
    let mut flipped = good.clone();
    let middle = flipped.len() / 2;
    flipped[middle] ^= 0x10;
    assert!(matches!(
        refuse(&mut scene, flipped),
        Error::CorruptSnapshot(_)
    ));
    assert!(matches!(
        refuse(&mut scene, good[..good.len() - 7].to_vec()),
        Error::CorruptSnapshot(_)
    ));
    assert!(matches!(
        refuse(&mut scene, good[..10].to_vec()),
        Error::CorruptSnapshot(_)
    ));
    assert!(matches!(
        refuse(&mut scene, b"not a snapshot at all".to_vec()),
        Error::CorruptSnapshot(_)
    ));
    // The world still steps, and the good snapshot still restores.
    scene.world.restore(&Snapshot::from_bytes(good)).unwrap();
    assert_eq!(scene.world.state_hash(), before);
}

fn bending_scene(spine: SpineMode) -> SceneWorld {
    build(&SceneConfig::new(Scene::PassiveBending, spine)).unwrap()
}

/// The state hash after each of `frames` of the passive bending scene.
fn bend(scene: &mut SceneWorld, frames: std::ops::Range<usize>) -> Vec<u64> {
    frames
        .map(|frame| {
            scene.advance(Scene::PassiveBending, frame, DT).unwrap();
            scene.world.state_hash()
        })
        .collect()
}

/// The child half of the test below: the scene built afresh in this
/// process, the parent's snapshot restored into its world, 30 more frames.
fn child(spine: SpineMode, path: &str) {
    let mut scene = bending_scene(spine);
    let snapshot = Snapshot::from_bytes(std::fs::read(path).unwrap());
    scene.world.restore(&snapshot).unwrap();
    println!("hashes {:?}", bend(&mut scene, 30..60));
}

/// A save game: both spines of the passive bending scene, 30 frames in,
/// saved to a file; a new process builds the scene, loads the file and runs
/// 30 more frames with the same bits as the original. (The ragdoll drop's
/// collision set holds its own world's handles: it moves between processes
/// with the collision set's own save, see docs/robustness.md.)
#[test]
fn a_scene_saved_and_loaded_in_another_process_steps_on_bit_for_bit() {
    const TEST: &str = "a_scene_saved_and_loaded_in_another_process_steps_on_bit_for_bit";
    let spines = [(SpineMode::Rod, "rod"), (SpineMode::Sockets, "sockets")];
    if let (Ok(path), Ok(name)) = (
        std::env::var("VERTEBRA_SNAPSHOT_CHILD"),
        std::env::var("VERTEBRA_SNAPSHOT_SPINE"),
    ) {
        let spine = spines.iter().find(|s| s.1 == name).unwrap().0;
        return child(spine, &path);
    }
    for (spine, name) in spines {
        let mut scene = bending_scene(spine);
        bend(&mut scene, 0..30);
        let path =
            std::env::temp_dir().join(format!("vertebra-scene-{name}-{}.bin", std::process::id()));
        std::fs::write(&path, scene.world.snapshot().as_bytes()).unwrap();
        let output = std::process::Command::new(std::env::current_exe().unwrap())
            .args([TEST, "--exact", "--nocapture", "--test-threads=1"])
            .env("VERTEBRA_SNAPSHOT_CHILD", &path)
            .env("VERTEBRA_SNAPSHOT_SPINE", name)
            .output()
            .unwrap();
        std::fs::remove_file(&path).unwrap();
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(
            output.status.success(),
            "{name}: the child failed: {stdout}"
        );
        // The test harness prints the test's name on the same line.
        let hashes = stdout
            .split_once("hashes ")
            .and_then(|(_, rest)| rest.lines().next())
            .unwrap_or_else(|| panic!("{name}: no hashes from the child: {stdout}"));
        let ahead = bend(&mut scene, 30..60);
        assert_ne!(ahead[0], ahead[29], "{name}: the scene moves");
        assert_eq!(hashes, format!("{ahead:?}"), "{name}: the load differs");
    }
}
