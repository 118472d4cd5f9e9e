//! Arbitrary call sequences on a world.

use glam::Vec3;
use vertebra_world::{
    AngularDrive, BodyDesc, BodyHandle, BodyKind, Contact, Error, JointDesc, JointHandle,
    JointKind, JointSolver, LimitSoftness, MAX_ANGULAR_SPEED_LIMIT, MAX_LINEAR_SPEED_LIMIT,
    RodDesc, RodHandle, RodStiffness, Shape, SolverConfig, Spring, Swing, SwingTwist, UprightDrive,
    World, WorldDrive,
};

use crate::input::Input;

/// What the world held before a call, to check a rejected one changed
/// nothing.
fn fingerprint(world: &World) -> (u64, usize, usize, usize) {
    (
        world.state_hash(),
        world.bodies().len(),
        world.joints().count(),
        world.rods().count(),
    )
}

/// Handles seen so far (live or removed: stale ones must be refused).
#[derive(Default)]
pub(crate) struct Seen {
    pub bodies: Vec<BodyHandle>,
    pub joints: Vec<JointHandle>,
    pub rods: Vec<RodHandle>,
}

impl Seen {
    fn body(&self, input: &mut Input) -> Option<BodyHandle> {
        (!self.bodies.is_empty()).then(|| self.bodies[input.pick(self.bodies.len())])
    }
}

/// A sphere, box or capsule of arbitrary size (m), for a body's mass or a
/// collider.
pub(crate) fn shape(input: &mut Input) -> Shape {
    match input.pick(3) {
        0 => Shape::Sphere {
            radius: input.float(0.5),
        },
        1 => Shape::Box {
            half_extents: input.vec3(0.5),
        },
        _ => Shape::capsule(input.vec3(0.5), input.vec3(0.5), input.float(0.2)),
    }
}

pub(crate) fn add_body(world: &mut World, input: &mut Input) -> Result<BodyHandle, Error> {
    let desc = match input.pick(3) {
        0 => BodyDesc::fixed(),
        // With a mass or without (only the first can become dynamic).
        1 if input.flag() => BodyDesc::kinematic()
            .with_mass(shape(input).mass_properties_with_mass(input.float(100.0))?),
        1 => BodyDesc::kinematic(),
        _ => BodyDesc::dynamic(shape(input).mass_properties_with_mass(input.float(100.0))?),
    };
    world.add_body(
        desc.with_position(input.vec3(5.0))
            .with_orientation(input.quat())
            .with_velocity(input.vec3(20.0), input.vec3(20.0))
            .with_damping(input.float(1.0), input.float(1.0)),
    )
}

pub(crate) fn add_joint(
    world: &mut World,
    seen: &Seen,
    input: &mut Input,
) -> Result<JointHandle, Error> {
    let (Some(a), Some(b)) = (seen.body(input), seen.body(input)) else {
        return Err(Error::SameBody);
    };
    let (anchor, axis) = (input.vec3(5.0), input.vec3(1.0));
    let mut joint = match input.pick(4) {
        0 => JointDesc::hinge_at_world_anchor(world.bodies(), a, b, anchor, axis)?.with_kind(
            JointKind::Hinge {
                range: input.flag().then(|| [input.float(4.0), input.float(4.0)]),
                softness: limit_softness(input),
            },
        ),
        1 => JointDesc::fixed_at(world.bodies(), a, b, anchor)?,
        _ => {
            let socket = JointDesc::socket_at_world_anchor(world.bodies(), a, b, anchor, axis)?;
            socket.with_kind(JointKind::Socket(SwingTwist {
                swing: swing(input),
                twist: input.flag().then(|| [input.float(4.0), input.float(4.0)]),
                softness: limit_softness(input),
            }))
        }
    };
    if input.flag() {
        joint = joint.with_drive(drive(input));
    }
    world.add_joint(joint)
}

/// Any swing limit, valid or not.
fn swing(input: &mut Input) -> Swing {
    match input.pick(4) {
        0 => Swing::Free,
        1 => Swing::Cone(input.float(4.0)),
        2 => Swing::Ellipse {
            y: input.float(4.0),
            z: input.float(4.0),
        },
        _ => Swing::Pyramid {
            y: [input.float(4.0), input.float(4.0)],
            z: [input.float(4.0), input.float(4.0)],
        },
    }
}

