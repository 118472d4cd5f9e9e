//! Four lanes in one WebAssembly `v128`, with explicit
//! `core::arch::wasm32` SIMD128 intrinsics.
//!
//! WebAssembly has no run-time feature detection: a module that holds one
//! SIMD instruction does not load on an engine without SIMD. So this type
//! exists only in builds compiled with the `simd128` target feature
//! (`-C target-feature=+simd128`), where [`crate::Backend::Simd128`] is
//! available and the intrinsics that take no pointer are safe to call;
//! a build without it has the scalar and portable backends. Only the loads
//! and stores are `unsafe`.
//!
//! Only instructions whose results the WebAssembly standard fixes bit for
//! bit are used (NaN payloads aside, which it leaves open as Rust does):
//! no relaxed-SIMD instruction (`relaxed_madd`, `relaxed_min`, ...), whose
//! results the standard lets engines choose, and nothing fused. Where the
//! standard's instructions differ from the contract ([`crate::lane`]):
//!
//! - `f32x4.min`/`max` return NaN when either operand is NaN and order
//!   `-0.0` below `0.0`; the pseudo-minimum `f32x4.pmin(a, b)` is
//!   `b < a ? b : a`, so [`Lane::min`] (`a < b ? a : b`) is `pmin(b, a)`
//!   and [`Lane::max`] (`a > b ? a : b`) is `pmax(b, a)`.
//! - [`Lane::round`] is `f32x4.nearest`: ties to even.
//! - [`Lane::mul_add`] is `f32::mul_add` lane by lane (SIMD128 has no fused
//!   multiply-add outside relaxed SIMD).
//! - WebAssembly has no floating-point environment: rounding is always to
//!   nearest and subnormals are always kept.

use core::arch::wasm32::*;
use core::fmt;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

use super::{Lane, Mask};
use crate::row::{NO_WRITE, ROW_LEN, Row};

/// Four `f32` lanes.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct F32x4Wasm(v128);

/// Four lane masks: all bits set (true) or clear (false).
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct M32x4Wasm(v128);

/// The sign bit of every lane.
#[inline(always)]
fn sign_bit() -> v128 {
    u32x4_splat(0x8000_0000)
}

impl F32x4Wasm {
    #[inline(always)]
    fn to_array(self) -> [f32; 4] {
        [
            f32x4_extract_lane::<0>(self.0),
            f32x4_extract_lane::<1>(self.0),
            f32x4_extract_lane::<2>(self.0),
            f32x4_extract_lane::<3>(self.0),
        ]
    }
}

impl fmt::Debug for F32x4Wasm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.to_array().fmt(f)
    }
}

impl fmt::Debug for M32x4Wasm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let bits = u32x4_bitmask(self.0);
        f.debug_list()
            .entries((0..4).map(|i| bits >> i & 1 == 1))
            .finish()
    }
}

impl BitAnd for M32x4Wasm {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(v128_and(self.0, rhs.0))
    }
}

impl BitOr for M32x4Wasm {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, rhs: Self) -> Self {
        Self(v128_or(self.0, rhs.0))
    }
}

impl Not for M32x4Wasm {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self(v128_not(self.0))
    }
}

impl Mask for M32x4Wasm {
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        Self(v128_andnot(self.0, other.0))
    }
}

macro_rules! wasm_binary_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident) => {
        impl $trait for F32x4Wasm {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self($intrinsic(self.0, rhs.0))
            }
        }
        impl $assign_trait for F32x4Wasm {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = $trait::$method(*self, rhs);
            }
        }
    };
}

wasm_binary_op!(Add, add, AddAssign, add_assign, f32x4_add);
wasm_binary_op!(Sub, sub, SubAssign, sub_assign, f32x4_sub);
wasm_binary_op!(Mul, mul, MulAssign, mul_assign, f32x4_mul);

impl Div for F32x4Wasm {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: Self) -> Self {
        Self(f32x4_div(self.0, rhs.0))
    }
}

impl Neg for F32x4Wasm {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(f32x4_neg(self.0))
    }
}

impl Lane for F32x4Wasm {
    type Mask = M32x4Wasm;
    type Narrow = Self;
    const WIDTH: usize = 4;

