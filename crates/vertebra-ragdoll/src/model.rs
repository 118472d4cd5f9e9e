//! A ragdoll's description as the rest of the crate reads it, however it
//! was made (a file: `description.rs`; code: `spec.rs`'s builder): its
//! bodies, joints, spine, drive and skeleton, checked and resolved
//! (`assemble.rs`).

use glam::{Quat, Vec3};
use vertebra_world::Shape;

use crate::drive::DriveSettings;
use crate::joint_def::JointDef;
use crate::profile::Profile;
use crate::skeleton::{Skeleton, Transform};
use vertebra_math::DefaultFloatMode;

/// A body: a capsule in bind pose (world frame, identity orientation, so
/// its centre of mass is the segment's midpoint).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDef {
    /// Unique name; also the animation bone's name.
    pub name: String,
    /// The capsule's core segment, bind pose, world (m).
    pub segment: [Vec3; 2],
    /// Capsule radius (m).
    pub radius: f32,
    /// Mass (kg).
    pub mass: f32,
    /// The skeleton bone this body follows, if the description has a
    /// skeleton and the body a bone.
    pub bone: Option<BoneBinding>,
}

/// Which bone of the description's skeleton a body follows, and where the
/// body sits on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoneBinding {
    /// The bone's index in [`RagdollDesc::skeleton`].
    pub bone: usize,
    /// The body's frame (its centre of mass, and the world's axes at bind
    /// pose) in the bone's frame: the body's world transform is the bone's
    /// model transform times `offset` (then the model's placement in the
    /// world). Unless the file gives one, it is what the two bind poses
    /// give: the bone's bind model transform, inverted, times the body's.
    pub offset: Transform,
}

impl BodyDef {
    /// The centre of mass at bind pose (m, world).
    pub fn centre(&self) -> Vec3 {
        (self.segment[0] + self.segment[1]) * 0.5
    }

    /// The body's frame at bind pose: its centre of mass (m, world) and the
    /// world's axes.
    pub fn bind_frame(&self) -> Transform {
        Transform::new(self.centre(), Quat::IDENTITY)
    }

    /// The capsule in its body frame (centred on the centre of mass).
    pub fn shape(&self) -> Shape {
        let centre = self.centre();
        Shape::capsule(
            self.segment[0] - centre,
            self.segment[1] - centre,
            self.radius,
        )
    }
}

/// The chain a rod replaces in the simplified ragdoll.
#[derive(Clone, Debug, PartialEq)]
pub struct SpineDef {
    /// Body indices from the base (hips) to the top (chest).
    pub bodies: Vec<usize>,
    /// Indices of the chain's joints, in order.
    pub joints: Vec<usize>,
    /// Largest bend (rad).
    pub bend_limit: f32,
    /// Twist range (rad).
    pub twist_limit: [f32; 2],
    /// Kirchhoff bending stiffness (N m^2).
    pub bend_stiffness: f32,
    /// Kirchhoff twisting stiffness (N m^2).
    pub twist_stiffness: f32,
}

/// The most bodies a ragdoll description may have: one per bone of the
/// largest skeleton ([`MAX_BONES`](crate::MAX_BONES)); a game's ragdoll
/// has 10 to 100. Counted before any body is read, by every way a
/// description is made (a file, a string, a builder, a generator) and by
/// [`RagdollDesc::validate`].
pub const MAX_BODIES: usize = crate::skeleton::MAX_BONES;

/// The most joints a ragdoll description may have: a tree over
/// [`MAX_BODIES`] bodies has one fewer. Counted with the bodies, before any
/// joint is read.
pub const MAX_JOINTS: usize = MAX_BODIES - 1;

/// A validated ragdoll description: names unique, joints a tree over the
/// bodies rooted at body `root`, every number finite and in range, each
/// bone followed by at most one body.
#[derive(Clone, Debug, PartialEq)]
pub struct RagdollDesc {
    /// The model's name.
    pub name: String,
    /// Bodies (and animation bones), in file order.
    pub bodies: Vec<BodyDef>,
    /// Joints, in file order.
    pub joints: Vec<JointDef>,
    /// The spine chain, if the file has one.
    pub spine: Option<SpineDef>,
    /// The body no joint has as its child.
    pub root: usize,
    /// For each body, the joint whose child it is (`None` for the root).
    pub parent_joint: Vec<Option<usize>>,
    /// How the ragdoll is driven toward an animation pose (the file's
    /// `[drive]` table, with each joint's own strength), if the file says.
    pub drive: Option<DriveSettings>,
    /// Named physical-animation profiles (the file's `[[profile]]`
    /// tables), names unique.
    pub profiles: Vec<Profile>,
    /// The animation skeleton the bodies follow ([`BodyDef::bone`]), its
    /// model frame the description's world frame at bind pose; if the
    /// description has one.
    pub skeleton: Option<Skeleton>,
}

impl RagdollDesc {
    /// The body index of `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// The index of the joint named `name`, if any.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The body that follows bone `bone` (an index into
    /// [`RagdollDesc::skeleton`]), if one does.
    pub fn body_on_bone(&self, bone: usize) -> Option<usize> {
        self.bodies
            .iter()
            .position(|b| b.bone.is_some_and(|binding| binding.bone == bone))
    }

    /// The profile named `name`, if the description has one.
    pub fn profile(&self, name: &str) -> Option<&Profile> {
        self.profiles.iter().find(|p| p.name == name)
    }

    /// Total mass (kg): the sum of the bodies' masses (a file's
    /// `total_mass` has scaled them to it).
    pub fn total_mass(&self) -> f32 {
        let _mode = DefaultFloatMode::enter();
        self.bodies.iter().map(|b| b.mass).sum()
    }
}

/// How the spine is simulated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SpineMode {
    /// The standard ragdoll: every spine body and its socket joints.
    Sockets,
    /// The simplified ragdoll: the spine's interior bodies removed (their
    /// mass split equally onto the two ends) and one rod between the ends.
    Rod,
}

/// How errors name a simplified ragdoll's spine rod: by its end bodies.
pub(crate) fn rod_name(desc: &RagdollDesc) -> String {
    match &desc.spine {
        Some(spine) => format!(
            "spine rod `{}`-`{}`",
            desc.bodies[spine.bodies[0]].name,
            desc.bodies[*spine.bodies.last().expect("a chain")].name
        ),
        None => "spine rod".to_owned(),
    }
}
