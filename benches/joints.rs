//! Nanoseconds per joint per backend: one position iteration over a batch
//! of sockets (point, swing cone and twist range, with and without the
//! angular drive; the shaped path's soft ellipse, pyramid and twist),
//! hinges, fixed joints, rods and contacts, each lane on its own two bodies (as in
//! one colour). In cache: 1024 joints on 2048 bodies in order. Out of
//! cache: 2^18 joints on 2^19 bodies scattered through memory (about
//! 90 MB).
//! `cargo bench -p vertebra-benches --bench joints`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use vertebra_benches::{
    ConstraintWorkload, ContactWorkload, FixedWorkload, HingeWorkload, OUT_OF_CACHE_JOINTS,
    Placement, RodWorkload, SocketWorkload,
};
use vertebra_math::Backend;

const PLACEMENTS: [(&str, Placement, usize); 2] = [
    ("", Placement::InCache, 1024),
    ("_out_of_cache", Placement::OutOfCache, OUT_OF_CACHE_JOINTS),
];

/// A constraint kind: its group name and how to build its workload.
type Kind = (
    &'static str,
    fn(Backend, usize, Placement) -> Box<dyn ConstraintWorkload>,
);

const KINDS: [Kind; 7] = [
    ("socket_limits_drive", |b, n, p| {
        Box::new(SocketWorkload::new(b, n, true, p))
    }),
    ("socket_limits", |b, n, p| {
        Box::new(SocketWorkload::new(b, n, false, p))
    }),
    ("socket_shaped", |b, n, p| {
        Box::new(SocketWorkload::shaped(b, n, p))
    }),
    ("hinge", |b, n, p| Box::new(HingeWorkload::new(b, n, p))),
    ("fixed", |b, n, p| Box::new(FixedWorkload::new(b, n, p))),
    ("rod", |b, n, p| Box::new(RodWorkload::new(b, n, p))),
    ("contact", |b, n, p| Box::new(ContactWorkload::new(b, n, p))),
];

fn joints(c: &mut Criterion) {
    for (suffix, placement, joints) in PLACEMENTS {
        for (name, make) in KINDS {
            let mut group = c.benchmark_group(format!("{name}{suffix}"));
            group.sample_size(if placement == Placement::InCache {
                100
            } else {
                10
            });
            group.throughput(Throughput::Elements(joints as u64));
            for backend in Backend::available() {
                let mut work = make(backend, joints, placement);
                group.bench_function(backend.name(), |b| {
                    b.iter(|| {
                        work.iterate();
                        black_box(work.probe())
                    })
                });
            }
            group.finish();
        }
    }
}

criterion_group!(benches, joints);
criterion_main!(benches);
