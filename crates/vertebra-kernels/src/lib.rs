//! The constraint kernels of vertebra, each one lane-generic body that runs
//! on every backend with the scalar reference as its twin.
//!
//! - [`body`]: body rows (pose, inverse inertia, velocity), gathered into
//!   [`body::BodyLanes`] and scattered back, and the generalised inverse
//!   masses and corrections of XPBD for rigid bodies.
//! - [`parts`]: the position-level constraint parts joints are composed of
//!   (after Jolt's constraint parts): point, angle correction, swing cone,
//!   twist range, angular drive. Each has its derivation in its header.
//! - [`socket`]: the ball-and-socket joint (circular cone, or elliptical
//!   cone and pyramid, and twist): its lane block, its position pass, the
//!   drives' velocity (damping) pass, and its residual.
//! - [`hinge`]: the hinge: one rotation axis with a range.
//! - [`fixed`]: the fixed joint: no relative motion.
//! - [`limited`]: soft limits' settings and their substep start pass.
//! - [`contact`]: contacts: non-penetration and static friction at the
//!   position level, dynamic friction and restitution at the velocity level.
//! - [`pass`]: one pass over any kernel's blocks ([`pass::BlockPass`]), each
//!   kernel a [`pass::BlockKernel`]: its block, what a pass shares, one slice.
//! - [`residual`]: one pass that measures any joint block's residual error.
//! - [`rod`]: the paper's rod constraint: curve, length, bending, twisting
//!   and limits in one kernel, its lane block and its residual.
//!
//! Kernels never use `core::arch`: the lane types and the row gather and
//! scatter in `vertebra-math` are the only places intrinsics live.

pub mod body;
pub mod contact;
pub mod direct;
pub mod driven;
pub mod fixed;
pub mod hinge;
pub mod limited;
pub mod parts;
pub mod pass;
pub mod reaction;
pub mod residual;
pub mod rod;
pub mod socket;

/// The joint frame's twist axis: +X of a joint frame (as in Jolt).
pub const TWIST_AXIS: glam::Vec3 = glam::Vec3::X;
