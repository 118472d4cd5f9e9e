//! The engine's threads: the one interface through which a step runs its
//! parallel work (as Box2D v3's enqueue/finish task callbacks and Jolt's
//! `JobSystem`). A world runs on a [`TaskSystem`]: [`RayonTasks`] (the
//! default for `SolverConfig::threads > 1`), [`SingleThreaded`] (the
//! default for 1), or the engine's own, given with
//! [`World::set_tasks`](crate::World::set_tasks).
//!
//! Each substep is one call of [`TaskSystem::parallel_for`] with one item
//! per worker; every item walks the substep's fixed list of stages
//! (`stages.rs`, as Box2D v3's solver stages), claiming chunks of work
//! from atomic counters and waiting only for chunks other running items
//! have claimed. Results do not depend on the task system, bit for bit:
//! a chunk's work does not depend on who runs it, and the stages run in a
//! fixed order. Nor do they depend on it being right: items run one after
//! another (in any order) or twice at once share the work out as they
//! come, an item never run leaves its work to the others, and the step
//! finishes what is left when `parallel_for` returns (the borrow the work
//! is lent under ends there), so a task system written in safe Rust
//! cannot make the step race, deadlock or lose work, only slow it down.
//!
//! **A task system that panics** (in `workers`, in `parallel_for` before,
//! while or after it runs the items, or in one of its threads) makes the
//! step unwind, and leaves the world as it was before the step, bit for
//! bit: the step keeps what it changes before its last `parallel_for`
//! returns and puts it back (`rollback.rs`; see
//! [`World::step`](crate::World::step)). The panic goes on to the caller,
//! who may replace the task system ([`World::set_tasks`](crate::World::set_tasks))
//! and step again. (The C ABI catches the panic and poisons the world
//! object, as it does for every panic: `VT_RESULT_PANIC`, then
//! `VT_RESULT_POISONED`; a C job system's callbacks must not unwind.)

/// A job system the world's step runs its parallel work on.
///
/// The step calls [`parallel_for`](Self::parallel_for) once per substep
/// (when [`workers`](Self::workers) is above 1) with one item per worker;
/// each item runs until the substep's work is done, waiting for other
/// items between its stages, so the items are worth running at once
/// (as Box2D v3's `enqueueTask` and `finishTask`, or one Jolt job per
/// worker).
pub trait TaskSystem: Send + Sync {
    /// How many threads may run items at once (at least 1): the number of
    /// items the step asks for. The calling thread waits in
    /// `parallel_for` and finishes what is left afterwards. Asked once as
    /// each step begins (an answer of 0 counts as 1).
    fn workers(&self) -> usize;

    /// Runs `task(i)` for every `i` in `0..count`, on whichever threads
    /// and in whichever order, and returns when all have run (the borrow
    /// of `task` ends here: it cannot be kept). Items should run at once
    /// to gain anything, but need not: an item run after another, run
    /// twice, or not run at all costs time, never a result. A panic here
    /// unwinds out of [`World::step`](crate::World::step) with the world
    /// as it was before the step.
    fn parallel_for(&self, count: usize, task: &(dyn Fn(usize) + Sync));
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
        // One job into the pool (`install`, which allocates nothing but a
        // slot of the pool's injector queue), split among the workers.
        self.pool
            .install(|| (0..count).into_par_iter().for_each(task));
    }
}
