//! Collision detection feeding the solver: resting, stacking, ragdolls on
//! the ground, and determinism with contacts.

use std::f32::consts::FRAC_PI_2;

use glam::{Quat, Vec3};
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_math::Backend;
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, SpineMode};
use vertebra_world::{
    BackendChoice, BodyDesc, BodyHandle, PinContacts, Shape, SolverConfig, World,
};

const DT: f32 = 1.0 / 60.0;

fn ground(w: &mut World, c: &mut Collisions) -> BodyHandle {
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    ground
}

fn cube(w: &mut World, c: &mut Collisions, at: Vec3, half: f32) -> BodyHandle {
    let shape = Shape::Box {
        half_extents: Vec3::splat(half),
    };
    let body = w
        .add_body(BodyDesc::dynamic(shape.mass_properties(500.0).unwrap()).with_position(at))
        .unwrap();
    c.add(Collider::new(body, ColliderShape::Solid(shape)))
        .unwrap();
    body
}

fn step(w: &mut World, c: &Collisions) {
    let contacts = c.find_contacts(w, DT).unwrap();
    w.set_contacts(&contacts).unwrap();
    w.step(DT).unwrap();
}

/// A capsule lying on the ground, at headings and turns about its own axis
/// that are not the world's: nothing pushes it, so it must stay at rest.
/// Its contact points turn with it, and a normal correction through the
/// turned points spun it up about its axis by 11% a frame, to 188 rad/s
/// within 10 s (`vertebra_kernels::contact`, the contact's arms).
#[test]
fn a_capsule_lying_on_the_ground_stays_at_rest_whatever_its_heading() {
    let shape = Shape::capsule(Vec3::new(-0.15, 0.0, 0.0), Vec3::new(0.15, 0.0, 0.0), 0.05);
    for turn in [
        Quat::from_rotation_y(0.3),
        Quat::from_rotation_x(0.3),
        Quat::from_rotation_y(-1.1) * Quat::from_rotation_x(2.0),
    ] {
        let mut w = World::new(SolverConfig {
            sleep: None,
            ..SolverConfig::default()
        })
        .unwrap();
        let mut c = Collisions::new();
        ground(&mut w, &mut c);
        let mass = shape.mass_properties_with_mass(2.0).unwrap();
        let at = Vec3::new(0.0, 0.05, 0.0);
        let body = w
            .add_body(
                BodyDesc::dynamic(mass)
                    .with_position(at)
                    .with_orientation(turn),
            )
            .unwrap();
        c.add(Collider::new(body, ColliderShape::Solid(shape)))
            .unwrap();
        let mut fastest = 0.0f32;
        for _ in 0..600 {
            step(&mut w, &c);
            fastest = fastest.max(w.body(body).unwrap().angular_velocity.length());
        }
        let moved = (w.body(body).unwrap().position - at).length();
        eprintln!("{turn:?}: fastest spin {fastest:.2e} rad/s, moved {moved:.2e} m");
        assert!(fastest < 1e-3, "{turn:?}: spun up to {fastest} rad/s");
        assert!(moved < 1e-3, "{turn:?}: moved {moved} m");
    }
}

#[test]
fn a_box_on_the_ground_rests_for_ten_seconds() {
    let mut w = World::new(SolverConfig::default()).unwrap();
    let mut c = Collisions::new();
    ground(&mut w, &mut c);
    let b = cube(&mut w, &mut c, Vec3::new(0.0, 0.26, 0.0), 0.25);
    let mut positions = Vec::new();
    let mut worst = 0.0f32;
    for frame in 0..600 {
        step(&mut w, &c);
        let s = w.body(b).unwrap();
        if frame >= 60 {
            worst = worst.max(0.25 - s.position.y);
            positions.push(s.position);
        }
    }
    let drift = positions
        .iter()
        .map(|p| (*p - positions[0]).length())
        .fold(0.0f32, f32::max);
    let speed = w.body(b).unwrap().linear_velocity.length();
    eprintln!(
        "box: worst penetration {:.3} mm, drift {:.3} mm, final speed {speed:.1e}",
        worst * 1e3,
        drift * 1e3
    );
    assert!(
        worst < 1e-3 && drift < 1e-3 && speed < 1e-2,
        "{worst} {drift} {speed}"
    );
}

