//! Islands and sleeping with collision detection: still bodies fall asleep
//! and stay put bit for bit, a ball wakes exactly the islands it touches,
//! every wake rule wakes, and sleeping worlds stay deterministic.

use glam::Vec3;
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_math::Backend;
use vertebra_world::{
    BackendChoice, BodyDesc, BodyHandle, BodyKind, Contact, JointDesc, Shape, SleepSettings,
    SolverConfig, World,
};

const DT: f32 = 1.0 / 60.0;

/// Boxes resting on the ground, apart (an island each); a stack of two
/// (one island through their contact); a chain of three boxes joined by
/// sockets lying on the ground (one island through its joints).
struct Floor {
    world: World,
    collisions: Collisions,
    contacts: Vec<Contact>,
    apart: Vec<BodyHandle>,
    stack: [BodyHandle; 2],
    chain: [BodyHandle; 3],
}

fn solid(world: &mut World, collisions: &mut Collisions, at: Vec3, shape: Shape) -> BodyHandle {
    let mass = shape.mass_properties(500.0).unwrap();
    let body = world
        .add_body(BodyDesc::dynamic(mass).with_position(at))
        .unwrap();
    collisions
        .add(Collider::new(body, ColliderShape::Solid(shape)))
        .unwrap();
    body
}

fn cube(half: f32) -> Shape {
    Shape::Box {
        half_extents: Vec3::splat(half),
    }
}

impl Floor {
    fn new(config: SolverConfig) -> Self {
        let mut world = World::new(config).unwrap();
        let mut collisions = Collisions::new();
        let ground = world.add_body(BodyDesc::fixed()).unwrap();
        collisions
            .add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
            .unwrap();
        let mut put = |w: &mut World, at: Vec3| solid(w, &mut collisions, at, cube(0.2));
        let apart = (0..4)
            .map(|k| put(&mut world, Vec3::new(1.0 * k as f32, 0.2, 0.0)))
            .collect();
        let stack = [
            put(&mut world, Vec3::new(0.0, 0.2, 2.0)),
            put(&mut world, Vec3::new(0.0, 0.6, 2.0)),
        ];
        let chain = [0, 1, 2].map(|k| put(&mut world, Vec3::new(0.45 * k as f32, 0.2, -2.0)));
        for pair in chain.windows(2) {
            let at = world.body(pair[0]).unwrap().position + Vec3::X * 0.225;
            let joint =
                JointDesc::socket_at_world_anchor(world.bodies(), pair[0], pair[1], at, Vec3::X);
            world.add_joint(joint.unwrap()).unwrap();
            collisions.exclude(pair[0], pair[1]);
        }
        Self {
            world,
            collisions,
            contacts: Vec::new(),
            apart,
            stack,
            chain,
        }
    }

    fn frame(&mut self) {
        self.collisions
            .find_contacts_into(&self.world, DT, &mut self.contacts)
            .unwrap();
        self.world.swap_contacts(&mut self.contacts).unwrap();
        self.world.step(DT).unwrap();
    }

    fn frames(&mut self, n: usize) {
        (0..n).for_each(|_| self.frame());
    }

    fn all(&self) -> Vec<BodyHandle> {
        let mut all = self.apart.clone();
        all.extend(self.stack);
        all.extend(self.chain);
        all
    }

    fn asleep(&self, body: BodyHandle) -> bool {
        self.world.is_asleep(body).unwrap()
    }

    /// Every body asleep (a second of settling is plenty: they start at
    /// rest on the ground).
    fn settled(config: SolverConfig) -> Self {
        let mut floor = Self::new(config);
        floor.frames(120);
        for body in floor.all() {
            assert!(floor.asleep(body), "{body:?} still awake after 2 s");
        }
        floor
    }
}

fn sleeping() -> SolverConfig {
    SolverConfig {
        sleep: Some(SleepSettings::default()),
        ..SolverConfig::default()
    }
}

fn bits(world: &World, bodies: &[BodyHandle]) -> Vec<[u32; 7]> {
    bodies
        .iter()
        .map(|&b| {
            let s = world.body(b).unwrap();
            let (p, q) = (s.position, s.orientation);
            [p.x, p.y, p.z, q.x, q.y, q.z, q.w].map(f32::to_bits)
        })
        .collect()
}

