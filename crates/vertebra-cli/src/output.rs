//! What `vertebra scene` prints: a one-line summary or JSON, for one run or
//! a run over seeds; and the per-frame CSV files of `reproduce`.

use std::fmt::Write as _;
use std::path::Path;

use serde_json::{Value, json};
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Quantity, SceneConfig, SceneRun, Seeded, Spread};
use vertebra_world::{JointSolver, PinContacts};

/// `rod` or `sockets`.
pub fn spine_name(spine: SpineMode) -> &'static str {
    match spine {
        SpineMode::Rod => "rod",
        SpineMode::Sockets => "sockets",
    }
}

/// `iterative` or `direct`, as `--joints` takes it.
pub fn joints_name(joints: JointSolver) -> &'static str {
    match joints {
        JointSolver::Iterative => "iterative",
        JointSolver::Direct => "direct",
    }
}

pub fn pins_name(pins: PinContacts) -> &'static str {
    match pins {
        PinContacts::Never => "never",
        PinContacts::Driven => "driven",
        PinContacts::Always => "always",
    }
}

pub fn io(e: impl std::fmt::Display) -> String {
    format!("cannot write the results: {e}")
}

/// The figures of one run, by name (`mean_eps_lin_cm`, ...), in order.
fn figures(run: &SceneRun) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    for q in Quantity::ALL {
        let s = run.stats(q);
        for (what, x) in [("mean", s.mean), ("max", s.max), ("final", s.last)] {
            out.push((format!("{what}_{}", q.key()), f64::from(x)));
        }
    }
    for (r, name) in run.recoveries().iter().zip(["chest", "head"]) {
        out.push((format!("peak_deviation_cm_{name}"), f64::from(r.peak_cm)));
        // Never back (within the window before the next hit): infinite,
        // `null` in JSON.
        let frames = r.frames.map_or(f64::INFINITY, |f| f as f64);
        out.push((format!("recovery_frames_{name}"), frames));
    }
    out.push(("ms_per_step".to_owned(), run.ms_per_step));
    out.push(("frame_ms".to_owned(), run.frame_ms));
    out
}

fn summary_json(run: &SceneRun) -> Value {
    Value::Object(
        figures(run)
            .into_iter()
            .map(|(k, x)| (k, json!(x)))
            .collect(),
    )
}

fn setting_json(config: &SceneConfig, run: &SceneRun) -> serde_json::Map<String, Value> {
    let Value::Object(map) = json!({
        "scene": config.scene.name(),
        "spine": spine_name(config.spine),
        "joints": joints_name(config.joints),
        "iterations": config.iterations,
        "substeps": config.substeps,
        "backend": run.backend.name(),
        "threads": config.threads,
        "sleep": config.sleep.is_some(),
        "relax_contacts": config.relax_contacts,
        "pin_contacts": pins_name(config.pin_contacts),
    }) else {
        unreachable!("a JSON object literal")
    };
    map
}

/// The `--json` record of one run.
pub fn run_json(config: &SceneConfig, run: &SceneRun) -> Value {
    let mut v = setting_json(config, run);
    v.insert("seed".to_owned(), json!(config.seed));
    v.insert(
        "frames".to_owned(),
        run.frames
            .iter()
            .map(|f| {
                Quantity::ALL
                    .iter()
                    .map(|q| (q.key().to_owned(), json!(q.of(f))))
                    .collect::<serde_json::Map<_, _>>()
            })
            .collect(),
    );
    v.insert("summary".to_owned(), summary_json(run));
    v.insert(
        "state_hash".to_owned(),
        json!(format!("{:016x}", run.state_hash)),
    );
    Value::Object(v)
}

/// The spread over seeds of every figure of [`figures`].
pub fn spreads(seeded: &Seeded) -> Vec<(String, Spread)> {
    let names: Vec<String> = seeded.runs[0..1]
        .iter()
        .flat_map(figures)
        .map(|(k, _)| k)
        .collect();
    names
        .into_iter()
        .enumerate()
        .map(|(i, name)| {
            let each = seeded.runs.iter().map(|r| figures(r)[i].1);
            (name, Spread::of(each))
        })
        .collect()
}

