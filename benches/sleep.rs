//! What a sleeping world costs: 30 reference humanoids (both spines) lying
//! apart on a floor, settled until every island sleeps, then one frame
//! (collision detection, handing the contacts over, the step) asleep, and
//! the same state in a world that does not sleep (every body solved at
//! rest). `cargo bench -p vertebra-benches --bench sleep`

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::{Quat, Vec3};
use vertebra_benches::DT;
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, SpineMode};
use vertebra_world::{BodyDesc, Contact, SolverConfig, World};

/// The floor's world, its colliders and the contact list it swaps.
struct Floor {
    world: World,
    collisions: Collisions,
    contacts: Vec<Contact>,
}

impl Floor {
    /// 30 ragdolls face down in a 6 x 5 grid, 2.5 m apart.
    fn new(spine: SpineMode) -> Self {
        let mut world = World::new(SolverConfig::default()).expect("a world");
        let mut collisions = Collisions::new();
        let ground = world.add_body(BodyDesc::fixed()).expect("ground");
        collisions
            .add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
            .expect("the floor");
        let desc = RagdollDesc::reference_humanoid();
        let hips = desc.bodies[desc.root].centre();
        for k in 0..30 {
            let at = Vec3::new(2.5 * (k % 6) as f32, 0.3, 2.5 * (k / 6) as f32);
            let turn = Quat::from_rotation_y(0.7 * k as f32)
                * Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
            let pose = Pose::bind(&desc).moved(hips, turn, at - hips);
            let ragdoll = Ragdoll::build(&mut world, &desc, BuildOptions::new(spine), &pose, None)
                .expect("a ragdoll");
            collisions.add_ragdoll(&ragdoll).expect("its colliders");
        }
        Self {
            world,
            collisions,
            contacts: Vec::new(),
        }
    }

    fn frame(&mut self) {
        self.collisions
            .find_contacts_into(&self.world, DT, &mut self.contacts)
            .expect("contacts");
        self.world.swap_contacts(&mut self.contacts).expect("valid");
        self.world.step(DT).expect("a step");
        black_box(&self.world);
    }

    /// Stepped until every island sleeps (at most 60 s).
    fn settled(spine: SpineMode) -> Self {
        let mut floor = Self::new(spine);
        for _ in 0..3600 {
            floor.frame();
            let (islands, asleep) = floor.world.island_count();
            if islands == asleep {
                return floor;
            }
        }
        panic!("{spine:?}: the floor did not fall asleep in 60 s");
    }

    /// The same state in a world that never sleeps.
    fn woken(&self) -> Self {
        let mut world = World::new(SolverConfig {
            sleep: None,
            ..SolverConfig::default()
        })
        .expect("a world");
        world
            .restore(&self.world.snapshot())
            .expect("its own snapshot");
        Self {
            world,
            collisions: self.collisions.clone(),
            contacts: Vec::new(),
        }
    }
}

fn asleep_and_awake(c: &mut Criterion) {
    let mut group = c.benchmark_group("sleep");
    group.sample_size(20);
    for (name, spine) in [
        ("simplified", SpineMode::Rod),
        ("standard", SpineMode::Sockets),
    ] {
        let mut asleep = Floor::settled(spine);
        let mut awake = asleep.woken();
        group.bench_function(BenchmarkId::new(name, "asleep"), |b| {
            b.iter(|| asleep.frame())
        });
        group.bench_function(BenchmarkId::new(name, "awake"), |b| {
            b.iter(|| awake.frame())
        });
    }
    group.finish();
}

criterion_group!(benches, asleep_and_awake);
criterion_main!(benches);
