//! Arcsine and arccosine from one core (Cephes `asinf`): a minimax
//! polynomial for |x| <= 1/2, and the half-angle identity
//! `asin(a) = pi/2 - 2 asin(sqrt((1 - a) / 2))` above it, which keeps
//! `acos` accurate near 1 where the rod's bend angle is small.

use crate::lane::Lane;

/// asin(s) = s + s^3 P(s^2) for |s| <= 1/2 (as published, digit for digit).
#[allow(clippy::excessive_precision)]
const ASIN: [f32; 5] = [
    4.216_32e-2,
    2.418_131_1e-2,
    4.547_002_6e-2,
    7.495_300_3e-2,
    1.666_675_2e-1,
];

/// The shared core for `a = |x|` clamped to [0, 1]: returns
/// `(asin(s), above_half)` where `s = a` for `a <= 1/2` and
/// `s = sqrt((1 - a) / 2)` above.
#[inline(always)]
fn core<L: Lane>(a: L) -> (L, L::Mask) {
    let above_half = a.gt(L::splat(0.5));
    let z = L::select(above_half, L::splat(0.5) * (L::splat(1.0) - a), a * a);
    let s = L::select(above_half, z.sqrt(), a);
    (s + s * z * super::horner(z, &ASIN), above_half)
}

/// `|x|` limited to 1, NaN kept: `min(1, v)` returns `v` when `v` is NaN.
#[inline(always)]
fn clamped_magnitude<L: Lane>(x: L) -> L {
    L::splat(1.0).min(x.abs())
}

/// Arcsine in [-pi/2, pi/2]. Input beyond [-1, 1] is clamped to it; NaN
/// gives NaN. Accurate to 1.5e-7 (see [`crate::poly`]).
#[inline(always)]
pub fn asin<L: Lane>(x: L) -> L {
    let (p, above_half) = core(clamped_magnitude(x));
    let magnitude = L::select(above_half, super::pi_minus(true, p + p), p);
    magnitude.copysign(x)
}

/// Arccosine in [0, pi]. Input beyond [-1, 1] is clamped to it; NaN gives
/// NaN. Accurate to 2.6e-7 (see [`crate::poly`]), and to a few ulps of the
/// result near `x = 1`, where `acos(x) = 2 asin(sqrt((1 - x) / 2))`.
#[inline(always)]
pub fn acos<L: Lane>(x: L) -> L {
    let (p, above_half) = core(clamped_magnitude(x));
    let negative = x.lt(L::splat(0.0));
    let twice = p + p;
    let far = L::select(negative, super::pi_minus(false, twice), twice);
    let near = super::pi_minus(true, p.copysign(x));
    L::select(above_half, far, near)
}
