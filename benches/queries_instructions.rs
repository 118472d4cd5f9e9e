//! Instructions (callgrind) of the calls a game makes each frame on the
//! 30-ragdoll drop's formed pile (three seconds in, `PILE_FRAMES`; rod
//! spines, AVX2, one thread): a ray cast at the pile through the query
//! tree and testing every collider; the solver step (contact impulses and
//! joint forces included) and the step followed by
//! `Collisions::after_step` (continuous collision, the contact events, the
//! query tree's refit). Needs valgrind and `iai-callgrind-runner` 0.16.1
//! (`./benches/install-iai-runner.sh`).
//! `cargo bench -p vertebra-benches --bench queries_instructions`

// The iai-callgrind macros generate undocumented modules and items.
#![allow(missing_docs)]

use std::hint::black_box;

use glam::Vec3;
use iai_callgrind::{library_benchmark, library_benchmark_group, main};
use vertebra_benches::{DT, INSTRUCTION_BACKENDS, drop_pile_on, rays_at_the_pile};
use vertebra_collide::{QueryFilter, QueryHit};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::SceneWorld;

/// The formed pile, two game frames (`Collisions::step`) after it (so the
/// query tree and the events are warm), its contacts found for the next
/// step (AVX2).
fn pile() -> SceneWorld {
    let mut scene = drop_pile_on(SpineMode::Rod, INSTRUCTION_BACKENDS[3]);
    let mut list = Vec::new();
    let set = scene.collisions.as_mut().expect("the drop collides");
    for _ in 0..2 {
        set.step(&mut scene.world, DT).expect("a frame");
    }
    set.find_contacts_into(&scene.world, DT, &mut list)
        .expect("contacts");
    scene
        .world
        .swap_contacts(&mut list)
        .expect("valid contacts");
    scene
}

/// A ray at the pile: the first of [`rays_at_the_pile`].
type Ray = (Vec3, Vec3);

/// The pile with its query tree built for its poses now, and the ray.
fn treed() -> (SceneWorld, Ray) {
    let mut scene = pile();
    let set = scene.collisions.as_mut().expect("the drop collides");
    set.refresh_queries(&scene.world).expect("a tree");
    let ray = rays_at_the_pile(&scene)[0];
    (scene, ray)
}

/// The pile with a body moved since the tree was built: every collider
/// tested.
fn untreed() -> (SceneWorld, Ray) {
    let (mut scene, ray) = treed();
    let body = scene.world.bodies().handle_at(1).expect("a body");
    let s = scene.world.body(body).expect("live");
    scene
        .world
        .set_body_pose(body, s.position, s.orientation)
        .expect("a pose");
    (scene, ray)
}

#[library_benchmark]
#[bench::tree(setup = treed)]
#[bench::every_collider(setup = untreed)]
fn ray_at_the_pile(input: (SceneWorld, Ray)) -> (SceneWorld, Option<QueryHit>) {
    let (scene, (from, direction)) = input;
    let set = scene.collisions.as_ref().expect("the drop collides");
    let hit = set
        .cast_ray(&scene.world, from, direction, 10.0, &QueryFilter::default())
        .expect("a query");
    // The scene goes back out: its drop is not the query's cost.
    black_box((scene, hit))
}

#[library_benchmark]
#[bench::formed(setup = pile)]
fn step(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    black_box(scene)
}

#[library_benchmark]
#[bench::formed(setup = pile)]
fn step_then_after_step(mut scene: SceneWorld) -> SceneWorld {
    scene.world.step(DT).expect("a step");
    let set = scene.collisions.as_mut().expect("the drop collides");
    set.after_step(&mut scene.world).expect("after the step");
    black_box(scene)
}

library_benchmark_group!(name = queries; benchmarks = ray_at_the_pile);
library_benchmark_group!(name = frame; benchmarks = step, step_then_after_step);
main!(library_benchmark_groups = queries, frame);
