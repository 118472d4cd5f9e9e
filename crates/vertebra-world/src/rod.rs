//! The rod constraint's public description, and its instantiation from any
//! pose of its two bodies (paper section 6).

use core::f32::consts::{PI, TAU};
use vertebra_math::PortableQuat;

use glam::{Quat, Vec3};
use vertebra_kernels::rod::RodSoftness;

use crate::spring::{MAX_DRIVE_DAMPING_RATIO, MAX_DRIVE_DAMPING_TIME, MIN_DRIVE_FREQUENCY};
use vertebra_math::DefaultFloatMode;
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
    /// Kirchhoff stiffness with damping: the torque is
    /// `-(stiffness / l0) C - (damping / l0) dC/dt` on the bend or twist
    /// error `C` (rad). Solved as XPBD with damping (compliance `l0 / k`,
    /// damping time `damping / stiffness`; `vertebra_kernels::parts::rod::drive`).
    Damped {
        /// Kirchhoff stiffness `k` (N m^2); 0 is none (and then damping
        /// does nothing: a damper needs a spring in XPBD), infinity rigid.
        stiffness: f32,
        /// Kirchhoff damping `d` (N m^2 s / rad), with `d / k` at most
        /// [`MAX_DRIVE_DAMPING_TIME`] s.
        damping: f32,
    },
    /// A damped spring at `frequency` with `damping_ratio` on the rod's
    /// effective inertia in bending or twisting (bending counts the
    /// bodies' centres carried round the arc; derivation in
    /// `vertebra_kernels::parts::rod::drive`): a driven rod oscillates at
    /// `frequency` whatever its bodies' masses.
    Spring {
        /// Natural frequency (Hz), at least [`MIN_DRIVE_FREQUENCY`];
        /// infinity is rigid.
        frequency: f32,
        /// Damping ratio in [0, [`MAX_DRIVE_DAMPING_RATIO`]]; 1 is critical.
        damping_ratio: f32,
    },
}

