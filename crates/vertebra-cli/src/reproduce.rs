//! `vertebra reproduce`: every scene both ways over seeded starts; a table
//! of each figure's median and spread, the rod's advantage with its spread,
//! CSV, plots, pictures, `summary.json`, and seed 0's run of each scene and
//! spine as an animated glTF file (`<scene>-<spine>.glb`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::{Value, json};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{
    Comparison, Quantity, Scene, SceneConfig, Seeded, Spread, compare, kinematics,
};
use vertebra_world::JointSolver;

use crate::gltf_out::write_run;
use crate::output::{io, joints_name, spine_name, spreads, write_csv};
use crate::plots::{font_options, picture, plot, plot_locus, to_png};
use crate::skeleton_csv::Failed;

/// Seeds `reproduce` runs each scene from unless told: enough for the 10th
/// and 90th percentiles, and the whole command in well under a minute on
/// two cores (`docs/reproduction.md`).
pub const DEFAULT_SEEDS: u64 = 16;

/// Where `reproduce` writes unless told: `out` for the paper's iterative
/// joints, `out-direct` for the direct solve, so that one run does not
/// overwrite the other.
pub fn default_out(joints: JointSolver) -> PathBuf {
    match joints {
        JointSolver::Iterative => PathBuf::from("out"),
        JointSolver::Direct => PathBuf::from("out-direct"),
    }
}

/// Runs every scene both ways from seeds `0 .. seeds`, the joints solved
/// by `joints`, and writes everything under `out`.
pub fn reproduce(out: &Path, seeds: u64, joints: JointSolver) -> Result<(), String> {
    // Everything the command is given, checked before anything is
    // written: a refused run leaves no output directory behind.
    for scene in Scene::PAPER {
        for spine in [SpineMode::Sockets, SpineMode::Rod] {
            let config = SceneConfig::new(scene, spine);
            Seeded::check(&config, seeds).map_err(|e| e.to_string())?;
        }
    }
    std::fs::create_dir_all(out).map_err(|e| io(format!("{}: {e}", out.display())))?;
    let fonts = font_options();
    let mut document = Vec::new();
    let mut table = format!("joints: {}\n\n", joints_name(joints));
    for scene in Scene::PAPER {
        let mut runs = Vec::new();
        for spine in [SpineMode::Sockets, SpineMode::Rod] {
            let mut config = SceneConfig::new(scene, spine);
            config.joints = joints;
            let label = format!("{scene} ({})", spine_name(spine));
            let bar = progress(label, seeds);
            // Figure 1's run beside the seeds' (one more run in the pool).
            let (seeded, figure) = rayon::join(
                || Seeded::run(&config, seeds, |done, _| bar.set_position(done as u64)),
                || (scene == Scene::RagdollDrop).then(|| figure_1(out, &config)),
            );
            let seeded = seeded.map_err(|e| e.to_string())?;
            figure.transpose()?;
            bar.finish();
            // Seed 0's run (the paper's start) to look at in any glTF viewer.
            write_run(
                &config,
                &out.join(format!("{scene}-{}.glb", spine_name(spine))),
            )?;
            write_csv(
                &out.join(format!("{scene}-{}.csv", spine_name(spine))),
                &seeded,
            )?;
            runs.push((spine, seeded));
        }
        write_table(&mut table, scene, &runs);
        document.push(scene_json(scene, &runs));
        let (chart, poses) = (
            out.join(format!("{scene}.svg")),
            out.join(format!("{scene}-poses.svg")),
        );
        plot(&chart, scene, &runs)?;
        picture(&poses, scene, &runs)?;
        to_png(&chart, &fonts)?;
        to_png(&poses, &fonts)?;
    }
    let locus = kinematics(0.45, 60f32.to_radians(), 61);
    plot_locus(&out.join("kinematics.svg"), &locus)?;
    to_png(&out.join("kinematics.svg"), &fonts)?;
    let mut csv = String::from("chain,largest_gap_m\n");
    for (name, _, gap) in &locus.chains {
        writeln!(csv, "{name},{gap}").ok();
    }
    std::fs::write(out.join("kinematics.csv"), csv).map_err(io)?;
    let document = json!({
        "joints": joints_name(joints),
        "seeds": { "first": 0, "count": seeds, "band": Spread::band_name(seeds as usize) },
        "scenes": document,
        "kinematics": locus.chains.iter().map(|(n, _, g)| json!({"chain": n, "largest_gap_m": g})).collect::<Vec<_>>(),
    });
    std::fs::write(
        out.join("summary.json"),
        serde_json::to_string_pretty(&document).map_err(io)?,
    )
    .map_err(io)?;
    print!("{table}");
    for (name, _, gap) in &locus.chains {
        println!(
            "kinematics: {name:<20} largest gap to the rod's end {:.2} mm",
            gap * 1e3
        );
    }
    println!("results in {}", out.display());
    Ok(())
}

