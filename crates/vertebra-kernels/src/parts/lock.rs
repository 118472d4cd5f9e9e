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
//! body) gives no correction.

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

/// Turns both bodies so that the frames agree; returns `|C|` before the
/// correction (rad).
#[inline(always)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> L {
    let c = measure(a, b, frame_a, frame_b);
    let w = a.world_inv_inertia() + b.world_inv_inertia();
    let dlambda = -w.inverse_or_zero().mul_vec(c);
    b.rotate(b.inv_inertia_mul(dlambda));
    a.rotate(a.inv_inertia_mul(-dlambda));
    c.length()
}