#[test]
fn islands_are_what_joints_and_contacts_link() {
    let mut floor = Floor::new(sleeping());
    floor.frame();
    let w = &floor.world;
    let island = |b: BodyHandle| w.island(b).unwrap().expect("dynamic");
    let chain = island(floor.chain[0]);
    assert!(floor.chain.iter().all(|&b| island(b) == chain));
    assert_eq!(island(floor.stack[0]), island(floor.stack[1]));
    let mut ids: Vec<u32> = floor.apart.iter().map(|&b| island(b)).collect();
    ids.extend([chain, island(floor.stack[0])]);
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), 6, "four apart, the stack, the chain");
    assert_eq!(floor.world.island_count(), (6, 0));
}

#[test]
fn still_bodies_fall_asleep_and_then_nothing_moves_by_a_bit() {
    let mut floor = Floor::new(sleeping());
    // Not before the sleep time (0.5 s) has passed.
    floor.frames(29);
    assert!(floor.all().iter().all(|&b| !floor.asleep(b)));
    floor.frames(91);
    assert_eq!(floor.world.island_count(), (6, 6));
    let (before, hash) = (bits(&floor.world, &floor.all()), floor.world.state_hash());
    floor.frames(600);
    assert_eq!(bits(&floor.world, &floor.all()), before);
    assert_eq!(floor.world.state_hash(), hash);
    assert_eq!(floor.world.island_count(), (6, 6));
    for body in floor.all() {
        assert_eq!(floor.world.body(body).unwrap().linear_velocity, Vec3::ZERO);
    }
}

#[test]
fn a_ball_wakes_exactly_the_islands_it_touches() {
    let mut floor = Floor::settled(sleeping());
    let top = floor.world.body(floor.stack[1]).unwrap().position;
    let ball = solid(
        &mut floor.world,
        &mut floor.collisions,
        top + Vec3::Y * 0.6,
        Shape::Sphere { radius: 0.1 },
    );
    let mut touched = false;
    for _ in 0..60 {
        floor.frame();
        touched |= floor.world.island(ball).unwrap() == floor.world.island(floor.stack[1]).unwrap();
        if touched {
            break;
        }
    }
    assert!(touched, "the ball reached the stack");
    // The stack's two boxes (one island through their contact) woke; every
    // other island sleeps on.
    assert!(!floor.asleep(floor.stack[0]) && !floor.asleep(floor.stack[1]));
    for &b in floor.apart.iter().chain(&floor.chain) {
        assert!(floor.asleep(b), "{b:?} woke untouched");
    }
    // And all of it sleeps again.
    floor.frames(240);
    for body in floor.all().into_iter().chain([ball]) {
        assert!(floor.asleep(body), "{body:?} still awake");
    }
}

#[test]
fn an_island_that_comes_apart_sleeps_in_parts() {
    let mut floor = Floor::settled(sleeping());
    let [low, high] = floor.stack;
    // Knock the top box off the stack: the island wakes whole, and when
    // they lie apart they are two islands.
    floor.world.apply_impulse(high, Vec3::X * 150.0).unwrap();
    floor.frames(180);
    let (a, b) = (
        floor.world.island(low).unwrap(),
        floor.world.island(high).unwrap(),
    );
    assert_ne!(a, b, "split once apart");
    assert!(floor.asleep(low) && floor.asleep(high));
}

