//! vertebra against rapier3d, side by side in one process, on the
//! reference humanoid: the passive-bending and ragdoll-drop scenes.
//!
//! First a table of whole runs (every frame of each scene, from ten seeded
//! starts): mean wall time per step and mean residual joint error per
//! frame, each as its median and spread over the seeds, rapier's measured
//! by our own metric on its body poses; vertebra with both joint solves
//! (`--joints iterative` and `direct`, and the world's default: direct at
//! 1x8 with relaxed contacts). Then, per scene, the error against
//! the cost at more settings (vertebra both ways at the substep x
//! iteration splits of [`SWEEP`], from [`SWEEP_SEEDS`] starts; the
//! default and rapier's rows of the table), written as a plot and CSV to
//! `target/figures/peer/error_vs_cost_<scene>.{svg,csv}` ([`peer_plot`]).
//! Then criterion's time per frame of the 30-ragdoll drop, one second in,
//! for each engine and setting.
//! `cargo bench -p vertebra-benches --bench peer`

mod peer_plot;

use std::hint::black_box;

use criterion::Criterion;
use vertebra_peer::{RapierScene, RapierSettings};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Frame, Scene, SceneConfig, Spread, build, run};
use vertebra_world::{JointSolver, SolverConfig};

use peer_plot::{Point, Series};

const DT: f32 = 1.0 / 60.0;

/// Seeded starts each whole run is repeated from (`vertebra_scenes::seed`):
/// ten, so that the 10th and 90th percentiles are samples, not guesses.
const SEEDS: u64 = 10;

/// The joint solves, by their `--joints` names.
const JOINTS: [(&str, JointSolver); 2] = [
    ("iterative", JointSolver::Iterative),
    ("direct", JointSolver::Direct),
];

/// A joint solve's `--joints` name.
fn name_of(joints: JointSolver) -> &'static str {
    JOINTS
        .iter()
        .find(|(_, j)| *j == joints)
        .map_or("?", |(name, _)| name)
}

/// The spines, by their names in the table.
const SPINES: [(&str, SpineMode); 2] = [("rod", SpineMode::Rod), ("socket", SpineMode::Sockets)];

/// The table's rows per joint solve (substeps x iterations): iterated, 20
/// iterations a frame in one substep (the paper's setting) and as 5
/// substeps of 4; solved directly, at the paper's setting and at the
/// fewer iterations it needs (1x4, 1x8: `docs/direct.md`).
const TABLE: [(JointSolver, &[(u32, u32)]); 2] = [
    (JointSolver::Iterative, &[(1, 20), (5, 4)]),
    (JointSolver::Direct, &[(1, 20), (1, 8), (1, 4)]),
];

/// The plot's splits (substeps x iterations): the paper's 1x20, fewer
/// iterations (1x10, 1x8, 1x4), the same 20 sweeps in more substeps (2x5...
/// 4x5), and many substeps of few iterations (10x2).
const SWEEP: [(u32, u32); 7] = [(1, 20), (1, 10), (1, 8), (1, 4), (2, 5), (4, 5), (10, 2)];

/// Seeded starts per point of the plot: three (the median of three), to
/// keep the sweep's 28 settings per scene to about two minutes.
const SWEEP_SEEDS: u64 = 3;

/// Per seed: ms per step, mean eps_lin (cm), mean eps_ang (rad).
type Figures = Vec<(f64, f32, f32)>;

/// Each figure's spread over the seeds: time, eps_lin, eps_ang.
fn spreads(figures: &Figures) -> [Spread; 3] {
    [0, 1, 2].map(|k| {
        Spread::of(
            figures
                .iter()
                .map(|f| [f.0, f64::from(f.1), f64::from(f.2)][k]),
        )
    })
}

fn row(engine: &str, figures: &Figures) {
    let [time, lin, ang] = spreads(figures);
    println!(
        "| {engine} | {:.3} | {} | {} |",
        time.median,
        lin.display(4),
        ang.display(5)
    );
}

/// The plot's point of `series` at `split`: each figure's median.
fn point(series: Series, split: String, figures: &Figures) -> Point {
    let [time, lin, ang] = spreads(figures);
    Point {
        series,
        split,
        seeds: figures.len() as u64,
        ms_per_step: time.median,
        eps_lin_cm: lin.median,
        eps_ang_rad: ang.median,
    }
}

fn figures(ms: f64, frames: &[Frame]) -> (f64, f32, f32) {
    let n = frames.len().max(1) as f32;
    let lin = frames.iter().map(|f| f.eps_lin_cm).sum::<f32>() / n;
    let ang = frames.iter().map(|f| f.eps_ang_rad).sum::<f32>() / n;
    (ms, lin, ang)
}

