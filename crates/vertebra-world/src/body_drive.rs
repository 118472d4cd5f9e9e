//! Body drives: a dynamic body pulled toward a pose in the world (a
//! [`WorldDrive`], as Unreal's physical animation in world space and
//! Box3D's motor anchors) or one of its axes held near a world direction
//! (an [`UprightDrive`], as Box3D's parallel joint), each a damped spring
//! with a cap, with no kinematic body in between.
//!
//! Where they act. A body drive has one body, so it needs no block, lane or
//! colour: it is applied as the substep integrates the body's velocities,
//! after gravity and the body's forces (`integrate::predict`), on the
//! calling worker's chunk of bodies. The joints, rods and contacts then
//! solve from the driven velocities, so a driven body pulls its limb along
//! through its joints and a contact stops it as it would stop a pushed
//! body.
//!
//! The step. Each part is the XPBD soft constraint of `parts::drive`
//! (Macklin et al. 2016, eq. 26) on the body alone, one iteration from
//! `lambda = 0`, written as the velocity change it makes:
//!
//! `dlambda = -((1 + gamma) W + alpha~)^-1 (C + gamma (C - C_0))`
//!
//! with `C` the error after the body's predicted motion, `C_0` the error
//! as the substep begins (against the target then: a moving target's
//! `C - C_0` is the body's velocity relative to the target's), `W` the
//! body's inverse mass (linear) or world inverse inertia (angular),
//! `alpha~ = (compliance + period2 W) / h^2` and `gamma = damping_time /
//! h` (the [`Spring`] lane). The body turns or moves by `W dlambda`, added
//! to its velocity as `W dlambda / h`. For a spring given by frequency the
//! mass cancels: the error after the substep is
//! `C_1 (1 + 2 zeta omega h + (omega h)^2) = C~ + 2 zeta omega h C_0`, the
//! implicit Euler step of an oscillator at `f` with ratio `zeta` for the
//! body alone (a body pulled by its joints responds more slowly, as a
//! limb would to a hand on it). Rigid (`alpha = 0`) reaches the target in
//! one substep unless something holds the body back.
//!
//! The cap. `dlambda / h^2` is the force (N) or torque (N m) the part
//! exerts over the substep; where its length would pass the cap it is
//! scaled back onto it, so a capped drive never pushes harder than its cap
//! whatever the error (a ragdoll held by capped drives under its own
//! weight falls when it leans too far, as it should).
//!
//! The upright part. The error is the rotation vector of the shortest arc
//! from the world direction `up` to the body's axis; turning the body
//! about the axis changes nothing, so the part solves the two rows across
//! the axis (`(1 + gamma) W + alpha~` restricted to the plane across it).
//! Exactly upside down the arc has no axis and the part pushes across an
//! arbitrary one (a world direction across `up`).
//!
//! Targets. A target moves at its velocity through the step: substep `k`
//! of a step of substeps `h` aims at the target advanced by `(k + 1) h`,
//! measures `C_0` against it advanced by `k h`, and after the step the
//! description holds the target advanced by `n h` (a still target reads
//! back as given). A body whose target moves does not sleep.

use glam::{Mat3, Quat, Vec3};
use serde::{Deserialize, Serialize};
use vertebra_math::{DefaultFloatMode, PortableQuat};
use vertebra_store::{
    BodyHandle, BodyKind, BodyStore, Error, check_coordinate, check_finite, check_unit_quat,
};

use crate::islands::Link;
use crate::spring::{Spring, SpringField, SpringLane};
use crate::{MAX_LINEAR_SPEED_LIMIT, World, checks};

/// Pulls a dynamic body toward a pose in the world: its centre of mass
/// toward `position`, its orientation toward `orientation`, each part a
/// damped spring with a cap (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldDrive {
    /// The target for the body's centre of mass (m, world) as the next
    /// step begins; it moves at `linear_velocity`.
    pub position: Vec3,
    /// The target orientation (unit quaternion, world) as the next step
    /// begins; it turns at `angular_velocity`.
    pub orientation: Quat,
    /// The target's velocity (m/s, world).
    pub linear_velocity: Vec3,
    /// The target's angular velocity (rad/s, world).
    pub angular_velocity: Vec3,
    /// The position part's strength (its errors name the `world drive
    /// position`); `None` leaves the position free.
    pub linear: Option<Spring>,
    /// The orientation part's strength (`world drive orientation`); `None`
    /// leaves the orientation free.
    pub angular: Option<Spring>,
    /// The largest force the position part exerts (N, not negative);
    /// infinity is unlimited.
    pub max_force: f32,
    /// The largest torque the orientation part exerts (N m, not negative);
    /// infinity is unlimited.
    pub max_torque: f32,
}

