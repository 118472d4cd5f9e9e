//! How the solver's stages would scale to 16 cores, simulated from stage
//! times measured on this machine (docs/threads.md): the drop scene's
//! steps are run with the chunks a P-worker launch makes, every chunk on
//! one thread and timed; then P workers claiming those chunks in order
//! (each the next chunk when it is free) are simulated stage by stage,
//! plus a cost per stage for waiting on the others. That cost is fitted
//! from a real 2-thread run of the same frames; at more workers it is
//! taken as the same (optimistic) or growing with P/2 (pessimistic).
//! `cargo bench -p vertebra-benches --bench stages --features stage-timing`

use std::hint::black_box;
use std::sync::Arc;
use std::time::{Duration, Instant};

use vertebra_benches::{DT, drop_scene};
use vertebra_ragdoll::SpineMode;
use vertebra_world::TaskSystem;
use vertebra_world::stage_timing::{self, Launch};

/// Frames stepped per measurement (from one second in).
const FRAMES: usize = 20;

/// Runs per measurement: each chunk's time (and the step's) is the least
/// of them, so that a run preempted by another process does not count.
const RUNS: usize = 5;

/// Workers simulated.
const WORKERS: [usize; 6] = [1, 2, 4, 8, 12, 16];

/// A task system that claims `0` workers but runs no item: the caller
/// runs every chunk of the `0`-worker split, one after another.
struct Recorder(usize);

impl TaskSystem for Recorder {
    fn workers(&self) -> usize {
        self.0
    }
    fn parallel_for(&self, _: usize, _: &(dyn Fn(usize) + Sync)) {}
}

/// Time of `FRAMES` steps of the drop on `tasks` (or `threads` rayon
/// workers), and the stages recorded on the way: the least of `RUNS`
/// runs, chunk by chunk (the runs are the same work, bit for bit).
fn run(
    spine: SpineMode,
    count: usize,
    threads: usize,
    tasks: Option<Arc<dyn TaskSystem>>,
) -> (Duration, Vec<Launch>) {
    let mut best: Option<(Duration, Vec<Launch>)> = None;
    for _ in 0..RUNS {
        let (total, launches) = run_once(spine, count, threads, tasks.clone());
        best = Some(match best {
            None => (total, launches),
            Some((least, mut kept)) => {
                let chunks = kept.iter_mut().flatten().flatten();
                for (k, d) in chunks.zip(launches.iter().flatten().flatten()) {
                    *k = (*k).min(*d);
                }
                (least.min(total), kept)
            }
        });
    }
    best.unwrap_or_default()
}

fn run_once(
    spine: SpineMode,
    count: usize,
    threads: usize,
    tasks: Option<Arc<dyn TaskSystem>>,
) -> (Duration, Vec<Launch>) {
    let mut scene = drop_scene(spine, count, threads);
    if let Some(tasks) = tasks {
        scene.world.set_tasks(tasks);
    }
    let mut total = Duration::ZERO;
    stage_timing::start();
    for _ in 0..FRAMES {
        scene.detect(DT).expect("contacts");
        let start = Instant::now();
        scene.world.step(DT).expect("a step");
        total += start.elapsed();
        black_box(scene.world.state_hash());
    }
    (total, stage_timing::stop())
}

/// What timing a chunk costs (two clock reads), taken off each chunk.
fn timer_cost() -> Duration {
    let n = 100_000;
    let start = Instant::now();
    for _ in 0..n {
        black_box(Instant::now().elapsed());
    }
    start.elapsed() / n
}

/// When the last of `p` workers finishes `chunks`, each worker taking the
/// next chunk as soon as it is free.
fn makespan(chunks: &[Duration], p: usize, timer: Duration) -> Duration {
    let mut free = vec![Duration::ZERO; p];
    for &d in chunks {
        let worker = (0..p).min_by_key(|&w| free[w]).unwrap_or(0);
        free[worker] += d.saturating_sub(timer);
    }
    free.into_iter().max().unwrap_or_default()
}

/// The stages' time on `p` workers, with `sync` per stage when p > 1.
fn stage_time(launches: &[Launch], p: usize, timer: Duration, sync: Duration) -> Duration {
    let stages = launches.iter().flatten();
    let wait = if p > 1 { sync } else { Duration::ZERO };
    stages.map(|chunks| makespan(chunks, p, timer) + wait).sum()
}

fn work(launches: &[Launch], timer: Duration) -> Duration {
    let chunks = launches.iter().flatten().flatten();
    chunks.map(|d| d.saturating_sub(timer)).sum()
}

/// A run's work outside its stages: what a P-worker launch leaves on the
/// calling thread (with more than one worker the step's start of a world
/// with many contacts is a stage: docs/threads.md, "The step's start").
fn outside(total: Duration, launches: &[Launch], timer: Duration) -> Duration {
    total.saturating_sub(work(launches, timer))
}

fn ms(total: Duration) -> f64 {
    total.as_secs_f64() * 1e3 / FRAMES as f64
}

fn main() {
    let timer = timer_cost();
    println!("timer cost per chunk: {} ns", timer.as_nanos());
    for (name, spine) in [
        ("simplified", SpineMode::Rod),
        ("standard", SpineMode::Sockets),
    ] {
        for count in [30, 300] {
            scene(name, spine, count, timer);
        }
    }
}

fn scene(name: &str, spine: SpineMode, count: usize, timer: Duration) {
    let (one, recorded) = run(spine, count, 1, Some(Arc::new(Recorder(1))));
    let serial = outside(one, &recorded, timer);
    let stages: usize = recorded.iter().map(Vec::len).sum();
    let (two, _) = run(spine, count, 2, None);
    let (total, split) = run(spine, count, 1, Some(Arc::new(Recorder(2))));
    let ideal = outside(total, &split, timer) + stage_time(&split, 2, timer, Duration::ZERO);
    // The waits of a 2-worker launch are its own stages' (islands apart
    // are one stage of bins there, one stage per colour with 1 worker).
    let stages_at_2: usize = split.iter().map(Vec::len).sum();
    let sync = two.saturating_sub(ideal) / stages_at_2.max(1) as u32;
    println!(
        "\n{name} {count}: {:.3} ms/step on 1 thread ({:.3} ms outside the stages, {} stages/step; \
         {} at 2 workers), {:.3} ms on 2 rayon threads: {:.2} us per stage fitted",
        ms(one),
        ms(serial),
        stages / FRAMES,
        stages_at_2 / FRAMES,
        ms(two),
        sync.as_secs_f64() * 1e6,
    );
    println!("| workers | no wait | speed-up | wait as at 2 | speed-up | wait x P/2 | speed-up |");
    let base = ms(serial + stage_time(&recorded, 1, timer, Duration::ZERO));
    for p in WORKERS {
        let (total, split) = run(spine, count, 1, Some(Arc::new(Recorder(p))));
        let serial = outside(total, &split, timer);
        let at = |sync: Duration| ms(serial + stage_time(&split, p, timer, sync));
        let (free, flat, growing) = (
            at(Duration::ZERO),
            at(sync),
            at(sync * (p as u32).max(2) / 2),
        );
        println!(
            "| {p} | {free:.3} ms | {:.2}x | {flat:.3} ms | {:.2}x | {growing:.3} ms | {:.2}x |",
            base / free,
            base / flat,
            base / growing
        );
    }
}
