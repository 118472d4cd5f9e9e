//! Sine and cosine: reduction by multiples of pi/2, then a minimax
//! polynomial on [-pi/4, pi/4] (Cephes `sinf`/`cosf`).

use crate::lane::Lane;

/// pi/2 split in three (Cody-Waite): `K * PIO2_HI` is exact for |K| < 2^15,
/// so the reduction stays accurate for |x| up to 8192 and beyond.
const PIO2_HI: f32 = 1.570_312_5;
const PIO2_MID: f32 = 4.837_513e-4;
const PIO2_LO: f32 = 7.549_79e-8;
const TWO_OVER_PI: f32 = core::f32::consts::FRAC_2_PI;

/// sin(r) = r + r^3 S(r^2) on [-pi/4, pi/4].
const SIN: [f32; 3] = [-1.951_529_6e-4, 8.332_161e-3, -1.666_665_5e-1];
/// cos(r) = 1 - r^2/2 + r^4 C(r^2) on [-pi/4, pi/4].
const COS: [f32; 3] = [2.443_315_7e-5, -1.388_731_6e-3, 4.166_664_6e-2];

/// Sine and cosine of `x` (radians) together, sharing the reduction.
///
/// Accurate to 1.0e-7 for |x| <= 8192 (see [`crate::poly`]); further out
/// the results stay finite and within [-1, 1]; infinite or NaN input gives
/// NaN.
#[inline(always)]
pub fn sin_cos<L: Lane>(x: L) -> (L, L) {
    let k = (x * L::splat(TWO_OVER_PI)).round();
    let r = ((x - k * L::splat(PIO2_HI)) - k * L::splat(PIO2_MID)) - k * L::splat(PIO2_LO);
    // Far beyond the domain the reduction is meaningless and the polynomial
    // could overflow to inf - inf; such lanes evaluate at 0 instead.
    let r = L::select(r.abs().le(L::splat(1.0)), r, L::splat(0.0));
    let z = r * r;
    let s = r + r * z * super::horner(z, &SIN);
    let c = (L::splat(1.0) - L::splat(0.5) * z) + z * z * super::horner(z, &COS);

    // The quadrant q = k mod 4, from floats: k - 4 floor(k / 4).
    let quarter = k * L::splat(0.25);
    let floor = quarter.round();
    let floor = L::select(floor.gt(quarter), floor - L::splat(1.0), floor);
    let q = k - L::splat(4.0) * floor;

    let odd = q.eq(L::splat(1.0)) | q.eq(L::splat(3.0));
    let (sin, cos) = (L::select(odd, c, s), L::select(odd, s, c));
    let sin = L::select(q.ge(L::splat(2.0)), -sin, sin);
    let cos = L::select(q.eq(L::splat(1.0)) | q.eq(L::splat(2.0)), -cos, cos);
    // Infinite or NaN input: NaN out (`0 x` is NaN exactly then).
    let zero_times = x * L::splat(0.0);
    let invalid = zero_times.is_nan();
    (
        L::select(invalid, zero_times, sin),
        L::select(invalid, zero_times, cos),
    )
}

/// Sine of `x` (radians); see [`sin_cos`].
#[inline(always)]
pub fn sin<L: Lane>(x: L) -> L {
    sin_cos(x).0
}

/// Cosine of `x` (radians); see [`sin_cos`].
#[inline(always)]
pub fn cos<L: Lane>(x: L) -> L {
    sin_cos(x).1
}
