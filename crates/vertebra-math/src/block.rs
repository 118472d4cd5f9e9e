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
