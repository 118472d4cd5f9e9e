//! The angular drive: how a socket's body b is turned toward a target
//! orientation relative to body a, and its validation.

use glam::Quat;
use vertebra_store::{Error, check_unit_quat};

/// Drives a socket's body b toward an orientation relative to body a.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AngularDrive {
    /// b's joint frame relative to a's joint frame (unit quaternion).
    pub target: Quat,
    /// Compliance (rad / (N m)), the inverse of stiffness; 0 is infinitely
    /// stiff. Independent of the time step and iteration count (XPBD).
    pub compliance: f32,
    /// Damping rate (1/s) of the relative angular velocity.
    pub damping: f32,
}

/// Checks a drive's target, compliance and damping.
pub(crate) fn validate_drive(d: &AngularDrive) -> Result<(), Error> {
    check_unit_quat("drive target", d.target)?;
    for (what, x) in [
        ("drive compliance", d.compliance),
        ("drive damping", d.damping),
    ] {
        if !x.is_finite() {
            return Err(Error::NonFinite(what));
        }
        if x < 0.0 {
            return Err(Error::NonPositive(what));
        }
    }
    Ok(())
}
