//! Hinge axis part: the two joint frames' +X axes held together (2
//! degrees of freedom, hard, solved together as Jolt's
//! `HingeRotationConstraintPart`, at the position level).
//!
//! With `t_a = q_a F_a x` (a's hinge axis) and b's two perpendicular axes
//! `y_b = q_b F_b y`, `z_b = q_b F_b z`, the constraint is
//! `C = (t_a . y_b, t_a . z_b) = 0` (both zero exactly when `t_b = t_a`,
//! or `-t_a`: the antiparallel pose is an unstable equilibrium the part
//! does not leave). Turning b by a small `v` moves `y_b` by `v x y_b`, so
//! `dC_1 = t_a . (v x y_b) = v . (y_b x t_a)`: `dC_1/dtheta_b = j_1 =
//! y_b x t_a`, likewise `j_2 = z_b x t_a`, and turning a gives `-j_k`
//! (checked against finite differences in `tests/joint_gradients.rs`).
//! The XPBD step for the 2-vector constraint is
//! `dlambda = -K^-1 C` with `K_kl = j_k^T (I_a^-1 + I_b^-1) j_l` (2x2,
//! world), then b turns by `I_b^-1 (j_1 dlambda_1 + j_2 dlambda_2)` and a
//! by the negative with `I_a^-1`. Solving both rows together removes the
//! error in one step whatever the inertia's anisotropy (one row along
//! `t_a x t_b` would be an oblique projection; see the drive part). A
//! singular `K` (no dynamic body) gives no correction.

use vertebra_math::{Lane, Quat, Vec3};

use crate::body::{BodyLanes, safe_ratio};

/// `C` and its two rows `j_1`, `j_2` (the gradients for b).
#[inline(always)]
pub fn measure<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> ([L; 2], [Vec3<L>; 2]) {
    let (one, zero) = (L::splat(1.0), L::splat(0.0));
    let fb = b.q * frame_b;
    let ta = (a.q * frame_a).rotate(Vec3::new(one, zero, zero));
    let yb = fb.rotate(Vec3::new(zero, one, zero));
    let zb = fb.rotate(Vec3::new(zero, zero, one));
    ([ta.dot(yb), ta.dot(zb)], [yb.cross(ta), zb.cross(ta)])
}

/// Aligns the axes; returns `|C|` before the correction.
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> L {
    let ([c1, c2], [j1, j2]) = measure(a, b, frame_a, frame_b);
    let w = a.world_inv_inertia() + b.world_inv_inertia();
    let (wj1, wj2) = (w.mul_vec(j1), w.mul_vec(j2));
    let (k11, k12, k22) = (j1.dot(wj1), j2.dot(wj1), j2.dot(wj2));
    let det = k11 * k22 - k12 * k12;
    // dlambda = -K^-1 C, K^-1 = [k22 -k12; -k12 k11] / det.
    let l1 = safe_ratio(k12 * c2 - k22 * c1, det);
    let l2 = safe_ratio(k12 * c1 - k11 * c2, det);
    let turn = j1.scale(l1) + j2.scale(l2);
    b.rotate(b.inv_inertia_mul(turn));
    a.rotate(a.inv_inertia_mul(-turn));
    (c1 * c1 + c2 * c2).sqrt()
}
