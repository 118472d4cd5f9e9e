//! Validation shared by every joint description.

use core::f32::consts::PI;

use glam::Vec3;
use vertebra_store::{BodyHandle, BodyKind, BodyStore, Error};

use crate::MAX_ANGULAR_SPEED_LIMIT;

use crate::drive::{MAX_DRIVE_DAMPING_RATIO, MAX_DRIVE_DAMPING_TIME, MIN_DRIVE_FREQUENCY};
use crate::joint::LimitSoftness;

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

/// A limit's softness: the drive's ranges, each error naming the limit's
/// field.
pub(crate) fn softness(softness: LimitSoftness) -> Result<(), Error> {
    let not_negative = |what, x: f32| {
        if !x.is_finite() {
            Err(Error::NonFinite(what))
        } else if x < 0.0 {
            Err(Error::NonPositive(what))
        } else {
            Ok(())
        }
    };
    match softness {
        LimitSoftness::Hard => Ok(()),
        LimitSoftness::Compliance {
            compliance,
            damping,
        } => {
            not_negative("limit compliance", compliance)?;
            not_negative("limit damping", damping)?;
            if compliance * damping > MAX_DRIVE_DAMPING_TIME {
                return Err(Error::OutOfRange(
                    "limit damping (compliance times damping at most 1e6 s)",
                ));
            }
            Ok(())
        }
        LimitSoftness::Spring {
            frequency,
            damping_ratio,
        } => {
            if frequency.is_nan() {
                return Err(Error::NonFinite("limit frequency"));
            }
            if frequency < MIN_DRIVE_FREQUENCY {
                return Err(Error::OutOfRange("limit frequency (at least 1e-3 Hz)"));
            }
            not_negative("limit damping ratio", damping_ratio)?;
            if damping_ratio > MAX_DRIVE_DAMPING_RATIO {
                return Err(Error::OutOfRange("limit damping ratio (at most 1e3)"));
            }
            Ok(())
        }
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
