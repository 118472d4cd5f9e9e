//! Building each scene's world.

use core::fmt;
use core::str::FromStr;
use std::collections::HashSet;

use glam::{Quat, Vec3};
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{
    BuildOptions, DriveSettings, Pose, Ragdoll, RagdollDesc, RagdollError, SpineMode, Strength,
};
use vertebra_world::{
    AngularDrive, BackendChoice, BodyDesc, BodyHandle, JointDesc, JointHandle, RodHandle, Shape,
    SolverConfig, World,
};

use crate::Frame;

/// A scene of the paper.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scene {
    /// Figures 2 and 8 (left): the hips fixed, the upper body slumps.
    PassiveBending,
    /// Figures 1 and 8 (right): 30 ragdolls dropped into a pit.
    RagdollDrop,
    /// Figure 7: the hips fixed, every joint driven to the bind pose, the
    /// chest pushed.
    Controllability,
}

impl Scene {
    /// Every simulated scene.
    pub const ALL: [Scene; 3] = [
        Scene::PassiveBending,
        Scene::RagdollDrop,
        Scene::Controllability,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Scene::PassiveBending => "passive-bending",
            Scene::RagdollDrop => "ragdoll-drop",
            Scene::Controllability => "controllability",
        }
    }

    /// Frames the paper's figure runs.
    pub fn default_frames(self) -> usize {
        match self {
            Scene::PassiveBending => 300,
            Scene::RagdollDrop => 600,
            Scene::Controllability => 240,
        }
    }
}

impl fmt::Display for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Scene {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Scene::ALL.into_iter().find(|x| x.name() == s).ok_or_else(|| {
            format!("unknown scene `{s}` (expected passive-bending, ragdoll-drop or controllability)")
        })
    }
}

/// How to run a scene.
#[derive(Clone, Debug)]
pub struct SceneConfig {
    /// Which scene.
    pub scene: Scene,
    /// Rod (simplified) or sockets (standard).
    pub spine: SpineMode,
    /// Position iterations per substep.
    pub iterations: u32,
    /// Substeps per frame.
    pub substeps: u32,
    /// Frames to run (the scene's default when `None`).
    pub frames: Option<usize>,
    /// Kernel backend.
    pub backend: BackendChoice,
    /// Worker threads.
    pub threads: usize,
    /// The ragdoll (the reference humanoid when `None`).
    pub ragdoll: Option<RagdollDesc>,
    /// Ragdolls dropped in the ragdoll-drop scene (the paper's 30; see
    /// [`ragdoll_drop`] for more).
    pub ragdolls: usize,
    /// The start: 0 is the paper's scene exactly; any other seed moves each
    /// ragdoll by at most 1 mm and 0.1 degree ([`crate::seed`]).
    pub seed: u64,
}

impl SceneConfig {
    /// The paper's settings for `scene` with `spine`.
    pub fn new(scene: Scene, spine: SpineMode) -> Self {
        Self {
            scene,
            spine,
            iterations: 20,
            substeps: 1,
            frames: None,
            backend: BackendChoice::Auto,
            threads: 1,
            ragdoll: None,
            ragdolls: 30,
            seed: 0,
        }
    }

    pub(crate) fn world(&self) -> Result<World, RagdollError> {
        let config = SolverConfig {
            iterations: self.iterations,
            substeps: self.substeps,
            backend: self.backend,
            threads: self.threads,
            ..SolverConfig::default()
        };
        Ok(World::new(config)?)
    }

    pub(crate) fn description(&self) -> RagdollDesc {
        self.ragdoll
            .clone()
            .unwrap_or_else(RagdollDesc::reference_humanoid)
    }
}

