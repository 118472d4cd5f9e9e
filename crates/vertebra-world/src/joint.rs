//! A joint's public description (its kind, limits and drive) and its
//! validation. See `docs/joints.md` for each kind's parts and units.

use glam::{Quat, Vec3};
use vertebra_math::PortableQuat;

use crate::drive::{AngularDrive, validate_drive};
use crate::spring::{Spring, SpringField};
use serde::{Deserialize, Serialize};
use vertebra_kernels::limited::LimitLane;
use vertebra_math::DefaultFloatMode;
use vertebra_store::{
    BodyHandle, BodyStore, Error, Handle, check_coordinate, check_unit_quat, check_unit_vec,
};

/// Marker for joint handles.
#[derive(Debug)]
pub enum JointTag {}

/// A stable reference to a joint.
pub type JointHandle = Handle<JointTag>;

/// How a limit holds: hard, or as a damped spring on the excess beyond
/// it, which acts only while the limit is exceeded and lets go inside
/// (`crates/vertebra-kernels/src/parts/limit.rs` derives it). Serialised
/// through its wire form (`joint_wire.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum LimitSoftness {
    /// Never exceeded (to the solver's convergence).
    #[default]
    Hard,
    /// A damped spring on the excess `C` ([`Spring`], as a drive's
    /// strength; its errors name the `limit`): given by frequency, scaled
    /// by the limit's effective inertia per lane and iteration; at damping
    /// ratio 1 the limb comes to rest against the limit without
    /// rebounding, at 0 it bounces back off it.
    Soft(Spring),
}

impl LimitSoftness {
    /// A spring of compliance `c` (rad / (N m)) without damping.
    pub const fn compliant(c: f32) -> Self {
        Self::Soft(Spring::compliant(c))
    }

    /// The kernel's lane data (`parts::limit`), the spring's; all 0 when
    /// hard.
    pub(crate) fn lane(&self) -> LimitLane {
        match self {
            Self::Hard => LimitLane::HARD,
            Self::Soft(spring) => {
                let lane = spring.lane();
                LimitLane {
                    compliance: lane.compliance,
                    period2: lane.period2,
                    damping_time: lane.damping_time,
                }
            }
        }
    }

    /// Checks a soft limit's spring; the error names the `limit`'s number.
    fn check(&self) -> Result<(), Error> {
        match self {
            Self::Hard => Ok(()),
            Self::Soft(spring) => spring.check(SpringField::Limit),
        }
    }
}

/// An elliptical cone's semi-axis for the half-angle `half` (rad):
/// `sin(half / 2)` by the kernels' polynomial (so that every platform lays
/// out the same bits), at least `parts::ellipse::MIN_SEMI_AXIS`.
pub(crate) fn ellipse_semi_axis(half: f32) -> f32 {
    vertebra_math::poly::sin(0.5 * half).max(vertebra_kernels::parts::ellipse::MIN_SEMI_AXIS)
}

/// A socket's swing limit: how far b's twist axis (its joint frame's +X)
/// may turn away from a's, measured on the swing of the swing-twist
/// decomposition (twist about +X) in a's joint frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Swing {
    /// No limit.
    Free,
    /// A circular cone of this half-angle (rad, in [0, pi]).
    Cone(f32),
    /// An elliptical cone: the half-angles (rad, each in [0, pi]) of the
    /// swing about the joint frame's Y axis (`y`) and Z axis (`z`), as
    /// Jolt's plane and normal half-angles; the largest swing about a unit
    /// axis `(0, u_y, u_z)` is
    /// `2 asin(1 / sqrt(u_y^2 / sin^2(y/2) + u_z^2 / sin^2(z/2)))`.
    /// Half-angles below 0.002 rad act as 0.002 rad.
    Ellipse {
        /// Half-angle about Y (rad).
        y: f32,
        /// Half-angle about Z (rad).
        z: f32,
    },
    /// A pyramid: the swing angles about Y and Z (rad, `2 atan2(s_y, s_w)`
    /// and `2 atan2(s_z, s_w)` of the swing quaternion), each held in its
    /// own `[min, max]` within [-pi, pi].
    Pyramid {
        /// Range about Y (rad).
        y: [f32; 2],
        /// Range about Z (rad).
        z: [f32; 2],
    },
}

