//! Arbitrary bytes as a ragdoll file.

use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, SpineMode};
use vertebra_world::{SolverConfig, World};

/// Arbitrary bytes (as UTF-8, lossily) through the TOML loader: an error,
/// or a description that builds both ways, is driven by its own drive
/// settings, and steps to a finite state without the step's NaN guard.
pub fn ragdoll_loader(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(desc) = RagdollDesc::from_toml(&text) else {
        return;
    };
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut world = World::new(SolverConfig::default()).expect("the default config is valid");
        let built = Ragdoll::build(
            &mut world,
            &desc,
            BuildOptions::new(spine),
            &Pose::bind(&desc),
            None,
        );
        let Ok(ragdoll) = built else {
            assert_eq!(
                world.bodies().len(),
                0,
                "a refused ragdoll left bodies behind"
            );
            continue;
        };
        // Drive settings the loader accepted drive the ragdoll.
        if let Some(drive) = &desc.drive {
            ragdoll
                .drive_to(&mut world, &Pose::bind(&desc), drive)
                .expect("accepted drive settings drive the ragdoll");
        }
        for _ in 0..4 {
            world.step(1.0 / 60.0).expect("a valid step");
        }
        let store = world.bodies();
        for i in (0..store.capacity()).filter(|&i| store.is_live(i)) {
            assert!(store.is_finite(i), "a loaded ragdoll went non-finite");
        }
        assert_eq!(
            world.repaired_bodies(),
            0,
            "a loaded ragdoll tripped the NaN guard"
        );
    }
}
