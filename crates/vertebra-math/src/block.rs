//! Lane blocks: the AoSoA storage unit of the constraint store. One block
//! holds [`BLOCK_LANES`] items as plain `f32` arrays, aligned for one AVX
//! load; a backend of fewer lanes reads it in `WIDTH`-sized slices.
//! Blocks are `bytemuck::Pod`, so a slice of them casts to and from a
//! slice of `f32` (snapshots, hashing, bulk copies) without copying.

use bytemuck::{Pod, Zeroable};

use crate::lane::Lane;
use crate::quat::Quat;
use crate::vec3::Vec3;

/// Items per block: the widest backend's lane count.
pub const BLOCK_LANES: usize = 8;

/// [`BLOCK_LANES`] 3-vectors, component by component.
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct Vec3Block {
    /// x components.
    pub x: [f32; BLOCK_LANES],
    /// y components.
    pub y: [f32; BLOCK_LANES],
    /// z components.
    pub z: [f32; BLOCK_LANES],
}

/// [`BLOCK_LANES`] quaternions, component by component.
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct QuatBlock {
    /// i components.
    pub x: [f32; BLOCK_LANES],
    /// j components.
    pub y: [f32; BLOCK_LANES],
    /// k components.
    pub z: [f32; BLOCK_LANES],
    /// Real parts.
    pub w: [f32; BLOCK_LANES],
}

impl Vec3Block {
    /// Every lane zero.
    pub const ZERO: Self = Self {
        x: [0.0; BLOCK_LANES],
        y: [0.0; BLOCK_LANES],
        z: [0.0; BLOCK_LANES],
    };

    /// Item `i` (`i < BLOCK_LANES`).
    pub fn get(&self, i: usize) -> glam::Vec3 {
        glam::Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// Sets item `i` (`i < BLOCK_LANES`).
    pub fn set(&mut self, i: usize, v: glam::Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }

    /// Items `start .. start + L::WIDTH` as lanes.
    #[inline(always)]
    pub fn load<L: Lane>(&self, start: usize) -> Vec3<L> {
        Vec3::load(&self.x[start..], &self.y[start..], &self.z[start..])
    }

    /// Writes lanes to items `start .. start + L::WIDTH`.
    #[inline(always)]
    pub fn store<L: Lane>(&mut self, start: usize, v: Vec3<L>) {
        v.store(
            &mut self.x[start..],
            &mut self.y[start..],
            &mut self.z[start..],
        );
    }
}

impl QuatBlock {
    /// Item `i` (`i < BLOCK_LANES`).
    pub fn get(&self, i: usize) -> glam::Quat {
        glam::Quat::from_xyzw(self.x[i], self.y[i], self.z[i], self.w[i])
    }

    /// Sets item `i` (`i < BLOCK_LANES`).
    pub fn set(&mut self, i: usize, q: glam::Quat) {
        (self.x[i], self.y[i], self.z[i], self.w[i]) = (q.x, q.y, q.z, q.w);
    }

    /// Items `start .. start + L::WIDTH` as lanes.
    #[inline(always)]
    pub fn load<L: Lane>(&self, start: usize) -> Quat<L> {
        Quat::load(
            &self.x[start..],
            &self.y[start..],
            &self.z[start..],
            &self.w[start..],
        )
    }

    /// Writes lanes to items `start .. start + L::WIDTH`.
    #[inline(always)]
    pub fn store<L: Lane>(&mut self, start: usize, q: Quat<L>) {
        q.store(
            &mut self.x[start..],
            &mut self.y[start..],
            &mut self.z[start..],
            &mut self.w[start..],
        );
    }
}

/// What a kernel does to one block, a slice of lanes at a time.
pub trait LaneSlices {
    /// Solves lanes `start .. start + L::WIDTH` of the block.
    fn slice<L: Lane>(&mut self, start: usize);
}

/// Runs `slices` over the lanes of one block that are not padding (bit
/// `i` of `padding` set: lane `i` is padding), so that a block of few
/// constraints is not paid for whole (a single ragdoll's colours hold two
/// or three joints). A lane type as wide as the block runs it whole unless
/// one half is all padding: then its [`Lane::Narrow`] type runs the other
/// half alone; a narrower lane type walks the block slice by slice and
/// skips a slice that is all padding. The choice reads the layout, never
/// lane data, so the code stays branch-free inside a slice.
///
/// A padding lane reads the null row and writes no row, so skipping it
/// changes no body: every backend gives the same rows as before and as
/// each other. What a skipped padding lane keeps in its own block fields
/// (multipliers, residuals) is left as it was: nothing reads it.
#[inline(always)]
pub fn for_live_slices<L: Lane, S: LaneSlices>(padding: u32, slices: &mut S) {
    const HALF: usize = BLOCK_LANES / 2;
    const LOW: u32 = (1 << HALF) - 1;
    const HIGH: u32 = LOW << HALF;
    if L::WIDTH == BLOCK_LANES && L::Narrow::WIDTH == HALF {
        match (padding & LOW == LOW, padding & HIGH == HIGH) {
            (false, false) => slices.slice::<L>(0),
            (false, true) => slices.slice::<L::Narrow>(0),
            (true, false) => slices.slice::<L::Narrow>(HALF),
            (true, true) => {}
        }
    } else {
        let all = (1u32 << L::WIDTH) - 1;
        for start in (0..BLOCK_LANES).step_by(L::WIDTH) {
            if (padding >> start) & all != all {
                slices.slice::<L>(start);
            }
        }
    }
}
