//! Ragdolls for vertebra (paper section 6): load a description, build it as
//! a standard ragdoll (a socket chain in the spine) or as the paper's
//! simplified ragdoll (one rod), switch a character from animation to
//! physics at any pose, drive it toward an animation pose, and write the
//! result back onto an animation skeleton that has more bones than the
//! ragdoll has bodies ([`SkeletonMapper`]; [`Transition`] switches from
//! animation without a pop, an example on its page). The format, the
//! mapper and the mapping modes are documented in `docs/ragdolls.md`.
//!
//! A description may follow an animation skeleton ([`Skeleton`]: a file
//! of `[[bone]]` tables, inline or next to the ragdoll file; the shipped
//! [`Skeleton::reference`] fits both humanoids), each body bound to a bone
//! ([`BoneBinding`]) or placed from one bone to another; it may be built in
//! code ([`RagdollDesc::builder`]), checked by hand
//! ([`RagdollDesc::validate`]) and written back ([`RagdollDesc::to_toml`]).
//!
//! How an engine wires it in, once per character:
//!
//! ```
//! use vertebra_ragdoll::{
//!     BuildOptions, DriveSettings, Pose, Ragdoll, RagdollDesc, SpineMapping, SpineMode, Strength,
//! };
//! use vertebra_world::{SolverConfig, World};
//!
//! # fn main() -> Result<(), vertebra_ragdoll::RagdollError> {
//! let desc = RagdollDesc::reference_humanoid(); // or RagdollDesc::from_toml(&file_text)?
//! let mut world = World::new(SolverConfig::default())?;
//!
//! // The transition from animation to physics: the last two animation
//! // poses give the ragdoll its pose and its velocities.
//! let previous = Pose::bind(&desc);
//! let current = previous.moved(glam::Vec3::ZERO, glam::Quat::IDENTITY, glam::Vec3::new(0.0, 0.0, 0.01));
//! let ragdoll = Ragdoll::build(&mut world, &desc, BuildOptions::new(SpineMode::Rod), &current, Some((&previous, 1.0 / 60.0)))?;
//!
//! // Optionally powered: follow the animation with stiff joints.
//! ragdoll.drive_to(&mut world, &current, &DriveSettings::uniform(Strength::Compliance(1e-3)))?;
//!
//! for _ in 0..60 {
//!     world.step(1.0 / 60.0)?;
//!     // Every animation bone, the spine's in-between bones included.
//!     let skeleton = ragdoll.skeleton_pose(&world, SpineMapping::Arc)?;
//!     assert_eq!(skeleton.bones.len(), desc.bodies.len());
//! }
//! # Ok(())
//! # }
//! ```

mod assemble;
mod blend;
mod blend_back;
mod description;
mod drive;
mod drive_def;
mod error;
mod joint_def;
mod mapper;
mod mapping;
mod motion;
mod partial;
mod pose;
mod ragdoll;
mod skeleton;
mod skeleton_file;
mod spec;
mod text;
mod transition;
mod write;

pub use blend_back::{Blend, BlendBack};
pub use description::{
    ANATOMICAL_HUMANOID, BodyDef, BoneBinding, REFERENCE_HUMANOID, RagdollDesc, SpineDef,
};
pub use drive::{DriveSettings, Strength};
pub use error::RagdollError;
pub use joint_def::{JointDef, JointFrame, JointSpec};
pub use mapper::{BoneRole, SkeletonMapper};
pub use mapping::SpineMapping;
pub use pose::Pose;
pub use ragdoll::{BuildOptions, Ragdoll, RodRest, SpineMode, body_masses};
pub use skeleton::{Bone, LocalPose, MAX_BONES, ModelPose, Skeleton, Transform};
pub use skeleton_file::REFERENCE_SKELETON;
pub use spec::{BodyShape, BodySpec, RagdollBuilder, SpineSpec};
pub use text::MAX_FILE_BYTES;
pub use transition::Transition;
