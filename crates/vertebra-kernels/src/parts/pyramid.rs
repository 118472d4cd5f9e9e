//! Pyramid: a swing limit with its own range about each of the joint
//! frame's Y and Z axes (Jolt's pyramid swing), at the position level: two
//! independent angle limits.
//!
//! With b's twist axis `d` in a's joint frame (`swing_direction`), the
//! swing angles about Y and Z are
//! `theta_y = 2 atan2(-d_z, 1 + d_x)` and `theta_z = 2 atan2(d_y, 1 + d_x)`,
//! in [-pi, pi]: they are `2 atan2(s_y, s_w)` and `2 atan2(s_z, s_w)` of the
//! swing quaternion (`s_y / s_w = -d_z / (1 + d_x)`), so a swing about Y
//! alone by `alpha` has `theta_y = alpha`, `theta_z = 0`. Each is held in
//! its own `[min, max]`; the error is the signed excess
//! `e = theta - clamp(theta, min, max)`, corrected as `|e|` about
//! `sign(e) n`.
//!
//! **Gradients.** For `theta = 2 atan2(a, b)`,
//! `dtheta = 2 (b da - a db) / (a^2 + b^2)`; so
//! `g_y = 2 (d_z, 0, -(1 + d_x)) / (d_z^2 + (1 + d_x)^2)` and
//! `g_z = 2 (-d_y, 1 + d_x, 0) / (d_y^2 + (1 + d_x)^2)` (a's joint frame),
//! which `swing_direction` turns into rotation axes. At `d = -x` both are
//! 0 (the angles are undefined there). Ranges of [-pi, pi] never bind.

use vertebra_math::{Lane, Vec3, poly};

use super::swing_direction::{self, Direction};
use crate::body::safe_ratio;

/// The swing angles `(theta_y, theta_z)` (rad).
#[inline(always)]
pub fn angles<L: Lane>(dir: &Direction<L>) -> (L, L) {
    let d = dir.d;
    let two = L::splat(2.0);
    let base = L::splat(1.0) + d.x;
    (two * poly::atan2(-d.z, base), two * poly::atan2(d.y, base))
}

/// The swing angles about Y and Z (rad) with their gradients `g_y`, `g_z`
/// (the module documentation's, a's joint frame).
#[inline(always)]
fn gradients<L: Lane>(dir: &Direction<L>) -> [(L, Vec3<L>); 2] {
    let (zero, two) = (L::splat(0.0), L::splat(2.0));
    let d = dir.d;
    let base = L::splat(1.0) + d.x;
    let (theta_y, theta_z) = angles(dir);
    let gy = Vec3::new(d.z, zero, -base).scale(safe_ratio(two, d.z * d.z + base * base));
    let gz = Vec3::new(-d.y, base, zero).scale(safe_ratio(two, d.y * d.y + base * base));
    [(theta_y, gy), (theta_z, gz)]
}

/// The violations `|e|` (rad) of the ranges `y` and `z` (rad) and their
/// axes `sign(e) n` (`d|e|/dtheta_b`, world, not unit).
#[inline(always)]
pub fn violations<L: Lane>(dir: &Direction<L>, y: [L; 2], z: [L; 2]) -> [(Vec3<L>, L); 2] {
    let [(theta_y, gy), (theta_z, gz)] = gradients(dir);
    [
        excess_axis(dir, theta_y, y, gy),
        excess_axis(dir, theta_z, z, gz),
    ]
}

/// As [`violations`], signed for the direct solve's active set: each
/// angle's distance past the nearer bounded end of its range (negative
/// inside, `free` for a range with no bounded end; `twist::signed`) and
/// the axis along which it grows (a's body frame).
#[inline(always)]
pub fn signed<L: Lane>(dir: &Direction<L>, y: [L; 2], z: [L; 2], free: L) -> [(Vec3<L>, L); 2] {
    let [(theta_y, gy), (theta_z, gz)] = gradients(dir);
    [
        signed_axis(dir, theta_y, y, gy, free),
        signed_axis(dir, theta_z, z, gz, free),
    ]
}

/// The signed distance and axis for one angle of gradient `g`.
#[inline(always)]
fn signed_axis<L: Lane>(
    dir: &Direction<L>,
    theta: L,
    range: [L; 2],
    g: Vec3<L>,
    free: L,
) -> (Vec3<L>, L) {
    let (c, sign) = super::twist::signed(theta, range[0], range[1], free);
    (swing_direction::axis(dir, g).scale(sign), c)
}

/// `|e|` and `sign(e) n` for one angle of gradient `g`.
#[inline(always)]
fn excess_axis<L: Lane>(dir: &Direction<L>, theta: L, range: [L; 2], g: Vec3<L>) -> (Vec3<L>, L) {
    let e = theta - theta.clamp(range[0], range[1]);
    let n = swing_direction::axis(dir, g).scale(L::splat(1.0).copysign(e));
    (n, e.abs())
}
