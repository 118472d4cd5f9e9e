//! Instructions per joint per backend (callgrind): one position iteration
//! over 256 joints (sockets: point, cone, twist, with and without the
//! drive, and the shaped path; hinges; fixed joints; rods; contacts).
//! Divide by 256.
//! Needs valgrind and `iai-callgrind-runner` 0.16.1 (see the README).

// The iai-callgrind macros generate undocumented modules and items.
#![allow(missing_docs)]

use std::hint::black_box;

use iai_callgrind::{library_benchmark, library_benchmark_group, main};
use vertebra_benches::{
    ConstraintWorkload, ContactWorkload, FixedWorkload, HingeWorkload, INSTRUCTION_BACKENDS,
    Placement, RodWorkload, SocketWorkload,
};

fn with_drive(backend: usize) -> SocketWorkload {
    SocketWorkload::new(INSTRUCTION_BACKENDS[backend], 256, true, Placement::InCache)
}

fn without_drive(backend: usize) -> SocketWorkload {
    SocketWorkload::new(
        INSTRUCTION_BACKENDS[backend],
        256,
        false,
        Placement::InCache,
    )
}

// Argument k is INSTRUCTION_BACKENDS[k]: 0 scalar, 1 portable, 2 sse4, 3 avx2 (8 lanes).
#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = with_drive)]
fn socket_limits_drive(mut work: SocketWorkload) -> f32 {
    work.iterate();
    black_box(work.probe())
}

#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = without_drive)]
fn socket_limits(mut work: SocketWorkload) -> f32 {
    work.iterate();
    black_box(work.probe())
}

fn shaped(backend: usize) -> SocketWorkload {
    SocketWorkload::shaped(INSTRUCTION_BACKENDS[backend], 256, Placement::InCache)
}

#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = shaped)]
fn socket_shaped(mut work: SocketWorkload) -> f32 {
    work.iterate();
    black_box(work.probe())
}

fn hinges(backend: usize) -> HingeWorkload {
    HingeWorkload::new(INSTRUCTION_BACKENDS[backend], 256, Placement::InCache)
}

#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = hinges)]
fn hinge(mut work: HingeWorkload) -> f32 {
    work.iterate();
    black_box(work.probe())
}

fn fixed_joints(backend: usize) -> FixedWorkload {
    FixedWorkload::new(INSTRUCTION_BACKENDS[backend], 256, Placement::InCache)
}

#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = fixed_joints)]
fn fixed(mut work: FixedWorkload) -> f32 {
    work.iterate();
    black_box(work.probe())
}

fn rods(backend: usize) -> RodWorkload {
    RodWorkload::new(INSTRUCTION_BACKENDS[backend], 256, Placement::InCache)
}

#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = rods)]
fn rod(mut work: RodWorkload) -> f32 {
    work.iterate();
    black_box(work.probe())
}

fn contacts(backend: usize) -> ContactWorkload {
    ContactWorkload::new(INSTRUCTION_BACKENDS[backend], 256, Placement::InCache)
}

#[library_benchmark]
#[benches::backend(args = [0, 1, 2, 3], setup = contacts)]
fn contact(mut work: ContactWorkload) -> f32 {
    work.iterate();
    black_box(work.probe())
}

library_benchmark_group!(name = joints; benchmarks = socket_limits_drive, socket_limits, socket_shaped, hinge, fixed, rod, contact);
main!(library_benchmark_groups = joints);
