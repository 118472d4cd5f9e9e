//! Time per step of the ragdoll drop for 1, 30 and 300 ragdolls, standard
//! (socket spine) and simplified (rod spine), at 20 iterations, one second
//! in; collision detection and the solver step timed apart, so `frame` =
//! `detect` + `step`. Then the step at 1 and 2 threads. Then (`direct_step`)
//! the step alone with the joints solved directly at 1 substep x 4
//! iterations, residuals not measured, one thread, one second in: the
//! 30-ragdoll drop on the reference humanoid and on the anatomical one,
//! each with both spines.
//! `cargo bench -p vertebra-benches --bench step`

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use vertebra_benches::{DT, direct_drop_scene, drop_scene};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::Scene;
use vertebra_world::BackendChoice;

const SPINES: [(&str, SpineMode); 2] = [
    ("simplified", SpineMode::Rod),
    ("standard", SpineMode::Sockets),
];

/// Times `iters` frames of `scene`: the step alone (`time_step`), or the
/// collision detection (with handing the contacts to the world) alone.
fn frames(scene: &mut vertebra_scenes::SceneWorld, iters: u64, time_step: bool) -> Duration {
    let mut total = Duration::ZERO;
    for _ in 0..iters {
        let start = Instant::now();
        scene.detect(DT).expect("contacts");
        let detected = start.elapsed();
        let start = Instant::now();
        scene.world.step(DT).expect("a step");
        total += if time_step { start.elapsed() } else { detected };
        black_box(scene.world.residuals().map(|r| r.eps_lin_cm));
    }
    total
}

fn per_step(c: &mut Criterion) {
    for (part, time_step) in [("step", true), ("detect", false)] {
        let mut group = c.benchmark_group(part);
        group.sample_size(20);
        for count in [1, 30, 300] {
            for (name, spine) in SPINES {
                let mut scene = drop_scene(spine, count, 1);
                group.bench_function(BenchmarkId::new(name, count), |b| {
                    b.iter_custom(|iters| frames(&mut scene, iters, time_step))
                });
            }
        }
        group.finish();
    }
}

fn threads(c: &mut Criterion) {
    let mut group = c.benchmark_group("step_threads");
    group.sample_size(20);
    for count in [30, 300] {
        for (name, spine) in SPINES {
            for threads in [1, 2] {
                let mut scene = drop_scene(spine, count, threads);
                let id = BenchmarkId::new(format!("{name}_{count}"), threads);
                group.bench_function(id, |b| {
                    b.iter_custom(|iters| frames(&mut scene, iters, true))
                });
            }
        }
    }
    group.finish();
}

fn direct(c: &mut Criterion) {
    let mut group = c.benchmark_group("direct_step");
    group.sample_size(20);
    for (scene_name, scene) in [
        ("reference", Scene::RagdollDrop),
        ("anatomical", Scene::AnatomicalDrop),
    ] {
        for (spine_name, spine) in [("rod", SpineMode::Rod), ("sockets", SpineMode::Sockets)] {
            let mut world = direct_drop_scene(scene, spine, BackendChoice::Auto);
            group.bench_function(format!("{scene_name}_{spine_name}_1x4"), |b| {
                b.iter_custom(|iters| frames(&mut world, iters, true))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, per_step, threads, direct);
criterion_main!(benches);
