//! Stress scenes: each either stays finite with bounded error or is
//! refused with an error. The figures they print are in
//! docs/robustness.md.

use glam::{Quat, Vec3};
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, SpineMode};
use vertebra_scenes::{Scene, SceneConfig, build};
use vertebra_world::{BodyDesc, BodyHandle, JointDesc, Shape, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

/// The fastest body (m/s); every body must be finite, and the step's NaN
/// guard must never have fired.
fn fastest(world: &World) -> f32 {
    assert_eq!(world.repaired_bodies(), 0, "the NaN guard fired");
    let store = world.bodies();
    (0..store.capacity())
        .filter(|&i| store.is_live(i))
        .map(|i| {
            assert!(store.is_finite(i), "body {i} went non-finite");
            store.linear_velocity[i].length()
        })
        .fold(0.0, f32::max)
}

fn lowest(world: &World) -> f32 {
    let store = world.bodies();
    (0..store.capacity())
        .filter(|&i| store.is_live(i) && store.inverse_mass[i] > 0.0)
        .map(|i| store.position[i].y)
        .fold(f32::INFINITY, f32::min)
}

#[test]
fn three_hundred_ragdolls_dropped_at_once() {
    for spine in [SpineMode::Rod, SpineMode::Sockets] {
        let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
        config.ragdolls = 300;
        let mut scene = build(&config).unwrap();
        let joints = (scene.world.joints().count() + scene.world.rods().count()) as f32;
        let mut worst = 0.0f32;
        for frame in 0..240 {
            scene.advance(config.scene, frame, DT).unwrap();
            worst = worst.max(scene.measure(&scene.world).eps_lin_cm);
        }
        let end = scene.measure(&scene.world);
        let (speed, low) = (fastest(&scene.world), lowest(&scene.world));
        eprintln!(
            "{spine:?}: 300 ragdolls, 4 s: worst eps_lin {worst:.1} cm ({:.3} cm per joint), \
             at the end {:.1} cm; fastest body {speed:.2} m/s; lowest centre {low:.3} m",
            worst / joints,
            end.eps_lin_cm
        );
        assert!(
            worst / joints < 1.0,
            "{spine:?}: mean joint error stays under 1 cm"
        );
        assert!(
            low > 0.0,
            "{spine:?}: nothing falls through the ground ({low} m)"
        );
        assert!(speed < 10.0, "{spine:?}: nothing is flung ({speed} m/s)");
    }
}

/// A 1 kg capsule and a 1000 kg one joined by a socket, the light one
/// hanging from a static anchor (`light_on_top`) or the other way round,
/// swinging for 5 s.
fn mass_ratio(light_on_top: bool, substeps: u32) -> (f32, f32) {
    let config = SolverConfig {
        substeps,
        ..SolverConfig::default()
    };
    let mut world = World::new(config).unwrap();
    let anchor = world
        .add_body(BodyDesc::fixed().with_position(Vec3::new(0.0, 2.0, 0.0)))
        .unwrap();
    let masses = if light_on_top {
        [1.0, 1000.0]
    } else {
        [1000.0, 1.0]
    };
    let mut parent = anchor;
    let mut top = Vec3::new(0.0, 2.0, 0.0);
    for mass in masses {
        // Sideways, so it swings.
        let bottom = top + Vec3::new(0.4, -0.2, 0.0);
        let centre = (top + bottom) / 2.0;
        let shape = Shape::capsule(top - centre, bottom - centre, 0.05);
        let body = world
            .add_body(
                BodyDesc::dynamic(shape.mass_properties_with_mass(mass).unwrap())
                    .with_position(centre),
            )
            .unwrap();
        let socket = JointDesc::socket_at_world_anchor(
            world.bodies(),
            parent,
            body,
            top,
            (bottom - top).normalize(),
        )
        .unwrap();
        world.add_joint(socket).unwrap();
        (parent, top) = (body, bottom);
    }
    let mut worst = 0.0f32;
    for _ in 0..300 {
        world.step(DT).unwrap();
        worst = worst.max(world.measure_residuals().eps_lin_cm);
    }
    (worst, fastest(&world))
}

#[test]
fn a_mass_ratio_of_one_to_a_thousand_across_a_joint() {
    for light_on_top in [true, false] {
        let mut previous = f32::INFINITY;
        for substeps in [1, 2, 4, 8, 16] {
            let (worst, speed) = mass_ratio(light_on_top, substeps);
            eprintln!(
                "1:1000, light on top {light_on_top}, {substeps} substeps: \
                 worst eps_lin {worst:.3} cm, fastest {speed:.2} m/s"
            );
            // Finite and joined at every setting; Gauss-Seidel converges
            // slowly through a light body held between a fixed anchor and
            // a heavy one, and substeps are the remedy.
            assert!(
                worst < 100.0,
                "{substeps} substeps: the joints came apart ({worst} cm)"
            );
            assert!(speed < 12.0, "{substeps} substeps: flung at {speed} m/s");
            assert!(
                worst <= previous + 1e-3,
                "more substeps, less error: {worst} after {previous}"
            );
            previous = worst;
        }
        assert!(
            previous < 1.0,
            "16 substeps hold the joints to a centimetre: {previous} cm"
        );
    }
}

/// Two reference humanoids lying on the ground in the same place (every
/// capsule inside another), with collisions, for 2 s: the deepest overlap
/// at first and at the end, and the fastest body on the way out.
fn teleported_overlap(max_push_out_speed: f32) -> (f32, f32, f32) {
    let desc = RagdollDesc::reference_humanoid();
    let config = SolverConfig {
        max_push_out_speed,
        ..SolverConfig::default()
    };
    let mut world = World::new(config).unwrap();
    let mut collisions = Collisions::new();
    let ground = world.add_body(BodyDesc::fixed()).unwrap();
    collisions
        .add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    let hips = desc.bodies[desc.root].centre();
    let lying = Pose::bind(&desc).moved(
        hips,
        Quat::from_rotation_x(-core::f32::consts::FRAC_PI_2),
        Vec3::new(0.0, 0.3 - hips.y, 0.0),
    );
    for spine in [SpineMode::Rod, SpineMode::Sockets] {
        let ragdoll =
            Ragdoll::build(&mut world, &desc, BuildOptions::new(spine), &lying, None).unwrap();
        collisions
            .add_jointed(&ragdoll.collision_shapes(), &ragdoll.non_colliding_pairs())
            .unwrap();
    }
    let deepest = |world: &World| {
        collisions
            .find_contacts(world, DT)
            .unwrap()
            .iter()
            .map(|c| c.depth)
            .fold(0.0, f32::max)
    };
    let start = deepest(&world);
    let mut speed = 0.0f32;
    for _ in 0..120 {
        let contacts = collisions.find_contacts(&world, DT).unwrap();
        world.set_contacts(&contacts).unwrap();
        world.step(DT).unwrap();
        speed = speed.max(fastest(&world));
    }
    (start, deepest(&world), speed)
}

#[test]
fn ragdolls_teleported_into_each_other_separate() {
    // Without a push-out limit (the default) every overlap is removed in
    // one step and the motion becomes velocity; at 3 m/s it comes out
    // over a few steps.
    let (start, end, unlimited) = teleported_overlap(f32::INFINITY);
    let (_, limited_end, limited) = teleported_overlap(3.0);
    eprintln!(
        "teleported overlap: deepest {start:.3} m at first; after 2 s {end:.4} m \
         (push-out unlimited, fastest {unlimited:.2} m/s) and {limited_end:.4} m \
         (3 m/s, fastest {limited:.2} m/s)"
    );
    assert!(start > 0.1, "they really overlap");
    assert!(
        end < 0.02 && limited_end < 0.02,
        "they separate: {end} m, {limited_end} m"
    );
    // Removing 24 cm in a 60 Hz step is 14 m/s. Contacts correct through
    // the step's first lever arms and every correction turns the body in
    // its own frame, so the unlimited way out is 7.3 m/s, and the limit
    // (5.6 m/s) calms it by less than it would a faster one.
    assert!(unlimited < 10.0, "no explosion: {unlimited} m/s");
    assert!(
        limited < 0.8 * unlimited,
        "the limit calms it: {limited} against {unlimited} m/s"
    );
}

/// A standing humanoid 5 m up (and a few millimetres either way), every
/// body thrown at 1000 m/s straight down at the ground, for 5 s. The world
/// accepts the velocity; the solver's speed limit (`max_linear_speed`,
/// 500 m/s) moves it at 500.
///
/// What happens after the impact is chaotic: from one start the rod
/// ragdoll comes to rest, from another a millimetre higher it ends
/// tangled, its joints and the ground fighting at a few m/s (both before
/// and after double-precision coordinates: docs/robustness.md). So this
/// asserts what holds from every start, and prints the end state.
#[test]
fn a_ragdoll_at_a_thousand_metres_per_second_stops_at_the_ground() {
    let desc = RagdollDesc::reference_humanoid();
    let starts = [4.999, 5.0, 5.001, 5.002, 5.01];
    for (spine, height) in [SpineMode::Rod, SpineMode::Sockets]
        .into_iter()
        .flat_map(|spine| starts.map(|h| (spine, h)))
    {
        let mut world = World::new(SolverConfig::default()).unwrap();
        let mut collisions = Collisions::new();
        let ground = world.add_body(BodyDesc::fixed()).unwrap();
        collisions
            .add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
            .unwrap();
        let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::new(0.0, height, 0.0));
        let ragdoll =
            Ragdoll::build(&mut world, &desc, BuildOptions::new(spine), &pose, None).unwrap();
        collisions
            .add_jointed(&ragdoll.collision_shapes(), &ragdoll.non_colliding_pairs())
            .unwrap();
        let bodies: Vec<BodyHandle> = ragdoll.bodies.iter().flatten().copied().collect();
        for &b in &bodies {
            world
                .set_body_velocity(b, Vec3::new(0.0, -1000.0, 0.0), Vec3::ZERO)
                .unwrap();
        }
        // The first frame catches every capsule at the ground at once (a
        // speculative contact each), flattening the ragdoll onto it; its
        // joints then pull it back together, which throws it up.
        let (mut low, mut rebound, mut late) = (f32::INFINITY, 0.0f32, 0.0f32);
        for frame in 0..300 {
            let contacts = collisions.find_contacts(&world, DT).unwrap();
            world.set_contacts(&contacts).unwrap();
            world.step(DT).unwrap();
            low = low.min(lowest(&world));
            if frame > 0 {
                rebound = rebound.max(fastest(&world));
            }
            if frame >= 120 {
                late = late.max(fastest(&world));
            }
        }
        let (speed, eps) = (fastest(&world), world.measure_residuals().eps_lin_cm);
        eprintln!(
            "{spine:?} from {height} m at 1000 m/s: lowest centre {low:.3} m; fastest after \
             the impact {rebound:.1} m/s, after 2 s {late:.1} m/s; after 5 s fastest \
             {speed:.3} m/s, eps_lin {eps:.2} cm"
        );
        // Not through the ground (a capsule centre at most its radius and
        // a push-out step below it); the 500 m/s gone, from the first
        // rebound on; the ragdoll stays together and near the ground.
        assert!(
            low > -0.15,
            "{spine:?} from {height} m: it went through the ground ({low} m)"
        );
        assert!(
            rebound < 50.0,
            "{spine:?} from {height} m: 500 m/s became at most a rebound ({rebound} m/s)"
        );
        assert!(
            late < 25.0,
            "{spine:?} from {height} m: no more than a tangle's fight after 2 s ({late} m/s)"
        );
        assert!(
            eps < 40.0,
            "{spine:?} from {height} m: its joints hold ({eps} cm)"
        );
        assert_eq!(world.repaired_bodies(), 0, "the NaN guard fired");
    }
}