/// Our whole runs of `scene` from seeds `0 .. seeds`, one at a time (so
/// that the times are one run's), the contacts as the paper's.
fn ours(
    scene: Scene,
    spine: SpineMode,
    joints: JointSolver,
    split: (u32, u32),
    seeds: u64,
) -> Figures {
    let solver = SolverConfig {
        joints,
        substeps: split.0,
        iterations: split.1,
        ..SolverConfig::paper()
    };
    ours_with(scene, spine, &solver, seeds)
}

/// [`ours`] with `solver`'s joints, split and contacts.
fn ours_with(scene: Scene, spine: SpineMode, solver: &SolverConfig, seeds: u64) -> Figures {
    (0..seeds)
        .map(|seed| {
            let mut config = SceneConfig::new(scene, spine);
            (config.substeps, config.iterations) = (solver.substeps, solver.iterations);
            config.joints = solver.joints;
            config.relax_contacts = solver.relax_contacts;
            config.seed = seed;
            let run = run(&config, |_, _| {}).expect("our scene");
            // The frame alone, as rapier's time is its step alone.
            figures(run.frame_ms, &run.frames)
        })
        .collect()
}

/// Whole runs of both scenes from seeds 0 .. SEEDS: time per step and
/// residual error, each as the median [10th, 90th percentile] over the
/// seeds; then each scene's error-versus-cost plot.
fn whole_runs() {
    for scene in [Scene::PassiveBending, Scene::RagdollDrop] {
        println!(
            "\n{scene}, {} frames, median [p10, p90] over seeds 0..{}:\n",
            scene.default_frames(),
            SEEDS - 1
        );
        println!("| engine | ms per step (median) | mean eps_lin (cm) | mean eps_ang (rad) |");
        println!("| --- | ---: | ---: | ---: |");
        for (joints, splits) in TABLE {
            let joints_name = name_of(joints);
            for &split @ (substeps, iterations) in splits {
                for (name, spine) in SPINES {
                    row(
                        &format!("vertebra {substeps}x{iterations} {joints_name}, {name} spine"),
                        &ours(scene, spine, joints, split, SEEDS),
                    );
                }
            }
        }
        let mut points = Vec::new();
        let default = SolverConfig::default();
        for (name, spine) in SPINES {
            let runs = ours_with(scene, spine, &default, SEEDS);
            let split = format!("{}x{}", default.substeps, default.iterations);
            row(
                &format!("vertebra {split} direct, relaxed contacts (the default), {name} spine"),
                &runs,
            );
            points.push(point(Series::Default(spine), split, &runs));
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
            let split = format!("{}x{}", settings.solver_iterations, settings.pgs_iterations);
            points.push(point(Series::Rapier, split, &peer));
        }
        for (_, joints) in JOINTS {
            for (_, spine) in SPINES {
                for split @ (substeps, iterations) in SWEEP {
                    let runs = ours(scene, spine, joints, split, SWEEP_SEEDS);
                    let name = format!("{substeps}x{iterations}");
                    points.push(point(Series::Vertebra(joints, spine), name, &runs));
                }
            }
        }
        let path = peer_plot::write(scene, &points).expect("the plot is written");
        println!(
            "\nerror against cost ({} settings, vertebra's the median over seeds 0..{}): {}",
            points.len(),
            SWEEP_SEEDS - 1,
            path.display()
        );
    }
}

/// The split each joint solve is timed at by criterion: iterated at the
/// paper's 1x20, solved directly at 1x4 (where it meets the direct
/// solve's error targets: `docs/performance.md`).
fn timed_split(joints: JointSolver) -> (u32, u32) {
    match joints {
        JointSolver::Iterative => (1, 20),
        JointSolver::Direct => (1, 4),
    }
}

/// The 30-ragdoll drop one second in (piled in the pit).
fn drop_after_one_second(spine: SpineMode, joints: JointSolver) -> vertebra_scenes::SceneWorld {
    let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
    config.joints = joints;
    (config.substeps, config.iterations) = timed_split(joints);
    let mut scene = build(&config).expect("the drop scene");
    for frame in 0..60 {
        scene.advance(config.scene, frame, DT).expect("a frame");
    }
    scene
}

fn frame_times(c: &mut Criterion) {
    let mut group = c.benchmark_group("peer_drop_30");
    group.sample_size(30);
    for (joints_name, joints) in JOINTS {
        for (name, spine) in [("rod", SpineMode::Rod), ("sockets", SpineMode::Sockets)] {
            let mut scene = drop_after_one_second(spine, joints);
            // The iterative benches keep their names from before the
            // direct solve, so that criterion compares them with older runs.
            let bench = match joints {
                JointSolver::Iterative => format!("vertebra_{name}"),
                JointSolver::Direct => format!("vertebra_{name}_{joints_name}_1x4"),
            };
            group.bench_function(bench, |b| {
                b.iter(|| {
                    scene.advance(Scene::RagdollDrop, 60, DT).expect("a frame");
                    black_box(scene.world.residuals().map(|r| r.eps_lin_cm))
                })
            });
        }
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