/// Figure 1: `config`'s pile at rest (seed 0's last frame), rendered to
/// `figure1-SPINE.png` in `out`.
fn figure_1(out: &Path, config: &SceneConfig) -> Result<(), String> {
    let frames = config.frames.unwrap_or(config.scene.default_frames());
    let mut image = None;
    let first = SceneConfig {
        seed: 0,
        ..config.clone()
    };
    vertebra_scenes::run_observed(
        &first,
        |_, _| {},
        |frame, scene| {
            if frame + 1 == frames {
                image = Some(crate::render::figure_1(scene).map_err(Failed)?);
            }
            Ok(())
        },
    )
    .map_err(|Failed(e)| e)?;
    let path = out.join(format!("figure1-{}.png", spine_name(config.spine)));
    image.ok_or("no frame to draw")?.save_png(&path)
}

/// One scene's block of the table: each figure's median \[band\] per spine,
/// then the rod against the sockets seed by seed.
fn write_table(table: &mut String, scene: Scene, runs: &[(SpineMode, Seeded)]) {
    let seeds = runs[0].1.runs.len();
    let band = Spread::band_name(seeds);
    writeln!(
        table,
        "{scene}: median [{band}] over {seeds} seeds\n{:<22} {:>28} {:>28}",
        "",
        spine_name(runs[0].0),
        spine_name(runs[1].0)
    )
    .ok();
    let (sockets, rod) = (spreads(&runs[0].1), spreads(&runs[1].1));
    let shown = |name: &str| {
        Quantity::compared(scene)
            .iter()
            .chain(&[Quantity::EpsLin, Quantity::EpsAng])
            .any(|q| name.ends_with(q.key()))
            || name == "ms_per_step"
            || name == "frame_ms"
    };
    for ((name, s), (_, r)) in sockets.iter().zip(&rod).filter(|(s, _)| shown(&s.0)) {
        writeln!(
            table,
            "{name:<22} {:>28} {:>28}",
            s.display(4),
            r.display(4)
        )
        .ok();
    }
    for quantity in Quantity::compared(scene) {
        let (ratio, lower) = compare(&runs[0].1, &runs[1].1, quantity);
        writeln!(
            table,
            "rod vs sockets, {quantity}: {} times lower, lower in {} of the frames",
            ratio.display(2),
            percent(&lower)
        )
        .ok();
    }
    table.push('\n');
}

/// A spread of fractions as percentages: `74% [60%, 85%]`.
fn percent(s: &Spread) -> String {
    let (low, high) = s.range();
    format!(
        "{:.0}% [{:.0}%, {:.0}%]",
        s.median * 100.0,
        low * 100.0,
        high * 100.0
    )
}

fn scene_json(scene: Scene, runs: &[(SpineMode, Seeded)]) -> Value {
    let spines: Vec<Value> = runs
        .iter()
        .map(|(spine, seeded)| {
            json!({
                "spine": spine_name(*spine),
                "state_hashes": seeded.runs.iter().map(|r| format!("{:016x}", r.state_hash)).collect::<Vec<_>>(),
                "spread": spreads(seeded).into_iter().map(|(k, s)| (k, json!(s))).collect::<serde_json::Map<_, _>>(),
            })
        })
        .collect();
    let comparison: serde_json::Map<String, Value> = Quantity::compared(scene)
        .into_iter()
        .map(|q| {
            let (ratio, lower) = compare(&runs[0].1, &runs[1].1, q);
            let per_seed: Vec<Value> = runs[0]
                .1
                .runs
                .iter()
                .zip(&runs[1].1.runs)
                .map(|(sockets, rod)| {
                    let c = Comparison::of(sockets, rod, q);
                    json!({ "sockets_over_rod": c.ratio, "fraction_of_frames_rod_lower": c.lower })
                })
                .collect();
            (
                q.key().to_owned(),
                json!({
                    "sockets_over_rod": ratio,
                    "fraction_of_frames_rod_lower": lower,
                    "per_seed": per_seed,
                }),
            )
        })
        .collect();
    json!({ "scene": scene.name(), "spines": spines, "rod_vs_sockets": comparison })
}

/// A scene's progress over its seeds, on stderr: drawn only when stderr is
/// a terminal (indicatif hides it otherwise), so a log file gets no
/// carriage returns.
fn progress(label: String, seeds: u64) -> ProgressBar {
    let style = ProgressStyle::with_template("{prefix:<28} [{bar:30}] {pos}/{len} seeds")
        .expect("a valid template")
        .progress_chars("#>.");
    let bar = ProgressBar::new(seeds).with_style(style).with_prefix(label);
    bar.tick();
    bar
}