#[test]
fn a_stack_of_ten_boxes_stands_for_ten_seconds() {
    // Stacks want substeps rather than iterations (Macklin et al. 2019,
    // "Small steps in physics simulation"): 16 substeps of 2 iterations.
    // Measured over 10 s: 9.7 mm and 0.02 rad (16 x 2), 20 mm (4 x 20),
    // 121 mm (1 x 40). The lean comes from solving a manifold's points one
    // after another with anchors renewed every frame (see docs/contacts.md).
    let mut w = World::new(SolverConfig {
        substeps: 16,
        iterations: 2,
        ..SolverConfig::default()
    })
    .unwrap();
    let mut c = Collisions::new();
    ground(&mut w, &mut c);
    let half = 0.2;
    let boxes: Vec<_> = (0..10)
        .map(|k| {
            cube(
                &mut w,
                &mut c,
                Vec3::new(0.0, half + 2.0 * half * k as f32 + 0.001 * k as f32, 0.0),
                half,
            )
        })
        .collect();
    let start: Vec<Vec3> = boxes.iter().map(|&b| w.body(b).unwrap().position).collect();
    for _ in 0..600 {
        step(&mut w, &c);
    }
    let moved = boxes
        .iter()
        .zip(&start)
        .map(|(&b, s)| (w.body(b).unwrap().position - *s).length())
        .fold(0.0f32, f32::max);
    let top = w.body(boxes[9]).unwrap();
    eprintln!(
        "stack: largest displacement {:.2} mm, top box tilt {:.4} rad",
        moved * 1e3,
        top.orientation.angle_between(Quat::IDENTITY)
    );
    assert!(moved < 0.02, "the stack stands: {moved} m");
    assert!(
        top.orientation.angle_between(Quat::IDENTITY) < 0.05,
        "and stays upright"
    );
}

fn drop_world(backend: Backend, threads: usize) -> (World, Collisions, Vec<Ragdoll>) {
    let config = SolverConfig {
        backend: BackendChoice::Forced(backend),
        threads,
        parallel_min_blocks: 1,
        ..SolverConfig::default()
    };
    drop_ragdolls(config, 3)
}

/// `count` humanoids (rod spine, sockets, rod, ...) lying face down, one
/// above the other, turned, in a world of `config` with a floor.
fn drop_ragdolls(config: SolverConfig, count: usize) -> (World, Collisions, Vec<Ragdoll>) {
    let mut w = World::new(config).unwrap();
    let mut c = Collisions::new();
    ground(&mut w, &mut c);
    let desc = RagdollDesc::reference_humanoid();
    let mut ragdolls = Vec::new();
    for k in 0..count {
        let spine = if k % 2 == 0 {
            SpineMode::Rod
        } else {
            SpineMode::Sockets
        };
        // Lying face down, one above the other, turned.
        let lying = Quat::from_rotation_y(0.6 * k as f32)
            * Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
        let pose = Pose::bind(&desc).moved(
            Vec3::new(0.0, 1.0, 0.0),
            lying,
            Vec3::new(0.0, 0.3 + 0.4 * k as f32 - 1.0, 0.0) + Vec3::Y,
        );
        let r = Ragdoll::build(&mut w, &desc, BuildOptions::new(spine), &pose, None).unwrap();
        c.add_jointed(&r.collision_shapes(), &r.non_colliding_pairs())
            .unwrap();
        ragdolls.push(r);
    }
    (w, c, ragdolls)
}

