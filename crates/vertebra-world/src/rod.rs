//! The rod constraint's public description, and its instantiation from any
//! pose of its two bodies (paper section 6).

use core::f32::consts::PI;

use glam::{Quat, Vec3};
use vertebra_kernels::rod::RodSoftness;
use vertebra_store::{
    BodyHandle, BodyStore, Error, Handle, MAX_COORDINATE, check_coordinate, check_unit_quat,
    check_unit_vec,
};

/// The longest rest length (m) a rod may have: two bodies within
/// [`MAX_COORDINATE`] of the origin on every axis are at most
/// `2 sqrt(3) MAX_COORDINATE` apart, and an arc over that chord bent by
/// nearly pi is pi/2 longer (5.44e6 m). A longer rest length is no rod any
/// body pair can hold: its length constraint throws the bodies apart (at
/// 1e30 m the last-line NaN guard fired every substep).
pub const MAX_ROD_LENGTH: f32 = 6.0 * MAX_COORDINATE;

/// Marker for rod handles.
#[derive(Debug)]
pub enum RodTag {}

/// A stable reference to a rod constraint.
pub type RodHandle = Handle<RodTag>;

/// How stiff a rod is in bending or twisting.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum RodStiffness {
    /// Kirchhoff stiffness `k` (N m^2): the energy is `1/2 k kappa^2 l0`
    /// with `kappa` the curvature (or twist rate). Solved as XPBD with
    /// compliance `l0 / k`: the same rod at any time step or iteration
    /// count. 0 is no resistance; infinity is rigid.
    Kirchhoff(f32),
    /// The paper's relaxation factor in [0, 1]: the fraction of the error
    /// removed per iteration. How stiff the rod ends up depends on the
    /// iteration count (see `docs/rod-constraint.md`).
    Relaxation(f32),
}

/// A rod between the centres of mass of two bodies.
///
/// The material frames `F_a`, `F_b` are given in the bodies' frames; their
/// +X axes are the tangents. [`RodDesc::from_pose`] sets everything so that
/// the rod holds exactly at the bodies' current poses.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RodDesc {
    /// The first body (the paper's `x_a`; the hips of a spine).
    pub body_a: BodyHandle,
    /// The second body (the chest of a spine).
    pub body_b: BodyHandle,
    /// Material frame at a, in a's body frame.
    pub frame_a: Quat,
    /// Material frame at b, in b's body frame.
    pub frame_b: Quat,
    /// Rest length `l0` of the arc (m, positive, at most [`MAX_ROD_LENGTH`]).
    pub rest_length: f32,
    /// Rest direction of `t_b` in a's material frame (unit; `+X` is
    /// straight). Its angle from `+X` is the rest bend, its direction the
    /// bend plane.
    pub bend_rest: Vec3,
    /// Rest twist (rad).
    pub twist_rest: f32,
    /// Bending stiffness.
    pub bending: RodStiffness,
    /// Twisting stiffness.
    pub twisting: RodStiffness,
    /// Largest bend angle `psi` (rad, in [0, pi]); `None` is unlimited.
    pub bend_limit: Option<f32>,
    /// Twist range (rad, within [-pi, pi]); `None` is unlimited.
    pub twist_limit: Option<[f32; 2]>,
}

impl RodDesc {
    /// A rod that holds exactly at the bodies' current poses (paper section
    /// 6: instantiate "only when the transition occurs, setting its rest
    /// length and body frames such that the new constraint is valid").
    ///
    /// `through` are world positions of the animation bones between the two
    /// bodies, in order (may be empty). With none, or all on the chord, the
    /// rod is straight. Otherwise its arc is the circle through `p_a`, the
    /// middle bone and `p_b`; the rest bend is that bend and the rest length
    /// that arc's length, so the bending energy is zero at creation. The
    /// material frame at a is a's frame turned minimally onto the tangent;
    /// at b it is that frame carried along the arc, so the twist is zero.
    ///
    /// Errors: stale handles, non-finite points, ends closer than 1e-4 m,
    /// and bones that bend the arc by pi or more (no chord-and-tangent rod
    /// can represent it).
    pub fn from_pose(
        bodies: &BodyStore,
        body_a: BodyHandle,
        body_b: BodyHandle,
        through: &[Vec3],
    ) -> Result<Self, Error> {
        if body_a == body_b {
            return Err(Error::SameBody);
        }
        let a = bodies.state(body_a)?;
        let b = bodies.state(body_b)?;
        for p in through {
            check_coordinate("bone position", *p)?;
        }
        let chord = b.position - a.position;
        if chord.length() < 1e-4 {
            return Err(Error::DegenerateShape("the rod's ends coincide"));
        }
        let o = chord.normalize();
        let ta = match through.get(through.len() / 2) {
            Some(&middle) => arc_tangent(a.position, middle, b.position).unwrap_or(o),
            None => o,
        };
        // The tangent-chord angle is half the arc's angle.
        let psi = 2.0 * ta.angle_between(o);
        if psi >= PI - 1e-3 {
            return Err(Error::InvalidLimit(
                "bend: the bones bend the arc by pi or more",
            ));
        }
        let tb = 2.0 * ta.dot(o) * o - ta;
        let rest_length = chord.length() / (2.0 * half_sinc(psi));
        let material_a = Quat::from_rotation_arc(a.orientation * Vec3::X, ta) * a.orientation;
        let material_b = Quat::from_rotation_arc(ta, tb) * material_a;
        Ok(Self {
            body_a,
            body_b,
            frame_a: (a.orientation.inverse() * material_a).normalize(),
            frame_b: (b.orientation.inverse() * material_b).normalize(),
            rest_length,
            bend_rest: (material_a.inverse() * tb).normalize(),
            twist_rest: 0.0,
            bending: RodStiffness::Kirchhoff(0.0),
            twisting: RodStiffness::Kirchhoff(0.0),
            bend_limit: None,
            twist_limit: None,
        })
    }

