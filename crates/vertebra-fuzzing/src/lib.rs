//! The bodies of the fuzz targets, callable on the stable toolchain.
//!
//! `fuzz/` (cargo-fuzz, nightly) wraps each in `fuzz_target!`; the test
//! `tests/corpora.rs` replays every file of `fuzz/corpus/<target>/` through
//! them on stable, so CI checks the corpora too. Each panics on a broken
//! promise and returns quietly otherwise:
//!
//! - [`math_backends`]: arbitrary floats through every lane operation and
//!   polynomial: every backend gives the scalar reference's bits.
//! - [`kernels`]: arbitrary socket, rod and contact lanes on arbitrary body
//!   rows: every backend gives the scalar reference's bits; finite, valid
//!   input gives finite output.
//! - [`world_api`]: arbitrary sequences of calls on a world with arbitrary
//!   floats: no panic, a rejected call changes nothing, no non-finite state.
//! - [`ragdoll_loader`]: arbitrary bytes as a ragdoll file: an error or a
//!   ragdoll that builds, never a panic.
//! - [`collisions`]: bodies, colliders and ragdolls added and removed, the
//!   world and the collision set saved and restored (also from crafted
//!   bytes), steps with detection: a refused call changes nothing, no
//!   collider or contact outlives its body.

mod collisions;
mod input;
mod kernels;
mod loader;
mod math;
mod world;

pub use collisions::collisions;
pub use kernels::kernels;
pub use loader::ragdoll_loader;
pub use math::math_backends;
pub use world::world_api;

/// A fuzz target's body: panics on a broken promise.
pub type Target = fn(&[u8]);

/// Every target, by its cargo-fuzz name.
pub const TARGETS: [(&str, Target); 5] = [
    ("math_backends", math_backends),
    ("kernels", kernels),
    ("world_api", world_api),
    ("ragdoll_loader", ragdoll_loader),
    ("collisions", collisions),
];
