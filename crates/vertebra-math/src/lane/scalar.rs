//! `f32` as a lane type of width 1: the reference every SIMD backend is
//! compared with, bit for bit.

use super::{Lane, Mask};
use crate::row::{ROW_LEN, Row};

impl Mask for bool {}

/// The comparison `min`/`max` select by. On AArch64 it passes through
/// [`super::neon::opaque_mask`]: LLVM there turns `if x < 0.0 { x } else
/// { 0.0 }` into `FMINNM`, which gives `-0.0` for `x = -0.0` where the
/// contract (and x86-64's `minss`) gives `0.0`.
#[inline(always)]
fn opaque_test(test: bool) -> bool {
    #[cfg(all(target_arch = "aarch64", target_feature = "neon"))]
    let test = super::neon::opaque_mask(test as u32) != 0;
    test
}

/// 2^23: from here on every `f32` is an integer.
const ROUND_LIMIT: f32 = 8_388_608.0;

impl Lane for f32 {
    type Mask = bool;
    type Narrow = f32;
    const WIDTH: usize = 1;

    #[inline(always)]
    fn splat(value: f32) -> Self {
        value
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        src[0]
    }
    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        dst[0] = self;
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    /// Ties-to-even by adding and subtracting 2^23: exact for |x| < 2^23,
    /// and without the libm call that `f32::round_ties_even` becomes on
    /// baseline x86_64 (no SSE4.1 `roundss`).
    #[inline(always)]
    fn round(self) -> Self {
        let magnitude = f32::abs(self);
        let rounded = (magnitude + ROUND_LIMIT) - ROUND_LIMIT;
        // Large values are integers already; infinities and NaN pass through.
        if magnitude < ROUND_LIMIT {
            rounded.copysign(self)
        } else {
            self
        }
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        if opaque_test(self < other) {
            self
        } else {
            other
        }
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if opaque_test(self > other) {
            self
        } else {
            other
        }
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f32::mul_add(self, a, b)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        f32::copysign(self, sign)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn ge(self, other: Self) -> bool {
        self >= other
    }
    #[inline(always)]
    fn eq(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn ne(self, other: Self) -> bool {
        self != other
    }
    #[inline(always)]
    fn select(mask: bool, on_true: Self, on_false: Self) -> Self {
        if mask { on_true } else { on_false }
    }
    #[inline(always)]
    fn gather_rows(rows: &[Row], indices: &[u32]) -> [Self; ROW_LEN] {
        super::by_lane::gather_by_lane(rows, indices)
    }
    #[inline(always)]
    fn scatter_rows(values: &[Self; ROW_LEN], rows: &[Row], indices: &[u32]) {
        super::by_lane::scatter_by_lane(values, rows, indices)
    }
    #[inline(always)]
    fn reduce_add(self) -> f32 {
        self
    }
}
