//! Four lanes in one NEON register (AArch64 Advanced SIMD), with explicit
//! `core::arch::aarch64` intrinsics.
//!
//! NEON is part of every AArch64 target Rust builds for here (the `neon`
//! target feature is on by default), so this type needs no
//! `#[target_feature]` entry: [`crate::Backend::Neon`] is available
//! wherever the crate is compiled with it, and the intrinsics that take no
//! pointer are safe to call. Only the loads and stores are `unsafe`.
//!
//! Where NEON's own instructions differ from the contract
//! ([`crate::lane`]), the contract's operation is built from exact ones:
//!
//! - `FMIN`/`FMAX` return NaN when either operand is NaN and order
//!   `-0.0` below `0.0`; [`Lane::min`]/[`Lane::max`] are a comparison and
//!   a bitwise select instead (the second operand on NaN or equality, as
//!   `minps`/`maxps`). The comparison's mask passes through an empty
//!   `asm!` block ([`opaque_mask`]): LLVM otherwise turns the select of
//!   `x < 0.0` between `x` and a constant `0.0` into `FMINNM`, which gives
//!   `-0.0` for `x = -0.0` (measured with rustc 1.95, in this lane type
//!   and in plain `f32` code alike).
//! - [`Lane::round`] is `FRINTN`: to nearest, ties to even, as `roundps`
//!   with `_MM_FROUND_TO_NEAREST_INT`.
//! - `FABS`, `FNEG` and the sign select of [`Lane::copysign`] touch only
//!   the sign bit; `FSQRT` and `FDIV` are the correctly rounded IEEE-754
//!   operations; `FMLA` ([`Lane::mul_add`]) rounds once, as `f32::mul_add`.
//! - Subnormals are kept as long as FPCR.FZ is clear, which the step's
//!   [`crate::DefaultFloatMode`] makes sure of.

use core::arch::aarch64::*;
use core::fmt;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

use super::{Lane, Mask};
use crate::row::{NO_WRITE, ROW_LEN, Row};

/// Runs a NEON intrinsic expression.
macro_rules! neon {
    ($e:expr) => {
        // SAFETY: NEON is the baseline of every AArch64 target this
        // type is compiled for (`target_feature = "neon"`, module documentation).
        unsafe { $e }
    };
}

/// Four `f32` lanes.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct F32x4Neon(float32x4_t);

/// Four lane masks: all bits set (true) or clear (false).
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct M32x4Neon(uint32x4_t);

/// The sign bit of every lane.
#[inline(always)]
fn sign_bit() -> uint32x4_t {
    neon!(vdupq_n_u32(0x8000_0000))
}

impl F32x4Neon {
    #[inline(always)]
    fn to_array(self) -> [f32; 4] {
        [
            neon!(vgetq_lane_f32::<0>(self.0)),
            neon!(vgetq_lane_f32::<1>(self.0)),
            neon!(vgetq_lane_f32::<2>(self.0)),
            neon!(vgetq_lane_f32::<3>(self.0)),
        ]
    }
}

impl fmt::Debug for F32x4Neon {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.to_array().fmt(f)
    }
}

impl fmt::Debug for M32x4Neon {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let lanes = [
            neon!(vgetq_lane_u32::<0>(self.0)),
            neon!(vgetq_lane_u32::<1>(self.0)),
            neon!(vgetq_lane_u32::<2>(self.0)),
            neon!(vgetq_lane_u32::<3>(self.0)),
        ];
        f.debug_list().entries(lanes.map(|l| l != 0)).finish()
    }
}

impl BitAnd for M32x4Neon {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, rhs: Self) -> Self {
        Self(neon!(vandq_u32(self.0, rhs.0)))
    }
}

impl BitOr for M32x4Neon {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, rhs: Self) -> Self {
        Self(neon!(vorrq_u32(self.0, rhs.0)))
    }
}

impl Not for M32x4Neon {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self(neon!(vmvnq_u32(self.0)))
    }
}

impl Mask for M32x4Neon {
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        Self(neon!(vbicq_u32(self.0, other.0)))
    }
}

macro_rules! neon_binary_op {
    ($trait:ident, $method:ident, $assign_trait:ident, $assign:ident, $intrinsic:ident) => {
        impl $trait for F32x4Neon {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(neon!($intrinsic(self.0, rhs.0)))
            }
        }
        impl $assign_trait for F32x4Neon {
            #[inline(always)]
            fn $assign(&mut self, rhs: Self) {
                *self = $trait::$method(*self, rhs);
            }
        }
    };
}

neon_binary_op!(Add, add, AddAssign, add_assign, vaddq_f32);
neon_binary_op!(Sub, sub, SubAssign, sub_assign, vsubq_f32);
neon_binary_op!(Mul, mul, MulAssign, mul_assign, vmulq_f32);

impl Div for F32x4Neon {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: Self) -> Self {
        Self(neon!(vdivq_f32(self.0, rhs.0)))
    }
}

impl Neg for F32x4Neon {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(neon!(vnegq_f32(self.0)))
    }
}

impl Lane for F32x4Neon {
    type Mask = M32x4Neon;
    type Narrow = Self;
    const WIDTH: usize = 4;

