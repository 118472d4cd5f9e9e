//! What a sleeping world costs: the paper's 30-ragdoll drop (both spines,
//! 1 x 20, residuals not measured) with sleeping on, stepped until its pile sleeps, then one frame
//! (collision detection, handing the contacts over, the step) asleep, and
//! the same state in a world that does not sleep (every body of the pile
//! solved at rest). `cargo bench -p vertebra-benches --bench sleep`

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use vertebra_benches::DT;
use vertebra_collide::Collisions;
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneConfig, build};
use vertebra_world::{Contact, SleepSettings, SolverConfig, World};

/// The pile's world, its colliders and the contact list it swaps.
struct Pile {
    world: World,
    collisions: Collisions,
    contacts: Vec<Contact>,
}

impl Pile {
    fn frame(&mut self) {
        self.collisions
            .find_contacts_into(&self.world, DT, &mut self.contacts)
            .expect("contacts");
        self.world.swap_contacts(&mut self.contacts).expect("valid");
        self.world.step(DT).expect("a step");
        black_box(&self.world);
    }

    /// The drop, stepped until every island sleeps (at most 60 s).
    fn settled(spine: SpineMode) -> Self {
        let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
        config.sleep = Some(SleepSettings::default());
        config.measure_residuals = false;
        let mut scene = build(&config).expect("the drop");
        for frame in 0..3600 {
            scene.advance(config.scene, frame, DT).expect("a frame");
            let (islands, asleep) = scene.world.island_count();
            if islands == asleep {
                return Self {
                    world: scene.world,
                    collisions: scene.collisions.expect("the pit's colliders"),
                    contacts: Vec::new(),
                };
            }
        }
        panic!("{spine:?}: the pile did not fall asleep in 60 s");
    }

    /// The same state in a world that never sleeps.
    fn woken(&self) -> Self {
        let mut world = World::new(SolverConfig {
            sleep: None,
            ..*self.world.config()
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
        let mut asleep = Pile::settled(spine);
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
