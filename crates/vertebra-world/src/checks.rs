//! Validation shared by every joint description.

use core::f32::consts::PI;

use glam::Vec3;
use vertebra_store::{BodyHandle, BodyKind, BodyStore, Error};

use crate::MAX_ANGULAR_SPEED_LIMIT;

/// The time step a drive or a rod follows an animation over: finite and at
/// least [`MIN_TIME_STEP`](vertebra_store::MIN_TIME_STEP). A negative one
/// would turn the target away from the animation, a zero one divide by
/// zero.
pub(crate) fn following_time_step(dt: f32) -> Result<(), Error> {
    vertebra_store::check_positive("following time step", dt)?;
    if dt < vertebra_store::MIN_TIME_STEP {
        return Err(Error::OutOfRange("following time step (at least 1e-6 s)"));
    }
    Ok(())
}

/// An angular velocity (rad/s): finite (`what` names it) and at most
/// [`MAX_ANGULAR_SPEED_LIMIT`] long (`out_of_range` says so). Drives'
/// target velocities and rods' rest velocities.
pub(crate) fn angular_velocity(
    v: Vec3,
    what: &'static str,
    out_of_range: &'static str,
) -> Result<(), Error> {
    if !v.is_finite() {
        return Err(Error::NonFinite(what));
    }
    if v.length() > MAX_ANGULAR_SPEED_LIMIT {
        return Err(Error::OutOfRange(out_of_range));
    }
    Ok(())
}

/// A largest angle (rad) in [0, pi], if set.
pub(crate) fn max_angle(limit: Option<f32>, what: &'static str) -> Result<(), Error> {
    match limit {
        Some(m) if !m.is_finite() => Err(Error::NonFinite(what)),
        Some(m) if !(0.0..=PI).contains(&m) => Err(Error::InvalidLimit(what)),
        _ => Ok(()),
    }
}

/// A twist range `[min, max]` (rad) within [-pi, pi], if set.
pub(crate) fn twist_range(limit: Option<[f32; 2]>) -> Result<(), Error> {
    match limit {
        Some([lo, hi]) if !lo.is_finite() || !hi.is_finite() => {
            Err(Error::NonFinite("twist limit"))
        }
        _ => angle_range(limit, "twist"),
    }
}

/// An angle range `[min, max]` (rad) within [-pi, pi], if set.
pub(crate) fn angle_range(limit: Option<[f32; 2]>, what: &'static str) -> Result<(), Error> {
    match limit {
        Some([lo, hi]) if !lo.is_finite() || !hi.is_finite() => Err(Error::NonFinite(what)),
        Some([lo, hi]) if !(-PI <= lo && lo <= hi && hi <= PI) => Err(Error::InvalidLimit(what)),
        _ => Ok(()),
    }
}

/// Two different live bodies, at least one dynamic: what a new joint or
/// rod needs.
pub(crate) fn joint_bodies(bodies: &BodyStore, a: BodyHandle, b: BodyHandle) -> Result<(), Error> {
    let [ka, kb] = joined_bodies(bodies, a, b)?;
    if ka != BodyKind::Dynamic && kb != BodyKind::Dynamic {
        return Err(Error::NoDynamicBody);
    }
    Ok(())
}

/// Two different live bodies, not both static (their kinds): what a joint
/// already in the world keeps. Its bodies may both have been made
/// kinematic since it was added (`World::set_body_kind`); it then moves
/// neither (the kernels give a pair of infinite masses no correction, as
/// they do padding lanes) until one is dynamic again.
pub(crate) fn joined_bodies(
    bodies: &BodyStore,
    a: BodyHandle,
    b: BodyHandle,
) -> Result<[BodyKind; 2], Error> {
    if a == b {
        return Err(Error::SameBody);
    }
    let kinds = [bodies.kind[bodies.index(a)?], bodies.kind[bodies.index(b)?]];
    if kinds == [BodyKind::Static; 2] {
        return Err(Error::NoDynamicBody);
    }
    Ok(kinds)
}

/// A joint's or contact's bodies as the colouring sees them: the slot of
/// each dynamic one (static and kinematic bodies are never written).
pub(crate) fn dynamic_bodies(bodies: &BodyStore, a: BodyHandle, b: BodyHandle) -> [Option<u32>; 2] {
    let dynamic =
        |h: BodyHandle| (bodies.kind[h.index()] == BodyKind::Dynamic).then_some(h.index() as u32);
    [dynamic(a), dynamic(b)]
}