/// Each way to wake a sleeping island, on a settled floor: the call, and
/// the body whose island must wake.
#[test]
fn every_wake_rule_wakes_the_island() {
    type Call = fn(&mut Floor) -> BodyHandle;
    let calls: [(&str, Call); 13] = [
        ("set_body_pose", |f| {
            let b = f.apart[0];
            let s = f.world.body(b).unwrap();
            f.world.set_body_pose(b, s.position, s.orientation).unwrap();
            b
        }),
        ("set_body_velocity", |f| {
            f.world
                .set_body_velocity(f.apart[0], Vec3::ZERO, Vec3::ZERO)
                .unwrap();
            f.apart[0]
        }),
        ("add_force", |f| {
            f.world.add_force(f.apart[0], Vec3::Y).unwrap();
            f.apart[0]
        }),
        ("add_force_at", |f| {
            f.world
                .add_force_at(f.apart[0], Vec3::Y, Vec3::ZERO)
                .unwrap();
            f.apart[0]
        }),
        ("add_torque", |f| {
            f.world.add_torque(f.apart[0], Vec3::Y).unwrap();
            f.apart[0]
        }),
        ("apply_impulse", |f| {
            f.world.apply_impulse(f.apart[0], Vec3::Y).unwrap();
            f.apart[0]
        }),
        ("apply_impulse_at", |f| {
            f.world
                .apply_impulse_at(f.apart[0], Vec3::Y, Vec3::ZERO)
                .unwrap();
            f.apart[0]
        }),
        ("apply_angular_impulse", |f| {
            f.world.apply_angular_impulse(f.apart[0], Vec3::Y).unwrap();
            f.apart[0]
        }),
        ("wake", |f| {
            f.world.wake(f.chain[2]).unwrap();
            f.chain[0]
        }),
        ("set_sleep_allowed", |f| {
            f.world.set_sleep_allowed(f.chain[2], false).unwrap();
            f.chain[0]
        }),
        ("set_body_kind", |f| {
            f.world
                .set_body_kind(f.chain[2], BodyKind::Kinematic)
                .unwrap();
            f.chain[0]
        }),
        ("add_joint", |f| {
            let (a, b) = (f.apart[0], f.apart[1]);
            let at = f.world.body(a).unwrap().position;
            let joint = JointDesc::socket_at_world_anchor(f.world.bodies(), a, b, at, Vec3::X);
            f.world.add_joint(joint.unwrap()).unwrap();
            f.apart[1]
        }),
        ("remove_joint", |f| {
            let (joint, _) = f.world.joints().next().unwrap();
            f.world.remove_joint(joint).unwrap();
            f.chain[2]
        }),
    ];
    for (name, call) in calls {
        let mut floor = Floor::settled(sleeping());
        let body = call(&mut floor);
        assert!(!floor.asleep(body), "{name} left the island asleep");
        floor.frame();
        assert!(!floor.asleep(body), "{name}: asleep again at once");
    }
}

#[test]
fn a_moving_kinematic_body_wakes_what_is_jointed_to_it_and_keeps_it_awake() {
    let mut floor = Floor::settled(sleeping());
    let [first, second, _] = floor.chain;
    floor
        .world
        .set_body_kind(first, BodyKind::Kinematic)
        .unwrap();
    floor.frames(120);
    assert!(floor.asleep(second), "a still kinematic body lets it sleep");
    let s = floor.world.body(first).unwrap();
    let up = s.position + Vec3::Y * 0.002;
    floor
        .world
        .move_kinematic(first, up, s.orientation, DT)
        .unwrap();
    assert!(!floor.asleep(second));
    for k in 0..120 {
        let up = s.position + Vec3::Y * 0.002 * (k + 2) as f32;
        floor
            .world
            .move_kinematic(first, up, s.orientation, DT)
            .unwrap();
        floor.frame();
        assert!(!floor.asleep(second), "asleep while held by a moving body");
    }
}

#[test]
fn sleeping_can_be_off_for_a_world_and_for_a_body() {
    let mut floor = Floor::new(SolverConfig {
        sleep: None,
        ..SolverConfig::default()
    });
    floor.frames(240);
    assert_eq!(floor.world.island_count().1, 0, "no island sleeps");
    let mut floor = Floor::new(sleeping());
    floor
        .world
        .set_sleep_allowed(floor.chain[1], false)
        .unwrap();
    floor.frames(240);
    assert!(!floor.asleep(floor.chain[0]), "its island stays awake");
    assert!(floor.asleep(floor.apart[0]));
}

