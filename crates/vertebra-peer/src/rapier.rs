//! Translating a vertebra scene into rapier3d.

use core::fmt;
use std::collections::{HashMap, HashSet};

use glam::Vec3;
use parry3d::math::Pose;
use rapier3d::prelude::*;
use vertebra_scenes::SceneWorld;
use vertebra_world::{
    AngularDrive, BodyHandle, BodyKind, JointDesc, JointKind, LimitSoftness, Swing, SwingTwist,
    World,
};

/// Rapier's solver budget per frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RapierSettings {
    /// `IntegrationParameters::num_solver_iterations`: rapier's substeps
    /// per frame (its TGS-soft solver integrates once per solver iteration).
    pub solver_iterations: usize,
    /// `IntegrationParameters::num_internal_pgs_iterations`: velocity
    /// (PGS) sweeps per solver iteration.
    pub pgs_iterations: usize,
}

impl RapierSettings {
    /// The settings of the comparison: rapier's default (4 x 1), its closest
    /// match to 20 iterations (20 x 1: twenty constraint sweeps and twenty
    /// integrations) and 20 sweeps in one substep (1 x 20).
    pub const COMPARED: [RapierSettings; 3] = [
        RapierSettings::new(4, 1),
        RapierSettings::new(20, 1),
        RapierSettings::new(1, 20),
    ];

    /// `solver_iterations` x `pgs_iterations`.
    pub const fn new(solver_iterations: usize, pgs_iterations: usize) -> Self {
        Self {
            solver_iterations,
            pgs_iterations,
        }
    }
}

impl fmt::Display for RapierSettings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "rapier {}x{}",
            self.solver_iterations, self.pgs_iterations
        )
    }
}

/// What cannot be translated.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PeerError {
    /// A joint or setting rapier has no counterpart for.
    Unsupported(&'static str),
    /// The scene's world refused a mirrored pose (a stale handle).
    Mirror(String),
}

impl fmt::Display for PeerError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PeerError::Unsupported(what) => write!(f, "rapier has no counterpart for {what}"),
            PeerError::Mirror(why) => write!(f, "cannot mirror rapier's poses: {why}"),
        }
    }
}

impl std::error::Error for PeerError {}

/// Filters out the collider pairs the scene excludes (a ragdoll's jointed
/// bodies), as vertebra's collision layer does.
struct Excluded(HashSet<(ColliderHandle, ColliderHandle)>);

impl PhysicsHooks for Excluded {
    fn filter_contact_pair(&self, context: &PairFilterContext) -> Option<SolverFlags> {
        let pair = (context.collider1, context.collider2);
        let excluded = self.0.contains(&pair) || self.0.contains(&(pair.1, pair.0));
        (!excluded).then_some(SolverFlags::COMPUTE_RIGID_IMPULSES)
    }
}

/// A scene rebuilt in rapier, and the map back to the scene's bodies.
pub struct RapierScene {
    physics: PhysicsWorld,
    hooks: Excluded,
    /// Rapier's body per vertebra body, in the scene world's slot order.
    bodies: Vec<(BodyHandle, RigidBodyHandle)>,
}

impl RapierScene {
    /// Rebuilds `scene` (at its current state) in rapier with `settings`,
    /// stepping `dt` seconds per frame, with the world's gravity. Sleeping is
    /// off, as vertebra has none.
    pub fn from_scene(
        scene: &SceneWorld,
        settings: RapierSettings,
        dt: f32,
    ) -> Result<Self, PeerError> {
        let world = &scene.world;
        let mut physics = PhysicsWorld::new();
        physics.gravity = world.config().gravity;
        let parameters = &mut physics.integration_parameters;
        parameters.dt = dt;
        parameters.num_solver_iterations = settings.solver_iterations;
        parameters.num_internal_pgs_iterations = settings.pgs_iterations;
        let bodies = translate_bodies(world, &mut physics.bodies);
        let handle: HashMap<BodyHandle, RigidBodyHandle> = bodies.iter().copied().collect();
        let hooks = Excluded(translate_colliders(scene, &handle, &mut physics));
        for &(_, rigid) in &bodies {
            physics.bodies[rigid].recompute_mass_properties_from_colliders(&physics.colliders);
        }
        // Leaves first: rapier's result depends on the order joints are
        // inserted. In slot order (root first) the passive-bending ragdoll
        // lost its hips-spine swing limit (72 degrees against 20); from the
        // leaves in, every limit holds (tests/peer.rs).
        let sockets: Vec<_> = world.joints().map(|(_, s)| s).collect();
        for socket in sockets.into_iter().rev() {
            let joint = translate_socket(&socket)?;
            let (a, b) = (handle[&socket.body_a], handle[&socket.body_b]);
            physics.impulse_joints.insert(a, b, joint, true);
        }
        if world.rods().next().is_some() {
            return Err(PeerError::Unsupported(
                "a rod constraint (build the scene with socket spines)",
            ));
        }
        Ok(Self {
            physics,
            hooks,
            bodies,
        })
    }

    /// One frame: rapier's collision detection and solve.
    pub fn step(&mut self) {
        self.physics.step_with_events(&self.hooks, &());
    }

    /// Copies rapier's body poses into `world` (the scene's world, whose
    /// handles these are) and measures its residuals there.
    pub fn mirror(&self, world: &mut World) -> Result<(), PeerError> {
        for &(body, rigid) in &self.bodies {
            let pose = self.physics.bodies[rigid].position();
            world
                .set_body_pose(body, pose.translation, pose.rotation.normalize())
                .map_err(|e| PeerError::Mirror(e.to_string()))?;
        }
        world.measure_residuals();
        Ok(())
    }

