//! Joints of every kind (socket, hinge, fixed) with their limits, limit
//! softness and drives (`docs/joints.md` gives each kind's parts and units).

use vertebra_world::{
    AngularDrive, JointBreaking, JointDesc, JointKind, LimitSoftness, Spring, Swing, SwingTwist,
};

use crate::error::{Failure, VtResult};
use crate::ffi::{out, read};
use crate::types::{VtBody, VtJoint, VtQuat, VtVec3, flag, pick};
use crate::world::{VtWorld, with_world};

/// A joint's kind.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtJointKind {
    /// Ball and socket, within its swing and twist limits.
    Socket = 0,
    /// Rotation about the joint frame's +X only, within its range.
    Hinge = 1,
    /// No relative motion.
    Fixed = 2,
}

/// A socket's swing limit's shape.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtSwingKind {
    /// No limit.
    Free = 0,
    /// A circular cone of `half_angle`.
    Cone = 1,
    /// An elliptical cone of `half_angle_y` about Y and `half_angle_z`
    /// about Z.
    Ellipse = 2,
    /// A pyramid: `[min_y, max_y]` about Y and `[min_z, max_z]` about Z.
    Pyramid = 3,
}

/// How a limit (or a drive) holds.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtSoftnessKind {
    /// A hard limit (not for a drive).
    Hard = 0,
    /// Compliance `a` (rad / (N m)) and damping `b` (N m s / rad).
    Compliance = 1,
    /// A spring of frequency `a` (Hz) and damping ratio `b`.
    Spring = 2,
}

/// A limit's or a drive's softness: `kind` is a `VtSoftnessKind`; `a` and
/// `b` as the kind says.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtSoftness {
    /// A `VtSoftnessKind`.
    pub kind: u32,
    /// Compliance (rad / (N m)) or frequency (Hz).
    pub a: f32,
    /// Damping (N m s / rad) or damping ratio.
    pub b: f32,
}

/// A socket's swing limit (angles in rad); only the fields of its kind
/// are read.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtSwing {
    /// A `VtSwingKind`.
    pub kind: u32,
    /// Cone: the half-angle, in [0, pi].
    pub half_angle: f32,
    /// Ellipse: the half-angle about Y, in [0, pi].
    pub half_angle_y: f32,
    /// Ellipse: the half-angle about Z, in [0, pi].
    pub half_angle_z: f32,
    /// Pyramid: the range about Y, within [-pi, pi].
    pub min_y: f32,
    /// Pyramid: see `min_y`.
    pub max_y: f32,
    /// Pyramid: the range about Z, within [-pi, pi].
    pub min_z: f32,
    /// Pyramid: see `min_z`.
    pub max_z: f32,
}

/// An angular drive toward a target rotation of b's joint frame relative
/// to a's (sockets and hinges).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtDrive {
    /// The target rotation (unit).
    pub target: VtQuat,
    /// The rate the target turns at (rad/s, a's joint frame).
    pub target_velocity: VtVec3,
    /// `VT_SOFTNESS_KIND_COMPLIANCE` (0 compliance: rigid) or
    /// `VT_SOFTNESS_KIND_SPRING`.
    pub strength: VtSoftness,
    /// The largest torque it exerts (N m; infinity: unlimited).
    pub max_torque: f32,
}

/// A joint between two bodies: each body carries a joint frame (anchor and
/// rotation, in its body frame); the anchors are held together and the
/// frames' relative rotation is what the kind limits.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtJointDesc {
    /// The parent body.
    pub body_a: VtBody,
    /// The child body.
    pub body_b: VtBody,
    /// Anchor on a (m, a's body frame).
    pub anchor_a: VtVec3,
    /// Anchor on b (m, b's body frame).
    pub anchor_b: VtVec3,
    /// Joint frame on a (a's body frame).
    pub frame_a: VtQuat,
    /// Joint frame on b (b's body frame).
    pub frame_b: VtQuat,
    /// A `VtJointKind`.
    pub kind: u32,
    /// Socket: the swing limit.
    pub swing: VtSwing,
    /// Non-zero: the range below holds (a socket's twist, a hinge's angle).
    pub has_range: u32,
    /// The range's lower end (rad, within [-pi, pi]).
    pub range_min: f32,
    /// The range's upper end (rad).
    pub range_max: f32,
    /// Softness of the socket's limits or the hinge's range.
    pub softness: VtSoftness,
    /// Non-zero: `drive` drives the joint (sockets and hinges).
    pub has_drive: u32,
    /// The drive.
    pub drive: VtDrive,
    /// Non-zero: the joint breaks past `break_force` or `break_torque`
    /// (it is removed at the end of that step and listed by
    /// `vt_world_broken_joints`).
    pub has_breaking: u32,
    /// The largest mean force it holds over a step (N, positive; infinity:
    /// never by force).
    pub break_force: f32,
    /// The largest mean torque it holds over a step (N m, positive;
    /// infinity: never by torque).
    pub break_torque: f32,
}

