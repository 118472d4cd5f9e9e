//! Instructions per element of the polynomials on each backend, counted by
//! callgrind (exact and repeatable, unlike time on a shared machine).
//! Needs valgrind and `iai-callgrind-runner` 0.16.1 on PATH; see the README.
//! Each benchmark maps `ELEMENTS` (1024) inputs: divide by 1024.

// The iai-callgrind macros generate undocumented modules and items.
#![allow(missing_docs)]

use std::hint::black_box;

use iai_callgrind::{library_benchmark, library_benchmark_group, main};
use vertebra_benches::{Acos, Atan2, HalfSinc, INSTRUCTION_BACKENDS, SinCos, Workload};

fn sin_cos_on(backend: usize) -> Workload {
    Workload::new(INSTRUCTION_BACKENDS[backend], &SinCos, -8.0, 8.0)
}
fn acos_on(backend: usize) -> Workload {
    Workload::new(INSTRUCTION_BACKENDS[backend], &Acos, -1.0, 1.0)
}
fn atan2_on(backend: usize) -> Workload {
    Workload::new(INSTRUCTION_BACKENDS[backend], &Atan2, -2.0, 2.0)
}
fn half_sinc_on(backend: usize) -> Workload {
    Workload::new(
        INSTRUCTION_BACKENDS[backend],
        &HalfSinc,
        0.0,
        std::f32::consts::PI,
    )
}

// Argument k is INSTRUCTION_BACKENDS[k]: 0 scalar, 1 portable, 2 sse4, 3 avx2 (8 lanes).
#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = sin_cos_on)]
fn sin_cos(mut work: Workload) -> f32 {
    work.run(&SinCos);
    black_box(work.output()[0])
}

#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = acos_on)]
fn acos(mut work: Workload) -> f32 {
    work.run(&Acos);
    black_box(work.output()[0])
}

#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = atan2_on)]
fn atan2(mut work: Workload) -> f32 {
    work.run(&Atan2);
    black_box(work.output()[0])
}

#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = half_sinc_on)]
fn half_sinc(mut work: Workload) -> f32 {
    work.run(&HalfSinc);
    black_box(work.output()[0])
}

library_benchmark_group!(name = polynomials; benchmarks = sin_cos, acos, atan2, half_sinc);
main!(library_benchmark_groups = polynomials);
