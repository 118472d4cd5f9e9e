//! Ragdolls for vertebra (paper section 6): load a description, build it as
//! a standard ragdoll (a socket chain in the spine) or as the paper's
//! simplified ragdoll (one rod), switch a character from animation to
//! physics at any pose, drive it toward an animation pose (joints, and
//! bodies in the world, with named [`Profile`]s blended over time by
//! [`ProfileBlend`]), and write the result back onto an animation skeleton
//! that has more bones than the ragdoll has bodies ([`SkeletonMapper`]; [`Transition`] switches from
//! animation without a pop, an example on its page). The format, the
//! mapper and the mapping modes are documented in `docs/ragdolls.md`.
//!
//! A description may follow an animation skeleton ([`Skeleton`]: a file
//! of `[[bone]]` tables, inline or next to the ragdoll file; the shipped
//! [`Skeleton::reference`] fits both humanoids), each body bound to a bone
//! ([`BoneBinding`]) or placed from one bone to another; it may be built in
//! code ([`RagdollDesc::builder`]) or generated from the skeleton and
//! per-bone radii, masses and joints ([`RagdollDesc::generator`]), checked
//! by hand ([`RagdollDesc::validate`]) and written back
//! ([`RagdollDesc::to_toml`]).
//!
//! How an engine wires it in, once per character:
//!
//! ```
//! use vertebra_ragdoll::{
//!     BuildOptions, DriveSettings, Pose, Ragdoll, RagdollDesc, SpineMapping, SpineMode,
//! };
//! use vertebra_world::{SolverConfig, Spring, World};
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
//! ragdoll.drive_to(&mut world, &current, &DriveSettings::uniform(Spring::compliant(1e-3)))?;
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
//!
//! From an engine's skeleton to a driven, partially animated ragdoll and
//! back to animation (the walk-through of `docs/ragdolls.md`):
//!
//! ```
//! use glam::{Quat, Vec3};
//! use vertebra_ragdoll::{
//!     BlendBack, BuildOptions, DriveSettings, LocalPose, Ragdoll, RagdollDesc, Skeleton,
//!     SkeletonMapper, SpineMapping, SpineMode, Transform, Transition,
//! };
//! use vertebra_world::{SolverConfig, Spring, World};
//!
//! # fn main() -> Result<(), vertebra_ragdoll::RagdollError> {
//! let skeleton = Skeleton::reference(); // the engine's skeleton: 63 bones
//! let desc = RagdollDesc::reference_humanoid(); // 13 bodies, each on the bone of its name
//! let mapper = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod)?;
//! // The model frame in the world: the character's place and heading.
//! let place = Transform::new(Vec3::new(40.0, 0.0, -12.0), Quat::from_rotation_y(1.0));
//! let dt = 1.0 / 60.0;
//!
//! // The animation's last two local poses: the bind pose, then the spine
//! // bending forward and the root moving on.
//! let previous = skeleton.bind_pose();
//! let mut current = previous.clone();
//! let spine = skeleton.bone_index("spine_middle").expect("a spine bone");
//! current.bones[spine].rotation *= Quat::from_rotation_x(0.05);
//! current.bones[0].translation.z += 0.02;
//!
//! // The switch: bodies where the animation has them, at its velocities,
//! // joints and rod made at that pose (nothing pops on the first step).
//! let bodies = |pose: &LocalPose| mapper.map_to_ragdoll(&pose.to_model(&skeleton)?, place);
//! let (now, before) = (bodies(&current)?, bodies(&previous)?);
//! let mut world = World::new(SolverConfig::default())?;
//! let options = BuildOptions::at_switch(SpineMode::Rod);
//! let ragdoll = Ragdoll::build(&mut world, &desc, options, &now, Some((&before, dt)))?;
//! let transition =
//!     Transition::new(&mapper, &ragdoll, &world, &current, place, SpineMapping::Arc, 0.3)?;
//!
//! // The legs stay animated (kinematic, on the animation); the upper body
//! // is powered toward it. The animation holds `current` from here on.
//! for leg in ["thigh_l", "shin_l", "thigh_r", "shin_r"] {
//!     ragdoll.set_body_kinematic(&mut world, leg, true)?;
//! }
//! let drive = DriveSettings::uniform(Spring::compliant(1e-3));
//! let mut bones = None;
//! for frame in 1..=30 {
//!     ragdoll.drive_following(&mut world, &now, &now, dt, &drive)?;
//!     ragdoll.drive_to_pose_using_kinematics(&mut world, &now, dt)?;
//!     world.step(dt)?;
//!     // Every bone of the engine's skeleton, in the world.
//!     let since = frame as f32 * dt;
//!     let pose = transition.skeleton_pose(&mapper, &ragdoll, &world, &current, place, since)?;
//!     assert_eq!(pose.bones.len(), 63);
//!     assert!(pose.bones.iter().all(|b| b.translation.is_finite() && b.rotation.is_finite()));
//!     bones = Some(pose);
//! }
//!
//! // Back to animation over half a second (getting up), in the model
//! // frame: the mapping's output is in the world.
//! let last = bones.expect("30 frames").in_world(place.inverse()).to_local(&skeleton)?;
//! let mut back = BlendBack::new(&skeleton, last, 0.5)?;
//! let hips = skeleton.bone_index("hips").expect("a hips bone");
//! while !back.is_done() {
//!     let out = back.pose(&skeleton, &current)?;
//!     // Blended in the model frame, placed in the world by `place`: the
//!     // hips stay near the animation's (1 m up at `place`).
//!     let world = out.to_model(&skeleton)?.in_world(place);
//!     let animated = place.transform_point(Vec3::new(0.0, 1.0, 0.02));
//!     assert!(world.bones[hips].translation.distance(animated) < 0.2);
//!     back.advance(dt)?;
//! }
//! assert_eq!(back.pose(&skeleton, &current)?, current);
//! # Ok(())
//! # }
//! ```

