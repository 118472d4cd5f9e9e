//! The engine's threads: a world steps to the same bits on every task
//! system, the default ones and an engine's own, and on task systems that
//! run items one after another (last first), run items twice at once,
//! leave items out or all of them, or call with indices out of range; and
//! each substep is one launch of the workers.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, JointDesc, RayonTasks, Shape, SingleThreaded, SolverConfig, TaskSystem, World,
};

/// Chains of six capsules hanging from fixed anchors, swinging: enough
/// joints that every colour splits over the workers.
fn chains(config: SolverConfig) -> World {
    let mut world = World::new(config).unwrap();
    let mass = Shape::Capsule {
        half_segment: Vec3::new(0.1, 0.0, 0.0),
        radius: 0.05,
    }
    .mass_properties_with_mass(1.0)
    .unwrap();
    for chain in 0..40 {
        let x = chain as f32 * 0.5;
        let mut parent = world
            .add_body(BodyDesc::fixed().with_position(Vec3::new(x, 3.0, 0.0)))
            .unwrap();
        for link in 1..=6 {
            let at = Vec3::new(x + 0.3 * link as f32, 3.0, 0.1 * chain as f32);
            let body = BodyDesc::dynamic(mass)
                .with_position(at)
                .with_orientation(Quat::from_rotation_z(0.1 * link as f32))
                .with_velocity(Vec3::new(0.0, 0.0, 0.2 * link as f32), Vec3::ZERO);
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

fn config(threads: usize) -> SolverConfig {
    SolverConfig {
        threads,
        parallel_min_blocks: 1,
        ..SolverConfig::default()
    }
}

/// The state hash after 30 steps of 1/60 s.
fn stepped(mut world: World) -> u64 {
    for _ in 0..30 {
        world.step(1.0 / 60.0).unwrap();
    }
    world.state_hash()
}

/// What an engine's job system does with the items it is given.
#[derive(Clone, Copy, Debug)]
enum Behaviour {
    /// Each item once, on scoped threads, last item first.
    Scoped,
    /// Each item once, one after another on the caller, last item first:
    /// no item runs while another waits.
    Reversed,
    /// Each item three times: twice at once on two threads, then again.
    Twice,
    /// Only the even items.
    Skipping,
    /// No item at all.
    Nothing,
    /// Each item once, and indices past the count as well.
    OutOfRange,
}

/// An engine's job system, counting the calls it gets.
struct Engine {
    behaviour: Behaviour,
    calls: AtomicUsize,
}

impl TaskSystem for Engine {
    fn workers(&self) -> usize {
        3
    }

    fn parallel_for(&self, count: usize, task: &(dyn Fn(usize) + Sync)) {
        self.calls.fetch_add(1, Ordering::Relaxed);
        match self.behaviour {
            Behaviour::Scoped => std::thread::scope(|s| {
                for i in (0..count).rev() {
                    s.spawn(move || task(i));
                }
            }),
            Behaviour::Reversed => (0..count).rev().for_each(task),
            Behaviour::Twice => {
                std::thread::scope(|s| {
                    for i in 0..count {
                        s.spawn(move || task(i));
                        s.spawn(move || task(i));
                    }
                });
                (0..count).for_each(task);
            }
            Behaviour::Skipping => (0..count).step_by(2).for_each(task),
            Behaviour::Nothing => {}
            Behaviour::OutOfRange => (0..count + 100).for_each(task),
        }
    }
}

#[test]
fn every_task_system_steps_to_the_same_bits() {
    let reference = stepped(chains(config(1)));
    assert_eq!(chains(config(1)).tasks().workers(), 1);
    for threads in [2, 3, 4] {
        assert_eq!(
            stepped(chains(config(threads))),
            reference,
            "{threads} threads"
        );
    }
    let mut world = chains(config(1));
    world.set_tasks(Arc::new(RayonTasks::new(2).unwrap()));
    assert_eq!(world.tasks().workers(), 2);
    assert_eq!(stepped(world), reference, "a rayon pool set later");
    let mut world = chains(config(4));
    world.set_tasks(Arc::new(SingleThreaded));
    assert_eq!(stepped(world), reference, "single-threaded set later");
}

#[test]
fn an_engines_job_system_runs_the_work_and_cannot_spoil_it() {
    let reference = stepped(chains(config(1)));
    for behaviour in [
        Behaviour::Scoped,
        Behaviour::Reversed,
        Behaviour::Twice,
        Behaviour::Skipping,
        Behaviour::Nothing,
        Behaviour::OutOfRange,
    ] {
        let engine = Arc::new(Engine {
            behaviour,
            calls: AtomicUsize::new(0),
        });
        let mut world = chains(config(1));
        world.set_tasks(engine.clone());
        assert_eq!(stepped(world), reference, "{behaviour:?}");
        // One launch of the workers per substep, however many colours and
        // iterations it has.
        let calls = engine.calls.load(Ordering::Relaxed);
        let substeps = config(1).substeps as usize;
        assert_eq!(calls, 30 * substeps, "{behaviour:?}");
    }
}
