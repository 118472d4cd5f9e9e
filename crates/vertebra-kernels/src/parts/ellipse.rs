//! Elliptical cone: a swing limit with a different half-angle about each of
//! the joint frame's Y and Z axes (Jolt's plane and normal half-angles),
//! at the position level.
//!
//! **The limit.** With the swing `s = (0, s_y, s_z, s_w)` of
//! `swing_direction` (so `(s_y, s_z) = sin(theta / 2) u` for a swing of
//! `theta` about the unit axis `u` in the YZ plane), the allowed swings
//! are the ellipse `(s_y / A)^2 + (s_z / B)^2 <= 1` in the swing-sine
//! plane `p = (s_y, s_z)`, with `A = sin(theta_y / 2)`,
//! `B = sin(theta_z / 2)` for the half-angles `theta_y` (about Y) and
//! `theta_z` (about Z), as Jolt's swing-twist constraint. So the largest
//! swing about `u` is, in closed form,
//! `theta_max(u) = 2 asin(1 / sqrt(u_y^2 / A^2 + u_z^2 / B^2))`: `theta_y`
//! about Y, `theta_z` about Z, and exactly the circular cone when `A = B`.
//! Half-angles of pi (`A = B = 1`) never bind.
//!
//! **The error.** Outside, `C = |p - q|` for the nearest point `q` of the
//! ellipse (as Jolt's `EllipseClosestPoint`): for `p = (x, y)`,
//! `q = (A^2 x / (t + A^2), B^2 y / (t + B^2))` with `t >= 0` the root of
//! `f(t) = (A x / (t + A^2))^2 + (B y / (t + B^2))^2 - 1` (then `p - q` is
//! along the ellipse's normal at `q`). `f` is convex and decreasing for
//! `t >= 0`, and `t_0 = max(A |x| - A^2, B |y| - B^2, 0)` lies left of the
//! root (each term is at most 1 there), so Newton's method climbs to the
//! root monotonically: [`NEWTON_STEPS`] fixed steps, branch-free, `t` held
//! at 0 or more (inside points, whose result is unused, stay finite).
//!
//! **The gradient.** As `q` is the nearest point, `dC = e . dp` with the
//! unit `e = (p - q) / C` (the envelope theorem: `q` moves along the
//! boundary, perpendicular to `e`). From `p = (-d_z, d_y) / k`,
//! `k = sqrt(2 (1 + d_x))`, `dk/dd_x = 1 / k`:
//! `dp_y = (d_z / k^3) dd_x - dd_z / k`, `dp_z = -(d_y / k^3) dd_x + dd_y / k`,
//! so `g = e_y (d_z / k^3, 0, -1 / k) + e_z (-d_y / k^3, 1 / k, 0)`, and
//! `swing_direction` turns it into the rotation axis.
//!
//! `C` is a distance in the swing-sine plane, where a swing `dtheta`
//! (rad) moves `p` by `cos(theta / 2) / 2 dtheta`: a soft ellipse's
//! compliance is given per radian (rad / (N m)) and applied as a quarter
//! of it here, exact for small swings, `cos^2(theta / 2)` stiffer at the
//! boundary of a wide cone. Semi-axes are held to at least
//! [`MIN_SEMI_AXIS`] so that every division is defined.

use vertebra_math::{Lane, Vec3};

use super::swing_direction::{self, Direction};
use crate::body::safe_ratio;

/// Newton steps toward the nearest point of the ellipse: eight reach it
/// to `f32` precision for semi-axes down to 0.05 (checked in
/// `tests/joint_gradients.rs`).
pub const NEWTON_STEPS: usize = 8;

/// The smallest semi-axis: `sin(0.001)`, a half-angle of 0.002 rad.
pub const MIN_SEMI_AXIS: f32 = 0.001;

/// The swing-sine point `p = (s_y, s_z)` and `k = sqrt(2 (1 + d_x))`
/// (0 at a swing of pi, where `p` is taken as `(-d_z, d_y)`).
#[inline(always)]
pub fn sines<L: Lane>(dir: &Direction<L>) -> ([L; 2], L) {
    let d = dir.d;
    let k = (L::splat(2.0) * (L::splat(1.0) + d.x))
        .max(L::splat(0.0))
        .sqrt();
    let defined = k.gt(L::splat(0.0));
    let inv = L::splat(1.0) / L::select(defined, k, L::splat(1.0));
    ([-d.z * inv, d.y * inv], k)
}

