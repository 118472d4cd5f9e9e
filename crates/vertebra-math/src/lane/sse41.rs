//! Four lanes in one SSE register, with explicit SSE4.1 intrinsics.
//!
//! Soundness: `F32x4` and `M32x4` are private to this crate, and a value of
//! either is only ever created inside a function that
//! [`crate::Backend::dispatch`] enters after `is_x86_feature_detected!`
//! confirmed SSE4.1. That is what each `// SAFETY:` below relies on. The
//! same type also serves the 4-lane AVX2 backend: entered through an
//! `avx2,fma` function, the same intrinsics are emitted with VEX encoding.
//! What it shares with the AVX type is written once in `x86.rs`, invoked
//! here with the SSE intrinsics.

use core::arch::x86_64::*;
use core::fmt;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

use super::{Lane, Mask};
use crate::row::{NO_WRITE, ROW_LEN, Row};

/// Four `f32` lanes.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct F32x4(__m128);

/// Four lane masks: all bits set (true) or clear (false).
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct M32x4(__m128);

/// Runs an SSE4.1 intrinsic expression.
macro_rules! sse41 {
    ($e:expr) => {
        // SAFETY: a value of this module's types exists only after SSE4.1
        // was detected at run time (module documentation).
        unsafe { $e }
    };
}

x86_lane_types!(
    F32x4, M32x4, __m128, 4, sse41,
    set1: _mm_set1_ps, and: _mm_and_ps, or: _mm_or_ps, xor: _mm_xor_ps,
    andnot: _mm_andnot_ps, all_ones: _mm_castsi128_ps(_mm_set1_epi32(-1)),
    movemask: _mm_movemask_ps,
    add: _mm_add_ps, sub: _mm_sub_ps, mul: _mm_mul_ps, div: _mm_div_ps,
);

impl Lane for F32x4 {
    type Mask = M32x4;
    type Narrow = Self;
    x86_lane_methods!(
        4, sse41,
        set1: _mm_set1_ps, loadu: _mm_loadu_ps, storeu: _mm_storeu_ps,
        sqrt: _mm_sqrt_ps, andnot: _mm_andnot_ps, and: _mm_and_ps, or: _mm_or_ps,
        round: _mm_round_ps, min: _mm_min_ps, max: _mm_max_ps, blendv: _mm_blendv_ps,
    );

    /// SSE4.1 has no fused multiply-add: lane by lane through `f32::mul_add`.
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        let (mut s, a, b) = (self.to_array(), a.to_array(), b.to_array());
        for i in 0..4 {
            s[i] = s[i].mul_add(a[i], b[i]);
        }
        Self::load(&s)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> M32x4 {
        M32x4(sse41!(_mm_cmplt_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn le(self, other: Self) -> M32x4 {
        M32x4(sse41!(_mm_cmple_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn gt(self, other: Self) -> M32x4 {
        M32x4(sse41!(_mm_cmpgt_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn ge(self, other: Self) -> M32x4 {
        M32x4(sse41!(_mm_cmpge_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn eq(self, other: Self) -> M32x4 {
        M32x4(sse41!(_mm_cmpeq_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn ne(self, other: Self) -> M32x4 {
        M32x4(sse41!(_mm_cmpneq_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn gather_rows(rows: &[Row], indices: &[u32]) -> [Self; ROW_LEN] {
        let (mut lo, mut hi) = ([sse41!(_mm_setzero_ps()); 4], [sse41!(_mm_setzero_ps()); 4]);
        for lane in 0..4 {
            let p = rows[indices[lane] as usize].as_ptr();
            // SAFETY: `p` is a live, 32-byte aligned row of eight floats
            // (bounds-checked) that no other thread writes now (`Row` is not
            // `Sync`; shared rows are written disjointly: crate::row); SSE4.1 detected.
            unsafe {
                lo[lane] = _mm_load_ps(p);
                hi[lane] = _mm_load_ps(p.add(4));
            }
        }
        let (lo, hi) = (transpose4(lo), transpose4(hi));
        [lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]].map(Self)
    }
    #[inline(always)]
    fn scatter_rows(values: &[Self; ROW_LEN], rows: &[Row], indices: &[u32]) {
        let lo = transpose4([values[0].0, values[1].0, values[2].0, values[3].0]);
        let hi = transpose4([values[4].0, values[5].0, values[6].0, values[7].0]);
        for (lane, &index) in indices[..4].iter().enumerate() {
            if index != NO_WRITE {
                let p = rows[index as usize].as_ptr();
                // SAFETY: `p` is a live, aligned row of eight floats that no
                // other thread reads or writes now (`Row` is not `Sync`; shared
                // rows are written disjointly: crate::row); SSE4.1 detected.
                unsafe {
                    _mm_store_ps(p, lo[lane]);
                    _mm_store_ps(p.add(4), hi[lane]);
                }
            }
        }
    }
}

/// Transposes a 4x4 block: rows in, columns out (its own inverse).
#[inline(always)]
fn transpose4(r: [__m128; 4]) -> [__m128; 4] {
    sse41!({
        let t0 = _mm_unpacklo_ps(r[0], r[1]);
        let t1 = _mm_unpacklo_ps(r[2], r[3]);
        let t2 = _mm_unpackhi_ps(r[0], r[1]);
        let t3 = _mm_unpackhi_ps(r[2], r[3]);
        [
            _mm_movelh_ps(t0, t1),
            _mm_movehl_ps(t1, t0),
            _mm_movelh_ps(t2, t3),
            _mm_movehl_ps(t3, t2),
        ]
    })
}
