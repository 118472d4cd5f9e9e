//! Rods: the paper's constraint, an inextensible Kirchhoff rod held to a
//! circular arc between two bodies (`docs/rod-constraint.md`).

use vertebra_world::{RodDesc, RodStiffness};

use crate::error::{Failure, VtResult};
use crate::ffi::{out, read, slice};
use crate::types::{VtBody, VtQuat, VtRod, VtVec3, flag, pick};
use crate::world::{VtWorld, with_world};

/// How stiff a rod is in bending or twisting.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtStiffnessKind {
    /// Kirchhoff stiffness `a` (N m^2); 0 none, infinity rigid.
    Kirchhoff = 0,
    /// The paper's relaxation factor `a` in [0, 1].
    Relaxation = 1,
    /// Kirchhoff stiffness `a` (N m^2) with damping `b` (N m^2 s / rad).
    Damped = 2,
    /// A spring of frequency `a` (Hz) and damping ratio `b`.
    Spring = 3,
}

/// A rod's stiffness: `kind` is a `VtStiffnessKind`; `a` and `b` as the
/// kind says.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtStiffness {
    /// A `VtStiffnessKind`.
    pub kind: u32,
    /// Stiffness, relaxation factor or frequency.
    pub a: f32,
    /// Damping or damping ratio.
    pub b: f32,
}

/// A rod between the centres of mass of two bodies (`RodDesc` in Rust,
/// whose docs give every field's range). `vt_rod_from_pose` fills one that
/// holds exactly at the bodies' current poses.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtRodDesc {
    /// The first body (the hips of a spine).
    pub body_a: VtBody,
    /// The second body (the chest).
    pub body_b: VtBody,
    /// Material frame at a (a's body frame); its +X is the tangent.
    pub frame_a: VtQuat,
    /// Material frame at b (b's body frame).
    pub frame_b: VtQuat,
    /// Rest length of the arc (m).
    pub rest_length: f32,
    /// Rest direction of b's tangent in a's material frame (unit).
    pub bend_rest: VtVec3,
    /// Rest twist (rad).
    pub twist_rest: f32,
    /// The rate the rest bend turns at (rad/s, a's material frame).
    pub bend_rest_velocity: VtVec3,
    /// The rate the rest twist turns at (rad/s).
    pub twist_rest_velocity: f32,
    /// Bending stiffness.
    pub bending: VtStiffness,
    /// Twisting stiffness.
    pub twisting: VtStiffness,
    /// Non-zero: `bend_limit` holds.
    pub has_bend_limit: u32,
    /// Largest bend angle (rad, in [0, pi]).
    pub bend_limit: f32,
    /// Non-zero: the twist range holds.
    pub has_twist_limit: u32,
    /// Twist range's lower end (rad).
    pub twist_min: f32,
    /// Twist range's upper end (rad).
    pub twist_max: f32,
    /// The largest torque the soft bending and twisting exert (N m).
    pub max_torque: f32,
}

impl TryFrom<VtStiffness> for RodStiffness {
    type Error = Failure;
    fn try_from(s: VtStiffness) -> Result<Self, Failure> {
        Ok(match pick(s.kind, "stiffness.kind", &[0, 1, 2, 3])? {
            0 => RodStiffness::Kirchhoff(s.a),
            1 => RodStiffness::Relaxation(s.a),
            2 => RodStiffness::Damped {
                stiffness: s.a,
                damping: s.b,
            },
            _ => RodStiffness::Spring {
                frequency: s.a,
                damping_ratio: s.b,
            },
        })
    }
}

impl From<RodStiffness> for VtStiffness {
    fn from(s: RodStiffness) -> Self {
        let (kind, a, b) = match s {
            RodStiffness::Kirchhoff(k) => (0, k, 0.0),
            RodStiffness::Relaxation(r) => (1, r, 0.0),
            RodStiffness::Damped { stiffness, damping } => (2, stiffness, damping),
            RodStiffness::Spring {
                frequency,
                damping_ratio,
            } => (3, frequency, damping_ratio),
        };
        Self { kind, a, b }
    }
}