/// A built scene: its world, collisions and ragdolls, and what is
/// measured. [`SceneWorld::advance`] runs one frame as [`run`](crate::run)
/// does; [`SceneWorld::measure`] measures any world holding the same joints
/// (the peer comparison measures a mirror of another engine's bodies).
pub struct SceneWorld {
    /// The world.
    pub world: World,
    /// The colliders (the ragdoll drop), or `None`.
    pub collisions: Option<Collisions>,
    /// The ragdolls.
    pub ragdolls: Vec<Ragdoll>,
    /// Target pose for the deviation metric (controllability).
    pub target: Option<Pose>,
    /// The body pushed, and the force (N) (controllability).
    pub push: Option<(BodyHandle, Vec3)>,
    /// The ragdolls' joints: the residual error counts these (not the pins
    /// holding hips in place).
    joints: HashSet<JointHandle>,
    rods: HashSet<RodHandle>,
}

impl SceneWorld {
    fn new(
        world: World,
        collisions: Option<Collisions>,
        ragdolls: Vec<Ragdoll>,
        target: Option<Pose>,
        push: Option<(BodyHandle, Vec3)>,
    ) -> Self {
        let joints = ragdolls
            .iter()
            .flat_map(|r| r.joints.iter().flatten().copied())
            .collect();
        let rods = ragdolls.iter().filter_map(|r| r.rod).collect();
        Self {
            world,
            collisions,
            ragdolls,
            target,
            push,
            joints,
            rods,
        }
    }

    /// Collision detection for a step of `dt` seconds: this scene's
    /// contacts, handed to the world for its next step (nothing without
    /// colliders).
    pub fn detect(&mut self, dt: f32) -> Result<(), RagdollError> {
        if let Some(collisions) = &self.collisions {
            let contacts = collisions.find_contacts(&self.world, dt)?;
            self.world.set_contacts(&contacts)?;
        }
        Ok(())
    }

    /// Frame `frame` of the scene, `dt` seconds: collision detection, the
    /// push of figure 7 (controllability, frames 30 to 90), the step.
    pub fn advance(&mut self, scene: Scene, frame: usize, dt: f32) -> Result<(), RagdollError> {
        self.detect(dt)?;
        if let (Some((body, force)), Scene::Controllability, true) =
            (self.push, scene, (30..90).contains(&frame))
        {
            self.world.add_force(body, force)?;
        }
        Ok(self.world.step(dt)?)
    }

    /// The ragdolls' residual error (as of `world`'s last step or
    /// [`World::measure_residuals`]) and deviation from the target, in
    /// `world`: this scene's own world, or one holding the same bodies and
    /// joints under the same handles (the peer comparison's mirror).
    pub fn measure(&self, world: &World) -> Frame {
        let r = world.residuals();
        let joint_errors = r
            .joints
            .iter()
            .filter(|j| self.joints.contains(&j.joint))
            .map(|j| (j.linear_cm, j.angular_rad));
        let rod_errors = r
            .rods
            .iter()
            .filter(|j| self.rods.contains(&j.joint))
            .map(|j| (j.linear_cm, j.angular_rad));
        let (eps_lin_cm, eps_ang_rad) = joint_errors
            .chain(rod_errors)
            .fold((0.0, 0.0), |(l, a), (dl, da)| (l + dl, a + da));
        let (mut deviation_cm, mut deviation_rad) = (0.0, 0.0);
        if let Some(target) = &self.target {
            for ragdoll in &self.ragdolls {
                for (i, body) in ragdoll.bodies.iter().enumerate() {
                    if let Some(state) = body.and_then(|b| world.body(b).ok()) {
                        deviation_cm += (state.position - target.bones[i].0).length() * 100.0;
                        deviation_rad += state.orientation.angle_between(target.bones[i].1);
                    }
                }
            }
        }
        Frame {
            eps_lin_cm,
            eps_ang_rad,
            deviation_cm,
            deviation_rad,
        }
    }
}