/// A rod between the centres of mass of two bodies.
///
/// The material frames `F_a`, `F_b` are given in the bodies' frames; their
/// +X axes are the tangents. [`RodDesc::from_pose`] sets everything so that
/// the rod holds exactly at the bodies' current poses.
///
/// The rest shape (`bend_rest`, `twist_rest`) may move at
/// `bend_rest_velocity` and `twist_rest_velocity`, as a drive's target
/// moves at its `target_velocity` ([`crate::AngularDrive`]): the world
/// advances it every substep and writes it back after each step, so
/// [`World::rod`](crate::World::rod) returns the rest shape as the next
/// step begins. [`RodDesc::following`] sets both from two animation
/// shapes.
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
    /// Rest twist (rad): the twist the soft twisting turns the rod toward,
    /// as the next step begins.
    pub twist_rest: f32,
    /// The rest direction's angular velocity (rad/s, in a's material frame,
    /// as `bend_rest`): substep `k` of a step aims at `bend_rest` turned by
    /// `k h` at this velocity (about its fixed axis), and the bend's damping
    /// acts on the bend's rate relative to the rest's. Only its part
    /// perpendicular to `bend_rest` moves the rest (the part along it turns
    /// the direction about itself). Zero is a still rest; its length is at
    /// most [`MAX_ANGULAR_SPEED_LIMIT`](crate::MAX_ANGULAR_SPEED_LIMIT).
    pub bend_rest_velocity: Vec3,
    /// The rest twist's rate (rad/s): substep `k` aims at `twist_rest + k h
    /// twist_rest_velocity` (wrapped to [-pi, pi]), and the twist's damping
    /// acts on the twist's rate relative to it. Zero is a still rest; at
    /// most [`MAX_ANGULAR_SPEED_LIMIT`](crate::MAX_ANGULAR_SPEED_LIMIT) in
    /// size.
    pub twist_rest_velocity: f32,
    /// Bending stiffness.
    pub bending: RodStiffness,
    /// Twisting stiffness.
    pub twisting: RodStiffness,
    /// Largest bend angle `psi` (rad, in [0, pi]); `None` is unlimited.
    pub bend_limit: Option<f32>,
    /// Twist range (rad, within [-pi, pi]); `None` is unlimited.
    pub twist_limit: Option<[f32; 2]>,
    /// The largest torque (N m, not negative) the soft bending and, apart,
    /// the soft twisting exert; infinity is unlimited. A hit beyond it bends
    /// or twists the rod away from its rest shape, which the rod recovers
    /// afterwards. The limits are not capped.
    pub max_torque: f32,
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
        let _mode = DefaultFloatMode::enter();
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
            return Err(Error::DegenerateShape(
                "the rod's bones bend its arc by pi or more",
            ));
        }
        let tb = 2.0 * ta.dot(o) * o - ta;
        let rest_length = chord.length() / (2.0 * half_sinc(psi));
        let material_a = Quat::from_rotation_arc_portable(a.orientation * Vec3::X, ta)
            .mul_portable(a.orientation);
        let material_b = Quat::from_rotation_arc_portable(ta, tb).mul_portable(material_a);
        Ok(Self {
            body_a,
            body_b,
            frame_a: a
                .orientation
                .inverse()
                .mul_portable(material_a)
                .normalize_portable(),
            frame_b: b
                .orientation
                .inverse()
                .mul_portable(material_b)
                .normalize_portable(),
            rest_length,
            bend_rest: (material_a.inverse() * tb).normalize(),
            twist_rest: 0.0,
            bend_rest_velocity: Vec3::ZERO,
            twist_rest_velocity: 0.0,
            bending: RodStiffness::Kirchhoff(0.0),
            twisting: RodStiffness::Kirchhoff(0.0),
            bend_limit: None,
            twist_limit: None,
            max_torque: f32::INFINITY,
        })
    }

    /// With bending and twisting stiffness.
    pub fn with_stiffness(mut self, bending: RodStiffness, twisting: RodStiffness) -> Self {
        self.bending = bending;
        self.twisting = twisting;
        self
    }

    /// With a torque limit (N m) on the soft bending and twisting.
    pub fn with_max_torque(mut self, max_torque: f32) -> Self {
        self.max_torque = max_torque;
        self
    }

    /// With the rest shape moving: the rest direction at `bend` (rad/s, a's
    /// material frame), the rest twist at `twist` (rad/s).
    pub fn with_rest_velocity(mut self, bend: Vec3, twist: f32) -> Self {
        self.bend_rest_velocity = bend;
        self.twist_rest_velocity = twist;
        self
    }

    /// Following an animation (as [`crate::AngularDrive::following`]): the
    /// rest shape is `prev` (rest direction, unit in a's material frame, and
    /// rest twist in rad) as the next step begins and moves at constant
    /// rates to reach `pose` when it ends, `dt` seconds later (the step's
    /// `dt`): the rest direction along the shortest arc, the twist the short
    /// way round. Call it every frame with the animation's last two shapes.
    /// `Err` for a `dt` that is not a time step, as
    /// [`AngularDrive::following`](crate::AngularDrive::following).
    pub fn following(
        mut self,
        prev: (Vec3, f32),
        pose: (Vec3, f32),
        dt: f32,
    ) -> Result<Self, Error> {
        crate::checks::following_time_step(dt)?;
        let (bend, twist) = prev;
        let turn = vertebra_math::Quat::<f32>::from(Quat::from_rotation_arc_portable(bend, pose.0));
        self.bend_rest = bend;
        self.twist_rest = twist;
        self.bend_rest_velocity = Vec3::from(turn.to_rotation_vector()) / dt;
        self.twist_rest_velocity = vertebra_math::poly::wrap_angle(pose.1 - twist) / dt;
        Ok(self)
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
        crate::checks::angular_velocity(
            self.bend_rest_velocity,
            "rod rest bend velocity",
            "rod rest bend velocity (at most MAX_ANGULAR_SPEED_LIMIT)",
        )?;
        crate::checks::angular_velocity(
            Vec3::new(self.twist_rest_velocity, 0.0, 0.0),
            "rod rest twist velocity",
            "rod rest twist velocity (at most MAX_ANGULAR_SPEED_LIMIT)",
        )?;
        check_stiffness(self.bending, STIFFNESS_FIELDS[0])?;
        check_stiffness(self.twisting, STIFFNESS_FIELDS[1])?;
        if self.max_torque.is_nan() {
            return Err(Error::NonFinite("rod max torque"));
        }
        if self.max_torque < 0.0 {
            return Err(Error::NonPositive("rod max torque"));
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
            RodStiffness::Damped { stiffness, damping } if stiffness > 0.0 => RodSoftness::Damped {
                compliance: self.rest_length / stiffness,
                damping_time: damping / stiffness,
            },
            RodStiffness::Kirchhoff(_) | RodStiffness::Damped { .. } => {
                RodSoftness::Relaxation(0.0)
            }
            RodStiffness::Relaxation(r) => RodSoftness::Relaxation(r),
            RodStiffness::Spring {
                frequency,
                damping_ratio,
            } => {
                let omega = TAU * frequency;
                RodSoftness::Spring {
                    period2: 1.0 / (omega * omega),
                    damping_time: 2.0 * damping_ratio / omega,
                }
            }
        }
    }
}

