//! The switch from animation to ragdoll without a pop.
//!
//! At the switch the bodies start exactly where the animation has them
//! ([`SkeletonMapper::map_to_ragdoll`] on the animation's last two poses
//! gives [`Ragdoll::build`] the pose and the velocities). The bones with a
//! body follow it, and a bone that follows its parent keeps the
//! animation's local transform, so neither moves. A chain bone does: the
//! mapping predicts it from the chain's two bodies (an animated spine with
//! unequal joint angles is not the evenly shared rotation the mapping
//! puts there). So the transition keeps, per chain bone, the offset the
//! animation had from the prediction at the switch,
//! `delta = predicted^-1 * animated` (in the predicted bone's frame), and
//! applies it to the mapping afterwards, before the bones below are
//! placed: held, or faded out over a set time. On the first frame every
//! bone is then where the animation had it, moved only by what the bodies
//! moved in that frame.

use glam::Quat;
use vertebra_world::World;

use crate::error::RagdollError;
use crate::mapper::{BoneRole, SkeletonMapper};
use crate::mapping::SpineMapping;
use crate::ragdoll::Ragdoll;
use crate::skeleton::{LocalPose, ModelPose, Transform};
use vertebra_math::{DefaultFloatMode, PortableQuat};

/// Refuses, naming the joint, a ragdoll one of whose joints has its two
/// anchors more than [`Transition::MAX_JOINT_GAP`] apart in `world` (a joint no
/// longer in the world, broken or removed, holds nothing and is passed).
fn joints_hold(
    mapper: &SkeletonMapper,
    ragdoll: &Ragdoll,
    world: &World,
) -> Result<(), RagdollError> {
    let bodies = world.bodies();
    for (k, handle) in ragdoll.joints.iter().enumerate() {
        let Some(Ok(joint)) = handle.map(|h| world.joint(h)) else {
            continue;
        };
        let (a, b) = (joint.body_a.index(), joint.body_b.index());
        // The bodies' offset first, in double precision: far from the
        // origin only their separation is rounded.
        let offset = (bodies.precise_position(b) - bodies.precise_position(a)).as_vec3();
        let gap = (offset + bodies.orientation[b] * joint.anchor_b
            - bodies.orientation[a] * joint.anchor_a)
            .length();
        if gap > Transition::MAX_JOINT_GAP {
            let name = mapper.desc.joints.get(k).map_or("?", |j| j.name.as_str());
            return Err(RagdollError::BadPose(format!(
                "joint `{name}`: its bodies are {:.1} mm apart at its pivot, which the first step would pull together (a pop): a transition is made at the switch, for a ragdoll built then with BuildOptions::at_switch",
                gap * 1e3
            )));
        }
    }
    Ok(())
}

/// The chain bones' offsets from the mapping at the switch to ragdoll.
///
/// The switch, from an engine's skeleton (here one bone per body; a game's
/// has more, and the mapper places them):
///
/// ```
/// use glam::{Quat, Vec3};
/// use vertebra_ragdoll::{
///     Bone, BuildOptions, Ragdoll, RagdollDesc, Skeleton, SkeletonMapper, SpineMapping,
///     SpineMode, Transform, Transition,
/// };
/// use vertebra_world::{SolverConfig, World};
///
/// # fn main() -> Result<(), vertebra_ragdoll::RagdollError> {
/// let desc = RagdollDesc::reference_humanoid();
/// let bones = (0..desc.bodies.len()).map(|b| {
///     let parent = desc.parent_joint[b].map(|j| desc.joints[j].parent);
///     let from = parent.map_or(Vec3::ZERO, |p| desc.bodies[p].centre());
///     let bind = Transform::new(desc.bodies[b].centre() - from, Quat::IDENTITY);
///     Bone { name: desc.bodies[b].name.clone(), parent, bind }
/// });
/// let skeleton = Skeleton::new(bones.collect())?;
/// let mapper = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod)?;
///
/// // The animation's last two poses (local), and where the model stands.
/// let current = skeleton.bind_pose();
/// let mut previous = current.clone();
/// previous.bones[0].translation.z -= 0.02; // it was walking forward
/// let place = Transform::new(Vec3::new(3.0, 0.0, -1.0), Quat::from_rotation_y(0.5));
///
/// let now = mapper.map_to_ragdoll(&current.to_model(&skeleton)?, place)?;
/// let before = mapper.map_to_ragdoll(&previous.to_model(&skeleton)?, place)?;
/// let mut world = World::new(SolverConfig::default())?;
/// // Joints made at the switch's pose: a body turned by a bone it has no
/// // body for (a clavicle, the neck) is not pulled back by the first step.
/// let options = BuildOptions::at_switch(SpineMode::Rod);
/// let ragdoll = Ragdoll::build(&mut world, &desc, options, &now, Some((&before, 1.0 / 60.0)))?;
/// let transition =
///     Transition::new(&mapper, &ragdoll, &world, &current, place, SpineMapping::Arc, 0.3)?;
///
/// for frame in 1..=30 {
///     world.step(1.0 / 60.0)?;
///     let since = frame as f32 / 60.0;
///     let pose = transition.skeleton_pose(&mapper, &ragdoll, &world, &current, place, since)?;
///     assert_eq!(pose.bones.len(), skeleton.len());
/// }
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Transition {
    mapping: SpineMapping,
    /// Per bone: a chain bone's `predicted^-1 * animated` at the switch;
    /// the identity for every other bone.
    offsets: Vec<Transform>,
    fade: f32,
}

