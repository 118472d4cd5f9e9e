//! The math layer of vertebra: lane-generic vectors, quaternions, symmetric
//! matrices and polynomials, written once over the [`Lane`] trait and run
//! as a scalar reference, 4-lane SSE4.1, 4- and 8-lane AVX2, or portable
//! `wide` SIMD with bit-identical results.
//!
//! - [`lane`]: the trait, its exact semantics, and the backends' lane types.
//! - [`Backend`]: run-time detection and entry into kernels.
//! - [`Vec3`], [`Quat`], [`Sym3`]: the solver's types, one item per lane.
//! - [`poly`]: `sin`, `cos`, `acos`, `asin`, `atan2` and `sin(x/2)/x`.
//! - [`block`]: `bytemuck` lane blocks for structure-of-arrays storage.
//! - [`row`]: body rows, gathered into lanes and scattered back.
//! - `map` and `check` (with the `harness` feature, for this workspace's
//!   tests, benches and fuzz targets only): one lane function applied
//!   across arrays on any backend, and every backend compared with the
//!   scalar reference, bit for bit.
//! - [`float_mode`]: the default floating-point mode for a solver step,
//!   whatever mode (FTZ, DAZ, rounding) the caller's thread runs in.
//! - [`portable_quat`]: glam's quaternion operations whose bits differ
//!   between targets, with the same bits on every one; [`trig`]: `sin`,
//!   `cos` and `atan2` of an `f32` without the platform's C library.
//!
//! Public values outside kernels are `glam` types; `Vec3<f32>` and
//! `Quat<f32>` convert to and from them.

pub mod backend;
pub mod block;
#[cfg(feature = "harness")]
pub mod check;
pub mod float_mode;
pub mod lane;
#[cfg(feature = "harness")]
pub mod map;
pub mod poly;
pub mod portable_quat;
pub mod quat;
pub mod row;
pub mod sym3;
pub mod trig;
pub mod vec3;

pub use backend::{Backend, BackendChoice, BackendError, LaneKernel};
pub use float_mode::DefaultFloatMode;
pub use lane::{Lane, Mask};
pub use portable_quat::PortableQuat;
pub use quat::Quat;
pub use sym3::Sym3;
pub use vec3::Vec3;
