//! Eight lanes in one AVX register, with explicit AVX/AVX2/FMA intrinsics.
//!
//! `wide` picks its instructions when it is compiled, not at run time, so
//! inside a `#[target_feature(enable = "avx2")]` function its `f32x8` would
//! still be two SSE halves; this type is raw intrinsics instead. What it
//! shares with the SSE4.1 type is written once in `x86.rs`, invoked here
//! with the AVX intrinsics.
//!
//! Soundness: `F32x8` and `M32x8` are private to this crate, and a value of
//! either is only ever created inside a function that
//! [`crate::Backend::dispatch`] enters after `is_x86_feature_detected!`
//! confirmed AVX2 and FMA. Every `// SAFETY:` below relies on that.

use core::arch::x86_64::*;
use core::fmt;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

use super::{Lane, Mask};
use crate::row::{NO_WRITE, ROW_LEN, Row, check_reads, check_writes};

/// Eight `f32` lanes.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct F32x8(__m256);

/// Eight lane masks: all bits set (true) or clear (false).
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct M32x8(__m256);

/// Runs an AVX/AVX2/FMA intrinsic expression.
macro_rules! avx {
    ($e:expr) => {
        // SAFETY: a value of this module's types exists only after AVX2 and
        // FMA were detected at run time (module documentation).
        unsafe { $e }
    };
}

x86_lane_types!(
    F32x8, M32x8, __m256, 8, avx,
    set1: _mm256_set1_ps, and: _mm256_and_ps, or: _mm256_or_ps, xor: _mm256_xor_ps,
    andnot: _mm256_andnot_ps, all_ones: _mm256_castsi256_ps(_mm256_set1_epi32(-1)),
    movemask: _mm256_movemask_ps,
    add: _mm256_add_ps, sub: _mm256_sub_ps, mul: _mm256_mul_ps, div: _mm256_div_ps,
);

impl F32x8 {
    #[inline(always)]
    fn compare<const PREDICATE: i32>(self, other: Self) -> M32x8 {
        M32x8(avx!(_mm256_cmp_ps::<PREDICATE>(self.0, other.0)))
    }
}

impl Lane for F32x8 {
    type Mask = M32x8;
    type Narrow = crate::lane::sse41::F32x4;
    x86_lane_methods!(
        8, avx,
        set1: _mm256_set1_ps, loadu: _mm256_loadu_ps, storeu: _mm256_storeu_ps,
        sqrt: _mm256_sqrt_ps, andnot: _mm256_andnot_ps, and: _mm256_and_ps, or: _mm256_or_ps,
        round: _mm256_round_ps, min: _mm256_min_ps, max: _mm256_max_ps,
        blendv: _mm256_blendv_ps,
    );

    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self(avx!(_mm256_fmadd_ps(self.0, a.0, b.0)))
    }
    #[inline(always)]
    fn lt(self, other: Self) -> M32x8 {
        self.compare::<_CMP_LT_OQ>(other)
    }
    #[inline(always)]
    fn le(self, other: Self) -> M32x8 {
        self.compare::<_CMP_LE_OQ>(other)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> M32x8 {
        self.compare::<_CMP_GT_OQ>(other)
    }
    #[inline(always)]
    fn ge(self, other: Self) -> M32x8 {
        self.compare::<_CMP_GE_OQ>(other)
    }
    #[inline(always)]
    fn eq(self, other: Self) -> M32x8 {
        self.compare::<_CMP_EQ_OQ>(other)
    }
    #[inline(always)]
    fn ne(self, other: Self) -> M32x8 {
        self.compare::<_CMP_NEQ_UQ>(other)
    }
    #[inline(always)]
    fn gather_rows(rows: &[Row], indices: &[u32]) -> [Self; ROW_LEN] {
        let indices = &indices[..8];
        check_reads(rows, indices);
        let mut loaded = [avx!(_mm256_setzero_ps()); 8];
        for (lane, &index) in loaded.iter_mut().zip(indices) {
            // SAFETY: `index` < `rows.len()` (`check_reads`): a live, 32-byte
            // aligned row that no other thread writes now (`Row` is not `Sync`;
            // shared rows are written disjointly: crate::row); AVX detected.
            *lane = unsafe { _mm256_load_ps(rows.get_unchecked(index as usize).as_ptr()) };
        }
        transpose8(loaded).map(Self)
    }
    #[inline(always)]
    fn scatter_rows(values: &[Self; ROW_LEN], rows: &[Row], indices: &[u32]) {
        let mut columns = [avx!(_mm256_setzero_ps()); 8];
        for (column, value) in columns.iter_mut().zip(values) {
            *column = value.0;
        }
        let lanes = transpose8(columns);
        let indices = &indices[..8];
        check_writes(rows, indices);
        for (lane, &index) in indices.iter().enumerate() {
            if index != NO_WRITE {
                // SAFETY: `index` < `rows.len()` (`check_writes`): a live,
                // aligned row no other thread reaches now (`Row` is not `Sync`;
                // shared rows are written disjointly: crate::row); AVX detected.
                unsafe {
                    _mm256_store_ps(rows.get_unchecked(index as usize).as_ptr(), lanes[lane])
                };
            }
        }
    }
}

/// Transposes an 8x8 block: rows in, columns out (its own inverse).
#[inline(always)]
fn transpose8(r: [__m256; 8]) -> [__m256; 8] {
    avx!({
        let t0 = _mm256_unpacklo_ps(r[0], r[1]);
        let t1 = _mm256_unpackhi_ps(r[0], r[1]);
        let t2 = _mm256_unpacklo_ps(r[2], r[3]);
        let t3 = _mm256_unpackhi_ps(r[2], r[3]);
        let t4 = _mm256_unpacklo_ps(r[4], r[5]);
        let t5 = _mm256_unpackhi_ps(r[4], r[5]);
        let t6 = _mm256_unpacklo_ps(r[6], r[7]);
        let t7 = _mm256_unpackhi_ps(r[6], r[7]);
        let s0 = _mm256_shuffle_ps::<0x44>(t0, t2);
        let s1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
        let s2 = _mm256_shuffle_ps::<0x44>(t1, t3);
        let s3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
        let s4 = _mm256_shuffle_ps::<0x44>(t4, t6);
        let s5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
        let s6 = _mm256_shuffle_ps::<0x44>(t5, t7);
        let s7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
        [
            _mm256_permute2f128_ps::<0x20>(s0, s4),
            _mm256_permute2f128_ps::<0x20>(s1, s5),
            _mm256_permute2f128_ps::<0x20>(s2, s6),
            _mm256_permute2f128_ps::<0x20>(s3, s7),
            _mm256_permute2f128_ps::<0x31>(s0, s4),
            _mm256_permute2f128_ps::<0x31>(s1, s5),
            _mm256_permute2f128_ps::<0x31>(s2, s6),
            _mm256_permute2f128_ps::<0x31>(s3, s7),
        ]
    })
}
