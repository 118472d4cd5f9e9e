//! A built scene: its world, what drives it frame by frame, and the
//! metric measured on it.

use std::collections::HashSet;

use glam::Vec3;
use vertebra_collide::Collisions;
use vertebra_ragdoll::{Pose, Ragdoll, RagdollError};
use vertebra_world::{BodyHandle, Contact, JointHandle, RodHandle, World};

use crate::{Following, Frame, Scene};
use vertebra_math::{DefaultFloatMode, PortableQuat};

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
    /// Impulses: (frame, body, impulse in N s through its centre of mass),
    /// applied before that frame's step (the hit reaction).
    pub hits: Vec<(usize, BodyHandle, Vec3)>,
    /// The animation the first ragdoll follows before each step (the
    /// stagger), or `None`.
    pub following: Option<Following>,
    /// The joints the residual error counts: the ragdolls' own (not the
    /// pins holding hips in place) and any the scene adds
    /// ([`Self::with_joints`]).
    joints: HashSet<JointHandle>,
    rods: HashSet<RodHandle>,
    /// The contact list the detection fills and swaps into the world.
    contacts: Vec<Contact>,
    /// Whether [`Self::advance`] measures the residuals after the frame.
    watching: bool,
}

impl SceneWorld {
    pub(crate) fn new(
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
            hits: Vec::new(),
            following: None,
            joints,
            rods,
            contacts: Vec::new(),
            watching: false,
        }
    }

    /// Measuring the residuals after every frame ([`Self::advance`]) or not.
    pub(crate) fn watching(mut self, watching: bool) -> Self {
        self.watching = watching;
        self
    }

    /// Also counting `joints` (not the ragdolls' own) in the residual
    /// error: the heavy chain's hanging socket.
    pub(crate) fn with_joints(mut self, joints: impl IntoIterator<Item = JointHandle>) -> Self {
        self.joints.extend(joints);
        self
    }

    /// With `hits` ([`Self::hits`]).
    pub(crate) fn with_hits(mut self, hits: Vec<(usize, BodyHandle, Vec3)>) -> Self {
        self.hits = hits;
        self
    }

    /// With the first ragdoll following `following` ([`Self::following`]).
    pub(crate) fn with_following(mut self, following: Following) -> Self {
        self.following = Some(following);
        self
    }

    /// Collision detection for a step of `dt` seconds: this scene's
    /// contacts, handed to the world for its next step (nothing without
    /// colliders), through a list kept from frame to frame
    /// (`World::swap_contacts`): no allocation once it has grown.
    pub fn detect(&mut self, dt: f32) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        if let Some(collisions) = &mut self.collisions {
            collisions.find_contacts_into(&self.world, dt, &mut self.contacts)?;
            self.world.swap_contacts(&mut self.contacts)?;
        }
        Ok(())
    }

    /// Frame `frame` of the scene, `dt` seconds, then (when the scene's
    /// config measures residuals) `World::measure_residuals` on its poses,
    /// for [`Self::measure`].
    pub fn advance(&mut self, scene: Scene, frame: usize, dt: f32) -> Result<(), RagdollError> {
        self.frame(scene, frame, dt)?;
        self.watch();
        Ok(())
    }

    /// Measures the residuals of the world's poses (`World::measure_residuals`)
    /// when the scene's config asks for them, for [`Self::measure`].
    pub fn watch(&mut self) {
        if self.watching {
            let _mode = DefaultFloatMode::enter();
            self.world.measure_residuals();
        }
    }

    /// Frame `frame` of the scene, `dt` seconds, and nothing that watches
    /// it: collision detection, the push of figure 7 (controllability,
    /// frames 30 to 90), the hits due this frame, the drives set to follow
    /// the animation (the stagger), the step. What a game pays for the
    /// frame ([`SceneRun::frame_ms`](crate::SceneRun::frame_ms)).
    pub fn frame(&mut self, scene: Scene, frame: usize, dt: f32) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.detect(dt)?;
        if let (Some((body, force)), Scene::Controllability, true) =
            (self.push, scene, (30..90).contains(&frame))
        {
            self.world.add_force(body, force)?;
        }
        for &(_, body, impulse) in self.hits.iter().filter(|h| h.0 == frame) {
            self.world.apply_impulse(body, impulse)?;
        }
        if let (Some(following), Some(ragdoll)) = (&self.following, self.ragdolls.first()) {
            following.follow(ragdoll, &mut self.world, frame, dt)?;
        }
        Ok(self.world.step(dt)?)
    }

    /// The ragdolls' residual error (as of `world`'s last step or
    /// [`World::measure_residuals`]), its largest angular error of any one
    /// joint, and deviation from the target, in
    /// `world`: this scene's own world, or one holding the same bodies and
    /// joints under the same handles (the peer comparison's mirror).
    ///
    /// # Panics
    /// If `world`'s residuals were not measured since its last step: a
    /// scene measures them after every frame ([`Self::advance`]) unless its
    /// config turned
    /// [`SceneConfig::measure_residuals`](crate::SceneConfig::measure_residuals)
    /// off.
    pub fn measure(&self, world: &World) -> Frame {
        let _mode = DefaultFloatMode::enter();
        let r = world
            .residuals()
            .expect("the residuals are measured after every step or on demand");
        let joint_errors = r
            .joints
            .iter()
            .filter(|j| self.joints.contains(&j.joint))
            .map(|j| (j.linear_cm, j.angular_rad, j.limit_rad));
        let rod_errors = r
            .rods
            .iter()
            .filter(|j| self.rods.contains(&j.joint))
            .map(|j| (j.linear_cm, j.angular_rad, j.limit_rad));
        let errors = joint_errors.chain(rod_errors);
        let (eps_lin_cm, eps_ang_rad) = errors
            .clone()
            .fold((0.0, 0.0), |(l, a), (dl, da, _)| (l + dl, a + da));
        let (max_angular_error_rad, max_violation_rad) = errors
            .fold((0.0f32, 0.0f32), |(a, v), (_, da, dv)| {
                (a.max(da), v.max(dv))
            });
        let (mut deviation_cm, mut deviation_rad) = (0.0, 0.0);
        if let Some(target) = &self.target {
            for ragdoll in &self.ragdolls {
                for (i, body) in ragdoll.bodies.iter().enumerate() {
                    if let Some(state) = body.and_then(|b| world.body(b).ok()) {
                        deviation_cm += (state.position - target.bones[i].0).length() * 100.0;
                        deviation_rad +=
                            state.orientation.angle_between_portable(target.bones[i].1);
                    }
                }
            }
        }
        Frame {
            eps_lin_cm,
            eps_ang_rad,
            deviation_cm,
            deviation_rad,
            max_violation_rad,
            max_angular_error_rad,
        }
    }
}
