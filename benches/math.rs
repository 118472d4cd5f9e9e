//! Time per element of the math layer on every backend this CPU has.
//! `cargo bench -p vertebra-benches --bench math`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use vertebra_benches::{Acos, Atan2, ELEMENTS, HalfSinc, QuatRotate, SinCos, Workload};
use vertebra_math::Backend;
use vertebra_math::map::LaneMap;

fn bench_map<M: LaneMap>(c: &mut Criterion, name: &str, map: &M, lo: f32, hi: f32) {
    let mut group = c.benchmark_group(name);
    group.throughput(Throughput::Elements(ELEMENTS as u64));
    for backend in Backend::available() {
        let mut work = Workload::new(backend, map, lo, hi);
        group.bench_function(backend.name(), |b| {
            b.iter(|| {
                work.run(black_box(map));
                black_box(work.output()[0])
            })
        });
    }
    group.finish();
}

fn math(c: &mut Criterion) {
    bench_map(c, "sin_cos", &SinCos, -8.0, 8.0);
    bench_map(c, "acos", &Acos, -1.0, 1.0);
    bench_map(c, "atan2", &Atan2, -2.0, 2.0);
    bench_map(c, "half_sinc", &HalfSinc, 0.0, std::f32::consts::PI);
    bench_map(c, "quat_normalize_rotate", &QuatRotate, -1.0, 1.0);
}

criterion_group!(benches, math);
criterion_main!(benches);
