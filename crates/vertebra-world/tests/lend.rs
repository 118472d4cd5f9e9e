//! An engine's persistent thread pool, written without `unsafe` on
//! `vertebra_world::lend`: the same bits as one thread, every item run
//! once, and a loan kept past its call runs nothing.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, mpsc};

use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, JointDesc, Shape, SingleThreaded, SolverConfig, TaskLoan, TaskSystem, World, lend,
};

/// What the pool does with each loan it is handed.
#[derive(Clone, Copy, PartialEq)]
enum Keeps {
    /// Runs it at once on one of its threads.
    Runs,
    /// Runs it twice, on two threads.
    RunsTwice,
    /// Keeps it and runs it only at the next call (after the loan closed).
    Late,
}

/// Threads started once, fed `'static` jobs over a channel.
struct Pool {
    jobs: Mutex<mpsc::Sender<TaskLoan>>,
    threads: usize,
    keeps: Keeps,
    kept: Mutex<Vec<TaskLoan>>,
}

impl Pool {
    fn new(threads: usize, keeps: Keeps) -> Self {
        let (send, receive) = mpsc::channel::<TaskLoan>();
        let receive = Arc::new(Mutex::new(receive));
        for _ in 0..threads {
            let receive = Arc::clone(&receive);
            std::thread::spawn(move || {
                loop {
                    let job = receive.lock().unwrap().recv();
                    match job {
                        Ok(loan) => loan.run(),
                        Err(_) => return,
                    }
                }
            });
        }
        Self {
            jobs: Mutex::new(send),
            threads,
            keeps,
            kept: Mutex::new(Vec::new()),
        }
    }
}

impl TaskSystem for Pool {
    fn workers(&self) -> usize {
        self.threads + 1
    }

    fn parallel_for(&self, count: usize, task: &(dyn Fn(usize) + Sync)) {
        lend(count, task, |loan| {
            let jobs = self.jobs.lock().unwrap();
            let mut kept = self.kept.lock().unwrap();
            // Loans kept from an earlier call: closed, they run nothing.
            for old in kept.drain(..) {
                jobs.send(old).unwrap();
            }
            for _ in 0..self.threads {
                match self.keeps {
                    Keeps::Runs => jobs.send(loan.clone()).unwrap(),
                    Keeps::RunsTwice => {
                        jobs.send(loan.clone()).unwrap();
                        jobs.send(loan.clone()).unwrap();
                    }
                    Keeps::Late => kept.push(loan.clone()),
                }
            }
        });
    }
}

/// Chains of six capsules hanging from fixed anchors, swinging.
fn chains(config: SolverConfig) -> World {
    let mut world = World::new(config).unwrap();
    let mass = Shape::Capsule {
        half_segment: Vec3::new(0.1, 0.0, 0.0),
        radius: 0.05,
    }
    .mass_properties_with_mass(1.0)
    .unwrap();
    for chain in 0..24 {
        let x = chain as f32 * 0.5;
        let mut parent = world
            .add_body(BodyDesc::fixed().with_position(Vec3::new(x, 3.0, 0.0)))
            .unwrap();
        for link in 1..=6 {
            let at = Vec3::new(x + 0.3 * link as f32, 3.0, 0.1 * chain as f32);
            let body = BodyDesc::dynamic(mass)
                .with_position(at)
                .with_orientation(Quat::from_rotation_z(0.1 * link as f32));
            let child = world.add_body(body).unwrap();
            let anchor = at - Vec3::new(0.15, 0.0, 0.0);
            let joint =
                JointDesc::socket_at_world_anchor(world.bodies(), parent, child, anchor, Vec3::X)
                    .unwrap();
            world.add_joint(joint).unwrap();
            parent = child;
        }
    }
    world
}

fn stepped(tasks: Arc<dyn TaskSystem>) -> u64 {
    let mut world = chains(SolverConfig {
        parallel_min_blocks: 1,
        ..SolverConfig::default()
    });
    world.set_tasks(tasks);
    for _ in 0..30 {
        world.step(1.0 / 60.0).unwrap();
    }
    world.state_hash()
}

#[test]
fn a_persistent_pool_on_lend_steps_to_the_bits_of_one_thread() {
    let alone = stepped(Arc::new(SingleThreaded));
    for keeps in [Keeps::Runs, Keeps::RunsTwice, Keeps::Late] {
        for threads in [1, 2, 3] {
            let hash = stepped(Arc::new(Pool::new(threads, keeps)));
            assert_eq!(hash, alone, "{threads} threads");
        }
    }
}

#[test]
fn every_item_runs_once_and_a_kept_loan_runs_nothing() {
    for keeps in [Keeps::Runs, Keeps::RunsTwice, Keeps::Late] {
        let pool = Pool::new(3, keeps);
        for count in [0, 1, 7, 100] {
            let runs: Vec<AtomicUsize> = (0..count).map(|_| AtomicUsize::new(0)).collect();
            pool.parallel_for(count, &|i| {
                runs[i].fetch_add(1, Ordering::Relaxed);
            });
            // Every item once, by the time the call returned.
            assert!(runs.iter().all(|r| r.load(Ordering::Relaxed) == 1));
        }
        // A loan kept past its call and run now: nothing happens.
        let late = AtomicUsize::new(0);
        let mut kept = None;
        lend(
            4,
            &|_| {
                late.fetch_add(1, Ordering::Relaxed);
            },
            |loan| kept = Some(loan.clone()),
        );
        assert_eq!(late.load(Ordering::Relaxed), 4);
        kept.unwrap().run();
        assert_eq!(late.load(Ordering::Relaxed), 4);
    }
}

#[test]
fn an_items_panic_reaches_the_caller_and_the_pool_lives_on() {
    let pool = Pool::new(2, Keeps::Runs);
    let caught = catch_unwind(AssertUnwindSafe(|| {
        pool.parallel_for(8, &|i| assert!(i != 5, "item {i}"));
    }));
    assert!(caught.is_err(), "the panic came back");
    // The pool's threads did not unwind: it still works.
    let runs = AtomicUsize::new(0);
    pool.parallel_for(16, &|_| {
        runs.fetch_add(1, Ordering::Relaxed);
    });
    assert_eq!(runs.load(Ordering::Relaxed), 16);
}
