//! Time per step of the reference ragdoll alone (passive bending, 1
//! substep x 4 iterations, one thread, one second in), standard (socket
//! spine) and simplified (rod spine): the cost a game pays for one ragdoll.
//! And a lone ragdoll lying on the ground (`lone_ragdoll_on_ground`): a
//! frame, collision detection and the step, iterated at 1 x 20 (the
//! world's default) and 1 x 4, and solved directly at 1 x 4 and 1 x 8.
//! `cargo bench -p vertebra-benches --bench single_ragdoll`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use vertebra_benches::{
    DT, LONE_SETTLE_FRAMES, lone_ragdoll_on_ground, lone_solvers, single_ragdoll,
};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::Scene;
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

fn on_ground(c: &mut Criterion) {
    let mut group = c.benchmark_group("lone_on_ground");
    for (spine_name, spine) in [("rod", SpineMode::Rod), ("sockets", SpineMode::Sockets)] {
        for (solver_name, solver) in lone_solvers() {
            let mut scene = lone_ragdoll_on_ground(spine, BackendChoice::Auto, &solver);
            group.bench_function(format!("{spine_name}/{solver_name}"), |b| {
                b.iter(|| {
                    let frame = LONE_SETTLE_FRAMES;
                    scene.frame(Scene::RagdollDrop, frame, DT).expect("a frame");
                    black_box(&scene.world);
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, per_step, on_ground);
criterion_main!(benches);
