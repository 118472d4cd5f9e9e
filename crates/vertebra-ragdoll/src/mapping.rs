//! Placing a chain of bones that have no body between two bodies that have
//! one (paper section 6): the simplified ragdoll's spine bones between the
//! hips and the chest, a neck between the chest and the head. One of three
//! modes:
//!
//! | mode | bone lengths | chain end on the top body | source |
//! | --- | --- | --- | --- |
//! | `Orientation` | kept exactly | misses when bent | the paper |
//! | `PositionOrientation` | change | exact | the paper |
//! | `Arc` | kept along the arc; straight-line length shrinks by the chord factor `sin(x/2)/(x/2)` of the bone's share `x` of the bend (0.5% at 20 degrees per bone) | exact (to the rod's residual) | beyond the paper |
//!
//! A chain runs from the base body's centre of mass through the interior
//! bones' origins to the top body's centre of mass, all at bind pose; the
//! fractions `s_k` are the points' shares of that polyline's length. The
//! mapper (`mapper.rs`) decides which bones form chains;
//! [`Ragdoll::skeleton_pose`] is the mapper on a skeleton of one bone per
//! body.

use glam::{Quat, Vec3};
use vertebra_math::PortableQuat;
use vertebra_math::trig;
use vertebra_world::{arc_tangent, rod_twist};

use crate::skeleton::Transform;
use vertebra_math::DefaultFloatMode;

/// How a chain of bones without bodies is placed between its two bodies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SpineMapping {
    /// The bones turn by shares of the top body's rotation relative to the
    /// base, and hang from each other at their bind offsets.
    Orientation,
    /// As `Orientation`, then each bone also moves by its share of the gap
    /// between the chain's end and the top body.
    PositionOrientation,
    /// The bones sit on the rod's arc at their fractions of its length,
    /// turned by the arc's natural frame and their share of the twist,
    /// each with the offset it has at bind pose from the arc a rod made at
    /// bind would take (none for a chain straight at bind, as the
    /// reference spine is: a bent one, such as a clavicle between the
    /// chest and the upper arm, maps bind pose to bind pose). A
    /// chain no rod holds (a neck, any chain of a standard ragdoll) takes
    /// the arc of a rod made at bind pose between its two bodies, so its
    /// end is exact only as far as the two bodies keep their chord halfway
    /// between their tangents.
    Arc,
}

/// A chain of bones between two bodies, at bind pose (model frame = the
/// description's world frame, bodies unrotated).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Chain {
    /// The base body (index in the description).
    pub base: usize,
    /// The top body.
    pub top: usize,
    /// The interior bones, base to top (skeleton indices).
    pub bones: Vec<usize>,
    /// The base body's centre, the interior bones' origins, the top body's
    /// centre (m, bind pose).
    pub points: Vec<Vec3>,
    /// Each point's share of the polyline's length, 0 to 1.
    pub fractions: Vec<f32>,
    /// Each interior bone's rotation at bind pose (model frame).
    pub bind_rotations: Vec<Quat>,
    /// The material frames (in the bodies' frames) of a rod made at bind
    /// pose between the two bodies through the interior bones: the arc of
    /// a chain no rod holds.
    pub bind_frames: (Quat, Quat),
    /// Each interior bone's bind transform in the frame of the bind arc
    /// (the arc of `bind_frames` at bind pose) at its fraction: the
    /// identity for a chain straight at bind.
    pub arc_offsets: Vec<Transform>,
    /// Whether the simplified ragdoll's rod joins the two bodies (the arc
    /// then takes the rod's own frames).
    pub rod: bool,
}

impl Chain {
    /// A chain from body `base` (bind centre `points[0]`) through `bones`
    /// to body `top` (bind centre `points.last()`).
    pub fn new(
        base: usize,
        top: usize,
        bones: Vec<usize>,
        points: Vec<Vec3>,
        bind_rotations: Vec<Quat>,
        rod: bool,
    ) -> Self {
        let _mode = DefaultFloatMode::enter();
        let fractions = fractions(&points);
        let bind_frames = bind_frames(&points);
        let last = points.len() - 1;
        let bind_arc = Arc::new(
            (points[0], Quat::IDENTITY),
            (points[last], Quat::IDENTITY),
            bind_frames.0,
            bind_frames.1,
        );
        let arc_offsets = (1..last)
            .map(|k| {
                let (p, q) = bind_arc.at(fractions[k]);
                Transform::new(p, q).inverse() * Transform::new(points[k], bind_rotations[k - 1])
            })
            .collect();
        Self {
            base,
            top,
            bones,
            points,
            fractions,
            bind_rotations,
            bind_frames,
            arc_offsets,
            rod,
        }
    }

