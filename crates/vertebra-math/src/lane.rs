//! The lane layer: one trait over which every kernel is written once.
//!
//! A *lane type* holds `WIDTH` independent `f32` values and applies every
//! operation to each of them. The implementations are siblings:
//!
//! | type | width | module | instructions |
//! | --- | --- | --- | --- |
//! | `f32` | 1 | [`scalar`] | plain Rust, the reference |
//! | `F32x4Portable` | 4 | `portable` | `wide::f32x4`, for targets without x86 intrinsics |
//! | `F32x4` | 4 | `sse41` | explicit SSE4.1 intrinsics |
//! | `F32x8` | 8 | `avx2` | explicit AVX intrinsics, entered with AVX2+FMA enabled |
//! | `F32x4Neon` | 4 | `neon` | explicit AArch64 NEON intrinsics (NEON is every AArch64 target's baseline) |
//! | `F32x4Wasm` | 4 | `simd128` | explicit WebAssembly SIMD128 intrinsics, in builds with the `simd128` target feature |
//!
//! The SIMD types are private to this crate: a value of one exists only
//! inside [`crate::Backend::dispatch`] after the CPU was checked for its
//! instructions (or, for NEON and SIMD128, in a build whose target has
//! them), which is what makes their safe methods sound.
//!
//! # Rules every implementation keeps (the bit-for-bit contract)
//!
//! - `+ - * /` and [`Lane::sqrt`] are the correctly rounded IEEE-754
//!   operations. No approximate reciprocal or reciprocal square root exists
//!   here: their results differ between CPU vendors.
//! - [`Lane::min`] is `if a < b { a } else { b }` and [`Lane::max`] is
//!   `if a > b { a } else { b }`, lane by lane: exactly what `minps`/`maxps`
//!   compute. With a NaN in either operand the *second* operand is returned;
//!   `min(-0.0, 0.0)` is `0.0`. (`f32::min` and `wide`'s `min` differ: they
//!   prefer the non-NaN operand.)
//! - [`Lane::round`] rounds to the nearest integer, ties to even.
//! - Comparisons are IEEE: false when either operand is NaN, except
//!   [`Lane::ne`], which is true then (as Rust's `!=`).
//! - [`Lane::abs`], `neg` and [`Lane::copysign`] only touch the sign bit.
//! - Fused multiply-add exists only as the explicit [`Lane::mul_add`], whose
//!   scalar twin is `f32::mul_add`. Rust never contracts `a * b + c` by
//!   itself, so every other expression rounds after each operation.
//!
//! NaN payloads are the one thing not promised: Rust's float semantics
//! leave the payload and sign of a NaN result unspecified, so the
//! cross-backend tests treat every NaN as one value and compare every other
//! result by its bits, signed zeros and subnormals included.
//!
//! # No closures in lane code
//!
//! A closure does not inherit the `#[target_feature]`s of the function it
//! is written in. If LLVM leaves one out of line, every AVX intrinsic in it
//! becomes a function call: a closure in `Sym3::rotated` once made the
//! 8-lane socket kernel four times slower than the 4-lane one. Lane-generic
//! code (vectors, quaternions, polynomials, kernels) uses loops and
//! `#[inline(always)]` functions instead; `tests/tidy.rs` checks it.
//!
//! # Why kernels do not use `mul_add`
//!
//! SSE4.1 has no fused multiply-add and `wide`'s portable fallback may lack
//! one too, so a kernel that fused would need a software `fmaf` (a libm
//! call, tens of nanoseconds) on those backends and on the scalar reference
//! to stay bit-identical with AVX2. Box2D v3 and box3d make the same choice
//! for the same reason. Unfused, every backend runs at full speed and gives
//! the same bits; the polynomials here are evaluated unfused too.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

use crate::row::{ROW_LEN, Row};

mod by_lane;
pub mod scalar;

pub(crate) mod portable;

#[cfg(target_arch = "x86_64")]
#[macro_use]
mod x86;
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx2;
#[cfg(target_arch = "x86_64")]
pub(crate) mod sse41;

#[cfg(all(target_arch = "aarch64", target_feature = "neon"))]
pub(crate) mod neon;

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub(crate) mod simd128;

/// A lane-wise boolean: all bits set for true, clear for false in the SIMD
/// types, `bool` in the scalar reference.
pub trait Mask:
    Copy + Debug + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// True in every lane where `self` is true and `other` is false.
    fn and_not(self, other: Self) -> Self {
        self & !other
    }
}