    #[inline(always)]
    fn splat(value: f32) -> Self {
        Self(f32x4_splat(value))
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        let src: &[f32; 4] = src[..4].try_into().expect("four lanes");
        // SAFETY: `src` is 16 readable bytes; `v128.load` takes any
        // alignment.
        Self(unsafe { v128_load(src.as_ptr().cast()) })
    }
    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        let dst: &mut [f32; 4] = (&mut dst[..4]).try_into().expect("four lanes");
        // SAFETY: `dst` is 16 writable bytes; `v128.store` takes any
        // alignment.
        unsafe { v128_store(dst.as_mut_ptr().cast(), self.0) }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(f32x4_sqrt(self.0))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Self(f32x4_abs(self.0))
    }
    #[inline(always)]
    fn round(self) -> Self {
        Self(f32x4_nearest(self.0))
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Self(f32x4_pmin(other.0, self.0))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Self(f32x4_pmax(other.0, self.0))
    }
    /// SIMD128 has no fused multiply-add: lane by lane through
    /// `f32::mul_add`.
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
        Self(v128_bitselect(sign.0, self.0, sign_bit()))
    }
    #[inline(always)]
    fn lt(self, other: Self) -> M32x4Wasm {
        M32x4Wasm(f32x4_lt(self.0, other.0))
    }
    #[inline(always)]
    fn le(self, other: Self) -> M32x4Wasm {
        M32x4Wasm(f32x4_le(self.0, other.0))
    }
    #[inline(always)]
    fn gt(self, other: Self) -> M32x4Wasm {
        M32x4Wasm(f32x4_gt(self.0, other.0))
    }
    #[inline(always)]
    fn ge(self, other: Self) -> M32x4Wasm {
        M32x4Wasm(f32x4_ge(self.0, other.0))
    }
    #[inline(always)]
    fn eq(self, other: Self) -> M32x4Wasm {
        M32x4Wasm(f32x4_eq(self.0, other.0))
    }
    #[inline(always)]
    fn ne(self, other: Self) -> M32x4Wasm {
        M32x4Wasm(f32x4_ne(self.0, other.0))
    }
    #[inline(always)]
    fn select(mask: M32x4Wasm, on_true: Self, on_false: Self) -> Self {
        Self(v128_bitselect(on_true.0, on_false.0, mask.0))
    }
    #[inline(always)]
    fn gather_rows(rows: &[Row], indices: &[u32]) -> [Self; ROW_LEN] {
        let (mut lo, mut hi) = ([f32x4_splat(0.0); 4], [f32x4_splat(0.0); 4]);
        for lane in 0..4 {
            let p = rows[indices[lane] as usize].as_ptr();
            // SAFETY: `p` is a live row of eight floats (bounds-checked)
            // that no other thread writes now (`Row` is not `Sync`; shared
            // rows are written disjointly: crate::row).
            unsafe {
                lo[lane] = v128_load(p.cast());
                hi[lane] = v128_load(p.add(4).cast());
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
                // SAFETY: `p` is a live row of eight floats that no other
                // thread reads or writes now (`Row` is not `Sync`; shared
                // rows are written disjointly: crate::row).
                unsafe {
                    v128_store(p.cast(), lo[lane]);
                    v128_store(p.add(4).cast(), hi[lane]);
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

/// Transposes a 4x4 block: rows in, columns out (its own inverse), by
/// lane shuffles of two registers (indices 4 to 7 name the second).
#[inline(always)]
fn transpose4(r: [v128; 4]) -> [v128; 4] {
    let t0 = i32x4_shuffle::<0, 4, 1, 5>(r[0], r[1]);
    let t1 = i32x4_shuffle::<0, 4, 1, 5>(r[2], r[3]);
    let t2 = i32x4_shuffle::<2, 6, 3, 7>(r[0], r[1]);
    let t3 = i32x4_shuffle::<2, 6, 3, 7>(r[2], r[3]);
    [
        i32x4_shuffle::<0, 1, 4, 5>(t0, t1),
        i32x4_shuffle::<2, 3, 6, 7>(t0, t1),
        i32x4_shuffle::<0, 1, 4, 5>(t2, t3),
        i32x4_shuffle::<2, 3, 6, 7>(t2, t3),
    ]
}
