//! Body rows: eight `f32` per body, gathered by index into lanes and
//! scattered back (Box2D v3 gathers body rows this way instead of using
//! hardware gathers, which are slower than loads and transposes).
//!
//! # Rows and threads
//!
//! Kernels read and write rows through a shared reference (`&[Row]`): a
//! row is a [`Cell`], and the SIMD backends load and store it with plain
//! vector moves. Plain stores are not atomic, so two threads must never
//! reach the same row at once: that is why `Row` is **not `Sync`**. Safe
//! code can therefore never share rows between threads, and
//! [`Lane::gather_rows`](crate::Lane::gather_rows) /
//! [`Lane::scatter_rows`](crate::Lane::scatter_rows) are sound from any
//! safe caller: whatever the indices (bounds-checked, repeated or not),
//! every access happens on the one thread that holds the rows.
//!
//! Solving one colour on several threads needs the rows shared, so the one
//! place that does it (`vertebra-world`'s `parallel.rs`) claims `Sync` for
//! them with `unsafe`, and keeps the condition that makes it sound: the
//! blocks run at once write rows no other of them reads or writes (checked
//! when the layout is built).
//!
//! ```compile_fail
//! // Rows cannot cross threads by reference: two threads scattering into
//! // the same row would race.
//! fn shared<T: Sync>() {}
//! shared::<vertebra_math::row::Row>();
//! ```

use core::cell::Cell;

/// Floats per row.
pub const ROW_LEN: usize = 8;

/// A scatter index that writes nothing: for lanes whose body must not be
/// written (static, kinematic, padding).
pub const NO_WRITE: u32 = u32::MAX;

/// Eight floats, 32-byte aligned so that one AVX load reads a row. `Send`
/// but not `Sync` (see [the module documentation](self)).
#[derive(Clone, Debug, Default)]
#[repr(C, align(32))]
pub struct Row(Cell<[f32; ROW_LEN]>);

impl Row {
    /// A row holding `values`.
    pub fn new(values: [f32; ROW_LEN]) -> Self {
        Self(Cell::new(values))
    }

    /// The row's values.
    #[inline(always)]
    pub fn get(&self) -> [f32; ROW_LEN] {
        self.0.get()
    }

    /// Overwrites the row's values.
    #[inline(always)]
    pub fn set(&self, values: [f32; ROW_LEN]) {
        self.0.set(values);
    }

    /// The first float, for the lane types' vector loads and stores (valid
    /// for reads and writes of the row's eight floats while `self` is
    /// borrowed, on this thread: the cell allows writes through `&self`).
    #[cfg(any(
        target_arch = "x86_64",
        all(target_arch = "aarch64", target_feature = "neon"),
        all(target_arch = "wasm32", target_feature = "simd128")
    ))]
    #[inline(always)]
    pub(crate) fn as_ptr(&self) -> *mut f32 {
        self.0.as_ptr().cast::<f32>()
    }
}

/// Panics unless every index of `indices` names a row of `rows`: the AVX
/// gather checks a slice's eight indices once (a vector maximum) instead
/// of once per row. (The SSE4.1 gather keeps its check per row: for four
/// indices the maximum costs more than it saves.)
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn check_reads(rows: &[Row], indices: &[u32]) {
    let mut largest = 0;
    for &index in indices {
        largest = largest.max(index);
    }
    assert!(
        (largest as usize) < rows.len(),
        "a row index is out of range"
    );
}

/// Panics unless every index of `indices` but [`NO_WRITE`] names a row of
/// `rows`, checked once for the slice as [`check_reads`] does (`NO_WRITE`
/// plus one wraps to zero, which every length passes).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn check_writes(rows: &[Row], indices: &[u32]) {
    let mut largest = 0;
    for &index in indices {
        largest = largest.max(index.wrapping_add(1));
    }
    assert!(
        (largest as usize) <= rows.len(),
        "a row index is out of range"
    );
}
