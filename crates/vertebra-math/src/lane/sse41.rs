//! Four lanes in one SSE register, with explicit SSE4.1 intrinsics.
//!
//! Soundness: `F32x4` and `M32x4` are private to this crate, and a value of
//! either is only ever created inside a function that
//! [`crate::Backend::dispatch`] enters after `is_x86_feature_detected!`
//! confirmed SSE4.1. That is what each `// SAFETY:` below relies on. The
//! same type also serves the 4-lane AVX2 backend: entered through an
//! `avx2,fma` function, the same intrinsics are emitted with VEX encoding.

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

#[inline(always)]
fn sign_bit() -> __m128 {
    sse41!(_mm_set1_ps(-0.0))
}

impl F32x4 {
    #[inline(always)]
    fn to_array(self) -> [f32; 4] {
        let mut out = [0.0; 4];
        self.store(&mut out);
        out
    }
}

impl fmt::Debug for F32x4 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.to_array().fmt(f)
    }
}

impl fmt::Debug for M32x4 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let bits = sse41!(_mm_movemask_ps(self.0));
        f.debug_list()
            .entries((0..4).map(|i| bits >> i & 1 == 1))
            .finish()
    }
}

impl BitAnd for M32x4 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(sse41!(_mm_and_ps(self.0, rhs.0)))
    }
}

impl BitOr for M32x4 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, rhs: Self) -> Self {
        Self(sse41!(_mm_or_ps(self.0, rhs.0)))
    }
}

impl Not for M32x4 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self(sse41!(_mm_xor_ps(
            self.0,
            _mm_castsi128_ps(_mm_set1_epi32(-1))
        )))
    }
}

impl Mask for M32x4 {
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        Self(sse41!(_mm_andnot_ps(other.0, self.0)))
    }
}

macro_rules! binary_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident) => {
        impl $trait for F32x4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(sse41!($intrinsic(self.0, rhs.0)))
            }
        }
        impl $assign_trait for F32x4 {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = $trait::$method(*self, rhs);
            }
        }
    };
}

binary_op!(Add, add, AddAssign, add_assign, _mm_add_ps);
binary_op!(Sub, sub, SubAssign, sub_assign, _mm_sub_ps);
binary_op!(Mul, mul, MulAssign, mul_assign, _mm_mul_ps);

impl Div for F32x4 {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: Self) -> Self {
        Self(sse41!(_mm_div_ps(self.0, rhs.0)))
    }
}

impl Neg for F32x4 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(sse41!(_mm_xor_ps(self.0, sign_bit())))
    }
}

impl Lane for F32x4 {
    type Mask = M32x4;
    const WIDTH: usize = 4;

    #[inline(always)]
    fn splat(value: f32) -> Self {
        Self(sse41!(_mm_set1_ps(value)))
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        let src: &[f32; 4] = src[..4].try_into().expect("four lanes");
        // SAFETY: `src` is four readable floats; `loadu` takes any alignment.
        Self(unsafe { _mm_loadu_ps(src.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        let dst: &mut [f32; 4] = (&mut dst[..4]).try_into().expect("four lanes");
        // SAFETY: `dst` is four writable floats; `storeu` takes any alignment.
        unsafe { _mm_storeu_ps(dst.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(sse41!(_mm_sqrt_ps(self.0)))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Self(sse41!(_mm_andnot_ps(sign_bit(), self.0)))
    }
    #[inline(always)]
    fn round(self) -> Self {
        Self(sse41!(_mm_round_ps::<
            { _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC },
        >(self.0)))
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Self(sse41!(_mm_min_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Self(sse41!(_mm_max_ps(self.0, other.0)))
    }
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
    fn copysign(self, sign: Self) -> Self {
        let s = sign_bit();
        Self(sse41!(_mm_or_ps(
            _mm_andnot_ps(s, self.0),
            _mm_and_ps(s, sign.0)
        )))
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
    fn select(mask: M32x4, on_true: Self, on_false: Self) -> Self {
        Self(sse41!(_mm_blendv_ps(on_false.0, on_true.0, mask.0)))
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
    #[inline(always)]
    fn reduce_add(self) -> f32 {
        let a = self.to_array();
        ((a[0] + a[1]) + a[2]) + a[3]
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
