//! `vertebra scene stagger`: the sweep of chest hits on the powered
//! standing and walking ragdoll over seeds, printed as a table (one row
//! per hit, then the walk's tracking and the largest impulse survived from
//! each side) or as one JSON object.

use std::fmt::Write as _;
use std::time::Instant;

use serde_json::{Value, json};
use vertebra_ragdoll::RagdollDesc;
use vertebra_scenes::{
    Activity, STAGGER_IMPULSES, SceneConfig, Side, StaggerHit, StaggerSweep, stagger_profile,
};

use crate::output::{joints_name, pins_name, spine_name};

/// Seeds the sweep runs from unless told.
pub const DEFAULT_SEEDS: u64 = 5;

/// Runs the sweep of `config` from seeds `config.seed ..` (`count` of
/// them) and prints it.
pub fn sweep(config: &SceneConfig, count: u64, json: bool) -> Result<(), String> {
    let end = (config.seed)
        .checked_add(count)
        .ok_or("--seed plus --seeds must stay below 2^64")?;
    let desc = config
        .ragdoll
        .clone()
        .unwrap_or_else(RagdollDesc::anatomical_humanoid);
    let animation = stagger_profile(&desc).map_err(|e| e.to_string())?;
    let started = Instant::now();
    let sweep = StaggerSweep::run(config, &animation, config.seed..end, &STAGGER_IMPULSES)
        .map_err(|e| e.to_string())?;
    let seconds = started.elapsed().as_secs_f64();
    let backend = config.backend.resolve().map_err(|e| e.to_string())?;
    if json {
        println!("{}", sweep_json(config, &sweep, backend.name(), seconds));
    } else {
        print!("{}", table(config, &sweep, backend.name(), seconds));
    }
    Ok(())
}

/// `recovered` in seconds, or `never`.
fn recovery(r: Option<f32>) -> String {
    r.map_or("never".to_owned(), |t| format!("{t:.2}"))
}

fn table(config: &SceneConfig, sweep: &StaggerSweep, backend: &str, seconds: f64) -> String {
    let seeds = sweep.walks.iter().map(|w| w.seed);
    let (first, last) = (seeds.clone().min().unwrap_or(0), seeds.max().unwrap_or(0));
    let mut out = String::new();
    writeln!(
        out,
        "stagger ({}, {} joints), seeds {first}..{last}: {} hits on the chest in {seconds:.1} s on {backend}",
        spine_name(config.spine),
        joints_name(config.joints),
        sweep.hits.len(),
    )
    .ok();
    writeln!(
        out,
        "up: the hips stay above {:.3} m ({}% of standing); peak: the hips' largest distance from the animation's; recovered: back within 2 cm (standing) or 5 cm (walking) for good",
        vertebra_scenes::UPRIGHT_FRACTION * sweep.standing_height,
        (vertebra_scenes::UPRIGHT_FRACTION * 100.0).round(),
    )
    .ok();
    writeln!(
        out,
        "{:<9} {:<6} {:>7} {:>5} {:>3} {:>13} {:>7} {:>11}",
        "activity", "from", "N s", "seed", "up", "lowest hips m", "peak m", "recovered s"
    )
    .ok();
    for h in &sweep.hits {
        writeln!(
            out,
            "{:<9} {:<6} {:>7} {:>5} {:>3} {:>13.3} {:>7.3} {:>11}",
            h.activity.name(),
            h.side.name(),
            h.size,
            h.seed,
            if h.stays_up { "yes" } else { "no" },
            h.lowest,
            h.peak,
            recovery(h.recovered)
        )
        .ok();
    }
    let (max, rms) = sweep.tracking();
    writeln!(
        out,
        "walking without hits, after the ramp: hips within {:.2} cm of the animation's (rms {:.2} cm; the worst seed's)",
        max * 100.0,
        rms * 100.0
    )
    .ok();
    writeln!(
        out,
        "largest impulse every seed survived from each side (and the slowest recovery up to it):"
    )
    .ok();
    for activity in Activity::ALL {
        let sides: Vec<String> = Side::ALL
            .iter()
            .map(|&side| match sweep.largest_survived(activity, side) {
                Some(size) => format!(
                    "{} {size} N s ({} s)",
                    side.name(),
                    recovery(sweep.slowest_recovery(activity, side, size))
                ),
                None => format!("{} none", side.name()),
            })
            .collect();
        writeln!(out, "  {:<9} {}", activity.name(), sides.join(", ")).ok();
    }
    out
}

fn hit_json(h: &StaggerHit) -> Value {
    json!({
        "activity": h.activity.name(),
        "from": h.side.name(),
        "impulse_ns": h.size,
        "seed": h.seed,
        "stays_up": h.stays_up,
        "lowest_hips_m": h.lowest,
        "peak_m": h.peak,
        "recovered_s": h.recovered,
    })
}

fn sweep_json(config: &SceneConfig, sweep: &StaggerSweep, backend: &str, seconds: f64) -> Value {
    let (max, rms) = sweep.tracking();
    let mut largest = serde_json::Map::new();
    for activity in Activity::ALL {
        let sides = Side::ALL.iter().map(|&side| {
            let size = sweep.largest_survived(activity, side);
            let slowest = size.and_then(|s| sweep.slowest_recovery(activity, side, s));
            (
                side.name().to_owned(),
                json!({ "impulse_ns": size, "slowest_recovery_s": slowest }),
            )
        });
        largest.insert(activity.name().to_owned(), Value::Object(sides.collect()));
    }
    json!({
        "scene": config.scene.name(),
        "spine": spine_name(config.spine),
        "joints": joints_name(config.joints),
        "iterations": config.iterations,
        "substeps": config.substeps,
        "backend": backend,
        "threads": config.threads,
        "sleep": config.sleep.is_some(),
        "relax_contacts": config.relax_contacts,
        "pin_contacts": pins_name(config.pin_contacts),
        "seconds": seconds,
        "standing_hips_m": sweep.standing_height,
        "hits": sweep.hits.iter().map(hit_json).collect::<Vec<_>>(),
        "walks": sweep.walks.iter().map(|w| json!({ "seed": w.seed, "max_m": w.max, "rms_m": w.rms })).collect::<Vec<_>>(),
        "tracking": { "max_m": max, "rms_m": rms },
        "largest_survived": largest,
    })
}
