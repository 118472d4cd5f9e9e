//! A scene over `K` seeded starts, its figures given with their spread, and
//! the comparison of two runs from the same start (rod against sockets,
//! one setting against another).

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use vertebra_ragdoll::RagdollError;

use crate::{MAX_FRAMES, Quantity, SceneConfig, SceneRun, Spread, run};

/// The most seeds a [`Seeded`] run takes.
pub const MAX_SEEDS: u64 = 10_000;

/// The most frames a [`Seeded`] run keeps over all its seeds (200 MB of
/// frame records): ten of the longest single runs.
pub const MAX_SEEDED_FRAMES: usize = 10 * MAX_FRAMES;

/// One scene run from seeds `first .. first + count`.
#[derive(Clone, Debug)]
pub struct Seeded {
    /// The seed of `runs[0]`; `runs[k]` ran from seed `first + k`.
    pub first: u64,
    /// One run per seed, in seed order.
    pub runs: Vec<SceneRun>,
}

impl Seeded {
    /// Whether [`Seeded::run`] takes `count` seeds of `config`: 1 to
    /// [`MAX_SEEDS`], the last seed at most `u64::MAX`, and seeds times
    /// frames at most [`MAX_SEEDED_FRAMES`]; refused naming the field, as
    /// `run` refuses it (for a caller that checks before it writes
    /// anything, as `vertebra reproduce` does).
    pub fn check(config: &SceneConfig, count: u64) -> Result<(), RagdollError> {
        let frames = config.frames.unwrap_or(config.scene.default_frames());
        let within = (1..=MAX_SEEDS).contains(&count)
            && config.seed.checked_add(count - 1).is_some()
            && (count as usize).saturating_mul(frames) <= MAX_SEEDED_FRAMES;
        if within {
            return Ok(());
        }
        Err(RagdollError::OutOfRange {
            context: "scene".to_owned(),
            field: "seeds",
            reason: format!(
                "is {count} from seed {}; must be 1 to {MAX_SEEDS}, end at most at seed {}, and seeds x frames ({frames}) at most {MAX_SEEDED_FRAMES}",
                config.seed,
                u64::MAX
            ),
        })
    }

    /// Runs `config` from seeds `config.seed .. config.seed + count`,
    /// independent runs spread over rayon's global pool (each run is
    /// deterministic, so the result does not depend on how many run at
    /// once; their timings do). `progress(done, count)` is called as runs
    /// finish, from any thread.
    pub fn run(
        config: &SceneConfig,
        count: u64,
        progress: impl Fn(usize, usize) + Sync,
    ) -> Result<Self, RagdollError> {
        Self::check(config, count)?;
        let done = AtomicUsize::new(0);
        let runs = (0..count)
            .into_par_iter()
            .map(|k| {
                let seeded = SceneConfig {
                    seed: config.seed + k,
                    ..config.clone()
                };
                let result = run(&seeded, |_, _| {});
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, count as usize);
                result
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            first: config.seed,
            runs,
        })
    }

    /// The spread over seeds of one figure of each run.
    pub fn spread(&self, figure: impl Fn(&SceneRun) -> f32) -> Spread {
        Spread::of(self.runs.iter().map(|r| f64::from(figure(r))))
    }

    /// Frame by frame, the spread of `quantity` over seeds (the bands of
    /// the plots).
    pub fn band(&self, quantity: Quantity) -> Vec<Spread> {
        let frames = self.runs.iter().map(|r| r.frames.len()).min().unwrap_or(0);
        (0..frames)
            .map(|k| {
                Spread::of(
                    self.runs
                        .iter()
                        .map(|r| f64::from(quantity.of(&r.frames[k]))),
                )
            })
            .collect()
    }
}

/// How run `b` compares with run `a` in one quantity, from the same start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// `a`'s mean over `b`'s: how many times lower `b` is.
    pub ratio: f32,
    /// The fraction of frames in which `b` is lower than `a`.
    pub lower: f32,
}

impl Comparison {
    /// `b` against `a` in `quantity`, over the frames both ran.
    pub fn of(a: &SceneRun, b: &SceneRun, quantity: Quantity) -> Self {
        let (ma, mb) = (a.stats(quantity).mean, b.stats(quantity).mean);
        let frames = a.frames.iter().zip(&b.frames);
        let lower = frames
            .clone()
            .filter(|(fa, fb)| quantity.of(fb) < quantity.of(fa))
            .count();
        Self {
            ratio: if mb > 0.0 { ma / mb } else { f32::INFINITY },
            lower: lower as f32 / frames.count().max(1) as f32,
        }
    }
}

/// Seed by seed, `b` against `a` (run from the same seeds) in `quantity`:
/// the spread of the ratio of means and of the fraction of frames `b` is
/// lower in.
pub fn compare(a: &Seeded, b: &Seeded, quantity: Quantity) -> (Spread, Spread) {
    let each: Vec<Comparison> = a
        .runs
        .iter()
        .zip(&b.runs)
        .map(|(ra, rb)| Comparison::of(ra, rb, quantity))
        .collect();
    (
        Spread::of(each.iter().map(|c| f64::from(c.ratio))),
        Spread::of(each.iter().map(|c| f64::from(c.lower))),
    )
}