/// A socket's limits: swing, twist and how hard they hold.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SwingTwist {
    /// The swing limit.
    pub swing: Swing,
    /// Twist range `[min, max]` (rad, within [-pi, pi]) about the twist
    /// axis; `None` is unlimited.
    pub twist: Option<[f32; 2]>,
    /// Softness of both limits.
    pub softness: LimitSoftness,
}

impl SwingTwist {
    /// No limit at all.
    pub const FREE: Self = Self {
        swing: Swing::Free,
        twist: None,
        softness: LimitSoftness::Hard,
    };

    /// With a swing limit.
    pub fn with_swing(mut self, swing: Swing) -> Self {
        self.swing = swing;
        self
    }

    /// With a twist range (rad).
    pub fn with_twist(mut self, min: f32, max: f32) -> Self {
        self.twist = Some([min, max]);
        self
    }

    /// With soft limits.
    pub fn with_softness(mut self, softness: LimitSoftness) -> Self {
        self.softness = softness;
        self
    }

    /// Whether the plain socket path solves it (a hard circular cone, or
    /// none, and a hard twist range): the cheaper path, without the shaped
    /// path's terms.
    pub(crate) fn is_plain(&self) -> bool {
        matches!(self.swing, Swing::Free | Swing::Cone(_)) && self.softness == LimitSoftness::Hard
    }
}

/// What a joint holds besides its anchors (which every kind holds
/// together).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum JointKind {
    /// Ball and socket: free rotation within the swing and twist limits
    /// (the paper's socket; Jolt's swing-twist constraint).
    Socket(SwingTwist),
    /// Rotation about the joint frame's +X axis only (the other two
    /// rotations held): a knee, an elbow, a door.
    Hinge {
        /// The hinge angle's range `[min, max]` (rad, within [-pi, pi]):
        /// the rotation of b's joint frame from a's about +X, positive
        /// counter-clockwise looking down +X; `None` is unlimited.
        range: Option<[f32; 2]>,
        /// Softness of the range.
        softness: LimitSoftness,
    },
    /// No relative motion: the bodies welded (a weapon in a hand).
    Fixed,
}

/// A joint between two bodies.
///
/// Each body carries a joint frame (an anchor point and a rotation, in its
/// body frame); every kind holds the anchors together, and the frames'
/// relative rotation is what the kind limits (see [`JointKind`]).
/// Serialised through its wire form (`joint_wire.rs`), which implements
/// serde's traits for it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointDesc {
    /// The parent body.
    pub body_a: BodyHandle,
    /// The child body.
    pub body_b: BodyHandle,
    /// Anchor on a (m, a's body frame).
    pub anchor_a: Vec3,
    /// Anchor on b (m, b's body frame).
    pub anchor_b: Vec3,
    /// Joint frame rotation on a (a's body frame).
    pub frame_a: Quat,
    /// Joint frame rotation on b (b's body frame).
    pub frame_b: Quat,
    /// The kind and its limits.
    pub kind: JointKind,
    /// The angular drive, if any (sockets and hinges).
    pub drive: Option<AngularDrive>,
    /// When the joint breaks, if ever ([`JointBreaking`]).
    pub breaking: Option<JointBreaking>,
}

