//! Fast limbs against static geometry at one substep: a ragdoll flung at
//! 35 to 50 m/s into walls and beams 10 cm thick. Speculative contacts
//! stop a body flying straight at a wall (a lone limb flung at 50 m/s,
//! spinning or not, never passed in any of 560 starts tried); they do not
//! stop a limb its joints drag through the wall within the step, which is
//! what continuous collision (`Collisions::after_step`) is for.

use glam::Vec3;
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{BuildOptions, Pose, RagdollDesc, SpineMode};
use vertebra_world::{BodyDesc, JointSolver, Shape, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

/// A slab 10 cm thick (x from 0.6 to 0.7 m), 2 m wide, between heights
/// `low` and `high` (m).
struct Wall {
    low: f32,
    high: f32,
}

/// The walls: a low wall (knee high), beams at hip, waist and chest
/// height.
const WALLS: [Wall; 4] = [
    Wall {
        low: 0.0,
        high: 0.4,
    },
    Wall {
        low: 0.7,
        high: 0.9,
    },
    Wall {
        low: 1.0,
        high: 1.2,
    },
    Wall {
        low: 1.35,
        high: 1.55,
    },
];

/// The bodies of the reference humanoid, standing at `x` (m) and flung at
/// `speed` (m/s) along +x into `wall`, that pass through it within 60
/// frames (each body's centre crossing the slab between its top and
/// bottom), by name, and the world's state hash after them; with `sweep`,
/// each frame is `Collisions::step` (with continuous collision), else
/// detection and step alone.
fn fling(config: SolverConfig, wall: &Wall, x: f32, speed: f32, sweep: bool) -> (Vec<String>, u64) {
    let mut w = World::new(config).unwrap();
    let mut c = Collisions::new();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    let centre = Vec3::new(0.65, 0.5 * (wall.low + wall.high), 0.0);
    let slab = w.add_body(BodyDesc::fixed().with_position(centre)).unwrap();
    let half_extents = Vec3::new(0.05, 0.5 * (wall.high - wall.low), 1.0);
    c.add(Collider::new(
        slab,
        ColliderShape::Solid(Shape::Box { half_extents }),
    ))
    .unwrap();
    let desc = RagdollDesc::reference_humanoid();
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, glam::Quat::IDENTITY, Vec3::X * x);
    let options = BuildOptions::new(SpineMode::Sockets);
    let ragdoll = c
        .build_ragdoll(&mut w, &desc, options, &pose, None)
        .unwrap();
    let bodies: Vec<_> = ragdoll.bodies.iter().flatten().copied().collect();
    for &b in &bodies {
        w.set_body_velocity(b, Vec3::X * speed, Vec3::ZERO).unwrap();
    }
    let mut list = Vec::new();
    let mut before: Vec<Vec3> = bodies
        .iter()
        .map(|&b| w.body(b).unwrap().position)
        .collect();
    let mut through = Vec::new();
    for _ in 0..60 {
        if sweep {
            c.step(&mut w, DT).unwrap();
        } else {
            c.find_contacts_into(&w, DT, &mut list).unwrap();
            w.swap_contacts(&mut list).unwrap();
            w.step(DT).unwrap();
        }
        for (k, &b) in bodies.iter().enumerate() {
            let (p, q) = (w.body(b).unwrap().position, before[k]);
            if q.x < 0.6 && p.x > 0.7 {
                let y = q.y + (p.y - q.y) * (0.65 - q.x) / (p.x - q.x);
                if (wall.low..=wall.high).contains(&y) {
                    let name = &desc.bodies[ragdoll.bone_of(b).unwrap()].name;
                    through.push(format!("{name} at {y:.2} m"));
                }
            }
            before[k] = p;
        }
    }
    (through, w.state_hash())
}

/// [`fling`]'s bodies that passed through.
fn passed(config: SolverConfig, wall: &Wall, x: f32, speed: f32, sweep: bool) -> Vec<String> {
    fling(config, wall, x, speed, sweep).0
}

#[test]
fn a_ragdoll_flung_at_50_m_s_passes_through_no_wall_at_one_substep() {
    let mut before = 0;
    let mut runs = 0;
    for joints in [JointSolver::Direct, JointSolver::Iterative] {
        let config = SolverConfig {
            substeps: 1,
            iterations: 4,
            joints,
            ..SolverConfig::default()
        };
        for wall in &WALLS {
            for x in [0.0, -0.3] {
                for speed in [35.0, 50.0] {
                    runs += 1;
                    let without = passed(config, wall, x, speed, false);
                    before += usize::from(!without.is_empty());
                    let with = passed(config, wall, x, speed, true);
                    assert!(
                        with.is_empty(),
                        "{joints:?}, wall {}-{} m, from x = {x}, {speed} m/s: {with:?} passed through",
                        wall.low,
                        wall.high
                    );
                }
            }
        }
    }
    eprintln!("{before} of {runs} runs had a body pass through without the sweep");
    assert!(
        before > 0,
        "the scenes are ones speculative contacts alone let through"
    );
}

/// The state hash of a ragdoll flung at 50 m/s into the low wall from
/// x = -0.3 m (direct joints, 1 x 4), its bodies swept every frame: the
/// same on every target (CI runs this test under qemu-aarch64 and Node's
/// WASI too). The sweep acts in it: the run without it ends elsewhere.
const FLUNG_GOLDEN: u64 = 0xdc47a94f40168d5e;

#[test]
fn a_swept_ragdoll_steps_to_the_same_bits_on_every_target() {
    let config = SolverConfig {
        substeps: 1,
        iterations: 4,
        ..SolverConfig::default()
    };
    let (through, swept) = fling(config, &WALLS[0], -0.3, 50.0, true);
    assert!(through.is_empty(), "{through:?}");
    let (_, plain) = fling(config, &WALLS[0], -0.3, 50.0, false);
    assert_ne!(swept, plain, "the sweep put no body back");
    assert_eq!(swept, FLUNG_GOLDEN, "{swept:#018x}");
}
