//! The project's own branch-free polynomials, generic over [`Lane`] so that
//! every backend evaluates exactly the same operations in the same order
//! (libm's `sinf`/`acosf` differ between platforms and have no SIMD twin).
//!
//! | function | domain (accurate) | max abs error there | measured | outside the domain |
//! | --- | --- | --- | --- | --- |
//! | [`sin`], [`cos`], [`sin_cos`] | \|x\| <= 8192 | 1.0e-7 | 9.2e-8 | finite input: a value in [-1, 1]; inf, NaN: NaN |
//! | [`asin`] | [-1, 1] | 1.5e-7 | 1.4e-7 | clamped to [-1, 1]; NaN: NaN |
//! | [`acos`] | [-1, 1] | 2.6e-7 | 2.5e-7 | clamped to [-1, 1]; NaN: NaN |
//! | [`atan2`] | all (y, x), both infinite too | 2.7e-7 | 2.6e-7 | NaN in either: NaN |
//! | [`half_sinc`] `sin(x/2)/x` | [-pi, pi] | 5.0e-8 | 4.3e-8 | clamped to [-pi, pi]; NaN: NaN |
//! | [`half_sinc_slope`] its derivative | [-pi, pi] | 5.0e-8 | | clamped to [-pi, pi]; NaN: NaN |
//! | [`wrap_angle`] to [-pi, pi] | \|x\| <= 4 pi | 3.5e-7 | 3.5e-7 | finite: a value near [-pi, pi], off by the rounding of `x / 2 pi`; inf, NaN: NaN |
//!
//! For scale: one ulp of pi in `f32` is 2.4e-7, so the inverse functions are
//! within about one ulp of their largest results. `acos` is also accurate
//! relative to its result near `x = 1` (4 epsilon), which is where the
//! rod's small bend angles live. The errors are measured against `f64` over
//! dense grids by `tests/poly_accuracy.rs`, which asserts the bounds. The coefficients of `sin`, `cos`, `asin` and the
//! arctangent are Cephes' single-precision minimax sets (S. L. Moshier);
//! `half_sinc` and its slope are Taylor series, which converge fast on
//! [-pi, pi].

mod asin;
mod atan;
mod half_sinc;
mod trig;

pub use asin::{acos, asin};
pub use atan::atan2;
pub use half_sinc::{half_sinc, half_sinc_slope};
pub use trig::{cos, sin, sin_cos};

use crate::lane::Lane;

/// `pi` as the nearest `f32`.
pub const PI: f32 = core::f32::consts::PI;
/// `pi / 2` as the nearest `f32`.
pub const FRAC_PI_2: f32 = core::f32::consts::FRAC_PI_2;
/// `pi - PI`: what the `f32` constant misses of pi.
const PI_LO: f32 = -8.742_278e-8;

/// `c pi - a` for `c` in {1/2, 1} with a single rounding of the result:
/// the small part of `c pi` meets `a` first, so the error of the `f32`
/// constant does not add to the rounding of the difference.
#[inline(always)]
pub(crate) fn pi_minus<L: Lane>(half: bool, a: L) -> L {
    let (hi, lo) = if half {
        (FRAC_PI_2, 0.5 * PI_LO)
    } else {
        (PI, PI_LO)
    };
    (L::splat(lo) - a) + L::splat(hi)
}

/// `x` wrapped to [-pi, pi] (rad), branch-free: `x - 2 pi round(x / 2 pi)`
/// (ties to even, so `pi` and `-pi` stay as they are). The difference of
/// two angles in [-pi, pi] is exact to within one rounding of `2 pi`; an
/// angle error wrapped so turns the short way round.
#[inline(always)]
pub fn wrap_angle<L: Lane>(x: L) -> L {
    const TAU: f32 = 2.0 * PI;
    x - L::splat(TAU) * (x * L::splat(1.0 / TAU)).round()
}

/// Evaluates the polynomial with `coefficients` (highest degree first) at
/// `x` by Horner's rule, unfused: `((c0 x + c1) x + c2) ...`.
#[inline(always)]
pub(crate) fn horner<L: Lane>(x: L, coefficients: &[f32]) -> L {
    // A loop, not a fold: lane code has no closures (see `crate::lane`).
    let mut acc = L::splat(coefficients[0]);
    for &c in &coefficients[1..] {
        acc = acc * x + L::splat(c);
    }
    acc
}