impl WorldDrive {
    /// A drive toward a still pose with both parts at `strength` and no
    /// caps.
    pub fn new(position: Vec3, orientation: Quat, strength: Spring) -> Self {
        Self {
            position,
            orientation,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            linear: Some(strength),
            angular: Some(strength),
            max_force: f32::INFINITY,
            max_torque: f32::INFINITY,
        }
    }

    /// With caps: force (N) and torque (N m).
    pub fn with_caps(mut self, max_force: f32, max_torque: f32) -> Self {
        self.max_force = max_force;
        self.max_torque = max_torque;
        self
    }

    /// With the parts' strengths (`None` turns a part off).
    pub fn with_strengths(mut self, linear: Option<Spring>, angular: Option<Spring>) -> Self {
        self.linear = linear;
        self.angular = angular;
        self
    }

    /// Following an animation: the target is the pose `prev` as the next
    /// step begins and moves at constant velocities to reach `pose` when
    /// it ends, `dt` seconds later (the step's `dt`). Call it every frame
    /// with the body's pose in the animation's last two frames (centre of
    /// mass, m, and orientation, world).
    ///
    /// `Err` (naming the `following time step`) for a `dt` that is not
    /// finite or below [`MIN_TIME_STEP`](crate::MIN_TIME_STEP).
    pub fn following(
        mut self,
        prev: (Vec3, Quat),
        pose: (Vec3, Quat),
        dt: f32,
    ) -> Result<Self, Error> {
        checks::following_time_step(dt)?;
        let turn = vertebra_math::Quat::<f32>::from(pose.1.mul_portable(prev.1.conjugate()));
        self.position = prev.0;
        self.orientation = prev.1;
        self.linear_velocity = (pose.0 - prev.0) / dt;
        self.angular_velocity = Vec3::from(turn.to_rotation_vector()) / dt;
        Ok(self)
    }

    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), Error> {
        check_coordinate("world drive position", self.position)?;
        check_unit_quat("world drive orientation", self.orientation)?;
        check_finite("world drive linear velocity", self.linear_velocity)?;
        if self.linear_velocity.length() > MAX_LINEAR_SPEED_LIMIT {
            return Err(Error::OutOfRange(
                "world drive linear velocity (at most MAX_LINEAR_SPEED_LIMIT)",
            ));
        }
        checks::angular_velocity(
            self.angular_velocity,
            "world drive angular velocity",
            "world drive angular velocity (at most MAX_ANGULAR_SPEED_LIMIT)",
        )?;
        if let Some(s) = &self.linear {
            s.check(SpringField::WorldPosition)?;
        }
        if let Some(s) = &self.angular {
            s.check(SpringField::WorldOrientation)?;
        }
        cap("world drive max force", self.max_force)?;
        cap("world drive max torque", self.max_torque)
    }

    fn moves(&self) -> bool {
        self.linear_velocity != Vec3::ZERO || self.angular_velocity != Vec3::ZERO
    }
}

/// Holds one axis of a dynamic body near a world direction (a chest or
/// hips kept upright), as a damped spring across the axis with a torque
/// cap (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct UprightDrive {
    /// The body's axis (unit, body frame).
    pub axis: Vec3,
    /// The world direction it is held near (unit, world).
    pub up: Vec3,
    /// Stiffness and damping (its errors name the `upright drive`).
    pub strength: Spring,
    /// The largest torque (N m, not negative); infinity is unlimited.
    pub max_torque: f32,
}

impl UprightDrive {
    /// Holds `axis` (body frame) near `up` (world) at `strength`, without
    /// a cap.
    pub fn new(axis: Vec3, up: Vec3, strength: Spring) -> Self {
        Self {
            axis,
            up,
            strength,
            max_torque: f32::INFINITY,
        }
    }

    /// With a torque cap (N m).
    pub fn with_max_torque(mut self, max_torque: f32) -> Self {
        self.max_torque = max_torque;
        self
    }

    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), Error> {
        unit("upright drive axis", self.axis)?;
        unit("upright drive up", self.up)?;
        self.strength.check(SpringField::Upright)?;
        cap("upright drive max torque", self.max_torque)
    }
}

