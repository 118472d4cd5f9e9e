//! The body passes of a substep (XPBD for rigid bodies, Müller et al.
//! 2020, algorithm 2): predict (integrate velocities and poses), derive
//! velocities from the solved motion, take back the velocity pass's
//! results, damp, and repair a body whose motion is no longer finite;
//! each over one chunk of bodies.

use glam::{Quat, Vec3};
use vertebra_kernels::body::BodyRows;
use vertebra_math::PortableQuat;
use vertebra_store::{BodyKind, BodyStore};

use crate::body_drive::{BodyDrives, Clock, Driven};
use crate::islands::Islands;

/// One chunk of bodies (slots `start..`): what the body passes write.
pub(crate) struct BodyChunk<'a> {
    pub start: usize,
    pub linear_velocity: &'a mut [Vec3],
    pub angular_velocity: &'a mut [Vec3],
    pub orientation: &'a mut [Quat],
    pub previous: &'a mut [(Vec3, Quat)],
}

/// What the body passes read: the bodies' other arrays, by slot, and the
/// world's settings.
pub(crate) struct BodyRead<'a> {
    pub moving: &'a [bool],
    pub kind: &'a [BodyKind],
    pub position: &'a [Vec3],
    pub inverse_mass: &'a [f32],
    pub inertia: &'a [glam::Mat3],
    pub inverse_inertia: &'a [glam::Mat3],
    pub force: &'a [Vec3],
    pub torque: &'a [Vec3],
    pub linear_damping: &'a [f32],
    pub angular_damping: &'a [f32],
    /// The bodies' drives by slot (empty when no body has one).
    pub drives: &'a [BodyDrives],
    pub gravity: Vec3,
    pub max_linear_speed: f32,
    pub max_angular_speed: f32,
}

/// Which slots the body passes move: live, not static, not asleep.
pub(crate) fn mark_moving(b: &BodyStore, islands: &Islands, moving: &mut Vec<bool>) {
    moving.clear();
    moving.extend(
        (0..b.capacity())
            .map(|i| b.is_live(i) && b.kind[i] != BodyKind::Static && !islands.is_asleep(i)),
    );
}

/// Integration of velocities (gravity, forces, the implicit gyroscopic
/// term in the body frame, then the body's drives, `body_drive.rs`) and of
/// the rows' displacements and orientations, for one chunk of bodies in
/// substep `clock`; the previous ones are kept for deriving velocities
/// afterwards.
pub(crate) fn predict(c: &mut BodyChunk, b: &BodyRead, rows: &BodyRows, clock: Clock) {
    let h = clock.h;
    let (max_linear, max_angular) = (b.max_linear_speed, b.max_angular_speed);
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        if !b.moving[i] {
            continue;
        }
        // The speed limits, before and after the forces: huge but finite
        // velocities or forces would overflow `|w|^2` in the exponential map
        // (or `w x I w`) and poison the world.
        let w = limit(c.angular_velocity[j], max_angular);
        if b.kind[i] == BodyKind::Dynamic {
            let v = c.linear_velocity[j] + (b.gravity + b.force[i] * b.inverse_mass[i]) * h;
            c.linear_velocity[j] = limit(v, max_linear);
            let q = c.orientation[j];
            let w_body = gyroscopic(q.inverse() * w, b.inertia[i], h);
            let torque_body = q.inverse() * b.torque[i];
            let w_body = limit(w_body + b.inverse_inertia[i] * torque_body * h, max_angular);
            c.angular_velocity[j] = q * w_body;
            if let Some(drives) = b.drives.get(i).filter(|d| d.any()) {
                let (displacement, orientation) = pose(rows, i);
                let body = Driven {
                    position: b.position[i],
                    displacement,
                    orientation,
                    inverse_mass: b.inverse_mass[i],
                    inertia: b.inertia[i],
                    inverse_inertia: b.inverse_inertia[i],
                };
                let (v, w) = drives.pull(&body, clock, c.linear_velocity[j], c.angular_velocity[j]);
                c.linear_velocity[j] = limit(v, max_linear);
                c.angular_velocity[j] = limit(w, max_angular);
            }
        } else {
            c.linear_velocity[j] = limit(c.linear_velocity[j], max_linear);
            c.angular_velocity[j] = w;
        }
        let (displacement, orientation) = pose(rows, i);
        c.previous[j] = (displacement, orientation);
        rows.pose[i + 1].set(BodyRows::pose_row(
            displacement + c.linear_velocity[j] * h,
            b.inverse_mass[i],
            orientation.turned_portable(c.angular_velocity[j], h),
        ));
    }
}

/// Derives velocities from the solved motion: `v = (d - d0) / h` from the
/// displacements since the step began (exact to the precision of the
/// motion, wherever the body is), `w = log(q q0*) / h` (shortest arc);
/// both held to the speed limits, which a hard correction can exceed.
pub(crate) fn derive_velocities(c: &mut BodyChunk, b: &BodyRead, rows: &BodyRows, h: f32) {
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        if !b.moving[i] || b.kind[i] != BodyKind::Dynamic {
            continue;
        }
        let (d, q) = pose(rows, i);
        let (d0, q0) = c.previous[j];
        c.orientation[j] = q;
        c.linear_velocity[j] = limit((d - d0) / h, b.max_linear_speed);
        c.angular_velocity[j] = limit(angular_velocity(q, q0, h), b.max_angular_speed);
        rows.velocity[i + 1].set(BodyRows::velocity_row(
            c.linear_velocity[j],
            c.angular_velocity[j],
        ));
    }
}

