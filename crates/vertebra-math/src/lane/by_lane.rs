//! The scalar and portable backends' row gather and scatter: each lane's
//! row copied through a column array, one lane at a time (the x86, NEON
//! and SIMD128 backends transpose in registers instead).

use crate::Lane;
use crate::block::BLOCK_LANES;
use crate::row::{NO_WRITE, ROW_LEN, Row};

/// The generic gather: lane `i` of output `k` is `rows[indices[i]][k]`.
#[inline(always)]
pub(crate) fn gather_by_lane<L: Lane>(rows: &[Row], indices: &[u32]) -> [L; ROW_LEN] {
    let mut columns = [[0.0f32; BLOCK_LANES]; ROW_LEN];
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
pub(crate) fn scatter_by_lane<L: Lane>(values: &[L; ROW_LEN], rows: &[Row], indices: &[u32]) {
    let mut columns = [[0.0f32; BLOCK_LANES]; ROW_LEN];
    for (column, value) in columns.iter_mut().zip(values) {
        value.store(column);
    }
    for (lane, &index) in indices[..L::WIDTH].iter().enumerate() {
        if index != NO_WRITE {
            rows[index as usize].set(core::array::from_fn(|k| columns[k][lane]));
        }
    }
}
