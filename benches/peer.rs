//! vertebra against rapier3d, side by side in one process, on the
//! reference humanoid: the passive-bending and ragdoll-drop scenes.
//!
//! First a table of whole runs (every frame of each scene, from ten seeded
//! starts): mean wall time per step and mean residual joint error per
//! frame, each as its median and spread over the seeds, rapier's measured
//! by our own metric on its body poses. Then criterion's time per frame of the
//! 30-ragdoll drop, one second in, for each engine and setting.
//! `cargo bench -p vertebra-benches --bench peer`

use std::hint::black_box;

use criterion::Criterion;
use vertebra_peer::{RapierScene, RapierSettings};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Frame, Scene, SceneConfig, Spread, build, run};

const DT: f32 = 1.0 / 60.0;

/// Seeded starts each whole run is repeated from (`vertebra_scenes::seed`):
/// ten, so that the 10th and 90th percentiles are samples, not guesses.
const SEEDS: u64 = 10;

/// Per seed: ms per step, mean eps_lin (cm), mean eps_ang (rad).
type Figures = Vec<(f64, f32, f32)>;

fn row(engine: &str, figures: &Figures) {
    let spread = |k: usize| {
        Spread::of(
            figures
                .iter()
                .map(|f| [f.0, f64::from(f.1), f64::from(f.2)][k]),
        )
    };
    println!(
        "| {engine} | {:.3} | {} | {} |",
        spread(0).median,
        spread(1).display(4),
        spread(2).display(5)
    );
}

fn figures(ms: f64, frames: &[Frame]) -> (f64, f32, f32) {
    let n = frames.len().max(1) as f32;
    let lin = frames.iter().map(|f| f.eps_lin_cm).sum::<f32>() / n;
    let ang = frames.iter().map(|f| f.eps_ang_rad).sum::<f32>() / n;
    (ms, lin, ang)
}

/// Whole runs of both scenes from seeds 0 .. SEEDS, one at a time (so that
/// the times are one run's): time per step and residual error, each as
/// the median [10th, 90th percentile] over the seeds.
fn whole_runs() {
    for scene in [Scene::PassiveBending, Scene::RagdollDrop] {
        println!(
            "\n{scene}, {} frames, median [p10, p90] over seeds 0..{}:\n",
            scene.default_frames(),
            SEEDS - 1
        );
        println!("| engine | ms per step (median) | mean eps_lin (cm) | mean eps_ang (rad) |");
        println!("| --- | ---: | ---: | ---: |");
        // 20 iterations a frame: in one substep (the paper's setting) and
        // as 5 substeps of 4.
        for (substeps, iterations) in [(1, 20), (5, 4)] {
            for (name, spine) in [("rod", SpineMode::Rod), ("socket", SpineMode::Sockets)] {
                let ours: Figures = (0..SEEDS)
                    .map(|seed| {
                        let mut config = SceneConfig::new(scene, spine);
                        (config.substeps, config.iterations) = (substeps, iterations);
                        config.seed = seed;
                        let run = run(&config, |_, _| {}).expect("our scene");
                        figures(run.ms_per_step, &run.frames)
                    })
                    .collect();
                row(
                    &format!("vertebra {substeps}x{iterations}, {name} spine"),
                    &ours,
                );
            }
        }
        for settings in RapierSettings::COMPARED {
            let peer: Figures = (0..SEEDS)
                .map(|seed| {
                    let mut config = SceneConfig::new(scene, SpineMode::Sockets);
                    config.seed = seed;
                    let run = vertebra_peer::run(&config, settings).expect("the rapier scene");
                    figures(run.ms_per_step, &run.frames)
                })
                .collect();
            row(&format!("{settings}, socket spine"), &peer);
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
                black_box(scene.world.residuals().map(|r| r.eps_lin_cm))
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
