//! Lock part: b's joint frame held to a's (3 rotational degrees of
//! freedom, hard, solved together): the fixed joint's orientation half.
//!
//! `C = log((q_b F_b) (q_a F_a)*)`, the rotation vector (world, shortest
//! arc) taking a's joint frame to b's. As for the drive part (whose 3x3
//! solve at compliance 0 this is), `dC/dtheta_b = 1` and
//! `dC/dtheta_a = -1` to first order (checked against finite differences
//! in `tests/joint_gradients.rs`), and the XPBD step is
//! `dlambda = -W^-1 C` with `W = I_a^-1 + I_b^-1` (world); b turns by
//! `I_b^-1 dlambda`, a by `-I_a^-1 dlambda`. A singular `W` (no dynamic
//! body) gives no correction. The kernel solves the same step in a's body
//! frame (every vector and `W` turned by `R_a^T`, which leaves `W^-1 C`
//! turned the same way): there `S_a` needs no rotation and `I_b^-1`
//! becomes `R S_b R^T` with `R` b's rotation relative to a's.

use vertebra_math::{Lane, Quat, Vec3};

use crate::body::BodyLanes;

/// The rotation vector from a's joint frame to b's (rad, world).
#[inline(always)]
pub fn measure<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> Vec3<L> {
    ((b.q * frame_b) * (a.q * frame_a).conjugate()).to_rotation_vector()
}

/// `C` in a's body frame, `R_a^T C = log((q_a* q_b) F_b F_a*)` (the
/// conjugate by `q_a` of the world rotation, whose rotation vector is the
/// world one turned by `R_a^T`), and b's orientation relative to a's,
/// `q_a* q_b`.
#[inline(always)]
pub fn measure_in_a<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> (Vec3<L>, Quat<L>) {
    let relative = a.q.conjugate() * b.q;
    (
        ((relative * frame_b) * frame_a.conjugate()).to_rotation_vector(),
        relative,
    )
}

/// Turns both bodies so that the frames agree; returns `|C|` before the
/// correction (rad). Solved in a's body frame: there `W = S_a + R S_b R^T`
/// (`R` b's rotation relative to a's), a turns by `-S_a dlambda` in its
/// own frame and b by `S_b R^T dlambda` in its own, so only b's inertia is
/// rotated, and nothing back into the world.
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> L {
    let (c, relative) = measure_in_a(a, b, frame_a, frame_b);
    let w = a.inv_inertia + b.inv_inertia.rotated(relative);
    let dlambda = -w.inverse_or_zero().mul_vec(c);
    let turn_b = b.inv_inertia.mul_vec(relative.inverse_rotate(dlambda));
    b.turn_local(turn_b, L::splat(1.0));
    a.turn_local(a.inv_inertia.mul_vec(dlambda), L::splat(-1.0));
    c.length()
}
