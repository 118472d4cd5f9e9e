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
//!
//! The linearisation only holds near alignment. With swing angle `theta`
//! between `t_a` and `t_b`, `|C| = sin theta`, so past 90 degrees the step
//! drives toward the antiparallel zero, and near 90 degrees `K` is nearly
//! singular (`j_1 = y_b x t_a` vanishes when `t_a = y_b`) and the step
//! huge. The hinge kernel therefore first applies the swing part
//! (`swing.rs`: one row along `t_a x t_b`, angle by atan2, exact for any
//! `theta` below 180 degrees) with the cone [`NEWTON_CONE`]: inside it the
//! swing part does nothing (the small-angle behaviour is today's), outside
//! it brings `theta` back to 45 degrees. There the step is well posed:
//! with `t_a = (cos theta, s_1, s_2)` in b's frame (`s_k = C_k`), the
//! rows' Gram matrix is `[1 - s_1^2, -s_1 s_2; -s_1 s_2, 1 - s_2^2]`,
//! whose determinant is `cos^2 theta` (1/2 at 45 degrees, 0 at 90), and
//! the Newton step heads for `t_b = t_a`. Only the exact antiparallel pose
//! (`n` undefined) remains an equilibrium.

/// The swing (rad) past which the hinge kernel turns the axes back with
/// the swing part before this part's 2-row step: 45 degrees.
pub const NEWTON_CONE: f32 = core::f32::consts::FRAC_PI_4;

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
    let fb = b.q * frame_b;
    let ta = axis_x(a.q * frame_a);
    let (yb, zb) = (axis_y(fb), axis_z(fb));
    ([ta.dot(yb), ta.dot(zb)], [yb.cross(ta), zb.cross(ta)])
}

/// Aligns the axes; returns `|C|` before the correction. `K` is formed in
/// each body's own frame (`j^T I^-1 j = (R^T j)^T S (R^T j)`), which also
/// gives each body's turn `R S (R^T j)` without a second rotation into it.
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> L {
    let ([c1, c2], [j1, j2]) = measure(a, b, frame_a, frame_b);
    let (ja1, ja2) = (a.q.inverse_rotate(j1), a.q.inverse_rotate(j2));
    let (jb1, jb2) = (b.q.inverse_rotate(j1), b.q.inverse_rotate(j2));
    let (sa1, sa2) = (a.inv_inertia.mul_vec(ja1), a.inv_inertia.mul_vec(ja2));
    let (sb1, sb2) = (b.inv_inertia.mul_vec(jb1), b.inv_inertia.mul_vec(jb2));
    let k11 = ja1.dot(sa1) + jb1.dot(sb1);
    let k12 = ja2.dot(sa1) + jb2.dot(sb1);
    let k22 = ja2.dot(sa2) + jb2.dot(sb2);
    let det = k11 * k22 - k12 * k12;
    // dlambda = -K^-1 C, K^-1 = [k22 -k12; -k12 k11] / det.
    let l1 = safe_ratio(k12 * c2 - k22 * c1, det);
    let l2 = safe_ratio(k12 * c1 - k11 * c2, det);
    b.rotate(b.q.rotate(sb1.scale(l1) + sb2.scale(l2)));
    a.rotate(-a.q.rotate(sa1.scale(l1) + sa2.scale(l2)));
    (c1 * c1 + c2 * c2).sqrt()
}

/// The unit quaternion's rotation of +X (its matrix's first column).
#[inline(always)]
fn axis_x<L: Lane>(q: Quat<L>) -> Vec3<L> {
    let (one, two) = (L::splat(1.0), L::splat(2.0));
    Vec3::new(
        one - two * (q.y * q.y + q.z * q.z),
        two * (q.x * q.y + q.w * q.z),
        two * (q.x * q.z - q.w * q.y),
    )
}

/// The rotation of +Y (second column).
#[inline(always)]
fn axis_y<L: Lane>(q: Quat<L>) -> Vec3<L> {
    let (one, two) = (L::splat(1.0), L::splat(2.0));
    Vec3::new(
        two * (q.x * q.y - q.w * q.z),
        one - two * (q.x * q.x + q.z * q.z),
        two * (q.y * q.z + q.w * q.x),
    )
}

/// The rotation of +Z (third column).
#[inline(always)]
fn axis_z<L: Lane>(q: Quat<L>) -> Vec3<L> {
    let (one, two) = (L::splat(1.0), L::splat(2.0));
    Vec3::new(
        two * (q.x * q.z + q.w * q.y),
        two * (q.y * q.z - q.w * q.x),
        one - two * (q.x * q.x + q.y * q.y),
    )
}
