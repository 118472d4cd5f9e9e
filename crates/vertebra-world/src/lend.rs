//! Lending a step's work to an engine's persistent threads, in safe code.
//!
//! [`TaskSystem::parallel_for`](crate::TaskSystem::parallel_for) borrows
//! its task for the call: it cannot be sent to threads that outlive the
//! call, which is what a persistent pool's threads are (a job queue takes
//! `'static` jobs). Scoped threads (`std::thread::scope`) are the safe way
//! to borrow across threads, but start threads every call (0.14 to 1.97 ms
//! a frame against 0.04 to 0.06 for a persistent pool, measured by a new
//! user), so engines reached for `unsafe` to extend the borrow.
//!
//! [`lend`] does it once, here, soundly: it hands out a [`TaskLoan`], a
//! `'static` handle (`Clone`, `Send`, `Sync`) that any thread may hold, and
//! whose [`TaskLoan::run`] runs the lent task's items while the loan is
//! open. `lend` returns only after closing the loan and waiting for every
//! `run` that entered it to leave; a `run` after that runs nothing. So the
//! borrow is never used after it ends, whatever the engine's threads do
//! with their loans (run them late, twice, never, or keep them forever),
//! and the engine writes no `unsafe`:
//!
//! ```
//! use std::sync::{Arc, Mutex, mpsc};
//! use vertebra_world::{TaskLoan, TaskSystem, lend};
//!
//! /// A persistent pool: threads started once, fed `'static` jobs.
//! struct Pool {
//!     jobs: Mutex<mpsc::Sender<TaskLoan>>,
//!     threads: usize,
//! }
//!
//! impl Pool {
//!     fn new(threads: usize) -> Self {
//!         let (send, receive) = mpsc::channel::<TaskLoan>();
//!         let receive = Arc::new(Mutex::new(receive));
//!         for _ in 0..threads {
//!             let receive = Arc::clone(&receive);
//!             std::thread::spawn(move || loop {
//!                 let job = receive.lock().unwrap().recv();
//!                 match job {
//!                     Ok(loan) => loan.run(),
//!                     Err(_) => return, // the pool was dropped
//!                 }
//!             });
//!         }
//!         Self { jobs: Mutex::new(send), threads }
//!     }
//! }
//!
//! impl TaskSystem for Pool {
//!     fn workers(&self) -> usize {
//!         self.threads + 1 // the pool's threads and the caller
//!     }
//!     fn parallel_for(&self, count: usize, task: &(dyn Fn(usize) + Sync)) {
//!         lend(count, task, |loan| {
//!             let jobs = self.jobs.lock().unwrap();
//!             for _ in 0..self.threads {
//!                 jobs.send(loan.clone()).unwrap();
//!             }
//!         }); // the caller runs what is left, then waits for the rest
//!     }
//! }
//!
//! # use vertebra_world::{BodyDesc, Shape, SolverConfig, World};
//! # use glam::Vec3;
//! let mut world = World::new(SolverConfig::default())?;
//! world.set_tasks(Arc::new(Pool::new(2)));
//! let shape = Shape::Sphere { radius: 0.1 };
//! world.add_body(BodyDesc::dynamic(shape.mass_properties(1000.0)?))?;
//! world.step(1.0 / 60.0)?;
//! # Ok::<(), vertebra_world::Error>(())
//! ```
//!
//! Items are claimed from a counter by whichever thread runs the loan, and
//! the lending thread runs every item no one has claimed once the engine's
//! closure returns: every item runs exactly once, and `lend` returns when
//! all have run, as `parallel_for` promises. An item that panics is caught
//! on the thread that ran it (a pool's thread never unwinds) and the first
//! panic is raised again on the lending thread when `lend` returns.

use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, PoisonError};

