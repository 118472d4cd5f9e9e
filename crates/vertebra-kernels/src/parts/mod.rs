//! Position-level constraint parts, shared by every joint (after Jolt's
//! `ConstraintPart`s, but at the position level of XPBD).
//!
//! Each part measures its error from the current poses and applies one
//! XPBD correction (Macklin et al. 2016; Müller et al. 2020):
//! `dlambda = (-C - alpha~ lambda) / (w_a + w_b + alpha~)`, with
//! `alpha~ = compliance / h^2` for a substep of `h` seconds, and the
//! generalised inverse masses `w` of `crate::body`. Hard parts have
//! `alpha~ = 0` and need no `lambda`. Every part is branch-free: an
//! inactive limit has `C = 0`, and a zero correction moves nothing.
//!
//! The socket uses `point`, `swing`, `twist` and `drive` (plain path) or
//! `ellipse`, `pyramid` (both through `swing_direction`) and `twist` with
//! `limit` (shaped path); the hinge `point`, `hinge_axis`, `twist` with
//! `limit`, and `drive`; the fixed joint `point` and `lock`; the rod its
//! own `rod` parts (curve, length, bend, twist), built on `angle`.
//!
//! # One verb set
//!
//! - `measure`: the part's value `C` (and its axis or gradient) from the
//!   poses; a suffix says the frame it is given in (`measure_local`: each
//!   body's own, `measure_in_a`: a's joint frame).
//! - `violation`: how far a limit (or a rest shape) is exceeded, `>= 0`
//!   unless named `signed_violation`; `violation_angle` the same in radians
//!   where the part works in other units.
//! - `solve`: one XPBD correction of the part (its `dlambda`, applied to
//!   both bodies), returning the accumulated `lambda` when it keeps one;
//!   `solve_local` with the axes in the bodies' own frames.
//! - `apply`: moves or turns the bodies by a given `dlambda`.

pub mod angle;
pub mod drive;
pub mod ellipse;
pub mod hinge_axis;
pub mod limit;
pub mod lock;
pub mod point;
pub mod pyramid;
pub mod rod;
pub mod swing;
pub mod swing_direction;
pub mod twist;

use vertebra_math::{Lane, Quat, Vec3};

use crate::body::BodyLanes;

/// Both bodies' joint (or material) frames in the world and their +X
/// axes: the twist axes of a socket, the tangents of a rod.
#[derive(Clone, Copy, Debug)]
pub struct Frames<L> {
    /// `F(0) = q_a F_a`.
    pub fa: Quat<L>,
    /// `F(1) = q_b F_b`.
    pub fb: Quat<L>,
    /// `t_a = F(0) x`.
    pub ta: Vec3<L>,
    /// `t_b = F(1) x`.
    pub tb: Vec3<L>,
}

impl<L: Lane> Frames<L> {
    /// The frames `fa`, `fb` (unit, world) with their +X axes, each its
    /// rotation matrix's first column ([`axis_x`]).
    #[inline(always)]
    pub fn new(fa: Quat<L>, fb: Quat<L>) -> Self {
        Self {
            fa,
            fb,
            ta: axis_x(fa),
            tb: axis_x(fb),
        }
    }
}

/// Measures the frames at the bodies' current orientations.
#[inline(always)]
pub fn frames<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
) -> Frames<L> {
    Frames::new(a.q * frame_a, b.q * frame_b)
}

/// `q x`: the unit quaternion's rotation of +X, its matrix's first column
/// (fewer operations than [`Quat::rotate`], and other roundings). Every
/// part takes a frame's twist axis or a rod's tangent this way.
#[inline(always)]
pub fn axis_x<L: Lane>(q: Quat<L>) -> Vec3<L> {
    let (one, two) = (L::splat(1.0), L::splat(2.0));
    Vec3::new(
        one - two * (q.y * q.y + q.z * q.z),
        two * (q.x * q.y + q.w * q.z),
        two * (q.x * q.z - q.w * q.y),
    )
}