/// Three ragdolls dropped on each other come to rest: by 8 s every body is
/// still (the top one rolls off the pile until 7 s; asleep by 2 to 7 s
/// over six headings of the three, 2 to 4 s with the contacts not
/// relaxed), none through the floor.
#[test]
fn dropped_ragdolls_come_to_rest_above_the_floor() {
    let (mut w, c, ragdolls) = drop_world(Backend::best(), 1);
    let (mut lowest, mut impact) = (f32::MAX, f32::MAX);
    for frame in 0..480 {
        if frame == 420 {
            // The last second is the resting one; before it, the impact.
            impact = lowest;
            lowest = f32::MAX;
        }
        step(&mut w, &c);
        for r in &ragdolls {
            for (i, b) in r.bodies.iter().enumerate() {
                if let Some(b) = b {
                    let s = w.body(*b).unwrap();
                    let def = &r.description().bodies[i];
                    let half = (def.segment[1] - def.segment[0]) * 0.5;
                    let bottom = (s.position + s.orientation * half)
                        .y
                        .min((s.position - s.orientation * half).y)
                        - def.radius;
                    lowest = lowest.min(bottom);
                }
            }
        }
    }
    let fastest = ragdolls
        .iter()
        .flat_map(|r| r.bodies.iter().flatten())
        .map(|&b| w.body(b).unwrap().linear_velocity.length())
        .fold(0.0f32, f32::max);
    eprintln!(
        "ragdolls: deepest at impact {:.2} mm, at rest {:.2} mm, fastest body after 8 s {fastest:.3} m/s",
        impact * 1e3,
        lowest * 1e3
    );
    assert!(
        lowest > -2e-3,
        "at rest nothing is through the floor: {lowest} m"
    );
    assert!(impact > -0.05, "and never through it: {impact} m");
    assert!(fastest < 0.1, "at rest: {fastest} m/s");
}

#[test]
fn a_colliding_world_is_bit_identical_across_backends_and_threads() {
    let run = |backend: Backend, threads: usize| {
        let (mut w, c, _) = drop_world(backend, threads);
        for _ in 0..120 {
            step(&mut w, &c);
        }
        w.state_hash()
    };
    let reference = run(Backend::Scalar, 1);
    for backend in Backend::available() {
        for threads in [1, 2] {
            assert_eq!(
                run(backend, threads),
                reference,
                "{backend}, {threads} thread(s)"
            );
        }
    }
}

/// With pins (`SolverConfig::pin_contacts`), a limp humanoid dropped face
/// down at eight headings, with each spine: it lands without going through
/// the floor, and over its fourth second its contacts carry its weight
/// (their normal impulse over a frame, the second's mean, is `m g dt` to
/// 1%). Prints, per drop, how far a frame's impulse strays from it and how
/// fast its bodies still move, and the same with iterated contacts: on pins
/// a lying limb can still roll (`docs/direct.md`, "Contacts in the solve:
/// pins").
#[test]
fn a_ragdoll_on_pins_lands_and_rests_its_weight_on_them() {
    for pin_contacts in [PinContacts::Always, PinContacts::Never] {
        let config = SolverConfig {
            sleep: None,
            pin_contacts,
            ..SolverConfig::default()
        };
        for spine in [SpineMode::Rod, SpineMode::Sockets] {
            for heading in 0..8 {
                let lying = Lying::measure(config, spine, 0.4 * heading as f32);
                eprintln!(
                    "{pin_contacts:?}, {spine:?}, heading {heading}: deepest {:.2} mm; its weight {:.3} N s a \
                     frame carried to {:+.4} on the mean, within {:.3} each frame; the fastest \
                     body {:.3} m/s, turn {:.2} rad/s",
                    lying.lowest * 1e3,
                    lying.weight,
                    lying.mean - lying.weight,
                    lying.worst,
                    lying.fastest,
                    lying.spin,
                );
                if pin_contacts == PinContacts::Always {
                    assert!(
                        lying.lowest > -0.02,
                        "through the floor: {} m",
                        lying.lowest
                    );
                    assert!(
                        (lying.mean - lying.weight).abs() < 0.01 * lying.weight,
                        "heading {heading}: its weight is not on its pins: {} of {}",
                        lying.mean,
                        lying.weight
                    );
                }
            }
        }
    }
}

