//! The two-argument arctangent: the ratio of the smaller to the larger
//! magnitude in [0, 1], reduced once more about tan(pi/8) (Cephes `atanf`),
//! then put back in its octant and quadrant by selects.

use crate::lane::Lane;

/// tan(pi/8): above it, atan(a) = pi/4 + atan((a - 1) / (a + 1)).
const TAN_PI_8: f32 = 0.414_213_57;
/// atan(a) = a + a^3 P(a^2) for |a| <= tan(pi/8).
const ATAN: [f32; 4] = [
    8.053_744_5e-2,
    -1.387_768_6e-1,
    1.997_771_1e-1,
    -3.333_295e-1,
];

/// The angle of the point `(x, y)` from the +x axis, in (-pi, pi], with
/// IEEE-754 conventions for signed zeros and infinities
/// (`atan2(0, -0) = pi`, `atan2(inf, inf) = pi/4`); NaN in either argument
/// gives NaN. Accurate to 2.7e-7 (see [`crate::poly`]).
#[inline(always)]
pub fn atan2<L: Lane>(y: L, x: L) -> L {
    let (ax, ay) = (x.abs(), y.abs());
    let (small, large) = (ax.min(ay), ax.max(ay));
    let zero = L::splat(0.0);
    let one = L::splat(1.0);
    // a = small / large in [0, 1]; 0/0 and inf/inf are settled by selects.
    let a = L::select(large.eq(zero), zero, small / large);
    let a = L::select(small.eq(L::splat(f32::INFINITY)), one, a);

    let reduced = a.gt(L::splat(TAN_PI_8));
    let t = L::select(reduced, (a - one) / (a + one), a);
    let z = t * t;
    let octant = t + t * z * super::horner(z, &ATAN);
    let angle = L::select(
        reduced,
        L::splat(core::f32::consts::FRAC_PI_4) + octant,
        octant,
    );

    let angle = L::select(ay.gt(ax), super::pi_minus(true, angle), angle);
    let x_negative = one.copysign(x).lt(zero);
    let angle = L::select(x_negative, super::pi_minus(false, angle), angle);
    let angle = angle.copysign(y);
    L::select(x.is_nan() | y.is_nan(), x + y, angle)
}
