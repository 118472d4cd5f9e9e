//! The socket joint's public description and its validation.

use crate::drive::{AngularDrive, validate_drive};
use glam::{Quat, Vec3};
use vertebra_store::{
    BodyHandle, BodyStore, Error, Handle, check_coordinate, check_unit_quat, check_unit_vec,
};

/// Marker for socket handles.
#[derive(Debug)]
pub enum SocketTag {}

/// A stable reference to a socket joint.
pub type SocketHandle = Handle<SocketTag>;

/// A ball-and-socket joint between two bodies.
///
/// Each body carries a joint frame (an anchor point and a rotation, in its
/// body frame); the anchors are held together, and the frames' +X axes are
/// the twist axes: the swing cone limits the angle between them, the twist
/// range the rotation about them.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SocketDesc {
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
    /// Swing cone half-angle (rad, in [0, pi]); `None` is unlimited.
    pub swing_limit: Option<f32>,
    /// Twist range `[min, max]` (rad, within [-pi, pi]); `None` is unlimited.
    pub twist_limit: Option<[f32; 2]>,
    /// The angular drive, if any.
    pub drive: Option<AngularDrive>,
}

impl SocketDesc {
    /// A socket whose anchor is the world point `anchor` and whose twist
    /// axis is the world direction `twist_axis` (unit, pointing from a to b)
    /// at the bodies' current poses. The frames are set so that the joint
    /// is exactly satisfied, with zero swing and twist, right now.
    pub fn at_world_anchor(
        bodies: &BodyStore,
        body_a: BodyHandle,
        body_b: BodyHandle,
        anchor: Vec3,
        twist_axis: Vec3,
    ) -> Result<Self, Error> {
        check_coordinate("anchor", anchor)?;
        check_unit_vec("twist axis", twist_axis)?;
        let a = bodies.state(body_a)?;
        let b = bodies.state(body_b)?;
        let joint = Quat::from_rotation_arc(Vec3::X, twist_axis.normalize());
        Ok(Self {
            body_a,
            body_b,
            anchor_a: a.orientation.inverse() * (anchor - a.position),
            anchor_b: b.orientation.inverse() * (anchor - b.position),
            frame_a: a.orientation.inverse() * joint,
            frame_b: b.orientation.inverse() * joint,
            swing_limit: None,
            twist_limit: None,
            drive: None,
        })
    }

    /// With a swing cone half-angle (rad).
    pub fn with_swing_limit(mut self, half_angle: f32) -> Self {
        self.swing_limit = Some(half_angle);
        self
    }

    /// With a twist range (rad).
    pub fn with_twist_limit(mut self, min: f32, max: f32) -> Self {
        self.twist_limit = Some([min, max]);
        self
    }

    /// With an angular drive.
    pub fn with_drive(mut self, drive: AngularDrive) -> Self {
        self.drive = Some(drive);
        self
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
        crate::checks::max_angle(self.swing_limit, "swing")?;
        crate::checks::twist_range(self.twist_limit)?;
        if let Some(d) = self.drive {
            validate_drive(&d)?;
        }
        Ok(())
    }

    /// Checks the bodies too: live, and at least one dynamic.
    pub(crate) fn validate_with(&self, bodies: &BodyStore) -> Result<(), Error> {
        self.validate()?;
        crate::checks::joint_bodies(bodies, self.body_a, self.body_b)
    }
}