/// The ellipse's nearest point to `p` (meaningful where `p` lies outside).
#[inline(always)]
pub fn nearest<L: Lane>(p: [L; 2], semi_y: L, semi_z: L) -> [L; 2] {
    let (one, zero) = (L::splat(1.0), L::splat(0.0));
    let (a2, b2) = (semi_y * semi_y, semi_z * semi_z);
    let (ax, by) = (semi_y * p[0], semi_z * p[1]);
    let mut t = (ax.abs() - a2).max(by.abs() - b2).max(zero);
    for _ in 0..NEWTON_STEPS {
        let (da, db) = (t + a2, t + b2);
        let (ga, gb) = (ax / da, by / db);
        let (ga2, gb2) = (ga * ga, gb * gb);
        let f = ga2 + gb2 - one;
        let slope = L::splat(2.0) * (ga2 / da + gb2 / db);
        t = (t + safe_ratio(f, slope)).max(zero);
    }
    [a2 * p[0] / (t + a2), b2 * p[1] / (t + b2)]
}

/// The violation `C` (swing-sine units, >= 0) and the axis `n`
/// (`dC/dtheta_b`, world, not unit); both 0 inside the cone.
#[inline(always)]
pub fn violation<L: Lane>(dir: &Direction<L>, semi_y: L, semi_z: L) -> (Vec3<L>, L) {
    let zero = L::splat(0.0);
    let (p, k) = sines(dir);
    let (u, v) = (p[0] / semi_y, p[1] / semi_z);
    let active = (u * u + v * v).gt(L::splat(1.0));
    let q = nearest(p, semi_y, semi_z);
    let (ey, ez) = (p[0] - q[0], p[1] - q[1]);
    let c = (ey * ey + ez * ez).sqrt();
    let (ey, ez) = (safe_ratio(ey, c), safe_ratio(ez, c));
    let n = plane_axis(dir, k, [ey, ez]);
    (
        Vec3::select(active, n, Vec3::zero()),
        L::select(active, c, zero),
    )
}

/// As [`violation`], signed for the direct solve's active set: outside,
/// the same distance and axis; inside, the first-order distance to the
/// boundary along the gradient of `s = sqrt((p_y / A)^2 + (p_z / B)^2)`,
/// `(s - 1) / |grad s|` (negative), about the level set's normal, which
/// meet the outside's on the boundary. An ellipse with no semi-axis below
/// 1 (half-angles of pi) never binds: its distance is `free`.
#[inline(always)]
pub fn signed<L: Lane>(dir: &Direction<L>, semi_y: L, semi_z: L, free: L) -> (Vec3<L>, L) {
    let one = L::splat(1.0);
    let (outside_axis, outside) = violation(dir, semi_y, semi_z);
    let (p, k) = sines(dir);
    let (u, v) = (p[0] / semi_y, p[1] / semi_z);
    let s = (u * u + v * v).sqrt();
    let (gy, gz) = (safe_ratio(u, s * semi_y), safe_ratio(v, s * semi_z));
    let norm = (gy * gy + gz * gz).sqrt();
    let inside = safe_ratio(s - one, norm);
    let inside_axis = plane_axis(dir, k, [safe_ratio(gy, norm), safe_ratio(gz, norm)]);
    let beyond = s.gt(one);
    let bounded = semi_y.min(semi_z).lt(one);
    (
        Vec3::select(beyond, outside_axis, inside_axis),
        L::select(bounded, L::select(beyond, outside, inside), free),
    )
}

/// The rotation axis (a's body frame) along which a unit direction
/// `e = (e_y, e_z)` of the swing-sine plane grows (the module
/// documentation's `g`, through `swing_direction`).
#[inline(always)]
fn plane_axis<L: Lane>(dir: &Direction<L>, k: L, [ey, ez]: [L; 2]) -> Vec3<L> {
    let zero = L::splat(0.0);
    let inv_k = safe_ratio(L::splat(1.0), k);
    let inv_k3 = inv_k * inv_k * inv_k;
    let d = dir.d;
    let g = Vec3::new(ey * d.z * inv_k3, zero, -(ey * inv_k))
        + Vec3::new(-(ez * d.y * inv_k3), ez * inv_k, zero);
    swing_direction::axis(dir, g)
}

/// The angle (rad) from b's twist axis to the nearest allowed one in the
/// swing-sine plane (0 inside): the residual's measure of the overshoot.
#[inline(always)]
pub fn violation_angle<L: Lane>(dir: &Direction<L>, semi_y: L, semi_z: L) -> L {
    let (one, zero) = (L::splat(1.0), L::splat(0.0));
    let (p, _) = sines(dir);
    let (u, v) = (p[0] / semi_y, p[1] / semi_z);
    let active = (u * u + v * v).gt(one);
    let q = nearest(p, semi_y, semi_z);
    // The allowed direction: x turned by the swing (0, q_y, q_z, q_w).
    let w = (one - (q[0] * q[0] + q[1] * q[1])).max(zero).sqrt();
    let allowed =
        vertebra_math::Quat::new(zero, q[0], q[1], w).rotate(Vec3::splat(crate::TWIST_AXIS));
    let d = dir.d;
    let angle = vertebra_math::poly::atan2(d.cross(allowed).length(), d.dot(allowed));
    L::select(active, angle, zero)
}
