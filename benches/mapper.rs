//! Mapping one ragdoll onto the shipped reference animation skeleton
//! (`Skeleton::reference()`, 63 bones) against the step of that ragdoll:
//! the ragdoll drop with one ragdoll at 20 iterations and 1 substep, one
//! thread, one second in. Target: mapping costs less than the step.
//! `cargo bench -p vertebra-benches --bench mapper`

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use vertebra_benches::{DT, advance_drop, drop_scene_built};
use vertebra_ragdoll::{Skeleton, SkeletonMapper, SpineMapping, SpineMode, Transform, Transition};

const SPINES: [(&str, SpineMode); 2] = [
    ("simplified", SpineMode::Rod),
    ("standard", SpineMode::Sockets),
];

fn mapping(c: &mut Criterion) {
    let skeleton = Skeleton::reference();
    let animation = skeleton.bind_pose();
    let animated = animation.to_model(&skeleton).expect("the bind pose");
    let mut group = c.benchmark_group("mapper");
    group.sample_size(20);
    for (name, spine) in SPINES {
        let mut scene = drop_scene_built(spine, 1, 1);
        let desc = scene.ragdolls[0].description().clone();
        let mapper = SkeletonMapper::new(&skeleton, &desc, spine).expect("the humanoid's bones");
        // Measured at the switch: the ragdoll as built, its joints holding;
        // then timed one second in, as the drop scene is.
        let transition = Transition::new(
            &mapper,
            &scene.ragdolls[0],
            &scene.world,
            &animation,
            Transform::IDENTITY,
            SpineMapping::Arc,
            0.5,
        )
        .expect("measured");
        advance_drop(&mut scene, 0..60);
        // The solver step alone (contacts found outside the timing).
        group.bench_function(BenchmarkId::new("step", name), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    scene.detect(DT).expect("contacts");
                    let start = Instant::now();
                    scene.world.step(DT).expect("a step");
                    total += start.elapsed();
                }
                total
            })
        });
        let (world, ragdoll) = (&scene.world, &scene.ragdolls[0]);
        for (mode, mapping) in [
            ("map_orientation", SpineMapping::Orientation),
            ("map_arc", SpineMapping::Arc),
        ] {
            group.bench_function(BenchmarkId::new(mode, name), |b| {
                b.iter(|| {
                    mapper
                        .map_to_skeleton(ragdoll, world, &animation, Transform::IDENTITY, mapping)
                        .expect("mapped")
                })
            });
        }

        group.bench_function(BenchmarkId::new("transition_arc", name), |b| {
            b.iter(|| {
                transition
                    .skeleton_pose(
                        &mapper,
                        ragdoll,
                        world,
                        &animation,
                        Transform::IDENTITY,
                        0.1,
                    )
                    .expect("mapped")
            })
        });
        group.bench_function(BenchmarkId::new("map_to_ragdoll", name), |b| {
            b.iter(|| {
                mapper
                    .map_to_ragdoll(black_box(&animated), Transform::IDENTITY)
                    .expect("mapped")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, mapping);
criterion_main!(benches);