/// One humanoid dropped face down on the floor, 4 s.
struct Lying {
    /// Its lowest point (m).
    lowest: f32,
    /// Its weight over a frame (N s).
    weight: f32,
    /// Over its fourth second, the contacts' normal impulse a frame: its
    /// mean (N s), and its largest difference from the weight.
    mean: f32,
    worst: f32,
    /// Over its fourth second, its bodies' fastest speed (m/s) and turn
    /// (rad/s).
    fastest: f32,
    spin: f32,
}

impl Lying {
    /// Drops the reference humanoid with `spine`, turned `heading` (rad)
    /// about the vertical, 0.3 m above the floor of a world of `config`.
    fn measure(config: SolverConfig, spine: SpineMode, heading: f32) -> Self {
        let mut w = World::new(config).unwrap();
        let mut c = Collisions::new();
        ground(&mut w, &mut c);
        let desc = RagdollDesc::reference_humanoid();
        let lying = Quat::from_rotation_y(heading) * Quat::from_rotation_x(FRAC_PI_2);
        let pose = Pose::bind(&desc).moved(Vec3::Y, lying, Vec3::new(0.0, 0.3, 0.0));
        let r = Ragdoll::build(&mut w, &desc, BuildOptions::new(spine), &pose, None).unwrap();
        c.add_jointed(&r.collision_shapes(), &r.non_colliding_pairs())
            .unwrap();
        let mass: f32 = desc.bodies.iter().map(|b| b.mass).sum();
        let weight = mass * 9.81 * DT;
        let mut out = Lying {
            lowest: f32::MAX,
            weight,
            mean: 0.0,
            worst: 0.0,
            fastest: 0.0,
            spin: 0.0,
        };
        for frame in 0..240 {
            step(&mut w, &c);
            for (b, def) in r.bodies.iter().zip(&desc.bodies) {
                let Some(b) = b else {
                    continue;
                };
                let s = w.body(*b).unwrap();
                let half = (def.segment[1] - def.segment[0]) * 0.5;
                for end in [
                    s.position + s.orientation * half,
                    s.position - s.orientation * half,
                ] {
                    out.lowest = out.lowest.min(end.y - def.radius);
                }
                if frame >= 180 {
                    out.fastest = out.fastest.max(s.linear_velocity.length());
                    out.spin = out.spin.max(s.angular_velocity.length());
                }
            }
            if frame >= 180 {
                let normal: f32 = w.contact_impulses().iter().map(|i| i.normal).sum();
                out.worst = out.worst.max((normal - weight).abs());
                out.mean += normal / 60.0;
            }
        }
        out
    }
}

/// A world with the ground, its contacts pinned as `pins` says, sleeping
/// off.
fn on_ground(pins: PinContacts) -> (World, Collisions) {
    let mut w = World::new(SolverConfig {
        sleep: None,
        pin_contacts: pins,
        ..SolverConfig::default()
    })
    .unwrap();
    let mut c = Collisions::new();
    ground(&mut w, &mut c);
    (w, c)
}

