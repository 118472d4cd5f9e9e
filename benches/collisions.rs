//! Collision detection per step for the 30-ragdoll drop world, after one
//! second of falling (ragdolls piled in the pit, many contacts).
//! `cargo bench -p vertebra-benches --bench collisions`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use vertebra_ragdoll::{RagdollDesc, SpineMode};
use vertebra_world::{SolverConfig, World};

fn collisions(c: &mut Criterion) {
    let mut group = c.benchmark_group("ragdoll_drop_30");
    for (name, spine) in [
        ("find_contacts_rod", SpineMode::Rod),
        ("find_contacts_sockets", SpineMode::Sockets),
    ] {
        let world = World::new(SolverConfig::default()).expect("default config");
        let (mut world, colliders, _) =
            vertebra_scenes::ragdoll_drop(world, &RagdollDesc::reference_humanoid(), spine, 30, 0)
                .expect("the drop world");
        for _ in 0..60 {
            let contacts = colliders
                .find_contacts(&world, 1.0 / 60.0)
                .expect("contacts");
            world.set_contacts(&contacts).expect("valid contacts");
            world.step(1.0 / 60.0).expect("step");
        }
        let count = colliders
            .find_contacts(&world, 1.0 / 60.0)
            .expect("contacts")
            .len();
        eprintln!("{name}: {count} contacts after 1 s");
        group.bench_function(name, |b| {
            b.iter(|| {
                black_box(
                    colliders
                        .find_contacts(&world, 1.0 / 60.0)
                        .expect("contacts")
                        .len(),
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, collisions);
criterion_main!(benches);
