//! Length part (paper eq. 9, hard, 1 degree of freedom): the chord of an
//! inextensible arc of length `l0` bent by `psi` is `2 l0 sin(psi/2)/psi`,
//! so `C = |p_b - p_a| - 2 l0 sin(psi/2)/psi`.
//!
//! As the paper does, the length is corrected "purely through linear motion
//! along the offset axis", holding `psi` fixed: `dC/dp_b = o`,
//! `dC/dp_a = -o`, `w = 1/m_a + 1/m_b`, `dlambda = -C/w`. The factor
//! `sin(psi/2)/psi` is `poly::half_sinc`, exact and smooth at `psi = 0`
//! (where the chord is `l0`) and up to `psi = pi` (where it is
//! `2 l0 / pi`).
//!
//! The direct solve's row takes the whole gradient: the chord also turns
//! with the bend, `dchord/dtheta_b = chord'(psi) n` ([`chord_turn`], `n`
//! the bend axis; `-` for a), so a bent rod's length converges as fast as
//! its other rows.

use vertebra_math::{Lane, Vec3, poly};

use super::{Frames, bend_angle};
use crate::body::{BodyLanes, PairStart, safe_ratio};

/// The chord length of an arc of `rest_length` bent by `psi` (m).
#[inline(always)]
pub fn chord<L: Lane>(rest_length: L, psi: L) -> L {
    L::splat(2.0) * rest_length * poly::half_sinc(psi)
}

/// How the chord's length turns with b (m/rad, world):
/// `dchord/dtheta_b = 2 l0 (d/dpsi sin(psi/2)/psi) n`, with `n` the bend
/// axis (`t_a x t_b` normalised; `dpsi/dtheta_b = n`, `dpsi/dtheta_a =
/// -n`). Zero for a straight rod, where `n` has no direction and the
/// chord's slope is zero too.
#[inline(always)]
pub fn chord_turn<L: Lane>(rest_length: L, f: &Frames<L>) -> Vec3<L> {
    let (n, psi) = bend_angle(f.ta, f.tb);
    n.scale(L::splat(2.0) * rest_length * poly::half_sinc_slope(psi))
}

/// The chord direction `o` and the length error `C` (m); the chord is
/// measured from the start of the step ([`PairStart::chord`]).
#[inline(always)]
pub fn measure<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    f: &Frames<L>,
    rest_length: L,
    start: &PairStart<L>,
) -> (Vec3<L>, L) {
    let (o, distance) = start.chord(a, b).normalize_or_zero();
    let (_, psi) = bend_angle(f.ta, f.tb);
    (o, distance - chord(rest_length, psi))
}

/// Moves the bodies along the chord to the arc's length; returns the error
/// before the correction (m).
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    f: &Frames<L>,
    rest_length: L,
    start: &PairStart<L>,
) -> L {
    let (o, c) = measure(a, b, f, rest_length, start);
    let dlambda = safe_ratio(-c, a.inv_mass + b.inv_mass);
    b.p += o.scale(dlambda * b.inv_mass);
    a.p -= o.scale(dlambda * a.inv_mass);
    c
}
