//! Impulses: an instant change of a dynamic body's momentum, as Jolt's
//! `Body::AddImpulse` and Rapier's `RigidBody::apply_impulse` make it.
//!
//! A linear impulse `J` (N s, world) through the centre of mass changes
//! the velocity by `J / m`; an angular impulse `L` (N m s, world) about the
//! centre of mass changes the angular velocity by `I_w^-1 L`, with the
//! world inverse inertia `I_w^-1 = R I^-1 R^T` at the body's orientation
//! `R` (the step turns torques into spin the same way). An impulse `J` at
//! a point `p` is both: `J` through the centre of mass `x`, and the angular
//! impulse `(p - x) x J`.

use glam::Vec3;
use vertebra_store::{BodyHandle, BodyKind, BodyStore, Error, check_finite};

use crate::integrate::limit;

/// Adds `linear` (N s) and `angular` (N m s, about the centre of mass),
/// both world frame, to a dynamic body's momentum, and holds the new
/// velocities to `max_speeds` (m/s, rad/s). Checked first, so a refusal
/// changes nothing: a stale or foreign handle, a static or kinematic body,
/// non-finite impulses, or velocity changes that overflow `f32`.
pub(crate) fn apply(
    bodies: &mut BodyStore,
    handle: BodyHandle,
    linear: Vec3,
    angular: Vec3,
    max_speeds: (f32, f32),
) -> Result<(), Error> {
    let i = bodies.index(handle)?;
    if bodies.kind[i] != BodyKind::Dynamic {
        return Err(Error::NotDynamic("an impulse"));
    }
    check_finite("impulse", linear)?;
    check_finite("angular impulse", angular)?;
    let q = bodies.orientation[i];
    let dv = linear * bodies.inverse_mass[i];
    let dw = q * (bodies.inverse_inertia[i] * (q.inverse() * angular));
    if !(dv.is_finite() && dw.is_finite()) {
        return Err(Error::OutOfRange(
            "impulse (its velocity change overflows f32)",
        ));
    }
    let (max_linear, max_angular) = max_speeds;
    bodies.linear_velocity[i] = limit(bodies.linear_velocity[i] + dv, max_linear);
    bodies.angular_velocity[i] = limit(bodies.angular_velocity[i] + dw, max_angular);
    Ok(())
}

/// The angular impulse (N m s, world, about the centre of mass) of an
/// impulse `linear` (N s, world) at the world `point` (m) on the body at
/// `handle`, checked: a finite impulse, a point within twice
/// `MAX_COORDINATE` (as `add_force_at` takes), and a finite product.
pub(crate) fn moment_at(
    bodies: &BodyStore,
    handle: BodyHandle,
    linear: Vec3,
    point: Vec3,
) -> Result<Vec3, Error> {
    let i = bodies.index(handle)?;
    check_finite("impulse", linear)?;
    vertebra_store::check_point("impulse point", point)?;
    let moment = (point - bodies.position[i]).cross(linear);
    check_finite("angular impulse of the impulse at the point", moment)?;
    Ok(moment)
}