/// The `--json` record of a run over seeds: each seed's summary and state,
/// every figure's spread, and frame by frame the spread of each quantity.
pub fn seeded_json(config: &SceneConfig, seeded: &Seeded) -> Value {
    let mut v = setting_json(config, &seeded.runs[0]);
    let count = seeded.runs.len();
    v.insert(
        "seeds".to_owned(),
        json!({ "first": seeded.first, "count": count, "band": Spread::band_name(count) }),
    );
    v.insert(
        "runs".to_owned(),
        seeded
            .runs
            .iter()
            .zip(seeded.first..)
            .map(|(run, seed)| {
                json!({
                    "seed": seed,
                    "summary": summary_json(run),
                    "state_hash": format!("{:016x}", run.state_hash),
                })
            })
            .collect(),
    );
    v.insert(
        "spread".to_owned(),
        Value::Object(
            spreads(seeded)
                .into_iter()
                .map(|(k, s)| (k, json!(s)))
                .collect(),
        ),
    );
    let bands: Vec<(Quantity, Vec<Spread>)> =
        Quantity::ALL.iter().map(|&q| (q, seeded.band(q))).collect();
    let frames = bands[0].1.len();
    v.insert(
        "frames".to_owned(),
        (0..frames)
            .map(|k| {
                bands
                    .iter()
                    .map(|(q, b)| (q.key().to_owned(), json!(b[k])))
                    .collect::<serde_json::Map<_, _>>()
            })
            .collect(),
    );
    Value::Object(v)
}

/// The one-line summary of `vertebra scene`.
pub fn print_summary(config: &SceneConfig, run: &SceneRun) {
    let (lin, ang) = (run.stats(Quantity::EpsLin), run.stats(Quantity::EpsAng));
    println!(
        "{} ({}, {} joints): mean eps_lin {:.4} cm, max {:.4} cm; mean eps_ang {:.5} rad, max {:.5} rad; {:.3} ms/step ({:.3} ms the frame alone) on {}; state {:016x}",
        config.scene,
        spine_name(config.spine),
        joints_name(config.joints),
        lin.mean,
        lin.max,
        ang.mean,
        ang.max,
        run.ms_per_step,
        run.frame_ms,
        run.backend,
        run.state_hash
    );
    if !config.scene.is_paper() {
        let v = run.stats(Quantity::MaxViolation).max.to_degrees();
        let e = run.stats(Quantity::MaxAngularError).max.to_degrees();
        println!(
            "  largest limit violation of any joint: {v:.3} degrees; largest angular error (held rotations too): {e:.3} degrees"
        );
    }
    for (r, name) in run.recoveries().iter().zip(["chest", "head"]) {
        let back = r
            .frames
            .map_or("never".to_owned(), |f| format!("{f} frames"));
        println!(
            "  {name} hit at frame {}: peak deviation {:.2} cm, back within {}% in {back}",
            r.hit,
            r.peak_cm,
            vertebra_scenes::RECOVERED * 100.0
        );
    }
}

/// The summary of `vertebra scene --seeds K`: each figure's median and
/// band over the seeds.
pub fn print_seeded_summary(config: &SceneConfig, seeded: &Seeded) {
    let spreads = spreads(seeded);
    let band = spreads[0].1.range_name();
    println!(
        "{} ({}, {} joints), seeds {}..{}: median [{band}] over {} runs on {}",
        config.scene,
        spine_name(config.spine),
        joints_name(config.joints),
        seeded.first,
        seeded.first + seeded.runs.len() as u64 - 1,
        seeded.runs.len(),
        seeded.runs[0].backend
    );
    for (name, spread) in &spreads {
        println!("  {name:<20} {}", spread.display(4));
    }
}

/// Frame by frame, each quantity's median and band over the seeds, and the
/// first seed's own value.
pub fn write_csv(path: &Path, seeded: &Seeded) -> Result<(), String> {
    let bands: Vec<(Quantity, Vec<Spread>)> =
        Quantity::ALL.iter().map(|&q| (q, seeded.band(q))).collect();
    let mut csv = String::from("frame");
    for (q, _) in &bands {
        write!(csv, ",{q},{q}_median,{q}_low,{q}_high").ok();
    }
    csv.push('\n');
    for (k, first) in seeded.runs[0].frames.iter().enumerate() {
        write!(csv, "{k}").ok();
        for (q, band) in &bands {
            let (low, high) = band[k].range();
            write!(csv, ",{},{},{low},{high}", q.of(first), band[k].median).ok();
        }
        csv.push('\n');
    }
    std::fs::write(path, csv).map_err(io)
}
