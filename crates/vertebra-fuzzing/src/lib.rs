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
//!   floats: no panic, a rejected call changes nothing, no non-finite state,
//!   the step's NaN guard never needed.
//! - [`world_settings`]: the same on a world with arbitrary solver
//!   settings (speed limits up to their ceilings, gravity, push-out).
//! - [`ragdoll_loader`]: arbitrary bytes as a ragdoll file (alone and on
//!   the reference skeleton) and as a skeleton file: an error, or a
//!   description or skeleton that reads back from its TOML as itself and a
//!   ragdoll that builds; never a panic.
//! - [`collisions`]: bodies, colliders and ragdolls added and removed, the
//!   world and the collision set saved and restored (also from crafted
//!   bytes), steps with detection: a refused call changes nothing, no
//!   collider or contact outlives its body.
//! - [`capi`]: arbitrary call sequences through the C ABI, structs filled
//!   as a C caller may (any enum value, any float bits, made-up handles):
//!   no call panics, a refused call leaves the world and the collision
//!   layer as they were, every body stays finite.
//! - [`snapshot`]: a valid world's snapshot with its decoded state changed
//!   (or its payload's bytes) and a correct checksum: refused by name with
//!   the world unchanged, or accepted and stepped with every body finite.

mod capi;
mod collisions;
mod input;
mod kernels;
mod loader;
mod math;
mod snapshot;
mod world;

pub use capi::capi;
pub use collisions::collisions;
pub use kernels::kernels;
pub use loader::ragdoll_loader;
pub use math::math_backends;
pub use snapshot::snapshot;
pub use world::{world_api, world_settings};

/// A fuzz target's body: panics on a broken promise.
pub type Target = fn(&[u8]);

/// Every target, by its cargo-fuzz name.
pub const TARGETS: [(&str, Target); 8] = [
    ("math_backends", math_backends),
    ("kernels", kernels),
    ("world_api", world_api),
    ("world_settings", world_settings),
    ("ragdoll_loader", ragdoll_loader),
    ("collisions", collisions),
    ("snapshot", snapshot),
    ("capi", capi),
];
