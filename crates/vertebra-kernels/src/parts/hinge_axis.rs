//! Hinge axis part: the two joint frames' +X axes held together (2
//! degrees of freedom, hard, solved together), globally: from any
//! misalignment below 180 degrees, in one step when one body is dynamic.
//!
//! With `t_a = q_a F_a x`, `t_b = q_b F_b x` (unit), `u = t_a x t_b`
//! (`|u| = sin theta`) and `s = t_a + t_b` (`|s|^2 = 2 (1 + cos theta)`),
//! the rows are the swing part's axis `n = u / |u|` (`swing.rs`: turning
//! b by a small `v` grows the angle `theta = atan2(|u|, t_a . t_b)` by
//! `v . n`, turning a by `v` shrinks it by `v . n`) and `m = n x s`.
//! Turning either body about `m` leaves `theta` unchanged to first order
//! (`m . n = 0`) and tilts `t_b` out of the plane of the two axes: the
//! pair spans the plane perpendicular to the bisector `s`, the one
//! direction left free (near alignment: the hinge's own rotation, as the
//! rows `y_b x t_a`, `z_b x t_a` of Jolt's `HingeRotationConstraintPart`;
//! both rows are checked against finite differences in
//! `tests/joint_gradients.rs`). `n` and `m` are orthogonal and nonzero
//! below 180 degrees (`|m| = |s|`), so `K = J (I_a^-1 + I_b^-1) J^T`
//! (`J = [n; m]`, 2x2) is positive definite whenever a body is dynamic,
//! at any misalignment; the step is `dlambda = -K^-1 (E, 0)`, b turns by
//! `I_b^-1 J^T dlambda` and a by the negative with `I_a^-1`, both rows
//! solved together (one row along `n` alone would be an oblique
//! projection whenever the inertia is anisotropic; see the drive part).
//!
//! The error `E` on the `n` row is not the linearised `theta` but what
//! the bodies' update makes exact. [`BodyLanes::turn_local`] turns by the
//! world `w = R v` as `q + 1/2 q (v, 0) = q + 1/2 (w, 0) q`, renormalised:
//! exactly the rotation whose Gibbs
//! (Rodrigues) vector is `g = w / 2` (angle `2 atan(|w| / 2)` about `w`).
//! A rotation with Gibbs vector `g` takes `t_b` to `t_a` if and only if
//! `t_a - t_b = g x s` (Rodrigues' formula). Both sides are perpendicular
//! to `s`, so it is two equations: along `n`, `0 = g . (s x n) = -g . m`;
//! along `t_a - t_b` (whose square is `2 (1 - cos theta)`),
//! `2 (1 - cos theta) = g . (s x (t_a - t_b)) = -2 g . u`. So
//! `w . n = -2 tan(theta / 2)`, `w . m = 0`: linear in the turn, not a
//! linearisation. With one dynamic body (b; a is the same with the signs
//! turned) the step with `E = 2 tan(theta / 2)` brings the axes together
//! in one step, whatever the inertia's anisotropy and the angle.
//!
//! Two dynamic bodies each turn by their own Gibbs vector, and Gibbs
//! vectors do not add. When both turn about `n` (`n` a principal axis of
//! both inverse inertias: isotropic ones, say), b by the share `f_b` of the
//! correction along `n` (`f_b = (K_b K^-1)_11`, `K_b = J I_b^-1 J^T`) and
//! a by `f_a = 1 - f_b`, the Gibbs magnitudes `x_b = f_b E / 2`,
//! `x_a = f_a E / 2` turn by `2 atan(x_a) + 2 atan(x_b) = theta` when
//! `(x_a + x_b) / (1 - x_a x_b) = tan(theta / 2) = T`, i.e.
//! `p T E^2 / 4 + E / 2 - T = 0` with `p = f_a f_b`:
//! `E = 4 T / (1 + sqrt(1 + 4 p T^2))`. With `T = |u| / d`,
//! `d = 1 + cos theta = |s|^2 / 2` (accurate at both ends, unlike
//! `1 + t_a . t_b`), `E = 4 |u| / (d + sqrt(d^2 + 4 p |u|^2))`: `2 T` for
//! one dynamic body (`p = 0`), `4 tan(theta / 4)` for equal shares, and
//! `theta + O(theta^3)` near alignment. Bodies turning about different
//! axes (anisotropic inertias on both sides) are not exact in one step
//! but come back from any angle below 180 degrees in a few (where `f_b`
//! leaves [0, 1], `p` is held at 0). Exactly antiparallel axes leave `n`
//! undefined: `u = 0` gives no correction (an unstable equilibrium no
//! other pose heads for).
//!
//! The rows are measured in each body's own frame: in a's, `t_a = F_a x`
//! and `t_b = (q_a* q_b F_b) x` (b's orientation relative to a, one
//! quaternion product), then `n` and `m` there, turned into b's frame by
//! the same relative rotation. `K` is formed from them
//! (`j^T I^-1 j = (R^T j)^T S (R^T j)`), which also gives each body's turn
//! `R S (R^T j)` with one rotation out of it (`angle::apply_local`);
//! `dlambda` comes from `k22 / det` and `k12 / det`, which stay bounded as
//! `|m| = |s|` vanishes near 180 degrees (`k22` and `det` shrink
//! together). A singular `K` (no dynamic body) gives no correction.