    #[inline(always)]
    fn splat(value: f32) -> Self {
        Self(neon!(vdupq_n_f32(value)))
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        let src: &[f32; 4] = src[..4].try_into().expect("four lanes");
        // SAFETY: `src` is four readable floats; `LD1` takes any alignment.
        Self(unsafe { vld1q_f32(src.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        let dst: &mut [f32; 4] = (&mut dst[..4]).try_into().expect("four lanes");
        // SAFETY: `dst` is four writable floats; `ST1` takes any alignment.
        unsafe { vst1q_f32(dst.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(neon!(vsqrtq_f32(self.0)))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Self(neon!(vabsq_f32(self.0)))
    }
    #[inline(always)]
    fn round(self) -> Self {
        Self(neon!(vrndnq_f32(self.0)))
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        let less = opaque_masks(neon!(vcltq_f32(self.0, other.0)));
        Self(neon!(vbslq_f32(less, self.0, other.0)))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        let greater = opaque_masks(neon!(vcgtq_f32(self.0, other.0)));
        Self(neon!(vbslq_f32(greater, self.0, other.0)))
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self(neon!(vfmaq_f32(b.0, self.0, a.0)))
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        Self(neon!(vbslq_f32(sign_bit(), sign.0, self.0)))
    }
    #[inline(always)]
    fn lt(self, other: Self) -> M32x4Neon {
        M32x4Neon(neon!(vcltq_f32(self.0, other.0)))
    }
    #[inline(always)]
    fn le(self, other: Self) -> M32x4Neon {
        M32x4Neon(neon!(vcleq_f32(self.0, other.0)))
    }
    #[inline(always)]
    fn gt(self, other: Self) -> M32x4Neon {
        M32x4Neon(neon!(vcgtq_f32(self.0, other.0)))
    }
    #[inline(always)]
    fn ge(self, other: Self) -> M32x4Neon {
        M32x4Neon(neon!(vcgeq_f32(self.0, other.0)))
    }
    #[inline(always)]
    fn eq(self, other: Self) -> M32x4Neon {
        M32x4Neon(neon!(vceqq_f32(self.0, other.0)))
    }
    #[inline(always)]
    fn ne(self, other: Self) -> M32x4Neon {
        M32x4Neon(neon!(vmvnq_u32(vceqq_f32(self.0, other.0))))
    }
    #[inline(always)]
    fn select(mask: M32x4Neon, on_true: Self, on_false: Self) -> Self {
        Self(neon!(vbslq_f32(mask.0, on_true.0, on_false.0)))
    }
    #[inline(always)]
    fn gather_rows(rows: &[Row], indices: &[u32]) -> [Self; ROW_LEN] {
        let (mut lo, mut hi) = ([neon!(vdupq_n_f32(0.0)); 4], [neon!(vdupq_n_f32(0.0)); 4]);
        for lane in 0..4 {
            let p = rows[indices[lane] as usize].as_ptr();
            // SAFETY: `p` is a live row of eight floats (bounds-checked)
            // that no other thread writes now (`Row` is not `Sync`; shared
            // rows are written disjointly: crate::row).
            unsafe {
                lo[lane] = vld1q_f32(p);
                hi[lane] = vld1q_f32(p.add(4));
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
                    vst1q_f32(p, lo[lane]);
                    vst1q_f32(p.add(4), hi[lane]);
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

/// `masks` unchanged, through an empty `asm!` block the optimiser cannot
/// see into, so that a select by them stays a select (module
/// documentation: LLVM would make `min` with a constant `0.0` an
/// `FMINNM`).
#[inline(always)]
fn opaque_masks(mut masks: uint32x4_t) -> uint32x4_t {
    // SAFETY: the block holds only a comment: it reads and writes no
    // register but `masks`'s own, and no memory.
    unsafe {
        core::arch::asm!("/* {0:v} */", inout(vreg) masks, options(pure, nomem, nostack, preserves_flags));
    }
    masks
}

/// `masks` unchanged, held as `wide` holds them, through [`opaque_masks`]:
/// the portable backend's `min`/`max` select by them on AArch64, for the
/// same reason.
#[inline(always)]
pub(super) fn opaque_wide_masks(masks: wide::f32x4) -> wide::f32x4 {
    bytemuck::cast(opaque_masks(bytemuck::cast(masks)))
}

/// `mask` unchanged, through an empty `asm!` block: the scalar reference's
/// `min`/`max` select by it on AArch64, for the reason [`opaque_masks`]
/// gives.
#[inline(always)]
pub(super) fn opaque_mask(mut mask: u32) -> u32 {
    // SAFETY: the block holds only a comment: it reads and writes no
    // register but `mask`'s own, and no memory.
    unsafe {
        core::arch::asm!("/* {0:w} */", inout(reg) mask, options(pure, nomem, nostack, preserves_flags));
    }
    mask
}

/// Transposes a 4x4 block: rows in, columns out (its own inverse). `TRN1`
/// and `TRN2` pair the lanes of two rows, the 64-bit `ZIP1`/`ZIP2` join
/// the pairs.
#[inline(always)]
fn transpose4(r: [float32x4_t; 4]) -> [float32x4_t; 4] {
    let t0 = neon!(vreinterpretq_f64_f32(vtrn1q_f32(r[0], r[1])));
    let t1 = neon!(vreinterpretq_f64_f32(vtrn2q_f32(r[0], r[1])));
    let t2 = neon!(vreinterpretq_f64_f32(vtrn1q_f32(r[2], r[3])));
    let t3 = neon!(vreinterpretq_f64_f32(vtrn2q_f32(r[2], r[3])));
    [
        neon!(vreinterpretq_f32_f64(vzip1q_f64(t0, t2))),
        neon!(vreinterpretq_f32_f64(vzip1q_f64(t1, t3))),
        neon!(vreinterpretq_f32_f64(vzip2q_f64(t0, t2))),
        neon!(vreinterpretq_f32_f64(vzip2q_f64(t1, t3))),
    ]
}