/// `WIDTH` independent `f32` values and the operations a kernel may use.
///
/// See the [module documentation](self) for the exact semantics each
/// implementation must share.
pub trait Lane:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// The lane-wise boolean produced by comparisons.
    type Mask: Mask;

    /// The lane type of at most half a block that runs in the same
    /// instruction set: `F32x4` for `F32x8` (entered with AVX2 and FMA, it
    /// is the VEX-encoded code of [`crate::Backend::Avx2x4`]), the type
    /// itself for every other. A block whose other half is padding runs on
    /// it (`block::for_live_slices`); every lane type gives the
    /// same bits per lane, so the narrower one changes no result.
    type Narrow: Lane;

    /// How many `f32` values one lane value holds.
    const WIDTH: usize;

    /// The same value in every lane.
    fn splat(value: f32) -> Self;

    /// Loads lanes from the first `WIDTH` values of `src` (any alignment).
    ///
    /// # Panics
    /// If `src` is shorter than `WIDTH`.
    fn load(src: &[f32]) -> Self;

    /// Stores the lanes into the first `WIDTH` values of `dst`.
    ///
    /// # Panics
    /// If `dst` is shorter than `WIDTH`.
    fn store(self, dst: &mut [f32]);

    /// Correctly rounded square root (NaN for negative lanes).
    fn sqrt(self) -> Self;

    /// Absolute value: clears the sign bit.
    fn abs(self) -> Self;

    /// Rounds to the nearest integer, ties to even; infinities and NaN pass
    /// through.
    fn round(self) -> Self;

    /// `if self < other { self } else { other }`, lane by lane.
    fn min(self, other: Self) -> Self;

    /// `if self > other { self } else { other }`, lane by lane.
    fn max(self, other: Self) -> Self;

    /// `self * a + b` with one rounding (`f32::mul_add` in every lane).
    /// Kernels do not use it; see the [module documentation](self).
    fn mul_add(self, a: Self, b: Self) -> Self;

    /// The magnitude of `self` with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;

    /// `self < other`.
    fn lt(self, other: Self) -> Self::Mask;
    /// `self <= other`.
    fn le(self, other: Self) -> Self::Mask;
    /// `self > other`.
    fn gt(self, other: Self) -> Self::Mask;
    /// `self >= other`.
    fn ge(self, other: Self) -> Self::Mask;
    /// `self == other` (false for NaN).
    fn eq(self, other: Self) -> Self::Mask;
    /// `self != other` (true for NaN).
    fn ne(self, other: Self) -> Self::Mask;

    /// `if mask { on_true } else { on_false }`, lane by lane, by bits.
    fn select(mask: Self::Mask, on_true: Self, on_false: Self) -> Self;

    /// Gathers body rows: lane `i` of element `k` is `rows[indices[i]][k]`
    /// (the loads and the transpose; `indices` holds `WIDTH` entries).
    ///
    /// Safe for any caller and any indices: rows are cells that cannot be
    /// shared between threads ([`Row`] is not `Sync`), so the plain vector
    /// loads and stores of this and [`Lane::scatter_rows`] never race (see
    /// [`crate::row`]).
    ///
    /// # Panics
    /// If an index is out of bounds.
    fn gather_rows(rows: &[Row], indices: &[u32]) -> [Self; ROW_LEN];

    /// The inverse of [`Lane::gather_rows`]: writes lane `i` of every
    /// element back to `rows[indices[i]]`, except where the index is
    /// [`NO_WRITE`](crate::row::NO_WRITE).
    ///
    /// # Panics
    /// If an index other than `NO_WRITE` is out of bounds.
    fn scatter_rows(values: &[Self; ROW_LEN], rows: &[Row], indices: &[u32]);

    /// The sum of the lanes, added in lane order `((l0 + l1) + l2) + ...`.
    /// For metrics and tests; kernels never reduce across lanes (the order
    /// would differ between 4 and 8 lanes).
    fn reduce_add(self) -> f32;

    /// True in the lanes that hold NaN.
    #[inline(always)]
    fn is_nan(self) -> Self::Mask {
        self.ne(self)
    }

    /// Clamps every lane to `[lo, hi]` with the [`Lane::min`]/[`Lane::max`]
    /// rule (a NaN lane becomes `lo`).
    #[inline(always)]
    fn clamp(self, lo: Self, hi: Self) -> Self {
        self.max(lo).min(hi)
    }
}
