//! Nanoseconds per joint per backend, sockets and rods: one position
//! iteration over a
//! batch of 1024 joints (2048 bodies, in cache): point, swing cone and
//! twist range, with and without the angular drive.
//! `cargo bench -p vertebra-benches --bench socket`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use vertebra_benches::{ContactWorkload, RodWorkload, SocketWorkload};
use vertebra_math::Backend;

fn joints(c: &mut Criterion) {
    for (name, drive) in [("socket_limits_drive", true), ("socket_limits", false)] {
        bench_sockets(c, name, drive);
    }
    let mut group = c.benchmark_group("contact");
    for backend in Backend::available() {
        let mut work = ContactWorkload::new(backend, 1024);
        group.throughput(Throughput::Elements(work.contacts() as u64));
        group.bench_function(backend.name(), |b| {
            b.iter(|| {
                work.iterate();
                black_box(work.probe())
            })
        });
    }
    group.finish();
    let mut group = c.benchmark_group("rod");
    for backend in Backend::available() {
        let mut work = RodWorkload::new(backend, 1024);
        group.throughput(Throughput::Elements(work.rods() as u64));
        group.bench_function(backend.name(), |b| {
            b.iter(|| {
                work.iterate();
                black_box(work.probe())
            })
        });
    }
    group.finish();
}

fn bench_sockets(c: &mut Criterion, name: &str, drive: bool) {
    let mut group = c.benchmark_group(name);
    for backend in Backend::available() {
        let mut work = SocketWorkload::new(backend, 1024, drive);
        group.throughput(Throughput::Elements(work.sockets() as u64));
        group.bench_function(backend.name(), |b| {
            b.iter(|| {
                work.iterate();
                black_box(work.probe())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, joints);
criterion_main!(benches);