impl TryFrom<&VtRodDesc> for RodDesc {
    type Error = Failure;
    fn try_from(d: &VtRodDesc) -> Result<Self, Failure> {
        Ok(RodDesc {
            body_a: d.body_a.into(),
            body_b: d.body_b.into(),
            frame_a: d.frame_a.into(),
            frame_b: d.frame_b.into(),
            rest_length: d.rest_length,
            bend_rest: d.bend_rest.into(),
            twist_rest: d.twist_rest,
            bend_rest_velocity: d.bend_rest_velocity.into(),
            twist_rest_velocity: d.twist_rest_velocity,
            bending: d.bending.try_into()?,
            twisting: d.twisting.try_into()?,
            bend_limit: flag(d.has_bend_limit).then_some(d.bend_limit),
            twist_limit: flag(d.has_twist_limit).then_some([d.twist_min, d.twist_max]),
            max_torque: d.max_torque,
        })
    }
}

impl From<&RodDesc> for VtRodDesc {
    fn from(d: &RodDesc) -> Self {
        let [twist_min, twist_max] = d.twist_limit.unwrap_or_default();
        Self {
            body_a: d.body_a.into(),
            body_b: d.body_b.into(),
            frame_a: d.frame_a.into(),
            frame_b: d.frame_b.into(),
            rest_length: d.rest_length,
            bend_rest: d.bend_rest.into(),
            twist_rest: d.twist_rest,
            bend_rest_velocity: d.bend_rest_velocity.into(),
            twist_rest_velocity: d.twist_rest_velocity,
            bending: d.bending.into(),
            twisting: d.twisting.into(),
            has_bend_limit: u32::from(d.bend_limit.is_some()),
            bend_limit: d.bend_limit.unwrap_or_default(),
            has_twist_limit: u32::from(d.twist_limit.is_some()),
            twist_min,
            twist_max,
            max_torque: d.max_torque,
        }
    }
}

/// Writes into `desc` a rod between two bodies that holds exactly at their
/// current poses: its arc through the middle of `through` (`count` world
/// points, m: the animation bones between; 0 for a straight rod), without
/// stiffness or limits.
///
/// # Safety
/// `world` is a live world; `through` points to `count` readable points;
/// `desc` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_rod_from_pose(
    world: *mut VtWorld,
    body_a: VtBody,
    body_b: VtBody,
    through: *const VtVec3,
    count: usize,
    desc: *mut VtRodDesc,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe { (slice(through, count, "through"), out(desc, "desc")) };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (through, desc) = (inputs.0?, inputs.1?);
            let points: Vec<glam::Vec3> = through.iter().map(|&p| p.into()).collect();
            let rod = RodDesc::from_pose(w.bodies(), body_a.into(), body_b.into(), &points)?;
            desc.set((&rod).into());
            Ok(())
        })
    }
}

/// Adds a rod and writes its handle into `rod`.
///
/// # Safety
/// `world` is a live world; `desc` is readable; `rod` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_add_rod(
    world: *mut VtWorld,
    desc: *const VtRodDesc,
    rod: *mut VtRod,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe { (read(desc, "desc"), out(rod, "rod")) };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (desc, rod) = (inputs.0?, inputs.1?);
            rod.set(w.add_rod(RodDesc::try_from(&desc)?)?.into());
            Ok(())
        })
    }
}

/// Replaces a rod's description (its bodies must stay the same).
///
/// # Safety
/// `world` is a live world; `desc` is readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_rod(
    world: *mut VtWorld,
    rod: VtRod,
    desc: *const VtRodDesc,
) -> VtResult {
    // SAFETY: the function's contract.
    let desc = unsafe { read(desc, "desc") };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            Ok(w.set_rod(rod.into(), RodDesc::try_from(&desc?)?)?)
        })
    }
}

/// Writes a rod's description into `desc` (its rest as the next step
/// begins).
///
/// # Safety
/// `world` is a live world; `desc` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_rod(
    world: *mut VtWorld,
    rod: VtRod,
    desc: *mut VtRodDesc,
) -> VtResult {
    // SAFETY: the function's contract.
    let desc = unsafe { out(desc, "desc") };
    // SAFETY: the function's contract.
    unsafe { with_world(world, |w| desc?.done((&w.rod(rod.into())?).into())) }
}

/// Removes a rod.
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_remove_rod(world: *mut VtWorld, rod: VtRod) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { with_world(world, |w| Ok(w.remove_rod(rod.into())?)) }
}