use vertebra_math::{Lane, Quat, Vec3};

use super::{angle, swing};
use crate::body::{BodyLanes, safe_ratio};

/// The part's measurement: its rows in each body's frame, and the angle.
#[derive(Clone, Copy, Debug)]
pub struct Rows<L> {
    /// `[n, m]` in a's body frame (`R_a^T n`, `R_a^T m`).
    pub a: [Vec3<L>; 2],
    /// `[n, m]` in b's body frame.
    pub b: [Vec3<L>; 2],
    /// `sin theta = |t_a x t_b|`.
    pub sin: L,
    /// `d = 1 + cos theta = |t_a + t_b|^2 / 2`.
    pub d: L,
}

/// The rows (the gradients for b, in each body's frame) and the angle.
#[inline(always)]
pub fn measure<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> Rows<L> {
    let relative = a.q.conjugate() * b.q;
    let (ta, tb) = (super::axis_x(frame_a), super::axis_x(relative * frame_b));
    let (n, sin) = swing::axis(ta, tb);
    let s = ta + tb;
    let m = n.cross(s);
    Rows {
        a: [n, m],
        b: [relative.inverse_rotate(n), relative.inverse_rotate(m)],
        sin,
        d: s.dot(s) * L::splat(0.5),
    }
}

/// Aligns the axes; returns `sin theta` before the correction.
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> L {
    let Rows {
        a: [ja1, ja2],
        b: [jb1, jb2],
        sin,
        d,
    } = measure(a, b, frame_a, frame_b);
    let (sa1, sa2) = (a.inv_inertia.mul_vec(ja1), a.inv_inertia.mul_vec(ja2));
    let (sb1, sb2) = (b.inv_inertia.mul_vec(jb1), b.inv_inertia.mul_vec(jb2));
    let (kb11, kb12) = (jb1.dot(sb1), jb2.dot(sb1));
    let k11 = ja1.dot(sa1) + kb11;
    let k12 = ja2.dot(sa1) + kb12;
    let k22 = ja2.dot(sa2) + jb2.dot(sb2);
    let det = k11 * k22 - k12 * k12;
    // K^-1 = [k22 -k12; -k12 k11] / det.
    let (r22, r12) = (safe_ratio(k22, det), safe_ratio(k12, det));
    let (zero, one, four) = (L::splat(0.0), L::splat(1.0), L::splat(4.0));
    let f_b = kb11 * r22 - kb12 * r12;
    let p = (f_b * (one - f_b)).max(zero);
    let e = safe_ratio(four * sin, d + (d * d + four * p * (sin * sin)).sqrt());
    // dlambda = -K^-1 (E, 0) = E (-r22, r12).
    angle::apply_local(
        a,
        b,
        (
            sa2.scale(r12) - sa1.scale(r22),
            sb2.scale(r12) - sb1.scale(r22),
        ),
        e,
    );
    sin
}