impl TryFrom<VtSoftness> for LimitSoftness {
    type Error = Failure;
    fn try_from(s: VtSoftness) -> Result<Self, Failure> {
        Ok(match pick(s.kind, "softness.kind", &[0, 1, 2])? {
            0 => LimitSoftness::Hard,
            1 => LimitSoftness::Soft(Spring::Compliance {
                compliance: s.a,
                damping: s.b,
            }),
            _ => LimitSoftness::Soft(Spring::Frequency {
                frequency: s.a,
                damping_ratio: s.b,
            }),
        })
    }
}

impl From<Spring> for VtSoftness {
    fn from(s: Spring) -> Self {
        let (kind, a, b) = match s {
            Spring::Compliance {
                compliance,
                damping,
            } => (1, compliance, damping),
            Spring::Frequency {
                frequency,
                damping_ratio,
            } => (2, frequency, damping_ratio),
        };
        Self { kind, a, b }
    }
}

impl From<LimitSoftness> for VtSoftness {
    fn from(s: LimitSoftness) -> Self {
        match s {
            LimitSoftness::Hard => Self {
                kind: 0,
                a: 0.0,
                b: 0.0,
            },
            LimitSoftness::Soft(spring) => spring.into(),
        }
    }
}

/// A drive's strength: compliance (0: rigid) or a spring, never hard; the
/// refusal names `field`.
pub(crate) fn drive_spring(s: VtSoftness, field: &str) -> Result<Spring, Failure> {
    match LimitSoftness::try_from(s)? {
        LimitSoftness::Soft(spring) => Ok(spring),
        LimitSoftness::Hard => Err(Failure::new(
            VtResult::InvalidEnum,
            format!(
                "{field}.kind is VT_SOFTNESS_KIND_HARD; a drive is compliant (0: rigid) or a spring"
            ),
        )),
    }
}

impl TryFrom<VtDrive> for AngularDrive {
    type Error = Failure;
    fn try_from(d: VtDrive) -> Result<Self, Failure> {
        let strength = drive_spring(d.strength, "drive.strength")?;
        Ok(AngularDrive {
            target: d.target.into(),
            target_velocity: d.target_velocity.into(),
            strength,
            max_torque: d.max_torque,
        })
    }
}

impl From<AngularDrive> for VtDrive {
    fn from(d: AngularDrive) -> Self {
        Self {
            target: d.target.into(),
            target_velocity: d.target_velocity.into(),
            strength: d.strength.into(),
            max_torque: d.max_torque,
        }
    }
}

impl TryFrom<VtSwing> for Swing {
    type Error = Failure;
    fn try_from(s: VtSwing) -> Result<Self, Failure> {
        Ok(match pick(s.kind, "swing.kind", &[0, 1, 2, 3])? {
            0 => Swing::Free,
            1 => Swing::Cone(s.half_angle),
            2 => Swing::Ellipse {
                y: s.half_angle_y,
                z: s.half_angle_z,
            },
            _ => Swing::Pyramid {
                y: [s.min_y, s.max_y],
                z: [s.min_z, s.max_z],
            },
        })
    }
}

impl From<Swing> for VtSwing {
    fn from(s: Swing) -> Self {
        let mut out = VtSwing {
            kind: 0,
            half_angle: 0.0,
            half_angle_y: 0.0,
            half_angle_z: 0.0,
            min_y: 0.0,
            max_y: 0.0,
            min_z: 0.0,
            max_z: 0.0,
        };
        match s {
            Swing::Free => {}
            Swing::Cone(half_angle) => (out.kind, out.half_angle) = (1, half_angle),
            Swing::Ellipse { y, z } => (out.kind, out.half_angle_y, out.half_angle_z) = (2, y, z),
            Swing::Pyramid { y, z } => {
                out.kind = 3;
                [out.min_y, out.max_y, out.min_z, out.max_z] = [y[0], y[1], z[0], z[1]];
            }
        }
        out
    }
}

impl TryFrom<&VtJointDesc> for JointDesc {
    type Error = Failure;
    fn try_from(d: &VtJointDesc) -> Result<Self, Failure> {
        let range = flag(d.has_range).then_some([d.range_min, d.range_max]);
        let softness = d.softness.try_into()?;
        let kind = match pick(d.kind, "joint.kind", &[0, 1, 2])? {
            0 => JointKind::Socket(SwingTwist {
                swing: d.swing.try_into()?,
                twist: range,
                softness,
            }),
            1 => JointKind::Hinge { range, softness },
            _ => JointKind::Fixed,
        };
        let drive = match flag(d.has_drive) {
            true => Some(d.drive.try_into()?),
            false => None,
        };
        Ok(JointDesc {
            body_a: d.body_a.into(),
            body_b: d.body_b.into(),
            anchor_a: d.anchor_a.into(),
            anchor_b: d.anchor_b.into(),
            frame_a: d.frame_a.into(),
            frame_b: d.frame_b.into(),
            kind,
            drive,
            breaking: flag(d.has_breaking).then_some(JointBreaking {
                force: d.break_force,
                torque: d.break_torque,
            }),
        })
    }
}