/// Hard, or any compliance.
fn limit_softness(input: &mut Input) -> LimitSoftness {
    if input.flag() {
        match input.pick(2) {
            0 => LimitSoftness::Soft(Spring::Compliance {
                compliance: input.float(1.0),
                damping: input.float(100.0),
            }),
            _ => LimitSoftness::Soft(Spring::Frequency {
                frequency: input.float(50.0),
                damping_ratio: input.float(2.0),
            }),
        }
    } else {
        LimitSoftness::Hard
    }
}

/// A drive of either strength, moving or not, limited or not.
fn drive(input: &mut Input) -> AngularDrive {
    let target = input.quat();
    let drive = if input.flag() {
        AngularDrive::compliant(target, input.float(1.0), input.float(10.0))
    } else {
        AngularDrive::spring(target, input.float(50.0), input.float(2.0))
    };
    let drive = drive.with_target_velocity(input.vec3(20.0));
    if input.flag() {
        drive.with_max_torque(input.float(100.0))
    } else {
        drive
    }
}

/// A spring of either kind.
fn spring(input: &mut Input) -> Spring {
    if input.flag() {
        Spring::Compliance {
            compliance: input.float(1.0),
            damping: input.float(10.0),
        }
    } else {
        Spring::Frequency {
            frequency: input.float(50.0),
            damping_ratio: input.float(2.0),
        }
    }
}

/// A world drive (each part on or off, moving or not, capped or not), an
/// upright drive, or either cleared.
pub(crate) fn body_drive(
    world: &mut World,
    body: BodyHandle,
    input: &mut Input,
) -> Result<(), Error> {
    let cap = |input: &mut Input| match input.flag() {
        true => input.float(1000.0),
        false => f32::INFINITY,
    };
    match input.pick(4) {
        0 => {
            let mut drive = WorldDrive::new(input.vec3(5.0), input.quat(), spring(input));
            drive.linear_velocity = input.vec3(20.0);
            drive.angular_velocity = input.vec3(20.0);
            let (linear, angular) = (
                input.flag().then(|| spring(input)),
                input.flag().then(|| spring(input)),
            );
            let drive = drive
                .with_strengths(linear, angular)
                .with_caps(cap(input), cap(input));
            world.set_world_drive(body, Some(drive))
        }
        1 => {
            let axis = input.vec3(1.0).normalize_or(Vec3::Y);
            let drive =
                UprightDrive::new(axis, input.vec3(1.0).normalize_or(Vec3::Y), spring(input));
            world.set_upright_drive(body, Some(drive.with_max_torque(cap(input))))
        }
        2 => world.set_world_drive(body, None),
        _ => world.set_upright_drive(body, None),
    }
}

pub(crate) fn add_rod(
    world: &mut World,
    seen: &Seen,
    input: &mut Input,
) -> Result<RodHandle, Error> {
    let (Some(a), Some(b)) = (seen.body(input), seen.body(input)) else {
        return Err(Error::SameBody);
    };
    let through: Vec<Vec3> = (0..input.pick(3)).map(|_| input.vec3(5.0)).collect();
    let mut rod = RodDesc::from_pose(world.bodies(), a, b, &through)?
        .with_stiffness(rod_stiffness(input), rod_stiffness(input));
    if input.flag() {
        rod = rod.with_max_torque(input.float(100.0));
    }
    if input.flag() {
        rod = rod.with_bend_limit(input.float(4.0));
    }
    if input.flag() {
        rod = rod.with_twist_limit(input.float(4.0), input.float(4.0));
    }
    world.add_rod(rod)
}

/// Any of a rod's stiffness forms, with values the world may refuse.
fn rod_stiffness(input: &mut Input) -> RodStiffness {
    match input.pick(4) {
        0 => RodStiffness::Damped {
            stiffness: input.float(100.0),
            damping: input.float(100.0),
        },
        1 => RodStiffness::Spring {
            frequency: input.float(20.0),
            damping_ratio: input.float(4.0),
        },
        2 => RodStiffness::Relaxation(input.float(1.0)),
        _ => RodStiffness::Kirchhoff(input.float(100.0)),
    }
}