/// A ragdoll at `pose` whose root body (the hips) is held where it is.
fn ragdoll_with_fixed_hips(
    world: &mut World,
    desc: &RagdollDesc,
    spine: SpineMode,
    pose: &Pose,
) -> Result<Ragdoll, RagdollError> {
    let ragdoll = Ragdoll::build(world, desc, BuildOptions::new(spine), pose, None)?;
    fix(
        world,
        ragdoll.bodies[desc.root].expect("the root body exists"),
    )?;
    Ok(ragdoll)
}

/// Holds `body` where it is: a static anchor and a socket with a stiff
/// drive (its error is not counted in the ragdoll's residuals).
fn fix(world: &mut World, body: BodyHandle) -> Result<(), RagdollError> {
    let at = world.body(body)?.position;
    let anchor = world.add_body(
        BodyDesc::fixed()
            .with_position(at)
            .with_orientation(world.body(body)?.orientation),
    )?;
    let pin = JointDesc::socket_at_world_anchor(world.bodies(), anchor, body, at, Vec3::Y)?
        .with_drive(AngularDrive::rigid(Quat::IDENTITY));
    world.add_joint(pin)?;
    Ok(())
}

/// Builds `config`'s scene at its first frame.
pub fn build(config: &SceneConfig) -> Result<SceneWorld, RagdollError> {
    let desc = config.description();
    let mut world = config.world()?;
    match config.scene {
        Scene::PassiveBending => {
            // Bind pose leaned 30 degrees about +X through the hips centre
            // (0, 1, 0): the upper body toward +Z.
            let pose = Pose::bind(&desc).moved(
                Vec3::new(0.0, 1.0, 0.0),
                Quat::from_rotation_x(30f32.to_radians()),
                Vec3::ZERO,
            );
            let pose = seeded(pose, &desc, config.seed, 0);
            let ragdoll = ragdoll_with_fixed_hips(&mut world, &desc, config.spine, &pose)?;
            Ok(SceneWorld::new(world, None, vec![ragdoll], None, None))
        }
        Scene::Controllability => {
            let pose = seeded(Pose::bind(&desc), &desc, config.seed, 0);
            let ragdoll = ragdoll_with_fixed_hips(&mut world, &desc, config.spine, &pose)?;
            ragdoll.drive_to(
                &mut world,
                &pose,
                &DriveSettings::uniform(Strength::Infinite),
            )?;
            // 200 N along +Z on the top of the spine (the chest).
            let push = ragdoll.bodies[spine_top(&desc)].map(|c| (c, Vec3::new(0.0, 0.0, 200.0)));
            Ok(SceneWorld::new(
                world,
                None,
                vec![ragdoll],
                Some(pose),
                push,
            ))
        }
        Scene::RagdollDrop => {
            let (world, collisions, ragdolls) =
                ragdoll_drop(world, &desc, config.spine, config.ragdolls, config.seed)?;
            Ok(SceneWorld::new(
                world,
                Some(collisions),
                ragdolls,
                None,
                None,
            ))
        }
    }
}

/// `pose` moved and turned about its root by ragdoll `index`'s seeded
/// perturbation; `pose` itself, bit for bit, for seed 0.
fn seeded(pose: Pose, desc: &RagdollDesc, seed: u64, index: usize) -> Pose {
    if seed == 0 {
        return pose;
    }
    let (offset, turn) = crate::seed::perturbation(seed, index);
    let root = pose.bones[desc.root].0;
    pose.moved(root, turn, offset)
}

/// The top of the spine chain (the chest), or the root when there is none.
fn spine_top(desc: &RagdollDesc) -> usize {
    desc.spine
        .as_ref()
        .and_then(|s| s.bodies.last().copied())
        .unwrap_or(desc.root)
}

/// Ragdolls per pit in [`ragdoll_drop`]: the paper's figure.
pub const RAGDOLLS_PER_PIT: usize = 30;

/// Distance (m) between the centres of neighbouring pits along +X.
const PIT_SPACING: f32 = 4.0;