mod assemble;
mod blend;
mod blend_back;
mod builder;
mod description;
mod drive;
mod drive_def;
mod error;
mod generate;
mod generate_file;
mod get_up;
mod joint_def;
mod mapper;
mod mapping;
mod model;
mod motion;
mod partial;
mod pose;
mod pose_drive;
mod profile;
mod profile_def;
mod ragdoll;
mod read_back;
mod skeleton;
mod skeleton_file;
mod spec;
mod text;
mod transition;
mod world_drive;
mod write;

pub use blend_back::{Blend, BlendBack};
pub use builder::RagdollBuilder;
pub use description::{ANATOMICAL_HUMANOID, REFERENCE_HUMANOID};
pub use drive::DriveSettings;
pub use error::RagdollError;
pub use generate::{BodyMass, BoneBody, MIN_SEGMENT, RagdollGenerator, RodSpine, SegmentEnd};
pub use get_up::GetUp;
pub use joint_def::{JointDef, JointFrame, JointSpec};
pub use mapper::{BoneRole, SkeletonMapper};
pub use mapping::SpineMapping;
pub use model::{BodyDef, BoneBinding, MAX_BODIES, MAX_JOINTS, RagdollDesc, SpineDef, SpineMode};
pub use pose::Pose;
pub use profile::{BodyDriveSetting, JointDriveSetting, Profile, ProfileBlend, UprightSetting};
#[cfg(feature = "harness")]
pub use ragdoll::body_masses;
pub use ragdoll::{BuildOptions, JointAnchors, Ragdoll, RodRest};
pub use skeleton::{Bone, LocalPose, MAX_BONES, ModelPose, Skeleton, Transform};
pub use skeleton_file::REFERENCE_SKELETON;
pub use spec::{BodyShape, BodySpec, SpineSpec};
pub use text::{MAX_FILE_BYTES, read_text};
pub use transition::Transition;
pub use world_drive::{PhysicalAnimation, Upright, WorldDriveSettings};