/// The velocity pass's results, held to the speed limits, back to the
/// bodies.
pub(crate) fn read_velocities(c: &mut BodyChunk, b: &BodyRead, rows: &BodyRows) {
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        if b.moving[i] && b.kind[i] == BodyKind::Dynamic {
            let [vx, vy, vz, _, wx, wy, wz, _] = rows.velocity[i + 1].get();
            c.linear_velocity[j] = limit(Vec3::new(vx, vy, vz), b.max_linear_speed);
            c.angular_velocity[j] = limit(Vec3::new(wx, wy, wz), b.max_angular_speed);
        }
    }
}

/// Linear and angular damping: `v /= 1 + h c`.
pub(crate) fn damp(c: &mut BodyChunk, b: &BodyRead, h: f32) {
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        if b.moving[i] && b.kind[i] == BodyKind::Dynamic {
            c.linear_velocity[j] /= 1.0 + h * b.linear_damping[i];
            c.angular_velocity[j] /= 1.0 + h * b.angular_damping[i];
        }
    }
}

/// The last line of defence: a body whose motion is no longer finite goes
/// back to its pose before the substep, at rest, and is counted. Validated
/// input keeps every body finite: it never fired in any test, scene or in
/// 390,000 fuzzed call sequences run with it made to panic
/// (docs/robustness.md). It stays so that a case nobody found yet costs a
/// body a substep, not the world.
pub(crate) fn repair(c: &mut BodyChunk, b: &BodyRead, rows: &BodyRows) -> u64 {
    let mut repaired = 0;
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        let (displacement, orientation) = c.previous[j];
        let (d, q) = pose(rows, i);
        let finite = b.position[i].is_finite()
            && c.orientation[j].is_finite()
            && c.linear_velocity[j].is_finite()
            && c.angular_velocity[j].is_finite()
            && d.is_finite()
            && q.is_finite();
        if b.moving[i] && !finite {
            c.orientation[j] = orientation;
            c.linear_velocity[j] = Vec3::ZERO;
            c.angular_velocity[j] = Vec3::ZERO;
            rows.pose[i + 1].set(BodyRows::pose_row(
                displacement,
                b.inverse_mass[i],
                orientation,
            ));
            repaired += 1;
        }
    }
    repaired
}

/// A body's displacement since the step began and its orientation, as the
/// rows hold them.
pub(crate) fn pose(rows: &BodyRows, i: usize) -> (Vec3, Quat) {
    let [px, py, pz, _, qx, qy, qz, qw] = rows.pose[i + 1].get();
    (Vec3::new(px, py, pz), Quat::from_xyzw(qx, qy, qz, qw))
}

/// Holds every moving body's velocities to the speed limits, as the step
/// begins: the contacts measure their approach speed from them before any
/// substep has held them (an accepted spin of 1e38 rad/s overflowed
/// `w x r` there and turned both bodies NaN).
pub(crate) fn hold_speeds(b: &mut BodyStore, islands: &Islands, max_linear: f32, max_angular: f32) {
    for i in 0..b.capacity() {
        if b.is_live(i) && b.kind[i] != BodyKind::Static && !islands.is_asleep(i) {
            b.linear_velocity[i] = limit(b.linear_velocity[i], max_linear);
            b.angular_velocity[i] = limit(b.angular_velocity[i], max_angular);
        }
    }
}

/// `v` shortened to at most `max` (`v` itself when it is no longer), and
/// finite even when a component overflowed to infinity.
pub(crate) fn limit(v: Vec3, max: f32) -> Vec3 {
    if v.length_squared() <= max * max {
        return v;
    }
    let v = v.clamp(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
    let scaled = v / v.abs().max_element();
    scaled.normalize() * max
}

/// The gyroscopic term, implicitly: `I (w' - w) + h w' x I w' = 0` in the
/// body frame, solved by one Newton step from `w` (as Bullet's implicit
/// gyroscopic body solver). The explicit term `-h I^-1 (w x I w)` gains
/// energy and lets the angular momentum drift; this does not blow up.
fn gyroscopic(w: Vec3, inertia: glam::Mat3, h: f32) -> Vec3 {
    let skew = |v: Vec3| {
        glam::Mat3::from_cols(
            Vec3::new(0.0, v.z, -v.y),
            Vec3::new(-v.z, 0.0, v.x),
            Vec3::new(v.y, -v.x, 0.0),
        )
    };
    let residual = w.cross(inertia * w) * h;
    let jacobian = inertia + (skew(w) * inertia - skew(inertia * w)) * h;
    let turned = w - jacobian.inverse() * residual;
    // A singular Jacobian, or an inertia so large the product overflowed:
    // no gyroscopic correction this substep.
    if jacobian.determinant().abs() > f32::MIN_POSITIVE && turned.is_finite() {
        turned
    } else {
        w
    }
}

/// The angular velocity that turns `q0` into `q` in `h` seconds, exactly
/// (the inverse of `PortableQuat::turned_portable`): `log(q q0*) / h`,
/// shortest arc.
pub(crate) fn angular_velocity(q: Quat, q0: Quat, h: f32) -> Vec3 {
    let turn = vertebra_math::Quat::<f32>::from(vertebra_math::PortableQuat::mul_portable(
        q,
        q0.conjugate(),
    ));
    Vec3::from(turn.to_rotation_vector()) / h
}