#[test]
fn a_snapshot_taken_asleep_steps_on_bit_for_bit_anywhere() {
    let mut floor = Floor::settled(sleeping());
    floor
        .world
        .apply_impulse(floor.apart[1], Vec3::X * 200.0)
        .unwrap();
    floor.frames(10);
    let snapshot = floor.world.snapshot();
    let set = floor.collisions.snapshot(&floor.world).unwrap();
    // Another world (of another lineage) takes the snapshot, and with it
    // the handles the colliders name; its set takes the set's.
    let mut copy = Floor::new(sleeping());
    copy.world.restore(&snapshot).unwrap();
    copy.collisions.restore(&set, &copy.world).unwrap();
    for body in floor.all() {
        assert_eq!(floor.asleep(body), copy.asleep(body));
    }
    assert!(floor.asleep(floor.chain[0]) && !floor.asleep(floor.apart[1]));
    assert_eq!(copy.world.state_hash(), floor.world.state_hash());
    floor.frames(200);
    copy.frames(200);
    assert_eq!(copy.world.state_hash(), floor.world.state_hash());
    // A world that does not sleep wakes a sleeping snapshot at its step.
    let mut awake = Floor::new(SolverConfig {
        sleep: None,
        ..SolverConfig::default()
    });
    awake.world.restore(&snapshot).unwrap();
    awake.collisions.restore(&set, &awake.world).unwrap();
    awake.frame();
    assert_eq!(awake.world.island_count().1, 0);
}

#[test]
fn sleeping_worlds_are_bit_identical_across_threads_and_backends() {
    let run = |threads: usize, backend: Backend| {
        let mut floor = Floor::settled(SolverConfig {
            threads,
            backend: BackendChoice::Forced(backend),
            parallel_min_blocks: 1,
            ..sleeping()
        });
        let ball = solid(
            &mut floor.world,
            &mut floor.collisions,
            Vec3::new(1.0, 0.9, 0.0),
            Shape::Sphere { radius: 0.1 },
        );
        floor.world.apply_angular_impulse(ball, Vec3::Z).unwrap();
        floor.frames(200);
        floor.world.state_hash()
    };
    let reference = run(1, Backend::Scalar);
    for threads in [1, 2, 3] {
        for backend in Backend::available() {
            assert_eq!(
                run(threads, backend),
                reference,
                "{threads} threads, {backend:?}"
            );
        }
    }
}

#[test]
fn a_turn_counts_by_how_far_it_carries_the_mass() {
    // Two capsules 0.5 m long spinning in free fall, one about its own axis
    // (a limb twisting in place in a pile), one end over end, at the same
    // rate. The mean speed of a body's mass spinning at `w` about a
    // principal axis of inertia `I` is `w sqrt(I / m)`: a few cm/s for the
    // twist, below the threshold, and more than it for the tumble. Sleeping
    // judged by the turning rate (0.05 rad/s) kept both awake, and a pile
    // of ragdolls, its limbs twisting back and forth at their limits, never
    // slept.
    let mut world = World::new(SolverConfig {
        gravity: Vec3::ZERO,
        ..sleeping()
    })
    .unwrap();
    let shape = Shape::capsule(Vec3::new(0.0, -0.2, 0.0), Vec3::new(0.0, 0.2, 0.0), 0.05);
    let mass = shape.mass_properties(1000.0).unwrap();
    let w = 0.8;
    let threshold = SleepSettings::default().speed;
    let mass_speed = |axis: usize| w * (mass.inertia.col(axis)[axis] / mass.mass).sqrt();
    assert!(mass_speed(1) < 0.7 * threshold && mass_speed(0) > 1.5 * threshold);
    let spin = |world: &mut World, x: f32, axis: Vec3| {
        let body = world
            .add_body(BodyDesc::dynamic(mass).with_position(Vec3::new(x, 0.0, 0.0)))
            .unwrap();
        world.set_body_velocity(body, Vec3::ZERO, axis * w).unwrap();
        body
    };
    let twisting = spin(&mut world, 0.0, Vec3::Y);
    let tumbling = spin(&mut world, 2.0, Vec3::X);
    for _ in 0..120 {
        world.step(DT).unwrap();
    }
    assert!(world.is_asleep(twisting).unwrap(), "the twisting capsule");
    assert!(!world.is_asleep(tumbling).unwrap(), "the tumbling capsule");
    let turning = world.body(tumbling).unwrap().angular_velocity;
    assert!((turning - Vec3::X * w).length() < 1e-4, "{turning}");
}
