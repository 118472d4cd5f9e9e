//! Eight lanes in one AVX register, with explicit AVX/AVX2/FMA intrinsics.
//!
//! `wide` picks its instructions when it is compiled, not at run time, so
//! inside a `#[target_feature(enable = "avx2")]` function its `f32x8` would
//! still be two SSE halves; this type is raw intrinsics instead.
//!
//! Soundness: `F32x8` and `M32x8` are private to this crate, and a value of
//! either is only ever created inside a function that
//! [`crate::Backend::dispatch`] enters after `is_x86_feature_detected!`
//! confirmed AVX2 and FMA. Every `// SAFETY:` below relies on that.

use core::arch::x86_64::*;
use core::fmt;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

use super::{Lane, Mask};
use crate::row::{NO_WRITE, ROW_LEN, Row};

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

#[inline(always)]
fn sign_bit() -> __m256 {
    avx!(_mm256_set1_ps(-0.0))
}

impl F32x8 {
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        let mut out = [0.0; 8];
        self.store(&mut out);
        out
    }
}

impl fmt::Debug for F32x8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.to_array().fmt(f)
    }
}

impl fmt::Debug for M32x8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let bits = avx!(_mm256_movemask_ps(self.0));
        f.debug_list()
            .entries((0..8).map(|i| bits >> i & 1 == 1))
            .finish()
    }
}

impl BitAnd for M32x8 {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(avx!(_mm256_and_ps(self.0, rhs.0)))
    }
}

impl BitOr for M32x8 {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, rhs: Self) -> Self {
        Self(avx!(_mm256_or_ps(self.0, rhs.0)))
    }
}

impl Not for M32x8 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self(avx!(_mm256_xor_ps(
            self.0,
            _mm256_castsi256_ps(_mm256_set1_epi32(-1))
        )))
    }
}

impl Mask for M32x8 {
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        Self(avx!(_mm256_andnot_ps(other.0, self.0)))
    }
}

macro_rules! binary_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident) => {
        impl $trait for F32x8 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(avx!($intrinsic(self.0, rhs.0)))
            }
        }
        impl $assign_trait for F32x8 {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = $trait::$method(*self, rhs);
            }
        }
    };
}

binary_op!(Add, add, AddAssign, add_assign, _mm256_add_ps);
binary_op!(Sub, sub, SubAssign, sub_assign, _mm256_sub_ps);
binary_op!(Mul, mul, MulAssign, mul_assign, _mm256_mul_ps);

impl Div for F32x8 {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: Self) -> Self {
        Self(avx!(_mm256_div_ps(self.0, rhs.0)))
    }
}

impl Neg for F32x8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(avx!(_mm256_xor_ps(self.0, sign_bit())))
    }
}

impl F32x8 {
    #[inline(always)]
    fn compare<const PREDICATE: i32>(self, other: Self) -> M32x8 {
        M32x8(avx!(_mm256_cmp_ps::<PREDICATE>(self.0, other.0)))
    }
}

impl Lane for F32x8 {
    type Mask = M32x8;
    const WIDTH: usize = 8;

    #[inline(always)]
    fn splat(value: f32) -> Self {
        Self(avx!(_mm256_set1_ps(value)))
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        let src: &[f32; 8] = src[..8].try_into().expect("eight lanes");
        // SAFETY: `src` is eight readable floats, `loadu` takes any
        // alignment, and AVX was detected (module documentation).
        Self(unsafe { _mm256_loadu_ps(src.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        let dst: &mut [f32; 8] = (&mut dst[..8]).try_into().expect("eight lanes");
        // SAFETY: `dst` is eight writable floats, `storeu` takes any
        // alignment, and AVX was detected (module documentation).
        unsafe { _mm256_storeu_ps(dst.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(avx!(_mm256_sqrt_ps(self.0)))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Self(avx!(_mm256_andnot_ps(sign_bit(), self.0)))
    }
    #[inline(always)]
    fn round(self) -> Self {
        Self(avx!(_mm256_round_ps::<
            { _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC },
        >(self.0)))
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Self(avx!(_mm256_min_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Self(avx!(_mm256_max_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self(avx!(_mm256_fmadd_ps(self.0, a.0, b.0)))
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        let s = sign_bit();
        Self(avx!(_mm256_or_ps(
            _mm256_andnot_ps(s, self.0),
            _mm256_and_ps(s, sign.0)
        )))
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
    fn select(mask: M32x8, on_true: Self, on_false: Self) -> Self {
        Self(avx!(_mm256_blendv_ps(on_false.0, on_true.0, mask.0)))
    }
    #[inline(always)]
    fn gather_rows(rows: &[Row], indices: &[u32]) -> [Self; ROW_LEN] {
        let mut loaded = [avx!(_mm256_setzero_ps()); 8];
        for (lane, &index) in loaded.iter_mut().zip(&indices[..8]) {
            let p = rows[index as usize].as_ptr();
            // SAFETY: `p` is a live, 32-byte aligned row of eight floats
            // (bounds-checked) that no other thread writes now (`Row` is not
            // `Sync`; shared rows are written disjointly: crate::row); AVX detected.
            *lane = unsafe { _mm256_load_ps(p) };
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
        for (lane, &index) in indices[..8].iter().enumerate() {
            if index != NO_WRITE {
                let p = rows[index as usize].as_ptr();
                // SAFETY: `p` is a live, aligned row of eight floats that no
                // other thread reads or writes now (`Row` is not `Sync`; shared
                // rows are written disjointly: crate::row); AVX detected.
                unsafe { _mm256_store_ps(p, lanes[lane]) };
            }
        }
    }
    #[inline(always)]
    fn reduce_add(self) -> f32 {
        let a = self.to_array();
        let mut sum = a[0];
        for x in &a[1..] {
            sum += x;
        }
        sum
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
