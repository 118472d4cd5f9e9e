//! Nanoseconds per socket joint per backend: one position iteration over a
//! batch of 1024 joints (2048 bodies, in cache), every part active.
//! `cargo bench -p vertebra-benches --bench socket`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use vertebra_benches::SocketWorkload;
use vertebra_math::Backend;

fn socket(c: &mut Criterion) {
    let mut group = c.benchmark_group("socket_position_iteration");
    for backend in Backend::available() {
        let mut work = SocketWorkload::new(backend, 1024);
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

criterion_group!(benches, socket);
criterion_main!(benches);
