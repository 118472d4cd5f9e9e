//! Blending back from ragdoll to animation (getting up): the ragdoll's
//! last simulated pose held, and the animation faded in over it with a
//! smooth weight, so the output skeleton leaves the ragdoll without a pop.
//!
//! The ragdoll's weight falls from 1 to 0 over `duration` seconds along
//! smoothstep, `w(t) = 1 - s(t / duration)` with `s(x) = 3 x^2 - 2 x^3`:
//! its rate is zero at both ends (no jolt as the blend starts or ends) and
//! at most `1.5 / duration` per second, in the middle. Each bone of the
//! output is the animation's blended toward the held pose at `w`
//! ([`Pose::blend`]): from frame to frame it moves by at most its
//! animation's own motion plus `|w' - w|` times its distance from the held
//! pose (metres for positions, radians for rotations), and `|w' - w|` is
//! at most `1.5 dt / duration`.

use crate::error::RagdollError;
use crate::model::RagdollDesc;
use crate::pose::Pose;
use crate::skeleton::{LocalPose, Skeleton};
use vertebra_math::DefaultFloatMode;

/// A pose that blends bone by bone with another of its kind: a ragdoll
/// [`Pose`] (checked against its [`RagdollDesc`]) or a skeleton's
/// [`LocalPose`] (checked against its [`Skeleton`]).
pub trait Blend: Sized {
    /// What a pose is checked against.
    type Rig;
    /// This pose blended with `other` at `weight` for every bone (0: this
    /// pose, 1: `other`); refused as the per-bone blend is.
    fn blend_all(&self, rig: &Self::Rig, other: &Self, weight: f32) -> Result<Self, RagdollError>;
}

impl Blend for Pose {
    type Rig = RagdollDesc;
    fn blend_all(
        &self,
        desc: &RagdollDesc,
        other: &Pose,
        weight: f32,
    ) -> Result<Pose, RagdollError> {
        self.blend(desc, other, &vec![weight; desc.bodies.len()])
    }
}

impl Blend for LocalPose {
    type Rig = Skeleton;
    fn blend_all(
        &self,
        skeleton: &Skeleton,
        other: &LocalPose,
        weight: f32,
    ) -> Result<LocalPose, RagdollError> {
        self.blend(skeleton, other, &vec![weight; skeleton.len()])
    }
}

/// The fade from a ragdoll's last simulated pose back to the animation.
/// Each frame: [`BlendBack::pose`] with the animation's pose of the frame,
/// then [`BlendBack::advance`] by the frame's time. The first frame's
/// output is the simulated pose, every frame from `duration` on the
/// animation's, both exactly.
///
/// A partial ragdoll (legs on the animation, upper body limp) blended back
/// to the animation once it is done:
///
/// ```
/// use glam::{Quat, Vec3};
/// use vertebra_ragdoll::{
///     BlendBack, BuildOptions, Pose, Ragdoll, RagdollDesc, SpineMapping, SpineMode,
/// };
/// use vertebra_world::{SolverConfig, World};
///
/// # fn main() -> Result<(), vertebra_ragdoll::RagdollError> {
/// let desc = RagdollDesc::reference_humanoid();
/// let mut world = World::new(SolverConfig::default())?;
/// // The animation: here the bind pose gliding forward at 1.2 m/s.
/// let animation =
///     |t: f32| Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::new(0.0, 0.0, 1.2 * t));
/// let dt = 1.0 / 60.0;
/// let options = BuildOptions::new(SpineMode::Rod);
/// let ragdoll = Ragdoll::build(&mut world, &desc, options, &animation(0.0), None)?;
/// for legs in ["hips", "thigh_l", "shin_l", "thigh_r", "shin_r"] {
///     ragdoll.set_body_kinematic(&mut world, legs, true)?;
/// }
/// for frame in 1..=60 {
///     let next = animation(frame as f32 * dt);
///     ragdoll.drive_to_pose_using_kinematics(&mut world, &next, dt)?;
///     world.step(dt)?;
/// }
/// // Back to the animation over 0.4 s, from where the ragdoll ended.
/// let last = ragdoll.skeleton_pose(&world, SpineMapping::Arc)?;
/// let mut blend = BlendBack::new(&desc, last, 0.4)?;
/// let mut t = 1.0;
/// while !blend.is_done() {
///     let output = blend.pose(&desc, &animation(t))?; // onto the skeleton
///     assert_eq!(output.bones.len(), desc.bodies.len());
///     blend.advance(dt)?;
///     t += dt;
/// }
/// assert_eq!(blend.pose(&desc, &animation(t))?, animation(t));
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct BlendBack<P> {
    simulated: P,
    duration: f32,
    elapsed: f32,
}

impl<P: Blend> BlendBack<P> {
    /// A blend starting at the ragdoll's `simulated` pose (held from now
    /// on: stop the ragdoll, or remove it, as the blend starts) and
    /// reaching the animation after `duration` seconds. Refused for a pose
    /// that does not fit `rig` (naming the bone) and a duration that is not
    /// finite and positive.
    pub fn new(rig: &P::Rig, simulated: P, duration: f32) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        if !(duration.is_finite() && duration > 0.0) {
            return Err(RagdollError::OutOfRange {
                context: "blend back".to_owned(),
                field: "duration",
                reason: format!("is {duration} s; must be finite and positive"),
            });
        }
        // Blended with itself, the pose is checked as every blend checks it.
        simulated.blend_all(rig, &simulated, 1.0)?;
        Ok(Self {
            simulated,
            duration,
            elapsed: 0.0,
        })
    }

    /// The ragdoll's weight now: 1 as the blend starts, 0 from `duration`
    /// on, smoothstep between (see the module documentation).
    pub fn weight(&self) -> f32 {
        let _mode = DefaultFloatMode::enter();
        let x = (self.elapsed / self.duration).min(1.0);
        1.0 - x * x * (3.0 - 2.0 * x)
    }

    /// The output for this frame: `animation` (this frame's animation pose)
    /// blended toward the held simulated pose at [`BlendBack::weight`].
    /// Refused for an animation pose that does not fit `rig` (naming the
    /// bone).
    pub fn pose(&self, rig: &P::Rig, animation: &P) -> Result<P, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        animation.blend_all(rig, &self.simulated, self.weight())
    }

    /// Moves the blend on by `dt` seconds (finite, not negative).
    pub fn advance(&mut self, dt: f32) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(RagdollError::OutOfRange {
                context: "blend back".to_owned(),
                field: "dt",
                reason: format!("is {dt} s; must be finite and not negative"),
            });
        }
        self.elapsed = (self.elapsed + dt).min(self.duration);
        Ok(())
    }

    /// Whether the blend has reached the animation (the output is the
    /// animation's pose).
    pub fn is_done(&self) -> bool {
        self.elapsed >= self.duration
    }

    /// The held simulated pose.
    pub fn simulated(&self) -> &P {
        &self.simulated
    }
}
