//! Instructions per step (callgrind) of the reference ragdoll alone
//! (passive bending, 1 substep x 4 iterations, one second in), per spine
//! and backend, with either joint solve. Needs valgrind and `iai-callgrind-runner` 0.16.1
//! (`./benches/install-iai-runner.sh`).
//! And a frame (collision detection and the step) of the reference ragdoll
//! lying on the ground (`lone_ragdoll_on_ground`), per spine and backend,
//! iterated at 1 x 20 (the paper's) and 1 x 4, and solved directly
//! at 1 x 4 and 1 x 8 (`lone_solvers`, in that order).
//! `cargo bench -p vertebra-benches --bench single_ragdoll_instructions`

// The iai-callgrind macros generate undocumented modules and items.
#![allow(missing_docs)]

use std::hint::black_box;

use iai_callgrind::{library_benchmark, library_benchmark_group, main};
use vertebra_benches::{
    DT, INSTRUCTION_BACKENDS, LONE_SETTLE_FRAMES, lone_ragdoll_on_ground, lone_solvers,
    single_ragdoll, single_ragdoll_solved,
};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneWorld};
use vertebra_world::{BackendChoice, JointSolver};

fn simplified(backend: usize) -> SceneWorld {
    single_ragdoll(
        SpineMode::Rod,
        BackendChoice::Forced(INSTRUCTION_BACKENDS[backend]),
    )
}

fn standard(backend: usize) -> SceneWorld {
    single_ragdoll(
        SpineMode::Sockets,
        BackendChoice::Forced(INSTRUCTION_BACKENDS[backend]),
    )
}

fn direct(spine: SpineMode, backend: usize) -> SceneWorld {
    let backend = BackendChoice::Forced(INSTRUCTION_BACKENDS[backend]);
    single_ragdoll_solved(spine, backend, JointSolver::Direct)
}

fn simplified_direct(backend: usize) -> SceneWorld {
    direct(SpineMode::Rod, backend)
}

fn standard_direct(backend: usize) -> SceneWorld {
    direct(SpineMode::Sockets, backend)
}

// Argument k is INSTRUCTION_BACKENDS[k]: 0 scalar, 1 portable, 2 sse4, 3 avx2 (8 lanes).
#[library_benchmark]
#[benches::backend(args = [0, 2, 3], setup = simplified)]
fn step_simplified(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[benches::backend(args = [0, 2, 3], setup = standard)]
fn step_standard(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

// The same ragdoll with its joints solved directly.
#[library_benchmark]
#[benches::backend(args = [0, 2, 3], setup = simplified_direct)]
fn step_simplified_direct(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[benches::backend(args = [0, 2, 3], setup = standard_direct)]
fn step_standard_direct(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

/// Argument `k` is `solver * 4 + backend`: solver `lone_solvers()[k / 4]`,
/// backend `INSTRUCTION_BACKENDS[k % 4]`.
fn on_ground(spine: SpineMode, k: usize) -> SceneWorld {
    let backend = BackendChoice::Forced(INSTRUCTION_BACKENDS[k % 4]);
    lone_ragdoll_on_ground(spine, backend, &lone_solvers()[k / 4].1)
}

fn rod_on_ground(k: usize) -> SceneWorld {
    on_ground(SpineMode::Rod, k)
}

fn sockets_on_ground(k: usize) -> SceneWorld {
    on_ground(SpineMode::Sockets, k)
}

// Solvers iterated 1x20, iterated 1x4, direct 1x4, direct 1x8 (k / 4 = 0
// to 3) on scalar, sse4 and avx2 (k % 4 = 0, 2, 3).
#[library_benchmark]
#[benches::solver_backend(args = [0, 2, 3, 4, 6, 7, 8, 10, 11, 12, 14, 15], setup = rod_on_ground)]
fn frame_rod_on_ground(mut scene: SceneWorld) -> SceneWorld {
    (scene.frame(Scene::RagdollDrop, LONE_SETTLE_FRAMES, DT)).expect("a frame");
    black_box(scene)
}

#[library_benchmark]
#[benches::solver_backend(args = [0, 2, 3, 4, 6, 7, 8, 10, 11, 12, 14, 15], setup = sockets_on_ground)]
fn frame_sockets_on_ground(mut scene: SceneWorld) -> SceneWorld {
    (scene.frame(Scene::RagdollDrop, LONE_SETTLE_FRAMES, DT)).expect("a frame");
    black_box(scene)
}

library_benchmark_group!(
    name = single_ragdoll;
    benchmarks = step_simplified, step_standard, step_simplified_direct, step_standard_direct
);
library_benchmark_group!(
    name = lone_on_ground;
    benchmarks = frame_rod_on_ground, frame_sockets_on_ground
);
main!(library_benchmark_groups = single_ragdoll, lone_on_ground);
