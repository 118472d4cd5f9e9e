//! Swing direction: what the shaped swing limits (elliptical cone, pyramid)
//! measure, and the chain rule from a limit on it to a rotation axis.
//!
//! The swing of the swing-twist decomposition (twist about +X) depends only
//! on where b's twist axis points in a's joint frame:
//! `d = (q_a F_a)* (q_b F_b) x`, a unit vector (the twist turns about +X
//! and leaves it). The swing `s = (0, s_y, s_z, s_w)` is the shortest arc
//! from `x` to `d`: with `k = sqrt(2 (1 + d_x))`,
//! `s_w = cos(theta / 2) = k / 2` and `(s_y, s_z) = (-d_z, d_y) / k`,
//! `theta` the swing angle.
//!
//! **Gradients.** Turning b by a small world rotation `v` turns `d` by
//! `v_a = (q_a F_a)* v` (the same rotation seen in a's joint frame):
//! `dd = v_a x d`. So for any limit function `C(d)` with gradient `g`
//! (`dC = g . dd`, in a's joint frame), `dC = v_a . (d x g)`: turning b
//! about the world axis `n = q_a F_a (d x g)` grows `C` by `|n|` per
//! radian, i.e. `dC/dtheta_b = n`, and turning a gives `-n` (its frame
//! carries `d` the other way). The angle part takes such axes as they are
//! (not unit), so each limit supplies only `C` and `g` (derived in its
//! own header; checked against finite differences in
//! `tests/joint_gradients.rs`). At `d = -x` (a swing of exactly pi) the
//! swing axis is undefined: the gradients are 0 there, by selects. The
//! kernel takes `n` in a's body frame, `F_a (d x g)`, and in b's, where
//! the limit part needs it with no further rotation.

use vertebra_math::{Lane, Quat, Vec3};

use crate::body::BodyLanes;

/// b's twist axis in a's joint frame, measured from b's orientation
/// relative to a's (as the plain path's swing and twist): no product with
/// either world orientation, and the limits' axes come out in the bodies'
/// own frames.
#[derive(Clone, Copy, Debug)]
pub struct Direction<L> {
    /// `F_a`: a's joint frame in a's body frame.
    pub frame_a: Quat<L>,
    /// `q_a* q_b`: b's orientation relative to a's.
    pub relative: Quat<L>,
    /// `d = F_a* (q_a* q_b) F_b x`, unit, in a's joint frame.
    pub d: Vec3<L>,
}

/// Measures `d` at the bodies' current orientations.
#[inline(always)]
pub fn measure<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> Direction<L> {
    let relative = a.q.conjugate() * b.q;
    Direction {
        frame_a,
        relative,
        d: super::axis_x(frame_a.conjugate() * (relative * frame_b)),
    }
}

/// The axis `F_a (d x g)` for a limit of gradient `g` (a's joint frame):
/// `R_a^T n`, the world axis `n = q_a F_a (d x g)` (`dC/dtheta_b = n`,
/// `dC/dtheta_a = -n`) in a's body frame, as
/// [`crate::parts::limit::solve_local`] takes it ([`Direction::in_b`] gives
/// b's).
#[inline(always)]
pub fn axis<L: Lane>(dir: &Direction<L>, g: Vec3<L>) -> Vec3<L> {
    dir.frame_a.rotate(dir.d.cross(g))
}

impl<L: Lane> Direction<L> {
    /// The axis `n` (a's body frame) in b's body frame, `(q_a* q_b)* n`.
    #[inline(always)]
    pub fn in_b(&self, n: Vec3<L>) -> Vec3<L> {
        self.relative.inverse_rotate(n)
    }
}
