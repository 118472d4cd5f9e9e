//! The engine's threads: the one interface through which a step runs its
//! parallel work (as Box2D v3's enqueue/finish task callbacks and Jolt's
//! `JobSystem`). A world runs on a [`TaskSystem`]: [`RayonTasks`] (the
//! default for `SolverConfig::threads > 1`), [`SingleThreaded`] (the
//! default for 1), or the engine's own, given with
//! [`World::set_tasks`](crate::World::set_tasks).
//!
//! Results do not depend on the task system, bit for bit: the step splits
//! a colour's blocks into ranges that share no dynamic body, so the ranges
//! may run in any order, on any threads. Nor do they depend on it being
//! right: each range is claimed before it runs (a range run twice runs
//! once; one never run is run by the step itself afterwards), and the
//! borrow the work is lent under ends when `parallel_for` returns, so a
//! task system written in safe Rust cannot make the step race or lose
//! work, only slow it down.

use std::sync::{Mutex, PoisonError};

/// A job system the world's step runs its parallel work on.
///
/// The step calls [`enter`](Self::enter) once per step with the whole
/// step, and inside it [`parallel_for`](Self::parallel_for) for each
/// colour of constraints large enough to split (a few dozen calls per
/// iteration): a fork-join, so an implementation that keeps its workers
/// awake inside `enter` (as a rayon pool's `install` does) pays no wake-up
/// per call.
pub trait TaskSystem: Send + Sync {
    /// How many threads may run items at once, the caller's included (at
    /// least 1). The step splits a colour into about twice as many ranges.
    fn workers(&self) -> usize;

    /// Runs `task(i)` for every `i` in `0..count`, on whichever threads
    /// and in whichever order, and returns when all have run (the borrow
    /// of `task` ends here: it cannot be kept). Each item should run once:
    /// the step skips an item run again, and runs one left out itself.
    fn parallel_for(&self, count: usize, task: &(dyn Fn(usize) + Sync));

    /// Runs one whole step (`step`, which calls
    /// [`parallel_for`](Self::parallel_for)); by default on the calling
    /// thread. A pool runs it inside itself, so that the step's fork-joins
    /// happen among its workers. The step runs once either way: calling
    /// `step` again does nothing, and a step not run here runs on the
    /// caller afterwards.
    fn enter(&self, step: &mut (dyn FnMut() + Send)) {
        step()
    }
}

/// Every item on the calling thread, in order.
#[derive(Clone, Copy, Debug, Default)]
pub struct SingleThreaded;

impl TaskSystem for SingleThreaded {
    fn workers(&self) -> usize {
        1
    }

    fn parallel_for(&self, count: usize, task: &(dyn Fn(usize) + Sync)) {
        (0..count).for_each(task);
    }
}

/// A rayon thread pool of its own.
#[derive(Debug)]
pub struct RayonTasks {
    pool: rayon::ThreadPool,
}

impl RayonTasks {
    /// A pool of `threads` workers (at least 1); `None` when the threads
    /// could not be started.
    pub fn new(threads: usize) -> Option<Self> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .build()
            .ok()?;
        Some(Self { pool })
    }
}

impl TaskSystem for RayonTasks {
    fn workers(&self) -> usize {
        self.pool.current_num_threads()
    }

    fn parallel_for(&self, count: usize, task: &(dyn Fn(usize) + Sync)) {
        use rayon::prelude::*;
        // Inside `enter` this thread is one of the pool's: `install` runs
        // inline, and the items are a fork-join among the workers.
        self.pool
            .install(|| (0..count).into_par_iter().for_each(task));
    }

    fn enter(&self, step: &mut (dyn FnMut() + Send)) {
        self.pool.install(step)
    }
}

/// The most ranges a colour is split into: a colour of the 300-ragdoll
/// drop has a few dozen blocks, so more ranges than this would hold a
/// block or less each. Kept on the stack (no allocation per call).
pub const MAX_RANGES: usize = 64;

/// Runs `run` on `blocks` split into about twice as many ranges as
/// `tasks` has workers (at most [`MAX_RANGES`]), through `tasks`; each
/// range exactly once whatever `tasks` does: a range is taken out of its
/// slot to run (a second run finds it gone), and the ranges still in their
/// slots when `parallel_for` returns run here.
pub(crate) fn for_each_range<B: Send>(
    tasks: &dyn TaskSystem,
    blocks: &mut [B],
    run: &(dyn Fn(&mut [B]) + Sync),
) {
    let ranges = tasks.workers().saturating_mul(2).clamp(1, MAX_RANGES);
    let chunk = blocks.len().div_ceil(ranges).max(1);
    let slots: [Mutex<Option<&mut [B]>>; MAX_RANGES] = core::array::from_fn(|_| Mutex::new(None));
    let mut count = 0;
    for (slot, range) in slots.iter().zip(blocks.chunks_mut(chunk)) {
        *slot.lock().unwrap_or_else(PoisonError::into_inner) = Some(range);
        count += 1;
    }
    let take = |i: usize| {
        slots
            .get(i)
            .and_then(|slot| slot.lock().unwrap_or_else(PoisonError::into_inner).take())
    };
    tasks.parallel_for(count, &|i| {
        if let Some(range) = take(i) {
            run(range);
        }
    });
    for i in 0..count {
        if let Some(range) = take(i) {
            run(range);
        }
    }
}