    /// Rapier's pose of `body` (centre of mass, world), if it was translated.
    pub fn pose(&self, body: BodyHandle) -> Option<(Vec3, glam::Quat)> {
        let (_, rigid) = self.bodies.iter().find(|(b, _)| *b == body)?;
        let pose = self.physics.bodies[*rigid].position();
        Some((pose.translation, pose.rotation))
    }

    /// Rapier's mass and body-frame inertia (kg, kg m^2) of `body`.
    pub fn mass_properties(&self, body: BodyHandle) -> Option<(f32, glam::Mat3)> {
        let (_, rigid) = self.bodies.iter().find(|(b, _)| *b == body)?;
        let props = self.physics.bodies[*rigid].mass_properties().local_mprops;
        Some((props.mass(), props.reconstruct_inertia_matrix()))
    }
}

/// Every live body, dynamic ones with vertebra's mass and body-frame
/// inertia about the centre of mass (the colliders add none).
fn translate_bodies(world: &World, set: &mut RigidBodySet) -> Vec<(BodyHandle, RigidBodyHandle)> {
    let store = world.bodies();
    (0..store.capacity())
        .filter_map(|i| store.handle_at(i).map(|h| (i, h)))
        .map(|(i, handle)| {
            let builder = match store.kind[i] {
                BodyKind::Dynamic => RigidBodyBuilder::dynamic().additional_mass_properties(
                    MassProperties::with_inertia_matrix(
                        Vec3::ZERO,
                        store.mass[i],
                        store.inertia[i],
                    ),
                ),
                BodyKind::Kinematic => RigidBodyBuilder::kinematic_velocity_based(),
                BodyKind::Static => RigidBodyBuilder::fixed(),
            };
            let body = builder
                .pose(Pose::from_parts(store.position[i], store.orientation[i]))
                .linvel(store.linear_velocity[i])
                .angvel(store.angular_velocity[i])
                .linear_damping(store.linear_damping[i])
                .angular_damping(store.angular_damping[i])
                .can_sleep(false)
                .build();
            (handle, set.insert(body))
        })
        .collect()
}

/// Every collider with its shape, friction (averaged: the scenes use one
/// value, so vertebra's geometric mean is the same), restitution (the
/// larger, as vertebra) and groups; returns the excluded collider pairs.
fn translate_colliders(
    scene: &SceneWorld,
    handle: &HashMap<BodyHandle, RigidBodyHandle>,
    physics: &mut PhysicsWorld,
) -> HashSet<(ColliderHandle, ColliderHandle)> {
    let Some(collisions) = &scene.collisions else {
        return HashSet::new();
    };
    let mut made = Vec::new();
    for (collider, shape) in collisions.shapes() {
        let groups = InteractionGroups::new(
            Group::from_bits_retain(collider.groups.membership),
            Group::from_bits_retain(collider.groups.filter),
            InteractionTestMode::And,
        );
        let built = ColliderBuilder::new(shape.clone())
            .density(0.0)
            .friction(collider.friction)
            .friction_combine_rule(CoefficientCombineRule::Average)
            .restitution(collider.restitution)
            .restitution_combine_rule(CoefficientCombineRule::Max)
            .collision_groups(groups)
            .active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS)
            .build();
        let rigid = handle[&collider.body];
        let made_handle = physics
            .colliders
            .insert_with_parent(built, rigid, &mut physics.bodies);
        made.push((collider.body, made_handle));
    }
    let mut excluded = HashSet::new();
    for (i, &(a, ca)) in made.iter().enumerate() {
        for &(b, cb) in &made[i + 1..] {
            if a == b || collisions.is_excluded(a, b) {
                excluded.insert((ca, cb));
            }
        }
    }
    excluded
}

/// A socket as a spherical joint: the same anchors and frames (+X the
/// twist axis), the twist range on +X, and the swing cone as the square
/// inscribed in it: a limit of `swing / sqrt 2` on each swing axis (rapier
/// limits axes, not cones). Inscribed, every pose rapier allows is inside
/// the cone, so the angular error our metric reports is rapier's own
/// violation, not the corners of a square the cone does not contain. A pin (a drive of zero
/// compliance and damping) is a fixed joint at the drive's target.
fn translate_socket(socket: &JointDesc) -> Result<GenericJoint, PeerError> {
    let frame_a = Pose::from_parts(socket.anchor_a, socket.frame_a);
    let frame_b = Pose::from_parts(socket.anchor_b, socket.frame_b);
    if let Some(drive) = socket.drive {
        let rigid = AngularDrive::rigid(drive.target);
        if drive != rigid {
            return Err(PeerError::Unsupported("a soft angular drive"));
        }
        let target = Pose::from_parts(socket.anchor_a, socket.frame_a * drive.target);
        let joint = FixedJointBuilder::new()
            .local_frame1(target)
            .local_frame2(frame_b)
            .build();
        return Ok(joint.into());
    }
    let limits = match socket.kind {
        JointKind::Socket(
            limits @ SwingTwist {
                swing: Swing::Free | Swing::Cone(_),
                softness: LimitSoftness::Hard,
                ..
            },
        ) => limits,
        _ => {
            return Err(PeerError::Unsupported(
                "a joint other than a socket with a hard circular cone",
            ));
        }
    };
    let mut joint = SphericalJointBuilder::new()
        .local_frame1(frame_a)
        .local_frame2(frame_b);
    if let Swing::Cone(swing) = limits.swing {
        let swing = swing * core::f32::consts::FRAC_1_SQRT_2;
        joint = joint
            .limits(JointAxis::AngY, [-swing, swing])
            .limits(JointAxis::AngZ, [-swing, swing]);
    }
    if let Some([min, max]) = limits.twist {
        joint = joint.limits(JointAxis::AngX, [min, max]);
    }
    Ok(joint.build().into())
}