/// The paper's ragdoll-drop world for `count` ragdolls: ground with its top
/// at y = 0 and, per 30 ragdolls, a pit (the first centred on the origin,
/// the next 4 m further along +X each): four static walls (inner faces at
/// x, z = +-1.5 about the pit's centre, 1 m tall, 0.1 m thick) and three
/// static boxes of half-extents (0.3, 0.15, 0.3). A pit's ragdolls lie face
/// down in 10 layers of 3, layer `j` turned by 37 j degrees about +Y, hips
/// at (0, 1 + 0.5 j, 0) + (i - 1) 0.6 u_j from its centre. A ragdoll's
/// jointed pairs never collide. With 30 and seed 0 this is exactly the
/// paper's scene; another seed moves each ragdoll by at most 1 mm and 0.1
/// degree ([`crate::seed`]).
pub fn ragdoll_drop(
    mut world: World,
    desc: &RagdollDesc,
    spine: SpineMode,
    count: usize,
    seed: u64,
) -> Result<(World, Collisions, Vec<Ragdoll>), RagdollError> {
    let mut collisions = Collisions::new();
    let mut fixed = |world: &mut World,
                     at: Vec3,
                     turn: Quat,
                     shape: ColliderShape|
     -> Result<(), RagdollError> {
        let body = world.add_body(BodyDesc::fixed().with_position(at).with_orientation(turn))?;
        collisions.add(Collider::new(body, shape))?;
        Ok(())
    };
    fixed(
        &mut world,
        Vec3::ZERO,
        Quat::IDENTITY,
        ColliderShape::Plane(Vec3::Y),
    )?;
    let pits = count.div_ceil(RAGDOLLS_PER_PIT);
    let centre = |pit: usize| Vec3::X * (PIT_SPACING * pit as f32);
    for pit in 0..pits {
        let half_box = Vec3::new(0.3, 0.15, 0.3);
        let walls = [
            (Vec3::new(1.55, 0.5, 0.0), Vec3::new(0.05, 0.5, 1.6), 0.0),
            (Vec3::new(-1.55, 0.5, 0.0), Vec3::new(0.05, 0.5, 1.6), 0.0),
            (Vec3::new(0.0, 0.5, 1.55), Vec3::new(1.6, 0.5, 0.05), 0.0),
            (Vec3::new(0.0, 0.5, -1.55), Vec3::new(1.6, 0.5, 0.05), 0.0),
        ];
        let boxes = [
            (Vec3::new(0.6, 0.15, 0.6), half_box, 0.0f32),
            (Vec3::new(-0.7, 0.25, -0.2), half_box, 30f32.to_radians()),
            (Vec3::new(0.2, 0.1, -0.8), half_box, 0.0),
        ];
        for (at, half, turn) in walls.into_iter().chain(boxes) {
            fixed(
                &mut world,
                centre(pit) + at,
                Quat::from_rotation_y(turn),
                ColliderShape::Solid(Shape::Box { half_extents: half }),
            )?;
        }
    }
    let hips = desc.bodies[desc.root].centre();
    let mut ragdolls = Vec::new();
    for index in 0..count {
        let (pit, k) = (index / RAGDOLLS_PER_PIT, index % RAGDOLLS_PER_PIT);
        let (layer, slot) = (k / 3, k % 3);
        let yaw = (37.0 * layer as f32).to_radians();
        let turn = Quat::from_rotation_y(yaw) * Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
        let u = Vec3::new(yaw.cos(), 0.0, -yaw.sin());
        let at = centre(pit)
            + Vec3::new(0.0, 1.0 + 0.5 * layer as f32, 0.0)
            + u * (0.6 * (slot as f32 - 1.0));
        let pose = seeded(
            Pose::bind(desc).moved(hips, turn, at - hips),
            desc,
            seed,
            index,
        );
        let ragdoll = Ragdoll::build(&mut world, desc, BuildOptions::new(spine), &pose, None)?;
        collisions.add_ragdoll(&ragdoll)?;
        ragdolls.push(ragdoll);
    }
    Ok((world, collisions, ragdolls))
}