/// A cap: not NaN, not negative (infinity is none).
fn cap(what: &'static str, x: f32) -> Result<(), Error> {
    if x.is_nan() {
        return Err(Error::NonFinite(what));
    }
    if x < 0.0 {
        return Err(Error::NonPositive(what));
    }
    Ok(())
}

/// A unit vector (to 1e-4 in length).
fn unit(what: &'static str, v: Vec3) -> Result<(), Error> {
    check_finite(what, v)?;
    if (v.length() - 1.0).abs() > 1e-4 {
        return Err(Error::NotNormalized(what));
    }
    Ok(())
}

/// A body's drives, by body slot in the world.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct BodyDrives {
    pub world: Option<WorldDrive>,
    pub upright: Option<UprightDrive>,
}

impl BodyDrives {
    pub fn any(&self) -> bool {
        self.world.is_some() || self.upright.is_some()
    }

    /// Both drives checked; the error names the field.
    pub fn validate(&self) -> Result<(), Error> {
        if let Some(d) = &self.world {
            d.validate()?;
        }
        if let Some(d) = &self.upright {
            d.validate()?;
        }
        Ok(())
    }

    /// The targets advanced by `t` seconds (the step's `n h`); a still
    /// target is left as it is, bit for bit.
    pub fn advance(&mut self, t: f32) {
        if let Some(d) = self.world.as_mut().filter(|d| d.moves()) {
            d.position += d.linear_velocity * t;
            d.orientation = d.orientation.turned_portable(d.angular_velocity, t);
        }
    }

    /// The velocities `(v, w)` (m/s, rad/s, world) after this substep's
    /// drives, from those the body's forces left (the module
    /// documentation's step, world drive then upright drive).
    pub fn pull(&self, body: &Driven, clock: Clock, v: Vec3, w: Vec3) -> (Vec3, Vec3) {
        let (mut v, mut w) = (v, w);
        if let Some(d) = &self.world {
            if let Some(s) = &d.linear {
                v = pull_position(d, s.lane(), body, clock, v);
            }
            if let Some(s) = &d.angular {
                let arc = |q: Quat, t: f32| {
                    let target = d.orientation.turned_portable(d.angular_velocity, t);
                    rotation_vector(q.mul_portable(target.conjugate()))
                };
                let turn = Turn::measure(body, clock, w, arc);
                w = turn.pull(body, s.lane(), d.max_torque, clock.h, Rows::All);
            }
        }
        if let Some(u) = &self.upright {
            let arc = |q: Quat, _: f32| shortest_arc(u.up, q * u.axis);
            let turn = Turn::measure(body, clock, w, arc);
            w = turn.pull(
                body,
                u.strength.lane(),
                u.max_torque,
                clock.h,
                Rows::Across(u.axis),
            );
        }
        (v, w)
    }
}

/// The self-links of the bodies whose world drive's target moves: they
/// keep their island awake (`islands::Link`).
pub(crate) fn moving_links(drives: &[BodyDrives]) -> impl Iterator<Item = Link> + Clone + '_ {
    drives.iter().enumerate().filter_map(|(i, d)| {
        d.world.filter(WorldDrive::moves).map(|_| Link {
            a: i as u32,
            b: i as u32,
            moving: true,
        })
    })
}

/// A dynamic body as the substep begins, as its drives see it.
pub(crate) struct Driven {
    /// Its position as the step began (m, world).
    pub position: Vec3,
    /// Its displacement since the step began (m).
    pub displacement: Vec3,
    /// Its orientation (world).
    pub orientation: Quat,
    pub inverse_mass: f32,
    /// Inertia and its inverse (body frame).
    pub inertia: Mat3,
    pub inverse_inertia: Mat3,
}

/// Where the substep stands in its step: substep `k` of length `h` (s).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Clock {
    pub k: u32,
    pub h: f32,
}

impl Clock {
    /// Seconds since the step began, as the substep begins and ends.
    fn times(self) -> (f32, f32) {
        (self.k as f32 * self.h, (self.k + 1) as f32 * self.h)
    }
}

