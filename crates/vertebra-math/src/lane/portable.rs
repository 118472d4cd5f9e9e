//! Four lanes through `wide::f32x4`: the backend for targets without x86
//! intrinsics (and, on x86_64, a cross-check compiled for baseline SSE2).
//!
//! Only the `wide` operations whose results are exact and specified are used
//! (`+ - * /`, `sqrt`, comparisons, bit operations). `min`, `max`, `round`,
//! `neg`, `abs` and `mul_add` are written here, because `wide`'s versions
//! either treat NaN differently, round ties away from zero, or fuse only when
//! the `fma` target feature happens to be on; its `recip`/`recip_sqrt` are
//! approximate on SSE and never called.

use core::fmt;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

use wide::f32x4;

use super::{Lane, Mask};
use crate::row::{ROW_LEN, Row};

/// Four `f32` lanes held in a `wide::f32x4`.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct F32x4Portable(f32x4);

/// Four lane masks: all bits set (true) or clear (false).
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct M32x4Portable(f32x4);

/// The comparison `min`/`max` select by. On AArch64 it passes through
/// [`super::neon::opaque_wide_masks`]: LLVM there may turn the select into
/// `FMIN`, which gives `-0.0` for `min(-0.0, 0.0)` where the contract gives
/// `0.0` (whether it does depends on how the crate is split into codegen
/// units).
#[inline(always)]
fn opaque(masks: M32x4Portable) -> M32x4Portable {
    #[cfg(all(target_arch = "aarch64", target_feature = "neon"))]
    let masks = M32x4Portable(super::neon::opaque_wide_masks(masks.0));
    masks
}

/// 2^23: from here on every `f32` is an integer.
const ROUND_LIMIT: f32 = 8_388_608.0;

#[inline(always)]
fn sign_bit() -> f32x4 {
    f32x4::splat(-0.0)
}

impl fmt::Debug for F32x4Portable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.to_array().fmt(f)
    }
}

impl fmt::Debug for M32x4Portable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list()
            .entries(self.0.to_array().iter().map(|x| x.to_bits() != 0))
            .finish()
    }
}

impl BitAnd for M32x4Portable {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(self.0 & rhs.0)
    }
}

impl BitOr for M32x4Portable {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, rhs: Self) -> Self {
        Self(self.0 | rhs.0)
    }
}

impl Not for M32x4Portable {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self(self.0 ^ f32x4::splat(f32::from_bits(u32::MAX)))
    }
}

impl Mask for M32x4Portable {}

macro_rules! binary_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $op:tt) => {
        impl $trait for F32x4Portable {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(self.0 $op rhs.0)
            }
        }
        impl $assign_trait for F32x4Portable {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = $trait::$method(*self, rhs);
            }
        }
    };
}

binary_op!(Add, add, AddAssign, add_assign, +);
binary_op!(Sub, sub, SubAssign, sub_assign, -);
binary_op!(Mul, mul, MulAssign, mul_assign, *);

impl Div for F32x4Portable {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: Self) -> Self {
        Self(self.0 / rhs.0)
    }
}

impl Neg for F32x4Portable {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(self.0 ^ sign_bit())
    }
}

impl Lane for F32x4Portable {
    type Mask = M32x4Portable;
    type Narrow = Self;
    const WIDTH: usize = 4;

    #[inline(always)]
    fn splat(value: f32) -> Self {
        Self(f32x4::splat(value))
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        let src: [f32; 4] = src[..4].try_into().expect("four lanes");
        Self(f32x4::new(src))
    }
    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        dst[..4].copy_from_slice(&self.0.to_array());
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(self.0.sqrt())
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Self(self.0 & !sign_bit())
    }
    /// Ties-to-even by adding and subtracting 2^23 (exact for |x| < 2^23);
    /// `wide`'s `round` rounds ties away from zero.
    #[inline(always)]
    fn round(self) -> Self {
        let magnitude = self.abs();
        let limit = Self::splat(ROUND_LIMIT);
        let rounded = ((magnitude + limit) - limit).copysign(self);
        Self::select(magnitude.lt(limit), rounded, self)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Self::select(opaque(self.lt(other)), self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Self::select(opaque(self.gt(other)), self, other)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        let (s, a, b) = (self.0.to_array(), a.0.to_array(), b.0.to_array());
        Self(f32x4::new(core::array::from_fn(|i| {
            s[i].mul_add(a[i], b[i])
        })))
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        Self((self.0 & !sign_bit()) | (sign.0 & sign_bit()))
    }
    #[inline(always)]
    fn lt(self, other: Self) -> M32x4Portable {
        M32x4Portable(self.0.simd_lt(other.0))
    }
    #[inline(always)]
    fn le(self, other: Self) -> M32x4Portable {
        M32x4Portable(self.0.simd_le(other.0))
    }
    #[inline(always)]
    fn gt(self, other: Self) -> M32x4Portable {
        M32x4Portable(self.0.simd_gt(other.0))
    }
    #[inline(always)]
    fn ge(self, other: Self) -> M32x4Portable {
        M32x4Portable(self.0.simd_ge(other.0))
    }
    #[inline(always)]
    fn eq(self, other: Self) -> M32x4Portable {
        M32x4Portable(self.0.simd_eq(other.0))
    }
    #[inline(always)]
    fn ne(self, other: Self) -> M32x4Portable {
        M32x4Portable(self.0.simd_ne(other.0))
    }
    #[inline(always)]
    fn select(mask: M32x4Portable, on_true: Self, on_false: Self) -> Self {
        Self(mask.0.bitselect(on_true.0, on_false.0))
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
        let a = self.0.to_array();
        ((a[0] + a[1]) + a[2]) + a[3]
    }
}
