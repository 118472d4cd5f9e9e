//! [`RagdollDesc::builder`]: a description built in code from specs
//! (`spec.rs`), assembled and checked as a file is (`assemble.rs`).

use crate::assemble::{Document, Item, assemble};
use crate::drive::DriveSettings;
use crate::error::RagdollError;
use crate::joint_def::JointSpec;
use crate::model::RagdollDesc;
use crate::profile::Profile;
use crate::profile_def::ProfileSource;
use crate::skeleton::Skeleton;
use crate::spec::{BodySpec, SpineSpec};
use vertebra_math::DefaultFloatMode;

/// Builds a [`RagdollDesc`] in code: bodies, joints, an optional spine,
/// drive settings, skeleton and total mass, then [`RagdollBuilder::build`]
/// checks it all as the file loader does.
///
/// ```
/// use glam::Vec3;
/// use vertebra_ragdoll::{BodySpec, JointSpec, RagdollDesc};
/// use vertebra_world::SwingTwist;
///
/// # fn main() -> Result<(), vertebra_ragdoll::RagdollError> {
/// let desc = RagdollDesc::builder("pendulum")
///     .body(BodySpec::capsule("top", [Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.8, 0.0)], 0.05, 1.0))
///     .body(BodySpec::capsule("bottom", [Vec3::new(0.0, 0.7, 0.0), Vec3::new(0.0, 0.5, 0.0)], 0.05, 1.0))
///     .joint(JointSpec::socket("swivel", "top", "bottom", Vec3::new(0.0, 0.75, 0.0), Vec3::NEG_Y, SwingTwist::FREE))
///     .total_mass(3.0)
///     .build()?;
/// assert_eq!(desc.bodies[1].mass, 1.5);
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Debug)]
pub struct RagdollBuilder {
    name: String,
    total_mass: Option<f32>,
    skeleton: Option<Skeleton>,
    bodies: Vec<BodySpec>,
    joints: Vec<JointSpec>,
    spine: Option<SpineSpec>,
    drive: Option<DriveSettings>,
    profiles: Vec<Profile>,
}

impl RagdollDesc {
    /// A builder for a description called `name`.
    pub fn builder(name: &str) -> RagdollBuilder {
        RagdollBuilder {
            name: name.to_owned(),
            total_mass: None,
            skeleton: None,
            bodies: Vec::new(),
            joints: Vec::new(),
            spine: None,
            drive: None,
            profiles: Vec::new(),
        }
    }
}

impl RagdollBuilder {
    /// With a body.
    pub fn body(mut self, body: BodySpec) -> Self {
        self.bodies.push(body);
        self
    }

    /// With a joint.
    pub fn joint(mut self, joint: JointSpec) -> Self {
        self.joints.push(joint);
        self
    }

    /// With the chain a rod replaces in the simplified ragdoll.
    pub fn spine(mut self, spine: SpineSpec) -> Self {
        self.spine = Some(spine);
        self
    }

    /// With drive settings (the `[drive]` table); their per-joint list
    /// must be empty: a joint's own strength is its spec's
    /// ([`JointSpec::with_drive`]).
    pub fn drive(mut self, settings: DriveSettings) -> Self {
        self.drive = Some(settings);
        self
    }

    /// With a physical-animation profile: one entry per joint and per
    /// body, in the order they are added (the file's `[[profile]]`).
    pub fn profile(mut self, profile: Profile) -> Self {
        self.profiles.push(profile);
        self
    }

    /// With the skeleton the bodies follow (its model frame the world at
    /// bind pose).
    pub fn skeleton(mut self, skeleton: Skeleton) -> Self {
        self.skeleton = Some(skeleton);
        self
    }

    /// With the bodies' masses scaled to `kg` in all, their ratios kept.
    pub fn total_mass(mut self, kg: f32) -> Self {
        self.total_mass = Some(kg);
        self
    }

    /// The description, checked as a file is; errors name the item and
    /// the field.
    pub fn build(self) -> Result<RagdollDesc, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        assemble(Document {
            name: self.name,
            total_mass: self.total_mass,
            skeleton: self.skeleton,
            bodies: unlined(self.bodies),
            joints: unlined(self.joints),
            spine: self.spine.map(Item::unlined),
            drive: self.drive.map(Item::unlined),
            profiles: (self.profiles.into_iter())
                .map(|p| Item::unlined(ProfileSource::Built(p)))
                .collect(),
        })
    }
}

/// Values built in code: no lines to name.
fn unlined<T>(values: Vec<T>) -> Vec<Item<T>> {
    values.into_iter().map(Item::unlined).collect()
}