impl Transition {
    /// The farthest apart a joint's two anchors may be when a transition
    /// is made (m): the most a joint's first step may pull its bodies.
    pub const MAX_JOINT_GAP: f32 = 1.0e-3;

    /// Measures the offsets for `ragdoll`, just built in `world` from the
    /// animation pose `animation` (local) placed in the world by
    /// `model_to_world`, mapped from then on by `mapping`. `fade` (s) is
    /// how long the offsets take to fade out: `f32::INFINITY` holds them,
    /// 0 drops them at once (the pure mapping, which pops). The fade is
    /// smooth at both ends: the offsets' weight is `1 - (3u^2 - 2u^3)` at
    /// `u = t / fade`, so the first frame after the switch drops only
    /// `3 (dt / fade)^2` of them (0.3% at 60 Hz and a 0.5 s fade).
    ///
    /// The ragdoll is built for the switch with
    /// [`BuildOptions::at_switch`](crate::BuildOptions::at_switch), so that
    /// its joints hold at the pose: refused, naming the joint, when one's
    /// two anchors are more than [`Self::MAX_JOINT_GAP`] apart (a ragdoll built
    /// with the description's anchors at a pose whose bodiless bones moved
    /// a child off its parent's pivot), whose first step would pull them
    /// together: the pop the transition is there to prevent.
    pub fn new(
        mapper: &SkeletonMapper,
        ragdoll: &Ragdoll,
        world: &World,
        animation: &LocalPose,
        model_to_world: Transform,
        mapping: SpineMapping,
        fade: f32,
    ) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        if fade.is_nan() || fade < 0.0 {
            return Err(RagdollError::OutOfRange {
                context: "transition".to_owned(),
                field: "fade",
                reason: format!("is {fade}; must be a time in s, 0 or more (infinity holds)"),
            });
        }
        let (bodies, rod_frames) = mapper.read(ragdoll, world)?;
        model_to_world.validate("model_to_world")?;
        joints_hold(mapper, ragdoll, world)?;
        let animated = animation
            .to_model(mapper.skeleton())?
            .in_world(model_to_world);
        let mut predicted = vec![Transform::IDENTITY; animated.bones.len()];
        mapper.place_chains(&bodies, rod_frames, mapping, &mut predicted);
        let offsets = mapper
            .roles()
            .iter()
            .zip(predicted.iter().zip(&animated.bones))
            .map(|(role, (&p, &a))| match role {
                BoneRole::Chain { .. } => p.inverse() * a,
                _ => Transform::IDENTITY,
            })
            .collect();
        Ok(Self {
            mapping,
            offsets,
            fade,
        })
    }

    /// The share of the offsets still applied `since_switch` seconds after
    /// the switch: 1 when held, 0 once the fade is over.
    pub fn weight(&self, since_switch: f32) -> f32 {
        let _mode = DefaultFloatMode::enter();
        if self.fade == f32::INFINITY {
            1.0
        } else if self.fade == 0.0 {
            0.0
        } else {
            let u = (since_switch / self.fade).clamp(0.0, 1.0);
            1.0 - u * u * (3.0 - 2.0 * u)
        }
    }

    /// The largest offset's translation (m) and rotation (rad) at the
    /// switch: how far the pure mapping would have moved a chain bone.
    pub fn largest_offset(&self) -> (f32, f32) {
        let _mode = DefaultFloatMode::enter();
        self.offsets.iter().fold((0.0f32, 0.0f32), |(t, r), o| {
            (t.max(o.translation.length()), r.max(angle(o.rotation)))
        })
    }

    /// Every bone's world transform, `since_switch` seconds (0 or more)
    /// after the switch: the mapper's, with each chain bone moved by its
    /// offset at the fade's weight. `animation` is the animation's
    /// current local pose (for the bones that follow their parents or the
    /// model frame); `mapper` must be the one the transition was measured
    /// with.
    pub fn skeleton_pose(
        &self,
        mapper: &SkeletonMapper,
        ragdoll: &Ragdoll,
        world: &World,
        animation: &LocalPose,
        model_to_world: Transform,
        since_switch: f32,
    ) -> Result<ModelPose, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        if since_switch.is_nan() || since_switch < 0.0 {
            return Err(RagdollError::OutOfRange {
                context: "transition".to_owned(),
                field: "since_switch",
                reason: format!("is {since_switch}; must be a time in s, 0 or more"),
            });
        }
        if self.offsets.len() != mapper.skeleton().len() {
            return Err(RagdollError::OutOfRange {
                context: "transition".to_owned(),
                field: "mapper",
                reason: format!(
                    "maps {} bones; the transition was measured over {}",
                    mapper.skeleton().len(),
                    self.offsets.len()
                ),
            });
        }
        let (bodies, rod_frames) = mapper.read(ragdoll, world)?;
        let weight = self.weight(since_switch);
        mapper.map(
            &bodies,
            rod_frames,
            animation,
            model_to_world,
            self.mapping,
            (weight > 0.0).then_some((self.offsets.as_slice(), weight)),
        )
    }
}

/// A rotation's angle (rad, in [0, pi]).
fn angle(q: Quat) -> f32 {
    Quat::IDENTITY.angle_between_portable(q)
}