/// A drive with no torque cap turning a chain into the ground: two
/// capsules lying on the ground on sockets, the first to a static anchor,
/// that joint driven 0.5 rad down at 5 Hz. The ground holds the chain on
/// its surface whatever the contacts' solve: iterated, or pinned into the
/// tree's direct solve, where the drive's hard row once overruled the
/// pins' springs and pressed the chain 0.19 m into the ground.
#[test]
fn an_uncapped_drive_does_not_press_a_chain_into_the_ground() {
    use vertebra_world::{AngularDrive, JointDesc, Spring};
    let radius = 0.1;
    for pins in [PinContacts::Never, PinContacts::Driven, PinContacts::Always] {
        let (mut w, mut c) = on_ground(pins);
        let anchor = w
            .add_body(BodyDesc::fixed().with_position(Vec3::new(0.0, radius, 0.0)))
            .unwrap();
        let shape = Shape::capsule(Vec3::new(-0.2, 0.0, 0.0), Vec3::new(0.2, 0.0, 0.0), radius);
        let mut chain = Vec::new();
        let mut parent = anchor;
        for k in 0..2 {
            let at = Vec3::new(0.3 + 0.6 * k as f32, radius, 0.0);
            let desc = BodyDesc::dynamic(shape.mass_properties(1000.0).unwrap()).with_position(at);
            let body = w.add_body(desc).unwrap();
            c.add(Collider::new(body, ColliderShape::Solid(shape)))
                .unwrap();
            let socket = at - Vec3::new(0.3, 0.0, 0.0);
            let mut joint =
                JointDesc::socket_at_world_anchor(w.bodies(), parent, body, socket, Vec3::X)
                    .unwrap();
            if k == 0 {
                let strength = Spring::Frequency {
                    frequency: 5.0,
                    damping_ratio: 1.0,
                };
                joint = joint.with_drive(AngularDrive::new(Quat::from_rotation_z(-0.5), strength));
            }
            w.add_joint(joint).unwrap();
            chain.push(body);
            parent = body;
        }
        let mut lowest = f32::MAX;
        for _ in 0..120 {
            step(&mut w, &c);
            for &b in &chain {
                lowest = lowest.min(w.body(b).unwrap().position.y);
            }
        }
        let heights: Vec<f32> = (chain.iter())
            .map(|&b| w.body(b).unwrap().position.y)
            .collect();
        eprintln!("{pins:?}: centres at {heights:?} m, lowest {lowest} m");
        assert!(lowest > radius - 0.01, "{pins:?}: {lowest} m");
    }
}

/// `PinContacts::Driven` pins every tree a driven joint touches: two
/// capsules falling 2 cm onto the ground, each on a socket to a static anchor
/// (two trees), joined by a driven joint (which closes a loop between
/// them, so it joins neither) step bit for bit as with every tree pinned.
#[test]
fn a_driven_joint_between_two_trees_pins_both() {
    use vertebra_world::{AngularDrive, JointDesc, Spring};
    let radius = 0.1;
    let run = |pins: PinContacts| {
        let (mut w, mut c) = on_ground(pins);
        let shape = Shape::capsule(Vec3::new(-0.2, 0.0, 0.0), Vec3::new(0.2, 0.0, 0.0), radius);
        let mut capsules = Vec::new();
        for z in [0.0, 0.5] {
            let anchor = w
                .add_body(BodyDesc::fixed().with_position(Vec3::new(0.0, radius, z)))
                .unwrap();
            let at = Vec3::new(0.3, radius + 0.02, z);
            let desc = BodyDesc::dynamic(shape.mass_properties(1000.0).unwrap()).with_position(at);
            let body = w.add_body(desc).unwrap();
            c.add(Collider::new(body, ColliderShape::Solid(shape)))
                .unwrap();
            let socket = Vec3::new(0.0, radius + 0.02, z);
            let joint =
                JointDesc::socket_at_world_anchor(w.bodies(), anchor, body, socket, Vec3::X)
                    .unwrap();
            w.add_joint(joint).unwrap();
            capsules.push(body);
        }
        let strength = Spring::Frequency {
            frequency: 2.0,
            damping_ratio: 1.0,
        };
        let drive = AngularDrive::new(Quat::IDENTITY, strength).with_max_torque(50.0);
        let (a, b) = (capsules[0], capsules[1]);
        let between = Vec3::new(0.6, radius + 0.02, 0.25);
        let joint = JointDesc::socket_at_world_anchor(w.bodies(), a, b, between, Vec3::Z)
            .unwrap()
            .with_drive(drive);
        w.add_joint(joint).unwrap();
        for _ in 0..30 {
            step(&mut w, &c);
        }
        (capsules.iter())
            .map(|&b| w.body(b).unwrap().position.to_array().map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    let [never, driven, always] =
        [PinContacts::Never, PinContacts::Driven, PinContacts::Always].map(run);
    assert_ne!(never, always, "the pins change nothing here");
    assert_eq!(driven, always);
}
