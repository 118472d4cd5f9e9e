//! Time per step of the reference ragdoll alone (passive bending, 1
//! substep x 4 iterations, one thread, one second in), standard (socket
//! spine) and simplified (rod spine): the cost a game pays for one ragdoll.
//! `cargo bench -p vertebra-benches --bench single_ragdoll`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use vertebra_benches::{DT, single_ragdoll};
use vertebra_ragdoll::SpineMode;
use vertebra_world::BackendChoice;

fn per_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("single_ragdoll");
    for (name, spine) in [
        ("simplified", SpineMode::Rod),
        ("standard", SpineMode::Sockets),
    ] {
        let mut scene = single_ragdoll(spine, BackendChoice::Auto);
        group.bench_function(name, |b| {
            b.iter(|| {
                scene.world.step(DT).expect("a step");
                black_box(&scene.world);
            })
        });
    }
    group.finish();
}

criterion_group!(benches, per_step);
criterion_main!(benches);
