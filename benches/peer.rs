//! vertebra against rapier3d, side by side in one process, on the
//! reference humanoid: the passive-bending and ragdoll-drop scenes.
//!
//! First a table of whole runs (every frame of each scene): mean wall time
//! per step and mean residual joint error per frame, rapier's measured by
//! our own metric on its body poses. Then criterion's time per frame of the
//! 30-ragdoll drop, one second in, for each engine and setting.
//! `cargo bench -p vertebra-benches --bench peer`

use std::hint::black_box;

use criterion::Criterion;
use vertebra_peer::{RapierScene, RapierSettings};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Frame, Scene, SceneConfig, build, run};

const DT: f32 = 1.0 / 60.0;

fn means(frames: &[Frame]) -> (f32, f32) {
    let n = frames.len().max(1) as f32;
    let lin = frames.iter().map(|f| f.eps_lin_cm).sum::<f32>() / n;
    let ang = frames.iter().map(|f| f.eps_ang_rad).sum::<f32>() / n;
    (lin, ang)
}

fn row(engine: &str, ms: f64, frames: &[Frame]) {
    let (lin, ang) = means(frames);
    println!("| {engine} | {ms:.3} | {lin:.4} | {ang:.5} |");
}

/// Whole runs of both scenes: time per step and residual error.
fn whole_runs() {
    for scene in [Scene::PassiveBending, Scene::RagdollDrop] {
        println!("\n{scene}, {} frames:\n", scene.default_frames());
        println!("| engine | ms per step | mean eps_lin (cm) | mean eps_ang (rad) |");
        println!("| --- | ---: | ---: | ---: |");
        // 20 iterations a frame: in one substep (the paper's setting) and
        // as 5 substeps of 4.
        for (substeps, iterations) in [(1, 20), (5, 4)] {
            for (name, spine) in [("rod", SpineMode::Rod), ("socket", SpineMode::Sockets)] {
                let mut config = SceneConfig::new(scene, spine);
                (config.substeps, config.iterations) = (substeps, iterations);
                let ours = run(&config, |_, _| {}).expect("our scene");
                let engine = format!("vertebra {substeps}x{iterations}, {name} spine");
                row(&engine, ours.ms_per_step, &ours.frames);
            }
        }
        for settings in RapierSettings::COMPARED {
            let config = SceneConfig::new(scene, SpineMode::Sockets);
            let peer = vertebra_peer::run(&config, settings).expect("the rapier scene");
            row(
                &format!("{settings}, socket spine"),
                peer.ms_per_step,
                &peer.frames,
            );
        }
    }
}

/// The 30-ragdoll drop one second in (piled in the pit).
fn drop_after_one_second(spine: SpineMode) -> vertebra_scenes::SceneWorld {
    let config = SceneConfig::new(Scene::RagdollDrop, spine);
    let mut scene = build(&config).expect("the drop scene");
    for frame in 0..60 {
        scene.advance(config.scene, frame, DT).expect("a frame");
    }
    scene
}

fn frame_times(c: &mut Criterion) {
    let mut group = c.benchmark_group("peer_drop_30");
    group.sample_size(30);
    for (name, spine) in [
        ("vertebra_rod", SpineMode::Rod),
        ("vertebra_sockets", SpineMode::Sockets),
    ] {
        let mut scene = drop_after_one_second(spine);
        group.bench_function(name, |b| {
            b.iter(|| {
                scene.advance(Scene::RagdollDrop, 60, DT).expect("a frame");
                black_box(scene.world.residuals().eps_lin_cm)
            })
        });
    }
    for settings in RapierSettings::COMPARED {
        let mut scene = build(&SceneConfig::new(Scene::RagdollDrop, SpineMode::Sockets))
            .expect("the drop scene");
        let mut rapier = RapierScene::from_scene(&scene, settings, DT).expect("translated");
        for _ in 0..60 {
            rapier.step();
        }
        let name = format!(
            "rapier_{}x{}",
            settings.solver_iterations, settings.pgs_iterations
        );
        group.bench_function(name, |b| b.iter(|| rapier.step()));
        rapier.mirror(&mut scene.world).expect("mirrored");
        black_box(scene.measure(&scene.world));
    }
    group.finish();
}

fn main() {
    whole_runs();
    let mut criterion = Criterion::default().configure_from_args();
    frame_times(&mut criterion);
    criterion.final_summary();
}
