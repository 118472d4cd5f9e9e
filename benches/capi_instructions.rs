//! Instructions (callgrind) of one frame of the 30-ragdoll drop one second
//! in (contacts found and handed over, then the step), through the Rust
//! API and through the C ABI, from the same state: the C ABI's cost
//! without the machine's noise. Needs valgrind and `iai-callgrind-runner`
//! 0.16.1 (`./benches/install-iai-runner.sh`).

// The iai-callgrind macros generate undocumented modules and items.
#![allow(missing_docs)]

#[path = "capi_scene.rs"]
mod capi_scene;

use std::hint::black_box;

use capi_scene::{CScene, put_back, save};
use iai_callgrind::{library_benchmark, library_benchmark_group, main};
use vertebra_benches::{DT, drop_scene};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::SceneWorld;

const SPINES: [SpineMode; 2] = [SpineMode::Rod, SpineMode::Sockets];

/// Both scenes are measured at the same state, restored from the same
/// bytes (a restored world's constraint layout and contact order are its
/// own, not the history's), a frame after the restore (which lays the
/// constraints out and grows the buffers once).
fn rust_scene(spine: usize) -> SceneWorld {
    let mut scene = drop_scene(SPINES[spine], 30, 1);
    let saved = save(&scene);
    put_back(&mut scene, &saved);
    scene.detect(DT).expect("contacts");
    scene.world.step(DT).expect("a step");
    scene
}

fn c_scene(spine: usize) -> CScene {
    let scene = drop_scene(SPINES[spine], 30, 1);
    let c = CScene::new(&scene, &save(&scene));
    c.frame();
    // The same world as the Rust scene's, bit for bit.
    assert_eq!(c.hash(), rust_scene(spine).world.state_hash());
    c
}

// Argument k is SPINES[k]: 0 the rod (simplified), 1 sockets (standard).
#[library_benchmark]
#[benches::spine(args = [0, 1], setup = rust_scene)]
fn rust_frame(mut scene: SceneWorld) -> SceneWorld {
    scene.detect(DT).expect("contacts");
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[benches::spine(args = [0, 1], setup = c_scene)]
fn c_frame(scene: CScene) -> CScene {
    scene.frame();
    black_box(scene)
}

library_benchmark_group!(name = capi_30; benchmarks = rust_frame, c_frame);
main!(library_benchmark_groups = capi_30);
