//! Solver stages (as Box2D v3's solver stages): the workers are launched
//! once per substep, and every worker walks the same fixed list of stages
//! (a pass over ranges of bodies, one colour's blocks of one kind, ...).
//! Inside a stage, workers claim chunks from an atomic counter; a worker
//! that finds nothing left to claim waits until every chunk of the stage
//! is finished, then moves on to the next stage.
//!
//! No worker ever waits for one that has not claimed work: a worker waits
//! only for chunks already claimed by workers that are running them. So a
//! task system may run the workers one after another (in any order), run
//! one twice at once, or leave some out: the first worker to run does
//! every stage, later ones find them done, and whatever is left when
//! `parallel_for` returns is finished by the caller, who walks the stages
//! last. Which worker runs a chunk changes no result (a chunk's work does
//! not depend on who runs it, and the stage order is fixed), so results
//! are bit-identical for any thread count and any task system. With one
//! worker there is nothing to share: the caller walks the stages and runs
//! every chunk in the order the lone worker would claim it, with no
//! counters (the same bits, without the bookkeeping).

use core::marker::PhantomData;
use core::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

use vertebra_math::DefaultFloatMode;

use crate::tasks::TaskSystem;

/// Spins before a waiting worker starts yielding its core (a stage of the
/// 300-ragdoll drop lasts tens of microseconds; a core shared with other
/// threads must be given up soon).
const SPINS: u32 = 64;

/// One stage's counters, each on its own cache line so that workers
/// claiming in one stage do not slow down those finishing another.
#[derive(Debug, Default)]
#[repr(align(64))]
struct Counters {
    /// Chunks handed out (past the stage's count once it is all taken).
    claimed: AtomicUsize,
    /// Chunks finished.
    done: AtomicUsize,
}

/// The counters of every stage of a launch: scratch of the world, grown
/// to the largest stage list seen and never shrunk (no allocation per
/// step).
#[derive(Debug, Default)]
pub(crate) struct Stages {
    counters: Vec<Counters>,
    /// Set when a worker panics inside a stage: the others stop waiting
    /// for its chunk and panic too, instead of waiting forever.
    poisoned: AtomicBool,
}

impl Stages {
    /// Runs the stage list `walk` describes on `workers` workers of `tasks`
    /// (the count the step asked it for once: `tasks` is not asked again),
    /// and returns when every stage is finished. `walk` must describe the
    /// same stages every time it is called (it is called once to count
    /// them, then by each worker and by the caller).
    pub fn run(
        &mut self,
        tasks: &dyn TaskSystem,
        workers: usize,
        walk: &(dyn Fn(&mut Cursor) + Sync),
    ) {
        if workers <= 1 {
            // One worker: every stage in order, every chunk in the order the
            // lone worker would claim it, with no count, counter or wait (a
            // single ragdoll's step walks about 50 stages a substep).
            #[cfg(feature = "stage-timing")]
            timing::launch();
            let _mode = DefaultFloatMode::enter();
            walk(&mut Cursor {
                counters: None,
                direct: true,
                poisoned: &self.poisoned,
                next: 0,
            });
            return;
        }
        let mut counting = Cursor {
            counters: None,
            direct: false,
            poisoned: &self.poisoned,
            next: 0,
        };
        walk(&mut counting);
        let count = counting.next;
        if self.counters.len() < count {
            self.counters.resize_with(count, Counters::default);
        }
        for c in &mut self.counters[..count] {
            *c.claimed.get_mut() = 0;
            *c.done.get_mut() = 0;
        }
        *self.poisoned.get_mut() = false;
        #[cfg(feature = "stage-timing")]
        timing::launch();
        let (counters, poisoned) = (&self.counters[..count], &self.poisoned);
        let worker = || {
            // A worker starts in whatever mode its creator had.
            let _mode = DefaultFloatMode::enter();
            let _guard = PanicGuard(poisoned);
            walk(&mut Cursor {
                counters: Some(counters),
                direct: false,
                poisoned,
                next: 0,
            });
        };
        tasks.parallel_for(workers, &|_| worker());
        // Every worker has returned: what is left (all of it, when the task
        // system ran nothing) is finished here.
        worker();
    }
}

/// Marks the launch poisoned when its worker unwinds.
struct PanicGuard<'a>(&'a AtomicBool);

