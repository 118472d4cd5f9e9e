//! Snapshots: stepping on from a restored world is bit-identical to
//! stepping on from the original (rollback networking depends on it), and a
//! snapshot of another world or a damaged one is refused with the world
//! untouched.

use glam::Vec3;
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneConfig, SceneWorld, build};
use vertebra_world::{BodyDesc, Error, Shape, Snapshot};

const DT: f32 = 1.0 / 60.0;

fn drop_scene(spine: SpineMode, ragdolls: usize) -> SceneWorld {
    let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
    config.ragdolls = ragdolls;
    build(&config).unwrap()
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
        let snapshot = scene.world.snapshot();
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
            .sockets
            .iter()
            .flatten()
            .next()
            .copied()
            .unwrap();
        scene.world.remove_socket(socket).unwrap();
        scene.world.restore(&snapshot).unwrap();
        assert_eq!(scene.world.state_hash(), at_snapshot);
        assert!(scene.world.body(extra).is_err(), "the added body is gone");
        assert!(
            scene.world.socket(socket).is_ok(),
            "the removed socket is back"
        );
        assert_eq!(run(&mut scene, 40..80), ahead, "{spine:?}: replay differs");
    }
}

#[test]
fn a_snapshot_survives_its_bytes() {
    let mut scene = drop_scene(SpineMode::Rod, 3);
    run(&mut scene, 0..20);
    let bytes = scene.world.snapshot().as_bytes().to_vec();
    let ahead = run(&mut scene, 20..40);
    scene.world.restore(&Snapshot::from_bytes(bytes)).unwrap();
    assert_eq!(run(&mut scene, 20..40), ahead);
}

#[test]
fn foreign_and_damaged_snapshots_are_refused_and_change_nothing() {
    let mut scene = drop_scene(SpineMode::Rod, 3);
    run(&mut scene, 0..10);
    let mut other = drop_scene(SpineMode::Rod, 3);
    run(&mut other, 0..10);
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
    // The same scene built again is another world.
    assert_eq!(
        refuse(&mut scene, other.world.snapshot().as_bytes().to_vec()),
        Error::ForeignSnapshot
    );
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
