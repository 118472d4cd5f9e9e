//! Time (criterion) of a ray cast at the 30-ragdoll drop's pile one second
//! in: through the query tree, and testing every collider; and the query
//! tree's refit. `cargo bench -p vertebra-benches --bench queries`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use vertebra_benches::drop_scene_on;
use vertebra_collide::QueryFilter;
use vertebra_math::Backend;
use vertebra_ragdoll::SpineMode;

fn queries(c: &mut Criterion) {
    let mut group = c.benchmark_group("ragdoll_drop_30_queries");
    let mut scene = drop_scene_on(SpineMode::Rod, 30, Backend::best());
    let set = scene.collisions.as_mut().expect("the drop collides");
    let all = QueryFilter::default();
    // Rays from a ring 4 m out and 2 m up toward the pit's middle.
    let rays: Vec<(Vec3, Vec3)> = (0..64)
        .map(|k| {
            let a = k as f32 * 0.1;
            let from = Vec3::new(4.0 * a.cos(), 2.0, 4.0 * a.sin());
            (from, (Vec3::new(0.0, 0.3, 0.0) - from).normalize())
        })
        .collect();
    let world = &scene.world;
    group.bench_function("ray_every_collider", |b| {
        let mut k = 0;
        b.iter(|| {
            let (o, d) = rays[k % rays.len()];
            k += 1;
            black_box(set.cast_ray(world, o, d, 10.0, &all).expect("a query"))
        })
    });
    set.refresh_queries(world).expect("a tree");
    group.bench_function("ray_tree", |b| {
        let mut k = 0;
        b.iter(|| {
            let (o, d) = rays[k % rays.len()];
            k += 1;
            black_box(set.cast_ray(world, o, d, 10.0, &all).expect("a query"))
        })
    });
    group.finish();
}

criterion_group!(benches, queries);
criterion_main!(benches);