/// The lent task, its lifetime erased: dereferenced only while the loan
/// is open and a `run` has entered it (see [`lend`]).
#[derive(Clone, Copy)]
struct Lent(*const (dyn Fn(usize) + Sync + 'static));

// SAFETY: the pointee is `Sync` (shared calls from any thread are
// allowed), and the pointer is used only while `lend`'s borrow lasts.
unsafe impl Send for Lent {}

/// A loan's state: the task while open, and how many `run`s are inside.
struct Gate {
    task: Option<Lent>,
    inside: usize,
}

struct Shared {
    gate: Mutex<Gate>,
    left: Condvar,
    count: usize,
    next: AtomicUsize,
    panic: Mutex<Option<Box<dyn Any + Send>>>,
}

/// A handle on a task lent by [`lend`]: `'static`, `Clone`, `Send` and
/// `Sync`, so a persistent thread pool's jobs may carry it. See the module
/// documentation.
#[derive(Clone)]
pub struct TaskLoan {
    shared: Arc<Shared>,
}

impl TaskLoan {
    /// Runs items of the lent task (each claimed by one thread only) until
    /// none is left, if the loan is still open; after [`lend`] has
    /// returned, runs nothing. Never unwinds: an item's panic is kept for
    /// the lending thread.
    pub fn run(&self) {
        let shared = &*self.shared;
        let task = {
            let mut gate = shared.gate.lock().unwrap_or_else(PoisonError::into_inner);
            let Some(task) = gate.task else { return };
            gate.inside += 1;
            task
        };
        // Leaves the gate however the items end.
        struct Leave<'a>(&'a Shared);
        impl Drop for Leave<'_> {
            fn drop(&mut self) {
                let mut gate = self.0.gate.lock().unwrap_or_else(PoisonError::into_inner);
                gate.inside -= 1;
                if gate.inside == 0 {
                    self.0.left.notify_all();
                }
            }
        }
        let _leave = Leave(shared);
        // SAFETY: the gate was open when this `run` entered, and `lend`
        // closes it and waits for every `run` inside to leave before its
        // borrow of the task ends: the task outlives this use.
        let task = unsafe { &*task.0 };
        shared.run_items(task);
    }
}

impl Shared {
    /// Claims and runs items until none is left, keeping the first panic.
    fn run_items(&self, task: &(dyn Fn(usize) + Sync)) {
        loop {
            let item = self.next.fetch_add(1, Ordering::Relaxed);
            if item >= self.count {
                return;
            }
            if let Err(payload) = catch_unwind(AssertUnwindSafe(|| task(item))) {
                let mut first = self.panic.lock().unwrap_or_else(PoisonError::into_inner);
                first.get_or_insert(payload);
            }
        }
    }
}

/// Lends `task`'s `count` items to `hand_out`, which passes the
/// [`TaskLoan`] (cloned as often as it likes) to the engine's threads;
/// then runs every item no thread has claimed, closes the loan, waits for
/// every thread inside it to leave, and returns (raising the first item's
/// panic, if one panicked). The way to write
/// [`TaskSystem::parallel_for`](crate::TaskSystem::parallel_for) on a
/// persistent pool without `unsafe` (see the module documentation).
pub fn lend(count: usize, task: &(dyn Fn(usize) + Sync), hand_out: impl FnOnce(&TaskLoan)) {
    let erased: *const (dyn Fn(usize) + Sync + '_) = task;
    // The lifetime alone changes: the pointer is dereferenced only by a
    // `run` inside the open gate, and the gate closes (waiting for every
    // `run` inside) before this function returns, by the guard below, on
    // every path out of it.
    // SAFETY: as above.
    let erased: *const (dyn Fn(usize) + Sync + 'static) = unsafe { core::mem::transmute(erased) };
    let loan = TaskLoan {
        shared: Arc::new(Shared {
            gate: Mutex::new(Gate {
                task: Some(Lent(erased)),
                inside: 0,
            }),
            left: Condvar::new(),
            count,
            next: AtomicUsize::new(0),
            panic: Mutex::new(None),
        }),
    };
    /// Closes the gate and waits for the threads inside, however `lend`
    /// is left (`hand_out` may panic).
    struct Close<'a>(&'a Shared);
    impl Drop for Close<'_> {
        fn drop(&mut self) {
            let mut gate = self.0.gate.lock().unwrap_or_else(PoisonError::into_inner);
            gate.task = None;
            while gate.inside > 0 {
                gate = self
                    .0
                    .left
                    .wait(gate)
                    .unwrap_or_else(PoisonError::into_inner);
            }
        }
    }
    let close = Close(&loan.shared);
    hand_out(&loan);
    loan.shared.run_items(task);
    drop(close);
    let panic = loan
        .shared
        .panic
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .take();
    if let Some(payload) = panic {
        resume_unwind(payload);
    }
}
