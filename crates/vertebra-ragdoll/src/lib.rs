//! Ragdolls for vertebra (paper section 6): load a description, build it as
//! a standard ragdoll (a socket chain in the spine) or as the paper's
//! simplified ragdoll (one rod), switch a character from animation to
//! physics at any pose, drive it toward an animation pose, and write the
//! result back onto an animation skeleton that has more bones than the
//! ragdoll has bodies. The format and the mapping modes are documented in
//! `docs/ragdolls.md`.

mod description;
mod drive;
mod error;
mod mapping;
mod pose;
mod ragdoll;

pub use description::{BodyDef, JointDef, REFERENCE_HUMANOID, RagdollDesc, SpineDef};
pub use drive::{DriveSettings, Strength};
pub use error::RagdollError;
pub use mapping::SpineMapping;
pub use pose::Pose;
pub use ragdoll::{BuildOptions, Ragdoll, SpineMode, body_masses};