    /// With bending and twisting stiffness.
    pub fn with_stiffness(mut self, bending: RodStiffness, twisting: RodStiffness) -> Self {
        self.bending = bending;
        self.twisting = twisting;
        self
    }

    /// With a largest bend angle (rad).
    pub fn with_bend_limit(mut self, max: f32) -> Self {
        self.bend_limit = Some(max);
        self
    }

    /// With a twist range (rad).
    pub fn with_twist_limit(mut self, min: f32, max: f32) -> Self {
        self.twist_limit = Some([min, max]);
        self
    }

    /// Checks every field but the handles' liveness.
    pub fn validate(&self) -> Result<(), Error> {
        if self.body_a == self.body_b {
            return Err(Error::SameBody);
        }
        check_unit_quat("rod frame a", self.frame_a)?;
        check_unit_quat("rod frame b", self.frame_b)?;
        check_unit_vec("rod rest bend", self.bend_rest)?;
        vertebra_store::check_positive("rod rest length", self.rest_length)?;
        if self.rest_length > MAX_ROD_LENGTH {
            return Err(Error::OutOfRange("rod rest length (at most 6e6 m)"));
        }
        if !self.twist_rest.is_finite() {
            return Err(Error::NonFinite("rod rest twist"));
        }
        for (what, s) in [
            ("rod bending", self.bending),
            ("rod twisting", self.twisting),
        ] {
            match s {
                RodStiffness::Kirchhoff(k) if k.is_nan() => return Err(Error::NonFinite(what)),
                RodStiffness::Kirchhoff(k) if k < 0.0 => return Err(Error::NonPositive(what)),
                RodStiffness::Relaxation(r) if !(0.0..=1.0).contains(&r) => {
                    return Err(Error::InvalidLimit("relaxation factor (must be in [0, 1])"));
                }
                _ => {}
            }
        }
        crate::checks::max_angle(self.bend_limit, "bend")?;
        crate::checks::twist_range(self.twist_limit)
    }

    pub(crate) fn validate_with(&self, bodies: &BodyStore) -> Result<(), Error> {
        self.validate()?;
        crate::checks::joint_bodies(bodies, self.body_a, self.body_b)
    }

    /// The kernel's softness for a stiffness of this rod.
    pub(crate) fn softness(&self, s: RodStiffness) -> RodSoftness {
        match s {
            RodStiffness::Kirchhoff(k) if k > 0.0 => RodSoftness::Compliance(self.rest_length / k),
            RodStiffness::Kirchhoff(_) => RodSoftness::Relaxation(0.0),
            RodStiffness::Relaxation(r) => RodSoftness::Relaxation(r),
        }
    }
}

/// The unit tangent at `a` of the circle through `a`, `m`, `b`, pointing
/// along the arc toward `m`; `None` when the points are (nearly) collinear.
pub fn arc_tangent(a: Vec3, m: Vec3, b: Vec3) -> Option<Vec3> {
    let (u, v) = (m - a, b - a);
    let w = u.cross(v);
    if w.length_squared() <= 1e-12 * u.length_squared() * v.length_squared() {
        return None;
    }
    // Circumcentre: a + (|u|^2 (v x w) + |v|^2 (w x u)) / (2 |w|^2).
    let centre = a
        + (u.length_squared() * v.cross(w) + v.length_squared() * w.cross(u))
            / (2.0 * w.length_squared());
    let t = w.cross(a - centre).normalize();
    Some(if t.dot(u) >= 0.0 { t } else { -t })
}

/// `sin(x/2) / x`, through the math layer (the kernels' own definition).
fn half_sinc(x: f32) -> f32 {
    vertebra_math::poly::half_sinc(x)
}