impl From<&JointDesc> for VtJointDesc {
    fn from(d: &JointDesc) -> Self {
        let (kind, swing, range, softness) = match d.kind {
            JointKind::Socket(limits) => (0, limits.swing, limits.twist, limits.softness),
            JointKind::Hinge { range, softness } => (1, Swing::Free, range, softness),
            JointKind::Fixed => (2, Swing::Free, None, LimitSoftness::Hard),
        };
        let [range_min, range_max] = range.unwrap_or_default();
        let drive = d.drive.unwrap_or(AngularDrive::rigid(glam::Quat::IDENTITY));
        Self {
            body_a: d.body_a.into(),
            body_b: d.body_b.into(),
            anchor_a: d.anchor_a.into(),
            anchor_b: d.anchor_b.into(),
            frame_a: d.frame_a.into(),
            frame_b: d.frame_b.into(),
            kind,
            swing: swing.into(),
            has_range: u32::from(range.is_some()),
            range_min,
            range_max,
            softness: softness.into(),
            has_drive: u32::from(d.drive.is_some()),
            drive: drive.into(),
            has_breaking: u32::from(d.breaking.is_some()),
            break_force: d.breaking.map_or(f32::INFINITY, |b| b.force),
            break_torque: d.breaking.map_or(f32::INFINITY, |b| b.torque),
        }
    }
}

/// Writes into `desc` a joint of `kind` (a `VtJointKind`) between two
/// bodies at their current poses, exactly satisfied now, without limits or
/// drive: its anchor at the world point `anchor` (m), its frame's +X along
/// the world direction `axis` (unit; a socket's twist axis from a to b, a
/// hinge's axis; a fixed joint ignores it). Set limits and a drive in
/// `desc`, then `vt_world_add_joint`.
///
/// # Safety
/// `world` is a live world; `desc` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_joint_at_world_anchor(
    world: *mut VtWorld,
    kind: u32,
    body_a: VtBody,
    body_b: VtBody,
    anchor: VtVec3,
    axis: VtVec3,
    desc: *mut VtJointDesc,
) -> VtResult {
    // SAFETY: the function's contract.
    let desc = unsafe { out(desc, "desc") };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (a, b, anchor, axis) = (body_a.into(), body_b.into(), anchor.into(), axis.into());
            let bodies = w.bodies();
            let joint = match pick(kind, "kind", &[0, 1, 2])? {
                0 => JointDesc::socket_at_world_anchor(bodies, a, b, anchor, axis),
                1 => JointDesc::hinge_at_world_anchor(bodies, a, b, anchor, axis),
                _ => JointDesc::fixed_at(bodies, a, b, anchor),
            }?;
            desc?.set((&joint).into());
            Ok(())
        })
    }
}

/// Adds a joint and writes its handle into `joint`.
///
/// # Safety
/// `world` is a live world; `desc` is readable; `joint` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_add_joint(
    world: *mut VtWorld,
    desc: *const VtJointDesc,
    joint: *mut VtJoint,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe { (read(desc, "desc"), out(joint, "joint")) };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (desc, joint) = (inputs.0?, inputs.1?);
            joint.set(w.add_joint(JointDesc::try_from(&desc)?)?.into());
            Ok(())
        })
    }
}

/// Removes a joint.
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_remove_joint(world: *mut VtWorld, joint: VtJoint) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { with_world(world, |w| Ok(w.remove_joint(joint.into())?)) }
}

/// Writes a joint's description into `desc` (its drive's target as the
/// next step begins).
///
/// # Safety
/// `world` is a live world; `desc` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_joint(
    world: *mut VtWorld,
    joint: VtJoint,
    desc: *mut VtJointDesc,
) -> VtResult {
    // SAFETY: the function's contract.
    let desc = unsafe { out(desc, "desc") };
    // SAFETY: the function's contract.
    unsafe { with_world(world, |w| desc?.done((&w.joint(joint.into())?).into())) }
}

/// Sets a joint's drive, or clears it (`drive` null).
///
/// # Safety
/// `world` is a live world; `drive` is null or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_joint_drive(
    world: *mut VtWorld,
    joint: VtJoint,
    drive: *const VtDrive,
) -> VtResult {
    let drive = match drive.is_null() {
        true => Ok(None),
        // SAFETY: the function's contract.
        false => unsafe { read(drive, "drive") }.map(Some),
    };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let drive = drive?.map(AngularDrive::try_from).transpose()?;
            Ok(w.set_joint_drive(joint.into(), drive)?)
        })
    }
}