/// The names a refusal gives each stiffness's fields, bending then
/// twisting: (stiffness, damping, frequency, damping ratio).
const STIFFNESS_FIELDS: [[&str; 4]; 2] = [
    [
        "rod bending",
        "rod bending damping",
        "rod bending frequency",
        "rod bending damping ratio",
    ],
    [
        "rod twisting",
        "rod twisting damping",
        "rod twisting frequency",
        "rod twisting damping ratio",
    ],
];

/// Checks one stiffness; `names` as in [`STIFFNESS_FIELDS`].
fn check_stiffness(s: RodStiffness, names: [&'static str; 4]) -> Result<(), Error> {
    let [what, damping_name, frequency_name, ratio_name] = names;
    match s {
        RodStiffness::Kirchhoff(k) => not_negative(what, k),
        RodStiffness::Relaxation(r) if !(0.0..=1.0).contains(&r) => {
            Err(Error::OutOfRange("rod relaxation factor (0 to 1)"))
        }
        RodStiffness::Relaxation(_) => Ok(()),
        RodStiffness::Damped { stiffness, damping } => {
            not_negative(what, stiffness)?;
            not_negative(damping_name, damping)?;
            if !damping.is_finite() {
                return Err(Error::NonFinite(damping_name));
            }
            if stiffness > 0.0 && damping / stiffness > MAX_DRIVE_DAMPING_TIME {
                return Err(Error::OutOfRange(
                    "rod damping (damping over stiffness at most 1e6 s)",
                ));
            }
            Ok(())
        }
        RodStiffness::Spring {
            frequency,
            damping_ratio,
        } => {
            if frequency.is_nan() {
                return Err(Error::NonFinite(frequency_name));
            }
            if frequency < MIN_DRIVE_FREQUENCY {
                return Err(Error::OutOfRange("rod frequency (at least 1e-3 Hz)"));
            }
            not_negative(ratio_name, damping_ratio)?;
            if damping_ratio > MAX_DRIVE_DAMPING_RATIO {
                return Err(Error::OutOfRange("rod damping ratio (at most 1e3)"));
            }
            Ok(())
        }
    }
}

/// A number, not negative (infinity allowed).
fn not_negative(what: &'static str, x: f32) -> Result<(), Error> {
    if x.is_nan() {
        return Err(Error::NonFinite(what));
    }
    if x < 0.0 {
        return Err(Error::NonPositive(what));
    }
    Ok(())
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

/// The rod's twist (rad, in [-pi, pi]) between its material frames
/// `f0 = q_a F_a` and `f1 = q_b F_b` (unit quaternions, world): the angle
/// about `t_b` from `f0`, carried by the minimal rotation from `t_a` to
/// `t_b`, to `f1`. It is the rod kernel's own measure
/// (`vertebra_kernels::parts::rod::twist::measure`) run on one `f32` lane,
/// so a rest twist or a mapping computed with it is the twist the solver
/// sees: to the bit where a's body is unrotated (the bind pose, where the
/// kernel's frames in a's body frame, `F_a` and `(q_a* q_b) F_b`, are
/// these), to rounding elsewhere.
pub fn rod_twist(f0: Quat, f1: Quat) -> f32 {
    use vertebra_kernels::parts::rod::{Frames, twist};
    twist::measure(&Frames::new(
        vertebra_math::Quat::<f32>::from(f0),
        vertebra_math::Quat::<f32>::from(f1),
    ))
}

/// `sin(x/2) / x`, through the math layer (the kernels' own definition).
fn half_sinc(x: f32) -> f32 {
    vertebra_math::poly::half_sinc(x)
}
