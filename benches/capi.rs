//! What the C ABI costs over the Rust API: a frame of the 30-ragdoll drop
//! (collision detection handed to the world, then the step), one second
//! in, through `vt_collisions_update` + `vt_world_step` against
//! `find_contacts_into` + `swap_contacts` + `World::step`, on the same
//! state. Both cycle through the same 60 frames (the state put back from
//! a snapshot, untimed, every 60), so both time the same work.
//! `cargo bench -p vertebra-benches --bench capi`

#[path = "capi_scene.rs"]
mod capi_scene;

use std::hint::black_box;
use std::time::{Duration, Instant};

use capi_scene::{CScene, Saved, put_back, save};
use criterion::{Criterion, criterion_group, criterion_main};
use vertebra_benches::{DT, drop_scene};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::SceneWorld;

/// Frames in the cycle both APIs step through.
const CYCLE: u64 = 60;

/// Times `iters` frames of `state`, putting it back every [`CYCLE`]
/// (untimed).
fn cycle<S>(state: &mut S, iters: u64, frame: fn(&mut S), put_back: fn(&mut S)) -> Duration {
    let mut total = Duration::ZERO;
    for i in 0..iters {
        if i % CYCLE == 0 {
            put_back(state);
        }
        let start = Instant::now();
        frame(state);
        total += start.elapsed();
    }
    black_box(total)
}

fn rust_frame((scene, _): &mut (SceneWorld, &Saved)) {
    scene.detect(DT).expect("contacts");
    scene.world.step(DT).expect("a step");
}

fn rust_put_back((scene, saved): &mut (SceneWorld, &Saved)) {
    put_back(scene, saved);
}

fn c_frame((scene, _): &mut (CScene, &Saved)) {
    scene.frame();
}

fn c_put_back((scene, saved): &mut (CScene, &Saved)) {
    scene.put_back(saved);
}

fn overhead(c: &mut Criterion) {
    let mut group = c.benchmark_group("capi_frame_30");
    group.sample_size(30);
    for (name, spine) in [
        ("simplified", SpineMode::Rod),
        ("standard", SpineMode::Sockets),
    ] {
        let mut scene = drop_scene(spine, 30, 1);
        let saved = save(&scene);
        let cscene = CScene::new(&scene, &saved);
        // Both APIs compute the same world, bit for bit.
        for _ in 0..CYCLE {
            scene.detect(DT).expect("contacts");
            scene.world.step(DT).expect("a step");
            cscene.frame();
        }
        assert_eq!(scene.world.state_hash(), cscene.hash());
        let mut rust = (scene, &saved);
        group.bench_function(format!("rust_{name}"), |b| {
            b.iter_custom(|iters| cycle(&mut rust, iters, rust_frame, rust_put_back))
        });
        let mut capi = (cscene, &saved);
        group.bench_function(format!("c_{name}"), |b| {
            b.iter_custom(|iters| cycle(&mut capi, iters, c_frame, c_put_back))
        });
    }
    group.finish();
}

criterion_group!(benches, overhead);
criterion_main!(benches);
