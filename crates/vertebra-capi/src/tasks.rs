//! The engine's job system, seen from C: a `parallel_for` callback (as
//! Box2D v3's `enqueueTask`/`finishTask` or a Jolt job per worker) that
//! the world's step runs its parallel work on.

use std::ffi::c_void;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::Mutex;

use vertebra_world::{MAX_THREADS, TaskSystem};

use crate::error::{Failure, VtResult};

/// One item of the step's parallel work: call it as
/// `task(task_context, index)` for each `index` the job system was asked
/// to run.
pub type VtTaskFn = unsafe extern "C" fn(task_context: *const c_void, index: u32);

/// Runs `task(task_context, i)` for every `i` in `0 .. count`, on
/// whichever threads and in whichever order, and returns when all have
/// run. `task` and `task_context` must not be used after it returns. It
/// returns normally (a C++ exception must not leave it or `task`), and
/// neither it nor the jobs it runs call vertebra with the world being
/// stepped: that world is inside `vt_world_step` (such a call is refused
/// with `VT_RESULT_POISONED` at best, and destroying the world there frees
/// it under the step).
pub type VtParallelFor = unsafe extern "C" fn(
    context: *mut c_void,
    count: u32,
    task: VtTaskFn,
    task_context: *const c_void,
);

/// The engine's job system.
///
/// Results do not depend on it, bit for bit: items run one after another,
/// in any order, or on any threads give the same world (an item run late
/// costs time, never a result).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtTaskSystem {
    /// How many threads may run items at once (1 to 256): the number of
    /// items a substep asks for.
    pub workers: u32,
    /// The job system's `parallel_for` (a `VtParallelFor`; not null). It
    /// returns normally (a C++ exception must not leave it or the items),
    /// and neither it nor the items call vertebra on the world being
    /// stepped: that world is inside `vt_world_step` (such a call is
    /// refused with `VT_RESULT_POISONED` at best; a destroy there frees
    /// the world under the step).
    pub parallel_for: Option<
        unsafe extern "C" fn(
            context: *mut c_void,
            count: u32,
            task: VtTaskFn,
            task_context: *const c_void,
        ),
    >,
    /// Passed back as `parallel_for`'s `context`.
    pub context: *mut c_void,
}

/// A [`VtTaskSystem`] as the world's [`TaskSystem`].
pub(crate) struct CTasks {
    workers: usize,
    parallel_for: VtParallelFor,
    context: *mut c_void,
}

// SAFETY: `vt_world_set_tasks`'s contract: the job system's context may be
// used from any thread that steps the world, and its `parallel_for` is
// callable from there.
unsafe impl Send for CTasks {}
// SAFETY: as above; `parallel_for` is called with shared access only.
unsafe impl Sync for CTasks {}

impl CTasks {
    /// The job system, or why it is refused.
    pub(crate) fn new(tasks: VtTaskSystem) -> Result<Self, Failure> {
        let parallel_for = tasks
            .parallel_for
            .ok_or_else(|| Failure::new(VtResult::NullPointer, "tasks.parallel_for is null"))?;
        let workers = tasks.workers as usize;
        if !(1..=MAX_THREADS).contains(&workers) {
            return Err(Failure::new(
                VtResult::InvalidConfig,
                format!("tasks.workers is {workers}; it takes 1 to {MAX_THREADS}"),
            ));
        }
        Ok(Self {
            workers,
            parallel_for,
            context: tasks.context,
        })
    }
}

/// One `parallel_for` call's work, and the first panic of its items.
struct Job<'a> {
    task: &'a (dyn Fn(usize) + Sync),
    panic: Mutex<Option<Box<dyn std::any::Any + Send>>>,
}

/// The C entry of an item: runs it, keeping a panic for the stepping
/// thread to raise (it must not unwind into the job system).
///
/// # Safety
/// `task_context` is the `Job` a running `parallel_for` lent.
unsafe extern "C" fn run_item(task_context: *const c_void, index: u32) {
    // SAFETY: `task_context` is the `Job` that `parallel_for` below lent
    // for this call, alive until it returns (the job system's contract).
    let job = unsafe { &*task_context.cast::<Job>() };
    if let Err(payload) = catch_unwind(AssertUnwindSafe(|| (job.task)(index as usize))) {
        let mut first = job.panic.lock().unwrap_or_else(|e| e.into_inner());
        first.get_or_insert(payload);
    }
}

impl TaskSystem for CTasks {
    fn workers(&self) -> usize {
        self.workers
    }

    fn parallel_for(&self, count: usize, task: &(dyn Fn(usize) + Sync)) {
        let job = Job {
            task,
            panic: Mutex::new(None),
        };
        let count = count.min(u32::MAX as usize) as u32;
        let context = (&raw const job).cast::<c_void>();
        // SAFETY: `vt_world_set_tasks`'s contract: a `parallel_for` that
        // runs the items and returns when all have run; `job` outlives it.
        unsafe { (self.parallel_for)(self.context, count, run_item, context) };
        if let Some(payload) = job.panic.into_inner().unwrap_or_else(|e| e.into_inner()) {
            resume_unwind(payload);
        }
    }
}