/// The position part: the body's velocity after it (m/s).
fn pull_position(d: &WorldDrive, s: SpringLane, body: &Driven, clock: Clock, v: Vec3) -> Vec3 {
    let (h, (t0, t1)) = (clock.h, clock.times());
    let base = (body.position - d.position) + body.displacement;
    let c0 = base - d.linear_velocity * t0;
    let c = (base + v * h) - d.linear_velocity * t1;
    let gamma = s.damping_time / h;
    let error = c + (c - c0) * gamma;
    let mass = 1.0 / body.inverse_mass;
    let soft = 1.0 + gamma + (s.period2 + s.compliance * mass) / (h * h);
    let impulse = capped(error * (-mass / soft), d.max_force * (h * h));
    v + impulse * (body.inverse_mass / h)
}

/// Which rows an angular part solves.
#[derive(Clone, Copy)]
enum Rows {
    /// All three: the whole orientation.
    All,
    /// The two across this axis (body frame).
    Across(Vec3),
}

/// An angular part's errors, body frame at the predicted orientation.
struct Turn {
    /// The body's angular velocity (rad/s, world) before the part.
    w: Vec3,
    /// The predicted orientation.
    predicted: Quat,
    /// `C + gamma (C - C_0)` waits for gamma: `C` and `C - C_0` (rad, body
    /// frame).
    error: Vec3,
    change: Vec3,
}

impl Turn {
    /// `arc(q, t)`: the error rotation vector (world) of orientation `q`
    /// against the target `t` seconds into the step.
    fn measure(body: &Driven, clock: Clock, w: Vec3, arc: impl Fn(Quat, f32) -> Vec3) -> Self {
        let (t0, t1) = clock.times();
        let predicted = body.orientation.turned_portable(w, clock.h);
        let c0 = arc(body.orientation, t0);
        let c = arc(predicted, t1);
        let back = predicted.conjugate();
        Self {
            w,
            predicted,
            error: back * c,
            change: back * (c - c0),
        }
    }

    /// The angular velocity after the part (rad/s, world).
    fn pull(&self, body: &Driven, s: SpringLane, max_torque: f32, h: f32, rows: Rows) -> Vec3 {
        let gamma = s.damping_time / h;
        let e = self.error + self.change * gamma;
        let scale = 1.0 + gamma + s.period2 / (h * h);
        // `(scale W + softness 1)^-1` as `(W + k 1)^-1 / scale`: the matrix
        // stays near `W` whatever the spring, `k` held finite (as the
        // kernels' `MAX_ALPHA`).
        let k = (s.compliance / (h * h) / scale).min(MAX_SOFTNESS);
        let w_body = body.inverse_inertia;
        let solved = match rows {
            Rows::All if k == 0.0 => body.inertia * e,
            Rows::All => (w_body + Mat3::from_diagonal(Vec3::splat(k))).inverse() * e,
            Rows::Across(axis) => {
                let (u, v) = axis.any_orthonormal_pair();
                let (su, sv) = (w_body * u, w_body * v);
                let (m00, m01, m11) = (u.dot(su) + k, u.dot(sv), v.dot(sv) + k);
                let (ru, rv) = (u.dot(e), v.dot(e));
                let det = m00 * m11 - m01 * m01;
                let (mu, mv) = ((m11 * ru - m01 * rv) / det, (m00 * rv - m01 * ru) / det);
                u * mu + v * mv
            }
        };
        let lambda = capped(solved * (-1.0 / scale), max_torque * (h * h));
        self.w + self.predicted * (w_body * lambda) / h
    }
}

/// The largest softness `compliance / (h^2 scale)` (1 / (kg m^2), beside
/// the inverse inertia) an angular part solves with: the 3x3 inverse's
/// cofactors stay finite for the largest inverse inertias a shape can
/// have, and the correction there is a millionth of the error or less.
const MAX_SOFTNESS: f32 = 1e12;

/// `lambda` shortened onto the sphere of radius `max` when longer.
fn capped(lambda: Vec3, max: f32) -> Vec3 {
    let length2 = lambda.length_squared();
    if length2 > max * max {
        lambda * (max / length2.sqrt())
    } else {
        lambda
    }
}

/// A unit quaternion's rotation vector (rad), shortest arc, by the math
/// layer's polynomials (the same bits on every platform).
fn rotation_vector(q: Quat) -> Vec3 {
    Vec3::from(vertebra_math::Quat::<f32>::from(q).to_rotation_vector())
}