/// A simplified humanoid created with its spine bent 105 degrees, past the
/// rod's 60-degree bend limit: created (the rod holds the pose's arc
/// exactly), then pushed back to the limit within a second, calmly.
#[test]
fn a_rod_bent_past_its_limit_at_creation_returns_to_the_limit() {
    let desc = RagdollDesc::reference_humanoid();
    let spine = desc.spine.as_ref().unwrap();
    let mut rotations = vec![Quat::IDENTITY; desc.joints.len()];
    for (k, joint) in desc.joints.iter().enumerate() {
        if spine.bodies.contains(&joint.parent) && spine.bodies.contains(&joint.child) {
            rotations[k] = Quat::from_rotation_x(35f32.to_radians());
        }
    }
    let root = desc.bodies[desc.root].centre();
    let pose = Pose::from_joint_rotations(&desc, (root, Quat::IDENTITY), &rotations).unwrap();
    let config = SolverConfig {
        gravity: Vec3::ZERO,
        ..SolverConfig::default()
    };
    let mut world = World::new(config).unwrap();
    let ragdoll = Ragdoll::build(
        &mut world,
        &desc,
        BuildOptions::new(SpineMode::Rod),
        &pose,
        None,
    )
    .unwrap();
    let rod = ragdoll.rod.unwrap();
    let at_creation = world.measure_residuals().eps_ang_rad;
    let mut speed = 0.0f32;
    for _ in 0..60 {
        world.step(DT).unwrap();
        speed = speed.max(fastest(&world));
    }
    let residual = world
        .measure_residuals()
        .rods
        .iter()
        .find(|j| j.joint == rod)
        .unwrap()
        .angular_rad;
    eprintln!(
        "rod bent past its limit: overshoot {at_creation:.3} rad at creation, {residual:.4} rad after 1 s; fastest {speed:.2} m/s"
    );
    assert!(
        at_creation > 0.5,
        "created past the limit ({at_creation} rad over)"
    );
    assert!(residual < 0.02, "back at the limit: {residual} rad over");
    assert!(speed < 3.0, "calmly: {speed} m/s");
}
