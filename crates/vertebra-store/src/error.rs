//! The one error type of the public API: every rejected call says what was
//! wrong with which input, and leaves the world as it was.

use core::fmt;
use vertebra_math::PortableQuat;

use crate::BodyHandle;

/// Why a call was rejected.
#[derive(Clone, Debug, PartialEq)]
pub enum Error {
    /// A value that must be finite was NaN or infinite.
    NonFinite(&'static str),
    /// A quaternion or direction that must have unit length did not
    /// (|length - 1| above 1e-3), or had length zero.
    NotNormalized(&'static str),
    /// A mass, density or dimension that must be positive was not.
    NonPositive(&'static str),
    /// An inertia tensor that is not symmetric positive definite.
    InvalidInertia,
    /// A shape with no volume (a zero radius or extent).
    DegenerateShape(&'static str),
    /// A joint, rod or contact between a body and itself.
    SameBody,
    /// A handle whose body or constraint was removed, or that never existed.
    StaleHandle(&'static str),
    /// A handle issued by another world (another lineage): refused rather
    /// than applied to whatever this world holds in the same slot. A world
    /// that restores a snapshot takes on the snapshot's lineage, so the
    /// handles of the world that took it work, and its own earlier ones
    /// become foreign.
    ForeignHandle(&'static str),
    /// A body that other constraints still reference.
    BodyInUse,
    /// A joint, rod or contact between two bodies neither of which is
    /// dynamic.
    NoDynamicBody,
    /// A call that only a dynamic body takes (an impulse), made on a
    /// static or kinematic one: their mass is infinite, so no impulse
    /// moves them (a kinematic body's velocity is set, not pushed).
    NotDynamic(&'static str),
    /// A call a body's kind does not take: a kind change to or from static,
    /// a kinematic body without mass made dynamic, a dynamic body moved as
    /// a kinematic one. The message names the field or the call first.
    WrongKind(&'static str),
    /// A limit range whose lower end is above its upper end, or outside
    /// the angle range it is measured in.
    InvalidLimit(&'static str),
    /// A solver setting out of its range.
    InvalidConfig(&'static str),
    /// A joint or rod setting it does not take: a drive on a fixed joint,
    /// other bodies for a rod in `set_rod` (a rod's bodies cannot change).
    InvalidJoint(&'static str),
    /// A finite value beyond what the solver can work with: a coordinate
    /// beyond [`MAX_COORDINATE`], a time step above [`MAX_TIME_STEP`].
    OutOfRange(&'static str),
    /// A snapshot written by an incompatible build: another snapshot
    /// format or another vertebra version.
    IncompatibleSnapshot(&'static str),
    /// A snapshot whose bytes are damaged, not a snapshot at all, or that
    /// decode to a state the API could never have produced; the message
    /// names the item (body, joint, contact, slot table) and the reason.
    CorruptSnapshot(String),
    /// A collider (of a collision layer such as `vertebra-collide`) that was
    /// refused, or whose body is no longer in the world.
    Collider {
        /// Its index in the collision set (the index it would have had, for
        /// one refused as it was added).
        index: usize,
        /// The body it is on.
        body: BodyHandle,
        /// Why.
        reason: Box<Error>,
    },
    /// A contact refused by the world's `set_contacts` or `swap_contacts`:
    /// the first in the list that is wrong, by its index in the list, and
    /// why.
    Contact {
        /// Its index in the list given.
        index: usize,
        /// Why.
        reason: Box<Error>,
    },
    /// A companion of a world (a collision set) used with, or restored for,
    /// a world it does not serve: one that restored a snapshot since the
    /// companion last served it (without the companion's own snapshot taken
    /// with it), another world, or a companion's snapshot taken with
    /// another state of the world (other bodies). The message says which
    /// and what to restore.
    WorldMismatch(&'static str),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::NonFinite(what) => write!(f, "{what} is not finite"),
            Error::NotNormalized(what) => write!(f, "{what} is not normalised"),
            Error::NonPositive(what) => write!(f, "{what} must be positive"),
            Error::InvalidInertia => write!(f, "inertia must be symmetric positive definite"),
            Error::DegenerateShape(why) => write!(f, "degenerate shape: {why}"),
            Error::SameBody => write!(f, "a joint, rod or contact needs two different bodies"),
            Error::StaleHandle(what) => write!(f, "stale or unknown {what} handle"),
            Error::ForeignHandle(what) => write!(f, "{what} handle of another world"),
            Error::BodyInUse => write!(
                f,
                "the body is still used by a joint; remove the joint first"
            ),
            Error::NoDynamicBody => {
                write!(f, "a joint, rod or contact needs at least one dynamic body")
            }
            Error::NotDynamic(what) => write!(
                f,
                "{what} needs a dynamic body (static and kinematic bodies have infinite mass)"
            ),
            Error::WrongKind(what) => write!(f, "{what}"),
            Error::InvalidLimit(what) => write!(f, "invalid {what} limit"),
            Error::InvalidConfig(what) => write!(f, "invalid solver setting: {what}"),
            Error::InvalidJoint(what) => write!(f, "invalid joint: {what}"),
            Error::OutOfRange(what) => write!(f, "{what} is out of range"),
            Error::IncompatibleSnapshot(why) => write!(f, "incompatible snapshot: {why}"),
            Error::CorruptSnapshot(why) => write!(f, "corrupt snapshot: {why}"),
            Error::Collider {
                index,
                body,
                reason,
            } => write!(f, "collider {index} on body {body:?}: {reason}"),
            Error::Contact { index, reason } => write!(f, "contact {index}: {reason}"),
            Error::WorldMismatch(why) => write!(f, "world mismatch: {why}"),
        }
    }
}

impl std::error::Error for Error {}

/// `Ok(())` if every component of `values` is finite.
pub(crate) fn finite(what: &'static str, values: &[f32]) -> Result<(), Error> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(Error::NonFinite(what))
    }
}

/// Checks a finite quaternion of unit length (within 1e-3).
pub fn check_unit_quat(what: &'static str, q: glam::Quat) -> Result<(), Error> {
    finite(what, &q.to_array())?;
    if (q.length_portable() - 1.0).abs() > 1e-3 {
        return Err(Error::NotNormalized(what));
    }
    Ok(())
}

/// Checks a finite vector.
pub fn check_finite(what: &'static str, v: glam::Vec3) -> Result<(), Error> {
    finite(what, &v.to_array())
}

/// The largest coordinate (m) a body's centre of mass or an anchor may
/// have; the step holds bodies inside it (the world's edge is a wall).
///
/// Motion is as precise anywhere inside as at the origin: bodies keep
/// their coordinates to double precision and the solver works on their
/// displacements since the step began (docs/robustness.md). What is given
/// or read as an `f32` coordinate resolves what an `f32` does there: a
/// pose set or read, a contact point from collision detection, 0.06 mm at
/// 1 km, 7.8 mm at 100 km, 6.25 cm at 1000 km.
pub const MAX_COORDINATE: f32 = 1.0e6;

/// The longest time step (s) a world takes in one call.
pub const MAX_TIME_STEP: f32 = 1.0;

/// The shortest time step (s) a world takes: velocities are derived by
/// dividing motion by the substep, and a subnormal step overflows them.
pub const MIN_TIME_STEP: f32 = 1.0e-6;

/// Checks a finite point within [`MAX_COORDINATE`] of the origin on every
/// axis.
pub fn check_coordinate(what: &'static str, v: glam::Vec3) -> Result<(), Error> {
    check_finite(what, v)?;
    if v.abs().max_element() > MAX_COORDINATE {
        return Err(Error::OutOfRange(what));
    }
    Ok(())
}

/// Checks a finite point on or near a body (a contact point, where a force
/// acts) within twice [`MAX_COORDINATE`] on every axis: a body held at the
/// world's edge keeps its contacts and forces.
pub fn check_point(what: &'static str, v: glam::Vec3) -> Result<(), Error> {
    check_finite(what, v)?;
    if v.abs().max_element() > 2.0 * MAX_COORDINATE {
        return Err(Error::OutOfRange(what));
    }
    Ok(())
}

/// Checks a finite direction of unit length (within 1e-3).
pub fn check_unit_vec(what: &'static str, v: glam::Vec3) -> Result<(), Error> {
    check_finite(what, v)?;
    if (v.length() - 1.0).abs() > 1e-3 {
        return Err(Error::NotNormalized(what));
    }
    Ok(())
}

/// Checks a finite, strictly positive scalar.
pub fn check_positive(what: &'static str, x: f32) -> Result<(), Error> {
    finite(what, &[x])?;
    if x > 0.0 {
        Ok(())
    } else {
        Err(Error::NonPositive(what))
    }
}
