//! `sin(x/2) / x`, the factor in the rod's chord `2 l0 sin(psi/2) / psi`
//! (paper eq. 9), and its slope (how the chord shortens as the rod bends:
//! the direct solve's length row). Written as series in `x^2` they have no
//! division and no special case at `x = 0`, where the factor is exactly
//! 1/2 and its slope 0, both smooth.

use crate::lane::Lane;

/// sin(x/2)/x = sum_n (-1)^n x^(2n) / (2^(2n+1) (2n+1)!), highest first.
const HALF_SINC: [f32; 7] = [
    1.960_332_5e-14,
    -1.223_247_5e-11,
    5.382_289e-9,
    -1.550_099_2e-6,
    2.604_166_7e-4,
    -2.083_333_4e-2,
    0.5,
];

/// `sin(x/2) / x` for `x` in [-pi, pi] (1/2 at `x = 0`); even in `x`.
/// Input beyond [-pi, pi] is clamped to it; NaN gives NaN. Accurate to
/// 5e-8 (see [`crate::poly`]).
#[inline(always)]
pub fn half_sinc<L: Lane>(x: L) -> L {
    let pi = L::splat(super::PI);
    // max(-pi, x) and min(pi, _) return the NaN operand, so NaN survives.
    let x = pi.min((-pi).max(x));
    super::horner(x * x, &HALF_SINC)
}

/// The slope's series: `d/dx sin(x/2)/x = x sum_n 2n c_n x^(2(n-1))` with
/// `c_n` [`HALF_SINC`]'s terms, highest first.
const HALF_SINC_SLOPE: [f32; 6] = [
    2.352_399e-13,
    -1.223_247_5e-10,
    4.305_831e-8,
    -9.300_596e-6,
    1.041_666_7e-3,
    -4.166_666_8e-2,
];

/// `d/dx (sin(x/2) / x)` for `x` in [-pi, pi] (0 at `x = 0`, `-x/24`
/// near it); odd in `x`. Input beyond [-pi, pi] is clamped to it; NaN
/// gives NaN. Accurate to 5e-8 (see [`crate::poly`]).
#[inline(always)]
pub fn half_sinc_slope<L: Lane>(x: L) -> L {
    let pi = L::splat(super::PI);
    let x = pi.min((-pi).max(x));
    x * super::horner(x * x, &HALF_SINC_SLOPE)
}