/// How strong a joint is: it breaks (the world removes it at the end of
/// the step and names it in [`World::broken_joints`](crate::World::broken_joints))
/// in the first step whose mean force on it exceeds `force` or whose mean
/// torque exceeds `torque` ([`World::joint_force`](crate::World::joint_force)):
/// a limb torn off, a ragdoll torn from its rope (PhysX's break force and
/// torque, Jolt's breakable constraints).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointBreaking {
    /// The largest force it holds (N, positive; infinity: never by force).
    pub force: f32,
    /// The largest torque it holds (N m, positive; infinity: never by
    /// torque).
    pub torque: f32,
}

impl JointBreaking {
    /// Checks both thresholds: positive, not NaN (infinity is allowed).
    pub fn validate(&self) -> Result<(), Error> {
        for (value, what) in [
            (self.force, "joint break force"),
            (self.torque, "joint break torque"),
        ] {
            if value.is_nan() {
                return Err(Error::NonFinite(what));
            }
            if value <= 0.0 {
                return Err(Error::NonPositive(what));
            }
        }
        Ok(())
    }
}

/// Both bodies' current poses and the frames that put the joint frame at
/// the world rotation `joint` and the anchors at the world point `anchor`.
fn frames_at(
    bodies: &BodyStore,
    body_a: BodyHandle,
    body_b: BodyHandle,
    anchor: Vec3,
    joint: Quat,
    kind: JointKind,
) -> Result<JointDesc, Error> {
    check_coordinate("anchor", anchor)?;
    let a = bodies.state(body_a)?;
    let b = bodies.state(body_b)?;
    Ok(JointDesc {
        body_a,
        body_b,
        anchor_a: a.orientation.inverse() * (anchor - a.position),
        anchor_b: b.orientation.inverse() * (anchor - b.position),
        frame_a: a.orientation.inverse().mul_portable(joint),
        frame_b: b.orientation.inverse().mul_portable(joint),
        kind,
        drive: None,
        breaking: None,
    })
}

impl JointDesc {
    /// A socket whose anchor is the world point `anchor` and whose twist
    /// axis is the world direction `twist_axis` (unit, pointing from a to b)
    /// at the bodies' current poses, without limits. The frames are set so
    /// that the joint is exactly satisfied, with zero swing and twist,
    /// right now.
    pub fn socket_at_world_anchor(
        bodies: &BodyStore,
        body_a: BodyHandle,
        body_b: BodyHandle,
        anchor: Vec3,
        twist_axis: Vec3,
    ) -> Result<Self, Error> {
        let _mode = DefaultFloatMode::enter();
        check_unit_vec("twist axis", twist_axis)?;
        let joint = Quat::from_rotation_arc_portable(Vec3::X, twist_axis.normalize());
        let kind = JointKind::Socket(SwingTwist::FREE);
        frames_at(bodies, body_a, body_b, anchor, joint, kind)
    }

    /// A hinge at the world point `anchor` turning about the world
    /// direction `axis` (unit) at the bodies' current poses, without a
    /// range: the hinge angle is 0 right now, and positive for b turning
    /// counter-clockwise about `axis` relative to a.
    pub fn hinge_at_world_anchor(
        bodies: &BodyStore,
        body_a: BodyHandle,
        body_b: BodyHandle,
        anchor: Vec3,
        axis: Vec3,
    ) -> Result<Self, Error> {
        let _mode = DefaultFloatMode::enter();
        check_unit_vec("hinge axis", axis)?;
        let joint = Quat::from_rotation_arc_portable(Vec3::X, axis.normalize());
        let kind = JointKind::Hinge {
            range: None,
            softness: LimitSoftness::Hard,
        };
        frames_at(bodies, body_a, body_b, anchor, joint, kind)
    }

    /// A fixed joint at the world point `anchor` that holds the bodies as
    /// they are posed right now.
    pub fn fixed_at(
        bodies: &BodyStore,
        body_a: BodyHandle,
        body_b: BodyHandle,
        anchor: Vec3,
    ) -> Result<Self, Error> {
        frames_at(
            bodies,
            body_a,
            body_b,
            anchor,
            Quat::IDENTITY,
            JointKind::Fixed,
        )
    }

