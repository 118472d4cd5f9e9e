//! Instructions per step (callgrind) of the 30-ragdoll drop one second in,
//! per spine and backend: the solver step alone, its contacts found before
//! the measured call. Needs valgrind and `iai-callgrind-runner` 0.16.1
//! (`./benches/install-iai-runner.sh`).

// The iai-callgrind macros generate undocumented modules and items.
#![allow(missing_docs)]

use std::hint::black_box;

use iai_callgrind::{library_benchmark, library_benchmark_group, main};
use vertebra_benches::{DT, INSTRUCTION_BACKENDS, drop_scene_on};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::SceneWorld;

fn prepared(scene: SceneWorld) -> SceneWorld {
    let mut scene = scene;
    let collisions = scene.collisions.as_ref().expect("the drop has colliders");
    let contacts = collisions
        .find_contacts(&scene.world, DT)
        .expect("contacts");
    scene.world.set_contacts(&contacts).expect("valid contacts");
    scene
}

fn simplified(backend: usize) -> SceneWorld {
    prepared(drop_scene_on(
        SpineMode::Rod,
        30,
        INSTRUCTION_BACKENDS[backend],
    ))
}

fn standard(backend: usize) -> SceneWorld {
    prepared(drop_scene_on(
        SpineMode::Sockets,
        30,
        INSTRUCTION_BACKENDS[backend],
    ))
}

// Argument k is INSTRUCTION_BACKENDS[k]: 0 scalar, 1 portable, 2 sse4, 3 avx2 (8 lanes).
#[library_benchmark]
#[benches::backend(args = [0, 2, 3], setup = simplified)]
fn step_simplified(mut scene: SceneWorld) -> Option<f32> {
    scene.world.step(DT).expect("a step");
    black_box(scene.world.residuals().map(|r| r.eps_lin_cm))
}

#[library_benchmark]
#[benches::backend(args = [0, 2, 3], setup = standard)]
fn step_standard(mut scene: SceneWorld) -> Option<f32> {
    scene.world.step(DT).expect("a step");
    black_box(scene.world.residuals().map(|r| r.eps_lin_cm))
}

library_benchmark_group!(name = drop_30; benchmarks = step_simplified, step_standard);
main!(library_benchmark_groups = drop_30);
