//! Validation shared by every joint description.

use core::f32::consts::PI;

use vertebra_store::{BodyHandle, BodyKind, BodyStore, Error};

use crate::joint::LimitSoftness;

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

/// A limit's softness: a compliance finite and not negative.
pub(crate) fn softness(softness: LimitSoftness) -> Result<(), Error> {
    match softness {
        LimitSoftness::Compliance(c) if !c.is_finite() => Err(Error::NonFinite("limit compliance")),
        LimitSoftness::Compliance(c) if c < 0.0 => Err(Error::NonPositive("limit compliance")),
        _ => Ok(()),
    }
}

/// Two different live bodies, at least one dynamic.
pub(crate) fn joint_bodies(bodies: &BodyStore, a: BodyHandle, b: BodyHandle) -> Result<(), Error> {
    if a == b {
        return Err(Error::SameBody);
    }
    let ka = bodies.kind[bodies.index(a)?];
    let kb = bodies.kind[bodies.index(b)?];
    if ka != BodyKind::Dynamic && kb != BodyKind::Dynamic {
        return Err(Error::NoDynamicBody);
    }
    Ok(())
}

/// A joint's or contact's bodies as the colouring sees them: the slot of
/// each dynamic one (static and kinematic bodies are never written).
pub(crate) fn dynamic_bodies(bodies: &BodyStore, a: BodyHandle, b: BodyHandle) -> [Option<u32>; 2] {
    let dynamic =
        |h: BodyHandle| (bodies.kind[h.index()] == BodyKind::Dynamic).then_some(h.index() as u32);
    [dynamic(a), dynamic(b)]
}