pub(crate) fn set_contacts(world: &mut World, seen: &Seen, input: &mut Input) -> Result<(), Error> {
    let mut contacts = Vec::new();
    for _ in 0..input.pick(5) {
        let (Some(body_a), Some(body_b)) = (seen.body(input), seen.body(input)) else {
            break;
        };
        contacts.push(Contact {
            body_a,
            body_b,
            point: input.vec3(5.0),
            normal: input.vec3(1.0).try_normalize().unwrap_or(Vec3::Y),
            depth: input.float(0.2),
            friction: input.float(1.0),
            restitution: input.float(1.0),
        });
    }
    if !input.flag() {
        return world.set_contacts(&contacts);
    }
    // Handed over without a copy: on a refusal the caller keeps its list.
    let offered = contacts.clone();
    let swapped = world.swap_contacts(&mut contacts);
    match &swapped {
        Ok(()) => assert!(contacts.is_empty(), "a swap hands back an empty list"),
        // Compared as printed: a NaN field is not equal to itself.
        Err(_) => assert_eq!(
            format!("{contacts:?}"),
            format!("{offered:?}"),
            "a refused swap changed the caller's list"
        ),
    }
    swapped
}

/// An impulse of one of the three kinds, at a point near the body or
/// anywhere (static and kinematic bodies refuse them all).
fn impulse(world: &mut World, body: BodyHandle, input: &mut Input) -> Result<(), Error> {
    let impulse = input.vec3(100.0);
    match input.pick(3) {
        0 => world.apply_impulse(body, impulse),
        1 => world.apply_impulse_at(body, impulse, input.vec3(5.0)),
        _ => world.apply_angular_impulse(body, impulse),
    }
}

/// A body's kind switched to any kind (to or from static is refused), or
/// a kinematic move to any pose over any time step.
fn kinematic(world: &mut World, body: BodyHandle, input: &mut Input) -> Result<(), Error> {
    if input.flag() {
        let kinds = [BodyKind::Dynamic, BodyKind::Kinematic, BodyKind::Static];
        world.set_body_kind(body, kinds[input.pick(3)])
    } else {
        let dt = if input.flag() {
            1.0 / 60.0
        } else {
            input.float(0.1)
        };
        world.move_kinematic(body, input.vec3(5.0), input.quat(), dt)
    }
}

/// One call chosen by the input; `Err` is a refusal.
fn call(world: &mut World, seen: &mut Seen, input: &mut Input) -> Result<(), Error> {
    match input.pick(14) {
        0 => add_body(world, input).map(|h| seen.bodies.push(h)),
        1 => match seen.body(input) {
            Some(h) => world.remove_body(h),
            None => Ok(()),
        },
        2 => add_joint(world, seen, input).map(|h| seen.joints.push(h)),
        3 if !seen.joints.is_empty() => {
            world.remove_joint(seen.joints[input.pick(seen.joints.len())])
        }
        4 => add_rod(world, seen, input).map(|h| seen.rods.push(h)),
        5 if !seen.rods.is_empty() => world.remove_rod(seen.rods[input.pick(seen.rods.len())]),
        6 => match seen.body(input) {
            Some(h) => world.set_body_pose(h, input.vec3(5.0), input.quat()),
            None => Ok(()),
        },
        7 => match seen.body(input) {
            Some(h) => world.set_body_velocity(h, input.vec3(50.0), input.vec3(50.0)),
            None => Ok(()),
        },
        8 => set_contacts(world, seen, input),
        9 => match seen.body(input) {
            Some(h) => world.add_force(h, input.vec3(1000.0)),
            None => Ok(()),
        },
        10 => match seen.body(input) {
            Some(h) => impulse(world, h, input),
            None => Ok(()),
        },
        11 => match seen.body(input) {
            Some(h) => kinematic(world, h, input),
            None => Ok(()),
        },
        12 => match seen.body(input) {
            Some(h) => body_drive(world, h, input),
            None => Ok(()),
        },
        _ => world.step(if input.flag() {
            1.0 / 60.0
        } else {
            input.float(0.1)
        }),
    }
}

