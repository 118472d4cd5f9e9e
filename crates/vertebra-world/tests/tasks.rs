//! The engine's threads: a world steps to the same bits on every task
//! system, the default ones and an engine's own, and on task systems that
//! run items one after another (last first), run items twice at once,
//! leave items out or all of them, or call with indices out of range; and
//! each substep is one launch of the workers (and the step's start one
//! more, when it has many contacts).

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, BodyHandle, Contact, JointDesc, RayonTasks, Shape, SingleThreaded, SleepSettings,
    SolverConfig, TaskSystem, World,
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

impl Behaviour {
    const EVERY: [Self; 6] = [
        Self::Scoped,
        Self::Reversed,
        Self::Twice,
        Self::Skipping,
        Self::Nothing,
        Self::OutOfRange,
    ];
}

/// An engine's job system, counting the calls it gets.
struct Engine {
    behaviour: Behaviour,
    calls: AtomicUsize,
}

impl Engine {
    fn new(behaviour: Behaviour) -> Arc<Self> {
        Arc::new(Self {
            behaviour,
            calls: AtomicUsize::new(0),
        })
    }
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
    for behaviour in Behaviour::EVERY {
        let engine = Engine::new(behaviour);
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

/// Sphere radius in the piles (m).
const R: f32 = 0.2;

/// Piles of spheres on a static ground: `piles` chains of `links`
/// spheres lying on the ground along z, each joined to the next by a
/// socket where they touch, the chains `spacing` apart along x (closer
/// than `2 R` they touch: one island; 3 m apart each is one of its own).
/// Returns the world, the ground and the spheres.
fn piles(
    config: SolverConfig,
    piles: usize,
    links: usize,
    spacing: f32,
) -> (World, BodyHandle, Vec<BodyHandle>) {
    let mut world = World::new(config).unwrap();
    let ground = world.add_body(BodyDesc::fixed()).unwrap();
    let mass = Shape::Sphere { radius: R }
        .mass_properties_with_mass(1.0)
        .unwrap();
    let mut spheres = Vec::new();
    for pile in 0..piles {
        let mut last = None;
        for link in 0..links {
            let at = Vec3::new(spacing * pile as f32, R, 2.0 * R * link as f32);
            let body = world
                .add_body(BodyDesc::dynamic(mass).with_position(at))
                .unwrap();
            if let Some(last) = last {
                let anchor = at - Vec3::Z * R;
                let joint =
                    JointDesc::socket_at_world_anchor(world.bodies(), last, body, anchor, Vec3::Z)
                        .unwrap();
                world.add_joint(joint).unwrap();
            }
            last = Some(body);
            spheres.push(body);
        }
    }
    (world, ground, spheres)
}

/// The contacts of the spheres with the ground (the plane y = 0) and with
/// each other, from their poses now (a 5 mm margin).
fn sphere_contacts(world: &World, ground: BodyHandle, spheres: &[BodyHandle]) -> Vec<Contact> {
    let at = |h: BodyHandle| world.bodies().position[h.index()];
    let contact = |body_a, body_b, point, normal, depth| Contact {
        body_a,
        body_b,
        point,
        normal,
        depth,
        friction: 0.5,
        restitution: 0.0,
    };
    let mut contacts = Vec::new();
    for (k, &a) in spheres.iter().enumerate() {
        let p = at(a);
        if p.y < R + 0.005 {
            let point = Vec3::new(p.x, 0.5 * (p.y - R), p.z);
            contacts.push(contact(ground, a, point, Vec3::Y, R - p.y));
        }
        for &b in &spheres[k + 1..] {
            let d = at(b) - p;
            let distance = d.length();
            if distance < 2.0 * R + 0.005 && distance > 1e-6 {
                let normal = d / distance;
                let point = p + normal * (0.5 * distance);
                contacts.push(contact(a, b, point, normal, 2.0 * R - distance));
            }
        }
    }
    contacts
}

/// What [`stepped_piles`] saw: the state hash at the end, the islands
/// asleep just before and just after the push, and the spheres' distinct
/// islands just before it.
type PilesRun = (u64, usize, usize, usize);

/// 160 steps of 1/60 s with the spheres' contacts, pushing sphere `push`
/// up at step 100.
fn stepped_piles(
    mut world: World,
    ground: BodyHandle,
    spheres: &[BodyHandle],
    push: usize,
) -> PilesRun {
    let (mut before, mut after, mut islands) = (0, 0, 0);
    for step in 0..160 {
        let contacts = sphere_contacts(&world, ground, spheres);
        world.set_contacts(&contacts).unwrap();
        if step == 100 {
            before = world.island_count().1;
            let mut ids: Vec<_> = spheres.iter().map(|&s| world.island(s).unwrap()).collect();
            ids.sort();
            ids.dedup();
            islands = ids.len();
            world
                .apply_impulse(spheres[push], Vec3::new(0.3, 3.0, 0.0))
                .unwrap();
        }
        world.step(1.0 / 60.0).unwrap();
        if step == 100 {
            after = world.island_count().1;
        }
    }
    (world.state_hash(), before, after, islands)
}

#[test]
fn islands_apart_and_one_pile_step_to_the_same_bits_on_every_task_system() {
    // Six chains apart (six islands, dealt to the workers' bins), the
    // same six side by side (one island: solved colour by colour), and
    // six lone spheres (six islands without a joint), with islands
    // falling asleep and one woken by a push mid-run.
    for (links, spacing, islands) in [(3, 3.0, 6), (3, 2.0 * R, 1), (1, 3.0, 6)] {
        let sleepy = |threads| SolverConfig {
            sleep: Some(SleepSettings::default()),
            ..config(threads)
        };
        let run = |world: (World, BodyHandle, Vec<BodyHandle>)| {
            let (world, ground, spheres) = world;
            stepped_piles(world, ground, &spheres, spheres.len() / 2)
        };
        let reference = run(piles(sleepy(1), 6, links, spacing));
        let (_, before, after, found) = reference;
        assert_eq!(found, islands, "{spacing} m: {reference:?}");
        assert!(
            before >= 1,
            "{spacing} m: islands fall asleep: {reference:?}"
        );
        assert_eq!(
            after,
            before - 1,
            "{spacing} m: the push wakes one: {reference:?}"
        );
        for threads in [2, 3, 4] {
            let world = piles(sleepy(threads), 6, links, spacing);
            assert_eq!(run(world), reference, "{threads} threads, {spacing} m");
        }
        for behaviour in Behaviour::EVERY {
            let mut world = piles(sleepy(1), 6, links, spacing);
            world.0.set_tasks(Engine::new(behaviour));
            assert_eq!(run(world), reference, "{behaviour:?}, {spacing} m");
        }
        // Awake throughout: the islands of touching piles are found each
        // step, not kept.
        let reference = run(piles(config(1), 6, links, spacing));
        for threads in [2, 3] {
            let world = piles(config(threads), 6, links, spacing);
            assert_eq!(
                run(world),
                reference,
                "awake, {threads} threads, {spacing} m"
            );
        }
    }
}

#[test]
fn islands_that_come_apart_step_to_the_same_bits_on_every_thread_count() {
    // Three pairs of lone spheres (no joint) overlapping by 2 cm on the
    // ground, 3 m apart: three islands that the overlap pushes apart into
    // six, so that the bins grow in number mid-run.
    let run = |threads: usize| {
        let mut world = World::new(config(threads)).unwrap();
        let ground = world.add_body(BodyDesc::fixed()).unwrap();
        let mass = Shape::Sphere { radius: R }
            .mass_properties_with_mass(1.0)
            .unwrap();
        let mut spheres = Vec::new();
        for pair in 0..3 {
            for side in [-1.0, 1.0] {
                let at = Vec3::new(3.0 * pair as f32 + side * (R - 0.01), R, 0.0);
                spheres.push(
                    world
                        .add_body(BodyDesc::dynamic(mass).with_position(at))
                        .unwrap(),
                );
            }
        }
        let mut islands = Vec::new();
        for _ in 0..60 {
            let contacts = sphere_contacts(&world, ground, &spheres);
            let touching = contacts.iter().filter(|c| c.body_a != ground).count();
            islands.push(6 - touching.min(3));
            world.set_contacts(&contacts).unwrap();
            world.step(1.0 / 60.0).unwrap();
        }
        (
            world.state_hash(),
            islands.first().copied(),
            islands.last().copied(),
        )
    };
    let reference = run(1);
    assert_eq!(
        (reference.1, reference.2),
        (Some(3), Some(6)),
        "the pairs come apart"
    );
    for threads in [2, 3] {
        assert_eq!(run(threads), reference, "{threads} threads");
    }
}

#[test]
fn many_contacts_are_laid_out_on_the_workers_to_the_same_bits() {
    // Ten chains of 40 spheres side by side on the ground: one island
    // with about 1,150 contacts, enough that the step's start (the
    // contacts' lanes, the joints' start of step) is a launch of the
    // workers of its own.
    let steps = 20;
    let run = |mut world: World, ground: BodyHandle, spheres: &[BodyHandle]| {
        let mut counts = Vec::new();
        for _ in 0..steps {
            let contacts = sphere_contacts(&world, ground, spheres);
            counts.push(contacts.len());
            world.set_contacts(&contacts).unwrap();
            world.step(1.0 / 60.0).unwrap();
        }
        (world.state_hash(), counts)
    };
    let (world, ground, spheres) = piles(config(1), 10, 40, 2.0 * R);
    let (reference, counts) = run(world, ground, &spheres);
    assert!(
        counts.iter().all(|&n| n >= 1024),
        "many contacts every step: {counts:?}"
    );
    for threads in [2, 3, 4] {
        let (world, ground, spheres) = piles(config(threads), 10, 40, 2.0 * R);
        assert_eq!(
            run(world, ground, &spheres).0,
            reference,
            "{threads} threads"
        );
    }
    for behaviour in Behaviour::EVERY {
        let engine = Engine::new(behaviour);
        let (mut world, ground, spheres) = piles(config(1), 10, 40, 2.0 * R);
        world.set_tasks(engine.clone());
        assert_eq!(run(world, ground, &spheres).0, reference, "{behaviour:?}");
        // The step's start, then one launch per substep.
        let substeps = config(1).substeps as usize;
        let calls = engine.calls.load(Ordering::Relaxed);
        assert_eq!(calls, steps * (1 + substeps), "{behaviour:?}");
    }
}