impl Drop for PanicGuard<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.store(true, Ordering::Release);
        }
    }
}

/// A worker's place in the stage list (or, while counting, just the
/// number of stages seen).
pub(crate) struct Cursor<'a> {
    counters: Option<&'a [Counters]>,
    /// The only worker: it runs every chunk itself, in order.
    direct: bool,
    poisoned: &'a AtomicBool,
    next: usize,
}

impl Cursor<'_> {
    /// One stage: the chunks of every part, claimed in any order by any
    /// worker; returns when every chunk is finished. The parts of a stage
    /// may run at once, so they must touch nothing in common that one of
    /// them writes. A stage of no chunks is no stage (the same while
    /// counting and running).
    pub fn stage(&mut self, parts: &[&dyn Part]) {
        let chunks: usize = parts.iter().map(|p| p.chunks()).sum();
        if chunks == 0 {
            return;
        }
        let index = self.next;
        self.next += 1;
        if self.direct {
            for part in parts {
                for chunk in 0..part.chunks() {
                    #[cfg(feature = "stage-timing")]
                    let started = std::time::Instant::now();
                    part.run(chunk);
                    #[cfg(feature = "stage-timing")]
                    timing::chunk(index, started.elapsed());
                }
            }
            return;
        }
        let Some(counters) = self.counters else {
            return;
        };
        let stage = &counters[index];
        loop {
            let mut chunk = stage.claimed.fetch_add(1, Ordering::Relaxed);
            if chunk >= chunks {
                break;
            }
            #[cfg(feature = "stage-timing")]
            let started = std::time::Instant::now();
            for part in parts {
                if chunk < part.chunks() {
                    part.run(chunk);
                    break;
                }
                chunk -= part.chunks();
            }
            #[cfg(feature = "stage-timing")]
            timing::chunk(index, started.elapsed());
            // Release: this chunk's writes are seen by whoever sees it done.
            stage.done.fetch_add(1, Ordering::Release);
        }
        self.wait(&stage.done, chunks);
    }

    /// Waits until `done` reaches `chunks`.
    fn wait(&self, done: &AtomicUsize, chunks: usize) {
        let mut spins = 0;
        // Acquire: every chunk's writes are seen before the next stage.
        while done.load(Ordering::Acquire) < chunks {
            assert!(
                !self.poisoned.load(Ordering::Acquire),
                "a worker panicked inside a solver stage"
            );
            if spins < SPINS {
                spins += 1;
                core::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
    }
}

/// Work of a stage, in chunks.
pub(crate) trait Part: Sync {
    /// How many chunks.
    fn chunks(&self) -> usize;
    /// Runs chunk `chunk` (below [`chunks`](Self::chunks)); a stage runs
    /// each chunk once.
    fn run(&self, chunk: usize);
}

/// `count` chunks, each run by a function of its index.
pub(crate) struct Chunks<F>(pub usize, pub F);

impl<F: Fn(usize) + Sync> Part for Chunks<F> {
    fn chunks(&self) -> usize {
        self.0
    }
    fn run(&self, chunk: usize) {
        (self.1)(chunk)
    }
}

/// The most chunks a [`SliceChunks`] splits its slice into.
const MAX_SLICE_CHUNKS: usize = 64;

/// A slice in chunks, each lent whole (`&mut`, behind one uncontended
/// mutex: safe code) to the worker that runs it; `run` gets the chunk's
/// first index in the slice and its elements.
pub(crate) struct SliceChunks<'a, T, F> {
    chunks: [Mutex<(usize, &'a mut [T])>; MAX_SLICE_CHUNKS],
    count: usize,
    run: F,
}

impl<'a, T, F> SliceChunks<'a, T, F> {
    /// `slice` in `pieces` chunks (1 to 64) of equal length, the last
    /// maybe shorter.
    pub fn new(slice: &'a mut [T], pieces: usize, run: F) -> Self {
        let size = slice
            .len()
            .div_ceil(pieces.clamp(1, MAX_SLICE_CHUNKS))
            .max(1);
        let mut chunks: [Mutex<(usize, &'a mut [T])>; MAX_SLICE_CHUNKS] =
            core::array::from_fn(|_| Mutex::new((0, Default::default())));
        let mut count = 0;
        for (slot, chunk) in chunks.iter_mut().zip(slice.chunks_mut(size)) {
            *slot.get_mut().unwrap_or_else(PoisonError::into_inner) = (count * size, chunk);
            count += 1;
        }
        Self { chunks, count, run }
    }
}

impl<T: Send, F: Fn(usize, &mut [T]) + Sync> Part for SliceChunks<'_, T, F> {
    fn chunks(&self) -> usize {
        self.count
    }
    fn run(&self, chunk: usize) {
        let mut held = self.chunks[chunk]
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        let (first, ref mut elements) = *held;
        (self.run)(first, elements)
    }
}

/// One kind of block, lent to the workers of a launch: each worker
/// reaches the blocks of the chunks it claims.
pub(crate) struct SharedBlocks<'a, B> {
    start: *mut B,
    len: usize,
    _borrow: PhantomData<&'a mut [B]>,
}

impl<'a, B> SharedBlocks<'a, B> {
    /// Lends `blocks` for as long as the result lives.
    pub fn new(blocks: &'a mut [B]) -> Self {
        Self {
            start: blocks.as_mut_ptr(),
            len: blocks.len(),
            _borrow: PhantomData,
        }
    }

    /// How many blocks are lent.
    pub fn len(&self) -> usize {
        self.len
    }

    /// The blocks in `range`.
    ///
    /// # Safety
    /// No other reference to any of these blocks may be alive while the
    /// result is.
    #[allow(clippy::mut_from_ref)]
    // SAFETY: unsafe to call: the result is a `&mut` to blocks others hold.
    pub unsafe fn range(&self, range: Range<usize>) -> &mut [B] {
        assert!(range.start <= range.end && range.end <= self.len);
        // SAFETY: the range lies inside the lent slice (asserted), which
        // is borrowed mutably for 'a; the caller promises no other
        // reference to these blocks is alive.
        unsafe { core::slice::from_raw_parts_mut(self.start.add(range.start), range.len()) }
    }
}

// SAFETY: `SharedBlocks` is a `&mut [B]` reached from several threads, each
// block by one thread at a time (`Cursor::blocks`): sound to share when a
// `&mut [B]` may be sent, that is when `B: Send`.
unsafe impl<B: Send> Sync for SharedBlocks<'_, B> {}

/// Each chunk's time, for simulating the stages on more cores than the
/// machine has (`benches/stages.rs`); only with the `stage-timing`
/// feature, which no release build needs.
#[cfg(feature = "stage-timing")]
pub mod timing {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{Mutex, PoisonError};
    use std::time::Duration;

    /// One launch (a substep): for each stage in order, the time each of
    /// its chunks took, in the order they were claimed.
    pub type Launch = Vec<Vec<Duration>>;

    static RECORDING: AtomicBool = AtomicBool::new(false);
    static LAUNCHES: Mutex<Vec<Launch>> = Mutex::new(Vec::new());

    /// Starts recording (what was recorded before is dropped).
    pub fn start() {
        LAUNCHES
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clear();
        RECORDING.store(true, Ordering::SeqCst);
    }

    /// Stops recording, and returns every launch since [`start`].
    pub fn stop() -> Vec<Launch> {
        RECORDING.store(false, Ordering::SeqCst);
        core::mem::take(&mut *LAUNCHES.lock().unwrap_or_else(PoisonError::into_inner))
    }

    /// A launch begins.
    pub(crate) fn launch() {
        if RECORDING.load(Ordering::Relaxed) {
            let mut launches = LAUNCHES.lock().unwrap_or_else(PoisonError::into_inner);
            launches.push(Vec::new());
        }
    }

    /// A chunk of stage `stage` of the current launch took `time`.
    pub(crate) fn chunk(stage: usize, time: Duration) {
        if RECORDING.load(Ordering::Relaxed) {
            let mut launches = LAUNCHES.lock().unwrap_or_else(PoisonError::into_inner);
            if let Some(launch) = launches.last_mut() {
                if launch.len() <= stage {
                    launch.resize(stage + 1, Vec::new());
                }
                launch[stage].push(time);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicUsize, Ordering};

    use super::*;

    /// How a task system runs the items it is given.
    #[derive(Clone, Copy, Debug)]
    enum Runs {
        /// Each on its own thread, at once.
        AtOnce,
        /// One after another on the caller, last first.
        Reversed,
        /// Each twice at once on two threads.
        Twice,
        /// None of them.
        Nothing,
    }

    struct Tasks(Runs);

    impl TaskSystem for Tasks {
        fn workers(&self) -> usize {
            4
        }
        fn parallel_for(&self, count: usize, task: &(dyn Fn(usize) + Sync)) {
            match self.0 {
                Runs::AtOnce => std::thread::scope(|s| {
                    for i in 0..count {
                        s.spawn(move || task(i));
                    }
                }),
                Runs::Reversed => (0..count).rev().for_each(task),
                Runs::Twice => std::thread::scope(|s| {
                    for i in 0..count {
                        s.spawn(move || task(i));
                        s.spawn(move || task(i));
                    }
                }),
                Runs::Nothing => {}
            }
        }
    }

    const STAGES: usize = 40;
    const CHUNKS: usize = 7;

    #[test]
    fn every_chunk_runs_once_after_every_chunk_of_the_stage_before() {
        for runs in [Runs::AtOnce, Runs::Reversed, Runs::Twice, Runs::Nothing] {
            let counts: Vec<AtomicUsize> =
                (0..STAGES * CHUNKS).map(|_| AtomicUsize::new(0)).collect();
            let out_of_order = AtomicUsize::new(0);
            let walk = |cursor: &mut Cursor| {
                for stage in 0..STAGES {
                    // Stages of 1 to 7 chunks, in two parts.
                    let first = stage % CHUNKS;
                    let run = |chunk: usize| {
                        let mut before = stage.saturating_sub(1) * CHUNKS..stage * CHUNKS;
                        if before.any(|c| counts[c].load(Ordering::Acquire) != 1) {
                            out_of_order.fetch_add(1, Ordering::Relaxed);
                        }
                        counts[stage * CHUNKS + chunk].fetch_add(1, Ordering::AcqRel);
                    };
                    let head = Chunks(first, run);
                    let tail = Chunks(CHUNKS - first, |chunk: usize| run(first + chunk));
                    cursor.stage(&[&head, &tail]);
                }
            };
            Stages::default().run(&Tasks(runs), Tasks(runs).workers(), &walk);
            assert!(
                counts.iter().all(|c| c.load(Ordering::Relaxed) == 1),
                "{runs:?}: every chunk once"
            );
            assert_eq!(out_of_order.load(Ordering::Relaxed), 0, "{runs:?}");
        }
    }

    #[test]
    fn slice_chunks_lend_every_element_once_with_its_index() {
        for runs in [Runs::AtOnce, Runs::Reversed, Runs::Twice, Runs::Nothing] {
            for (len, pieces) in [(0, 8), (1, 8), (7, 3), (100, 16), (1000, 500)] {
                let mut seen = vec![usize::MAX; len];
                let chunks = SliceChunks::new(&mut seen, pieces, |first, part: &mut [usize]| {
                    for (k, v) in part.iter_mut().enumerate() {
                        assert_eq!(*v, usize::MAX, "{runs:?}: lent once");
                        *v = first + k;
                    }
                });
                assert!(chunks.chunks() <= pieces.clamp(1, MAX_SLICE_CHUNKS));
                Stages::default().run(
                    &Tasks(runs),
                    Tasks(runs).workers(),
                    &|cursor: &mut Cursor| cursor.stage(&[&chunks]),
                );
                assert!(
                    seen.iter().enumerate().all(|(i, &v)| v == i),
                    "{runs:?}, {len} in {pieces}"
                );
            }
        }
    }

    #[test]
    fn counters_grow_to_the_longest_launch_and_are_reset_for_the_next() {
        let mut stages = Stages::default();
        for count in [3, 9, 5] {
            let runs = AtomicUsize::new(0);
            let walk = |cursor: &mut Cursor| {
                for _ in 0..count {
                    cursor.stage(&[&Chunks(2, |_| {
                        runs.fetch_add(1, Ordering::Relaxed);
                    })]);
                }
            };
            stages.run(&Tasks(Runs::AtOnce), Tasks(Runs::AtOnce).workers(), &walk);
            assert_eq!(runs.load(Ordering::Relaxed), 2 * count);
        }
        assert_eq!(stages.counters.len(), 9);
    }
}