/// Up to 64 arbitrary calls (bodies, sockets, rods and contacts added and
/// removed, contacts copied in or swapped in without a copy, poses, velocities, forces and impulses set, kinds switched,
/// world and upright drives set and cleared,
/// kinematic bodies moved, steps) with arbitrary floats
/// one time in eight: no panic; every refused call leaves the world as it
/// was; every body stays finite; no pending contact names a removed body;
/// and the step's last-line NaN guard never fires (accepted input must
/// never need it).
pub fn world_api(data: &[u8]) {
    let mut input = Input::new(data);
    let config = SolverConfig {
        iterations: 1 + input.pick(8) as u32,
        substeps: 1 + input.pick(3) as u32,
        joints: joint_solver(&mut input),
        ..SolverConfig::default()
    };
    calls(World::new(config).expect("a valid config"), &mut input);
}

/// As [`world_api`], on a world with arbitrary settings: speed limits up
/// to their ceilings (or wild), gravity and push-out speed arbitrary,
/// residuals measured every step or not, now
/// and then a count far out of range. A refused setting is an error, and
/// every accepted one steps as [`world_api`] promises.
pub fn world_settings(data: &[u8]) {
    let mut input = Input::new(data);
    let config = settings(&mut input);
    match World::new(config) {
        Ok(world) => calls(world, &mut input),
        Err(error) => assert!(!error.to_string().is_empty()),
    }
}

/// Solver settings from the input (one thread: thread counts do not change
/// the bits, and pools are slow to start).
fn settings(input: &mut Input) -> SolverConfig {
    let count = |input: &mut Input| match input.pick(16) {
        0 => u32::MAX - input.pick(4) as u32,
        _ => 1 + input.pick(8) as u32,
    };
    let (substeps, iterations) = (count(input), count(input));
    let speed = |input: &mut Input, ceiling: f32| match input.pick(4) {
        0 => ceiling,
        _ => input.float(ceiling).abs(),
    };
    SolverConfig {
        substeps,
        iterations,
        max_linear_speed: speed(input, MAX_LINEAR_SPEED_LIMIT),
        max_angular_speed: speed(input, MAX_ANGULAR_SPEED_LIMIT),
        max_push_out_speed: match input.pick(4) {
            0 => f32::INFINITY,
            _ => input.float(10.0).abs(),
        },
        gravity: input.vec3(100.0),
        parallel_min_blocks: 1 + input.pick(8),
        measure_residuals: input.flag(),
        joints: joint_solver(input),
        relax_contacts: input.flag(),
        ..SolverConfig::default()
    }
}

/// Either joint solver: every promise holds for both.
fn joint_solver(input: &mut Input) -> JointSolver {
    if input.flag() {
        JointSolver::Direct
    } else {
        JointSolver::Iterative
    }
}

/// Up to 64 calls on `world`, checking the promises after each.
fn calls(mut world: World, input: &mut Input) {
    let mut seen = Seen::default();
    for _ in 0..64 {
        if input.is_empty() {
            break;
        }
        let before = fingerprint(&world);
        let result = call(&mut world, &mut seen, input);
        if let Err(error) = result {
            assert!(!error.to_string().is_empty());
            assert_eq!(
                fingerprint(&world),
                before,
                "refused ({error}) but changed the world"
            );
        }
        let store = world.bodies();
        for i in (0..store.capacity()).filter(|&i| store.is_live(i)) {
            assert!(store.is_finite(i), "body {i} went non-finite");
        }
        let live = |b: BodyHandle| store.contains(b);
        assert!(
            world
                .contacts()
                .iter()
                .all(|c| live(c.body_a) && live(c.body_b)),
            "a pending contact names a removed body"
        );
        assert_eq!(
            world.repaired_bodies(),
            0,
            "accepted input tripped the step's NaN guard"
        );
        if let Some(r) = world.residuals() {
            assert!(
                r.eps_lin_cm.is_finite() && r.eps_ang_rad.is_finite(),
                "measured residuals are not finite"
            );
        }
    }
}
