//! Instructions per step (callgrind) of the 30-ragdoll drop one second in,
//! per spine and backend: the solver step alone, its contacts found before
//! the measured call. Then (`direct_1x4`) the same with the joints solved
//! directly at 1 substep x 4 iterations, residuals not measured, on avx2:
//! the 30-ragdoll drop on the reference humanoid and on the anatomical one,
//! each with both spines. Then (`direct_window`) the same drops' steps at
//! eight frames from 0.8 s to 1.7 s in (landing and settling), whose mean
//! is the figure: one frame's count moves with how many of its solves
//! needed a second pass. Needs valgrind and `iai-callgrind-runner` 0.16.1
//! (`./benches/install-iai-runner.sh`).
//! `cargo bench -p vertebra-benches --bench step_instructions` (`-- direct`
//! for the direct group alone)

// The iai-callgrind macros generate undocumented modules and items.
#![allow(missing_docs)]

use std::hint::black_box;

use iai_callgrind::{library_benchmark, library_benchmark_group, main};
use vertebra_benches::{
    DT, INSTRUCTION_BACKENDS, direct_drop_scene, direct_drop_scene_at, drop_scene_on,
};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneWorld};
use vertebra_world::BackendChoice;

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

fn direct(scene: Scene, spine: SpineMode, backend: usize) -> SceneWorld {
    let backend = BackendChoice::Forced(INSTRUCTION_BACKENDS[backend]);
    prepared(direct_drop_scene(scene, spine, backend))
}

fn reference_rod(backend: usize) -> SceneWorld {
    direct(Scene::RagdollDrop, SpineMode::Rod, backend)
}

fn reference_sockets(backend: usize) -> SceneWorld {
    direct(Scene::RagdollDrop, SpineMode::Sockets, backend)
}

fn anatomical_rod(backend: usize) -> SceneWorld {
    direct(Scene::AnatomicalDrop, SpineMode::Rod, backend)
}

fn anatomical_sockets(backend: usize) -> SceneWorld {
    direct(Scene::AnatomicalDrop, SpineMode::Sockets, backend)
}

// The drops with their joints solved directly at 1x4, on avx2 only (3); the
// scene is returned so that its drop is not counted.
#[library_benchmark]
#[benches::backend(args = [3], setup = reference_rod)]
fn direct_reference_rod_1x4(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[benches::backend(args = [3], setup = reference_sockets)]
fn direct_reference_sockets_1x4(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[benches::backend(args = [3], setup = anatomical_rod)]
fn direct_anatomical_rod_1x4(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[benches::backend(args = [3], setup = anatomical_sockets)]
fn direct_anatomical_sockets_1x4(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

fn at_frame(scene: Scene, spine: SpineMode, frames: usize) -> SceneWorld {
    let backend = BackendChoice::Forced(INSTRUCTION_BACKENDS[3]);
    prepared(direct_drop_scene_at(scene, spine, backend, frames))
}

fn reference_rod_at(frames: usize) -> SceneWorld {
    at_frame(Scene::RagdollDrop, SpineMode::Rod, frames)
}

fn reference_sockets_at(frames: usize) -> SceneWorld {
    at_frame(Scene::RagdollDrop, SpineMode::Sockets, frames)
}

fn anatomical_rod_at(frames: usize) -> SceneWorld {
    at_frame(Scene::AnatomicalDrop, SpineMode::Rod, frames)
}

fn anatomical_sockets_at(frames: usize) -> SceneWorld {
    at_frame(Scene::AnatomicalDrop, SpineMode::Sockets, frames)
}

// The direct drops' steps at eight frames, on avx2.
#[library_benchmark]
#[benches::frame(args = [48, 56, 64, 72, 80, 88, 96, 104], setup = reference_rod_at)]
fn window_reference_rod(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[benches::frame(args = [48, 56, 64, 72, 80, 88, 96, 104], setup = reference_sockets_at)]
fn window_reference_sockets(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[benches::frame(args = [48, 56, 64, 72, 80, 88, 96, 104], setup = anatomical_rod_at)]
fn window_anatomical_rod(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[benches::frame(args = [48, 56, 64, 72, 80, 88, 96, 104], setup = anatomical_sockets_at)]
fn window_anatomical_sockets(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

library_benchmark_group!(name = drop_30; benchmarks = step_simplified, step_standard);
library_benchmark_group!(
    name = direct_1x4;
    benchmarks = direct_reference_rod_1x4, direct_reference_sockets_1x4,
        direct_anatomical_rod_1x4, direct_anatomical_sockets_1x4
);
library_benchmark_group!(
    name = direct_window;
    benchmarks = window_reference_rod, window_reference_sockets, window_anatomical_rod,
        window_anatomical_sockets
);
main!(
    library_benchmark_groups = drop_30,
    direct_1x4,
    direct_window
);
