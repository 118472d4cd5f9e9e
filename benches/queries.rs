//! Time (criterion) of a ray cast at the 30-ragdoll drop's formed pile
//! (three seconds in, `PILE_FRAMES`): through the query tree, and testing
//! every collider. `cargo bench -p vertebra-benches --bench queries`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use vertebra_benches::{drop_pile_on, rays_at_the_pile};
use vertebra_collide::QueryFilter;
use vertebra_math::Backend;
use vertebra_ragdoll::SpineMode;

fn queries(c: &mut Criterion) {
    let mut group = c.benchmark_group("ragdoll_drop_30_queries");
    let mut scene = drop_pile_on(SpineMode::Rod, Backend::best());
    let rays = rays_at_the_pile(&scene);
    let set = scene.collisions.as_mut().expect("the drop collides");
    let (world, all) = (&scene.world, QueryFilter::default());
    let mut bench = |name: &str, set: &vertebra_collide::Collisions| {
        group.bench_function(name, |b| {
            let mut k = 0;
            b.iter(|| {
                let (o, d) = rays[k % rays.len()];
                k += 1;
                black_box(set.cast_ray(world, o, d, 10.0, &all).expect("a query"))
            })
        });
    };
    // The scene's frames build no query tree: every collider is tested.
    bench("ray_every_collider", set);
    set.refresh_queries(world).expect("a tree");
    let bones = rays.iter().filter(|&&(o, d)| {
        let hit = set.cast_ray(world, o, d, 10.0, &all).expect("a query");
        hit.and_then(|h| h.part).is_some()
    });
    // Most meet a bone first (a few graze a wall's top or a box).
    assert!(
        bones.count() * 10 >= rays.len() * 9,
        "the rays miss the pile"
    );
    bench("ray_tree", set);
    group.finish();
}

criterion_group!(benches, queries);
criterion_main!(benches);
