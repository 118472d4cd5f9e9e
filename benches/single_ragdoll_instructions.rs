//! Instructions per step (callgrind) of the reference ragdoll alone
//! (passive bending, 1 substep x 4 iterations, one second in), per spine
//! and backend, with either joint solve. Needs valgrind and `iai-callgrind-runner` 0.16.1
//! (`./benches/install-iai-runner.sh`).
//! `cargo bench -p vertebra-benches --bench single_ragdoll_instructions`

// The iai-callgrind macros generate undocumented modules and items.
#![allow(missing_docs)]

use std::hint::black_box;

use iai_callgrind::{library_benchmark, library_benchmark_group, main};
use vertebra_benches::{DT, INSTRUCTION_BACKENDS, single_ragdoll, single_ragdoll_solved};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::SceneWorld;
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

// The same ragdoll with its joints solved directly (issue 18).
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

library_benchmark_group!(
    name = single_ragdoll;
    benchmarks = step_simplified, step_standard, step_simplified_direct, step_standard_direct
);
main!(library_benchmark_groups = single_ragdoll);