    /// Writes each interior bone's world transform into `out` (indexed by
    /// bone) from the two bodies' world poses (centre of mass, rotation
    /// relative to bind). `rod_frames` are the rod's material frames, for
    /// the arc of a chain a rod holds.
    pub fn place(
        &self,
        mode: SpineMapping,
        base: (Vec3, Quat),
        top: (Vec3, Quat),
        rod_frames: Option<(Quat, Quat)>,
        out: &mut [Transform],
    ) {
        let _mode = DefaultFloatMode::enter();
        let last = self.points.len() - 1;
        let mut put = |k: usize, (p, q): (Vec3, Quat)| {
            out[self.bones[k - 1]] = Transform::new(
                p,
                q.mul_portable(self.bind_rotations[k - 1])
                    .normalize_portable(),
            );
        };
        match mode {
            SpineMapping::Orientation | SpineMapping::PositionOrientation => {
                let relative = base.1.inverse().mul_portable(top.1);
                let relative = if relative.w < 0.0 {
                    -relative
                } else {
                    relative
                };
                let (mut p, mut q) = base;
                for k in 1..=last {
                    p += q * (self.points[k] - self.points[k - 1]);
                    q = base
                        .1
                        .mul_portable(Quat::IDENTITY.slerp_portable(relative, self.fractions[k]));
                    if k < last {
                        put(k, (p, q));
                    }
                }
                if mode == SpineMapping::PositionOrientation {
                    // p is now where the chain's end lands; the gap to the
                    // top body is shared out by fraction.
                    let gap = top.0 - p;
                    for (k, &bone) in self.bones.iter().enumerate() {
                        out[bone].translation += gap * self.fractions[k + 1];
                    }
                }
            }
            SpineMapping::Arc => {
                let (frame_a, frame_b) = match (self.rod, rod_frames) {
                    (true, Some(frames)) => frames,
                    _ => self.bind_frames,
                };
                let arc = Arc::new(base, top, frame_a, frame_b);
                for (k, offset) in self.arc_offsets.iter().enumerate() {
                    let (p, q) = arc.at(self.fractions[k + 1]);
                    out[self.bones[k]] = Transform::new(p, q) * *offset;
                }
            }
        }
    }
}

/// Each point's share of the polyline's length, from 0 to 1.
fn fractions(points: &[Vec3]) -> Vec<f32> {
    let mut acc = vec![0.0f32];
    for pair in points.windows(2) {
        acc.push(acc.last().expect("started") + (pair[1] - pair[0]).length());
    }
    let total = acc.last().copied().unwrap_or(1.0).max(f32::MIN_POSITIVE);
    acc.iter().map(|a| a / total).collect()
}

/// The material frames `RodDesc::from_pose` gives a rod made at bind pose
/// (bodies unrotated) from `points[0]` to `points.last()` through the
/// points between: the tangent at the base along the circle through the
/// ends and the middle point (the chord when they are in line), the top's
/// tangent its reflection about the chord.
fn bind_frames(points: &[Vec3]) -> (Quat, Quat) {
    let (a, b) = (points[0], points[points.len() - 1]);
    let o = (b - a).normalize_or(Vec3::X);
    let interior = &points[1..points.len() - 1];
    let ta = interior
        .get(interior.len() / 2)
        .and_then(|&m| arc_tangent(a, m, b))
        .unwrap_or(o);
    let tb = 2.0 * ta.dot(o) * o - ta;
    let frame_a = Quat::from_rotation_arc_portable(Vec3::X, ta);
    (
        frame_a,
        Quat::from_rotation_arc_portable(ta, tb)
            .mul_portable(frame_a)
            .normalize_portable(),
    )
}

/// A rod's arc between two bodies. With `F(0) = q_a F_a`, tangents `t_a`,
/// `t_b`, bend `psi` about `n`, the arc's length
/// `L = |d| / (2 sin(psi/2)/psi)` and `m = n x t_a`:
/// `gamma(s) = p_a + L s (2 h(x) cos(x/2) t_a + 2 x h(x)^2 m)`, `x = psi s`,
/// `h(x) = sin(x/2)/x` (smooth at `psi = 0`). The frame at `s` is
/// `R(t(s), tau s) M(s) F(0) G(s)`, with `M(s)` the turn by `psi s` about
/// `n`, `tau` the rod's twist and `G(s)` from `F_a^-1` to `F_b^-1`: so the
/// ends are exactly the two bodies' orientations.
struct Arc {
    start: Vec3,
    ta: Vec3,
    n: Vec3,
    psi: f32,
    length: f32,
    tau: f32,
    f0: Quat,
    ga: Quat,
    gb: Quat,
}

impl Arc {
    fn new(a: (Vec3, Quat), b: (Vec3, Quat), frame_a: Quat, frame_b: Quat) -> Self {
        let (f0, f1) = (a.1.mul_portable(frame_a), b.1.mul_portable(frame_b));
        let (ta, tb) = (f0 * Vec3::X, f1 * Vec3::X);
        let cross = ta.cross(tb);
        let psi = trig::atan2(cross.length(), ta.dot(tb));
        Self {
            start: a.0,
            ta,
            n: cross.normalize_or_zero(),
            psi,
            length: (b.0 - a.0).length() / (2.0 * half_sinc(psi)),
            tau: rod_twist(f0, f1),
            f0,
            ga: frame_a.inverse(),
            gb: frame_b.inverse(),
        }
    }

    /// The position and rotation (relative to bind) at fraction `s`.
    fn at(&self, s: f32) -> (Vec3, Quat) {
        let h = half_sinc;
        let x = self.psi * s;
        let along = self.ta * (2.0 * h(x) * trig::cos(x / 2.0))
            + self.n.cross(self.ta) * (2.0 * x * h(x) * h(x));
        let turn = if self.n == Vec3::ZERO {
            Quat::IDENTITY
        } else {
            Quat::from_axis_angle_portable(self.n, x)
        };
        let twist = Quat::from_axis_angle_portable(turn * self.ta, self.tau * s);
        (
            self.start + along * (self.length * s),
            twist
                .mul_portable(turn)
                .mul_portable(self.f0)
                .mul_portable(self.ga.slerp_portable(self.gb, s))
                .normalize_portable(),
        )
    }
}

/// `sin(x/2) / x`, through the math layer (the kernels' own definition).
fn half_sinc(x: f32) -> f32 {
    vertebra_math::poly::half_sinc(x)
}
