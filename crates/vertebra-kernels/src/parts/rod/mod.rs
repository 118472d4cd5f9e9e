//! The rod's parts (paper sections 5.1-5.5), over one shared measurement
//! of the two material frames.
//!
//! Bodies `a` and `b` carry the rod at their centres of mass; their
//! material frames are `F(0) = q_a F_a` and `F(1) = q_b F_b`, and the
//! tangents `t_a`, `t_b` are the frames' +X axes. The bend angle is
//! `psi = atan2(|t_a x t_b|, t_a . t_b)` (the paper's `acos(t_a . t_b)`,
//! computed without its loss of precision near 0), bending about
//! `n = (t_a x t_b) / |t_a x t_b|`. The derivations are in
//! `docs/rod-constraint.md`.

pub mod bend;
pub mod curve;
pub mod drive;
pub mod length;
pub mod twist;

use vertebra_math::{Lane, Quat, Vec3, poly};

use crate::body::BodyLanes;
pub use crate::parts::{Frames, frames};

/// The material frames measured in a's body frame: `F(0)` is `F_a` itself
/// and `F(1)` is `(q_a* q_b) F_b`, one quaternion product where the world
/// frames take two; `t_a = F_a x` is the same for every part of an
/// iteration. The angles (bend, twist, their axes' relations) are the same
/// in any frame, and an axis `n` found in a's frame is already the
/// `R_a^T n` that a's inverse inertia needs; b's is `relative* n`
/// ([`LocalFrames::in_b`]): one rotation per correction instead of two.
#[derive(Clone, Copy, Debug)]
pub struct LocalFrames<L> {
    /// The frames and tangents, in a's body frame.
    pub f: Frames<L>,
    /// b's orientation relative to a's, `q_a* q_b`.
    pub relative: Quat<L>,
}

impl<L: Lane> LocalFrames<L> {
    /// Measures the frames at the bodies' current orientations; `ta` is
    /// `F_a x` ([`crate::parts::axis_x`]), which the caller forms once.
    #[inline(always)]
    pub fn new(
        a: &BodyLanes<L>,
        b: &BodyLanes<L>,
        frame_a: Quat<L>,
        frame_b: Quat<L>,
        ta: Vec3<L>,
    ) -> Self {
        let relative = a.q.conjugate() * b.q;
        let fb = relative * frame_b;
        Self {
            f: Frames {
                fa: frame_a,
                fb,
                ta,
                tb: crate::parts::axis_x(fb),
            },
            relative,
        }
    }

    /// As [`LocalFrames::new`], with `t_b` the rotation of `F_b x`
    /// (`tb`, which the caller forms once) by the relative orientation
    /// rather than the column of `F(1)`: one rotation instead of a product
    /// and a column, for the parts that read only the tangents (the bend,
    /// its limit, the length), whose unread `F(1)` the compiler drops.
    #[inline(always)]
    pub fn tangents(
        a: &BodyLanes<L>,
        b: &BodyLanes<L>,
        (frame_a, frame_b): (Quat<L>, Quat<L>),
        (ta, tb): (Vec3<L>, Vec3<L>),
    ) -> Self {
        let relative = a.q.conjugate() * b.q;
        Self {
            f: Frames {
                fa: frame_a,
                fb: relative * frame_b,
                ta,
                tb: relative.rotate(tb),
            },
            relative,
        }
    }

    /// The axis `n` (a's body frame) in b's body frame.
    #[inline(always)]
    pub fn in_b(&self, n: Vec3<L>) -> Vec3<L> {
        self.relative.inverse_rotate(n)
    }
}

/// The world frames with each tangent rotated from its body frame's
/// (`ta = F_a x`, `tb = F_b x`, formed once by the caller): two rotations
/// instead of two products and two columns, for the curve, which reads
/// only the tangents (the unread frames the compiler drops).
#[inline(always)]
pub fn world_tangents<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    (frame_a, frame_b): (Quat<L>, Quat<L>),
    (ta, tb): (Vec3<L>, Vec3<L>),
) -> Frames<L> {
    Frames {
        fa: a.q * frame_a,
        fb: b.q * frame_b,
        ta: a.q.rotate(ta),
        tb: b.q.rotate(tb),
    }
}

/// The bend axis (unit, or zero when straight or folded back) and the bend
/// angle `psi` in [0, pi].
#[inline(always)]
pub fn bend_angle<L: Lane>(ta: Vec3<L>, tb: Vec3<L>) -> (Vec3<L>, L) {
    let (n, sin) = ta.cross(tb).normalize_or_zero();
    (n, poly::atan2(sin, ta.dot(tb)))
}
