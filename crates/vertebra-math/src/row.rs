//! Body rows: eight `f32` per body, gathered by index into lanes and
//! scattered back (Box2D v3 gathers body rows this way instead of using
//! hardware gathers, which are slower than loads and transposes).
//!
//! The floats are stored as `AtomicU32` bits so that batches of one colour
//! can write their (disjoint) rows from several threads through a shared
//! reference without `unsafe`: relaxed loads and stores compile to plain
//! moves, and the colouring guarantees no two batches of a colour touch
//! the same written row, so no value is ever raced on.

use core::sync::atomic::{AtomicU32, Ordering};

/// Floats per row.
pub const ROW_LEN: usize = 8;

/// A scatter index that writes nothing: for lanes whose body must not be
/// written (static, kinematic, padding).
pub const NO_WRITE: u32 = u32::MAX;

/// Eight floats, 32-byte aligned so that one AVX load reads a row.
#[derive(Debug, Default)]
#[repr(C, align(32))]
pub struct Row([AtomicU32; ROW_LEN]);

impl Row {
    /// A row holding `values`.
    pub fn new(values: [f32; ROW_LEN]) -> Self {
        Self(values.map(|v| AtomicU32::new(v.to_bits())))
    }

    /// The row's values.
    #[inline(always)]
    pub fn get(&self) -> [f32; ROW_LEN] {
        core::array::from_fn(|k| f32::from_bits(self.0[k].load(Ordering::Relaxed)))
    }

    /// Overwrites the row's values.
    #[inline(always)]
    pub fn set(&self, values: [f32; ROW_LEN]) {
        for (cell, v) in self.0.iter().zip(values) {
            cell.store(v.to_bits(), Ordering::Relaxed);
        }
    }

    /// The first float, for the lane types' vector loads and stores.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) fn as_ptr(&self) -> *mut f32 {
        self.0.as_ptr().cast::<u32>().cast_mut().cast::<f32>()
    }
}

impl Clone for Row {
    fn clone(&self) -> Self {
        Self::new(self.get())
    }
}

/// The generic gather: lane `i` of output `k` is `rows[indices[i]][k]`.
#[inline(always)]
pub(crate) fn gather_by_lane<L: crate::Lane>(rows: &[Row], indices: &[u32]) -> [L; ROW_LEN] {
    let mut columns = [[0.0f32; crate::block::BLOCK_LANES]; ROW_LEN];
    for (lane, &index) in indices[..L::WIDTH].iter().enumerate() {
        for (k, v) in rows[index as usize].get().into_iter().enumerate() {
            columns[k][lane] = v;
        }
    }
    columns.map(|c| L::load(&c))
}

/// The generic scatter: writes lane `i` of every value to
/// `rows[indices[i]]`, skipping [`NO_WRITE`] lanes.
#[inline(always)]
pub(crate) fn scatter_by_lane<L: crate::Lane>(
    values: &[L; ROW_LEN],
    rows: &[Row],
    indices: &[u32],
) {
    let mut columns = [[0.0f32; crate::block::BLOCK_LANES]; ROW_LEN];
    for (column, value) in columns.iter_mut().zip(values) {
        value.store(column);
    }
    for (lane, &index) in indices[..L::WIDTH].iter().enumerate() {
        if index != NO_WRITE {
            rows[index as usize].set(core::array::from_fn(|k| columns[k][lane]));
        }
    }
}
