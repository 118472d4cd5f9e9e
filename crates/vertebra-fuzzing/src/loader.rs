//! Arbitrary bytes as a ragdoll file, a skeleton file or a generator file.

use std::sync::OnceLock;

use vertebra_ragdoll::{
    BuildOptions, Pose, Ragdoll, RagdollDesc, RagdollGenerator, Skeleton, SpineMode,
};
use vertebra_world::{SolverConfig, World};

/// The reference skeleton, parsed once.
fn reference() -> &'static Skeleton {
    static REFERENCE: OnceLock<Skeleton> = OnceLock::new();
    REFERENCE.get_or_init(Skeleton::reference)
}

/// Arbitrary bytes (as UTF-8, lossily) through the TOML loaders. As a
/// skeleton file: an error, or a skeleton that reads back from its TOML
/// as itself and converts to model space. As a ragdoll file, alone and on
/// the reference skeleton: an error, or a description that validates,
/// reads back from its TOML as itself, builds both ways, is driven by its
/// own drive settings and profiles (and blends of them), and steps to a finite state without the step's NaN
/// guard.
pub fn ragdoll_loader(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Ok(skeleton) = Skeleton::from_toml(&text) {
        assert_eq!(
            Skeleton::from_toml(&skeleton.to_toml()).as_ref(),
            Ok(&skeleton),
            "a skeleton reads back from its TOML as itself"
        );
        skeleton
            .bind_pose()
            .to_model(&skeleton)
            .expect("a loaded skeleton's bind pose converts to model space");
    }
    let alone = RagdollDesc::from_toml(&text);
    let on_bones = RagdollDesc::from_toml_with_skeleton(&text, reference());
    for desc in [&alone, &on_bones].into_iter().flatten() {
        assert_eq!(desc.validate(), Ok(()), "a loaded description validates");
        assert_eq!(
            RagdollDesc::from_toml(&desc.to_toml()).as_ref(),
            Ok(desc),
            "a description reads back from its TOML as itself"
        );
    }
    // The skeleton changes the bodies only where they are placed from bones
    // (which needs it): build the one that loaded, alone first.
    if let Some(desc) = alone.ok().or(on_bones.ok()) {
        build(&desc);
    }
    // As a generator file on the reference skeleton: an error, or a
    // description that validates, reads back as itself and builds.
    let generated = RagdollGenerator::from_toml(&text, reference()).and_then(|g| g.generate());
    if let Ok(desc) = generated {
        assert_eq!(desc.validate(), Ok(()), "a generated description validates");
        assert_eq!(
            RagdollDesc::from_toml(&desc.to_toml()).as_ref(),
            Ok(&desc),
            "a generated description reads back from its TOML as itself"
        );
        build(&desc);
    }
}

fn build(desc: &RagdollDesc) {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut world = World::new(SolverConfig::default()).expect("the default config is valid");
        let built = Ragdoll::build(
            &mut world,
            desc,
            BuildOptions::new(spine),
            &Pose::bind(desc),
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
                .drive_to(&mut world, &Pose::bind(desc), drive)
                .expect("accepted drive settings drive the ragdoll");
        }
        for _ in 0..4 {
            world.step(1.0 / 60.0).expect("a valid step");
        }
        // Profiles the loader accepted, and blends between them, drive it.
        let bind = Pose::bind(desc);
        for (k, profile) in desc.profiles.iter().enumerate() {
            let next = &desc.profiles[(k + 1) % desc.profiles.len()];
            let half = profile
                .blended(next, 0.5)
                .expect("a description's profiles blend");
            for p in [profile, &half] {
                ragdoll
                    .follow_profile(&mut world, (&bind, &bind), 1.0 / 60.0, p)
                    .expect("accepted profiles drive the ragdoll");
                world.step(1.0 / 60.0).expect("a valid step");
            }
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
