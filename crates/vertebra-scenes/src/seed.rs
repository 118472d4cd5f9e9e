//! Seeded starts: a scene run from a slightly different initial state, so
//! that a figure of a chaotic scene (a pile of ragdolls) can be given with
//! its spread instead of from one run.
//!
//! Seed 0 is the scene exactly as the paper sets it up, bit for bit. Any
//! other seed moves each ragdoll's placement by at most 1 mm along each
//! horizontal axis and turns it by at most 0.1 degree about +Y, by amounts
//! drawn from the seed and the ragdoll's index alone (SplitMix64), so a
//! seeded scene is the same on every backend, thread count and machine.

use glam::{Quat, Vec3};
use vertebra_math::PortableQuat;

/// The largest horizontal offset of a seeded start (m).
pub const MAX_OFFSET: f32 = 1.0e-3;

/// The largest turn of a seeded start about +Y (rad): 0.1 degree.
pub const MAX_TURN: f32 = 0.1 * core::f32::consts::PI / 180.0;

/// The placement change of ragdoll `index` for `seed`: an offset (m,
/// world) and a turn about +Y; none for seed 0.
pub fn perturbation(seed: u64, index: usize) -> (Vec3, Quat) {
    if seed == 0 {
        return (Vec3::ZERO, Quat::IDENTITY);
    }
    let mut state = seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let mut unit = || {
        // SplitMix64, then the top 24 bits as a number in [-1, 1).
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 23) as f32 - 1.0
    };
    let offset = Vec3::new(unit() * MAX_OFFSET, 0.0, unit() * MAX_OFFSET);
    (offset, Quat::from_rotation_y_portable(unit() * MAX_TURN))
}