/// The rotation vector (rad, world) of the shortest arc from `from` to
/// `to` (unit vectors); exactly opposite, a half turn about a direction
/// across `from`.
/// (`PortableQuat::from_rotation_arc_portable` is the identity within
/// 7e-4 rad of `from`: a dead zone here.)
fn shortest_arc(from: Vec3, to: Vec3) -> Vec3 {
    let half = 1.0 + from.dot(to);
    if half <= 1e-6 {
        return from.any_orthonormal_vector() * core::f32::consts::PI;
    }
    let q = vertebra_math::Quat::<f32>::from_parts(from.cross(to).into(), half);
    Vec3::from(q.normalize().to_rotation_vector())
}

impl World {
    /// Sets or clears `body`'s world drive (see [`WorldDrive`]), waking its
    /// island. Refused, with nothing changed, for a stale or foreign
    /// handle, a body that is not dynamic, or a drive whose field is out of
    /// range (the error names it). A body made kinematic or static later
    /// keeps its drives; they act while it is dynamic.
    pub fn set_world_drive(
        &mut self,
        body: BodyHandle,
        drive: Option<WorldDrive>,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        let checked = drive.as_ref().map_or(Ok(()), WorldDrive::validate);
        self.set_body_drives(body, checked, |d| d.world = drive)
    }

    /// `body`'s world drive (its target as the next step begins).
    pub fn world_drive(&self, body: BodyHandle) -> Result<Option<WorldDrive>, Error> {
        let i = self.bodies.index(body)?;
        Ok(self.body_drives.get(i).and_then(|d| d.world))
    }

    /// Sets or clears `body`'s upright drive (see [`UprightDrive`]), as
    /// [`World::set_world_drive`] does a world drive.
    pub fn set_upright_drive(
        &mut self,
        body: BodyHandle,
        drive: Option<UprightDrive>,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        let checked = drive.as_ref().map_or(Ok(()), UprightDrive::validate);
        self.set_body_drives(body, checked, |d| d.upright = drive)
    }

    /// `body`'s upright drive.
    pub fn upright_drive(&self, body: BodyHandle) -> Result<Option<UprightDrive>, Error> {
        let i = self.bodies.index(body)?;
        Ok(self.body_drives.get(i).and_then(|d| d.upright))
    }

    /// Changes a live dynamic `body`'s drives by `change`, once the new
    /// drive has passed its check (`checked`), and wakes its island; else
    /// the refusal, nothing changed.
    fn set_body_drives(
        &mut self,
        body: BodyHandle,
        checked: Result<(), Error>,
        change: impl FnOnce(&mut BodyDrives),
    ) -> Result<(), Error> {
        let i = self.bodies.index(body)?;
        if self.bodies.kind[i] != BodyKind::Dynamic {
            return Err(Error::NotDynamic("a driven body"));
        }
        checked?;
        if self.body_drives.len() <= i {
            self.body_drives.resize(i + 1, BodyDrives::default());
        }
        change(&mut self.body_drives[i]);
        trim(&mut self.body_drives);
        self.wake_islands_of(body);
        Ok(())
    }

    /// Clears slot `i`'s drives (its body is gone).
    pub(crate) fn clear_body_drives(&mut self, i: usize) {
        if let Some(d) = self.body_drives.get_mut(i) {
            *d = BodyDrives::default();
            trim(&mut self.body_drives);
        }
    }
}

/// Drops the undriven slots at the end: the list is as long as its last
/// driven slot, so equal worlds hold equal lists.
fn trim(drives: &mut Vec<BodyDrives>) {
    while drives.last().is_some_and(|d| !d.any()) {
        drives.pop();
    }
}

/// A snapshot's drives, as the API leaves them: no longer than its last
/// driven slot, every drive on a live body and in range; the error names
/// the body.
pub(crate) fn validate_all(drives: &[BodyDrives], bodies: &BodyStore) -> Result<(), String> {
    if drives.last().is_some_and(|d| !d.any()) {
        return Err("body drives: the list ends in an undriven slot".into());
    }
    for (i, d) in drives.iter().enumerate() {
        if !d.any() {
            continue;
        }
        if i >= bodies.capacity() || !bodies.is_live(i) {
            return Err(format!("body {i}: drives on no live body"));
        }
        d.validate().map_err(|e| format!("body {i}: {e}"))?;
    }
    Ok(())
}