    /// With a kind (its limits).
    pub fn with_kind(mut self, kind: JointKind) -> Self {
        self.kind = kind;
        self
    }

    /// A socket with a circular swing cone of this half-angle (rad),
    /// keeping a socket's twist range and softness (any other kind becomes
    /// a socket without them).
    pub fn with_swing_limit(self, half_angle: f32) -> Self {
        let limits = self.socket_limits().with_swing(Swing::Cone(half_angle));
        self.with_kind(JointKind::Socket(limits))
    }

    /// A socket with this twist range (rad), keeping a socket's swing limit
    /// and softness (any other kind becomes a socket without them).
    pub fn with_twist_limit(self, min: f32, max: f32) -> Self {
        let limits = self.socket_limits().with_twist(min, max);
        self.with_kind(JointKind::Socket(limits))
    }

    /// With an angular drive.
    pub fn with_drive(mut self, drive: AngularDrive) -> Self {
        self.drive = Some(drive);
        self
    }

    fn socket_limits(&self) -> SwingTwist {
        match self.kind {
            JointKind::Socket(limits) => limits,
            _ => SwingTwist::FREE,
        }
    }

    /// Checks everything but the handles' liveness.
    pub fn validate(&self) -> Result<(), Error> {
        if self.body_a == self.body_b {
            return Err(Error::SameBody);
        }
        check_coordinate("anchor a", self.anchor_a)?;
        check_coordinate("anchor b", self.anchor_b)?;
        check_unit_quat("frame a", self.frame_a)?;
        check_unit_quat("frame b", self.frame_b)?;
        validate_kind(&self.kind)?;
        if let Some(breaking) = &self.breaking {
            breaking.validate()?;
        }
        validate_drive_for(&self.kind, self.drive.as_ref())
    }

    /// The joint, breaking past `force` (N) or `torque` (N m): see
    /// [`JointBreaking`] (checked when the joint is added).
    pub fn with_breaking(mut self, force: f32, torque: f32) -> Self {
        self.breaking = Some(JointBreaking { force, torque });
        self
    }

    /// Checks the bodies too: live, and at least one dynamic.
    pub(crate) fn validate_with(&self, bodies: &BodyStore) -> Result<(), Error> {
        self.validate()?;
        crate::checks::joint_bodies(bodies, self.body_a, self.body_b)
    }
}

/// Checks a kind's limits and softness.
fn validate_kind(kind: &JointKind) -> Result<(), Error> {
    use crate::checks::{angle_range, max_angle, twist_range};
    match *kind {
        JointKind::Socket(SwingTwist {
            swing,
            twist,
            softness: soft,
        }) => {
            match swing {
                Swing::Free => {}
                Swing::Cone(half) => max_angle(Some(half), "swing")?,
                Swing::Ellipse { y, z } => {
                    max_angle(Some(y), "swing ellipse y")?;
                    max_angle(Some(z), "swing ellipse z")?;
                }
                Swing::Pyramid { y, z } => {
                    angle_range(Some(y), "swing pyramid y")?;
                    angle_range(Some(z), "swing pyramid z")?;
                }
            }
            twist_range(twist)?;
            soft.check()
        }
        JointKind::Hinge {
            range,
            softness: soft,
        } => {
            angle_range(range, "hinge range")?;
            soft.check()
        }
        JointKind::Fixed => Ok(()),
    }
}

/// A drive is checked, and refused on a fixed joint (nothing turns).
pub(crate) fn validate_drive_for(
    kind: &JointKind,
    drive: Option<&AngularDrive>,
) -> Result<(), Error> {
    match (kind, drive) {
        (JointKind::Fixed, Some(_)) => Err(Error::InvalidJoint(
            "drive (a fixed joint has no rotation to drive)",
        )),
        (_, Some(d)) => validate_drive(d),
        (_, None) => Ok(()),
    }
}
