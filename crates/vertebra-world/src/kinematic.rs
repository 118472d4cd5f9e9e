//! Kinematic bodies at run time: a body switched between dynamic and
//! kinematic (as Jolt's `SetMotionType`), and a kinematic body moved to a
//! pose over the next step with the velocities that take it there (as
//! Jolt's `MoveKinematic`).
//!
//! A kind change re-colours the body's joints and rods: the colouring sees
//! only dynamic bodies (static and kinematic rows are never written), so a
//! body made dynamic must take colours apart from its joints' others, and
//! one made kinematic frees them. Each of its constraints leaves the
//! colouring and comes back in key order, so the result depends only on
//! the sequence of calls, and whole worlds stay bit-identical across
//! backends and thread counts.

use glam::{Quat, Vec3};
use vertebra_math::DefaultFloatMode;
use vertebra_math::PortableQuat;
use vertebra_store::{
    BodyHandle, BodyKind, Error, MAX_TIME_STEP, MIN_TIME_STEP, check_coordinate, check_positive,
    check_unit_quat,
};

use crate::{World, checks, integrate, layout::ROD_KEY};

impl World {
    /// Switches a body between dynamic and kinematic at run time, as
    /// Jolt's `SetMotionType` (Jolt needs `mAllowDynamicOrKinematic` at
    /// creation; here every dynamic and kinematic body may switch). Its
    /// mass and inertia are kept, so a body made kinematic goes back to
    /// dynamic with its own mass; a body created kinematic can become
    /// dynamic if it was given a mass (`BodyDesc::with_mass`). Velocities
    /// are kept (m/s, rad/s, world): a body made kinematic moves on at its
    /// velocity until it is set ([`World::move_kinematic`],
    /// [`World::set_body_velocity`]), one made dynamic starts with its
    /// current velocity. Its joints and rods are re-coloured and laid out
    /// again at the next step; a joint whose bodies are both kinematic
    /// moves neither until one is dynamic again. The same kind again
    /// changes nothing. Refused with nothing changed
    /// ([`Error::WrongKind`], naming `kind`): a static body, a change to
    /// static (Jolt refuses both as well), a kinematic body without mass
    /// made dynamic; and a stale or foreign handle.
    pub fn set_body_kind(&mut self, handle: BodyHandle, kind: BodyKind) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        let before = self.bodies.kind[self.bodies.index(handle)?];
        self.bodies.set_kind(handle, kind)?;
        if before != kind {
            self.recolour(handle);
            self.rejoin(handle, before);
        }
        Ok(())
    }

    /// Takes every joint and rod at `body` out of the colouring and puts
    /// them back, in key order, over the bodies' kinds now.
    fn recolour(&mut self, body: BodyHandle) {
        let at = |a: BodyHandle, b: BodyHandle| a == body || b == body;
        let joints = self
            .joints()
            .filter(|(_, d)| at(d.body_a, d.body_b))
            .map(|(h, d)| (h.index() as u64, d.body_a, d.body_b));
        let rods = self
            .rods()
            .filter(|(_, d)| at(d.body_a, d.body_b))
            .map(|(h, d)| (h.index() as u64 + ROD_KEY, d.body_a, d.body_b));
        let keys: Vec<_> = joints.chain(rods).collect();
        if keys.is_empty() {
            return;
        }
        for &(key, ..) in &keys {
            self.colouring.remove(key);
        }
        for (key, a, b) in keys {
            self.colouring
                .add(key, checks::dynamic_bodies(&self.bodies, a, b));
        }
        self.layout_dirty = true;
    }

    /// Sets a kinematic body's velocities so that the next step, of `dt`
    /// seconds, ends with it at `position` (its centre of mass, m, world)
    /// and `orientation` (unit quaternion), as Jolt's
    /// `MoveKinematic(position, rotation, dt)`: linear velocity
    /// `(position - x) / dt` from its coordinate `x` in double precision,
    /// angular velocity `log(orientation q*) / dt` (the shorter way round).
    /// The step moves a kinematic body exactly by its velocities, so it
    /// arrives to float rounding, and everything jointed to it or resting
    /// on it sees it move at those velocities through the step (a
    /// teleport by [`World::set_body_pose`] would carry nothing along).
    /// The velocities stay after the step: call it every step with the
    /// next target (an animation's next pose), or set the velocity to zero
    /// to stop there. Refused with nothing changed: a dynamic or static
    /// body ([`Error::WrongKind`]), a non-finite or out-of-range position
    /// (beyond [`crate::MAX_COORDINATE`]), a non-unit orientation, a `dt`
    /// outside [`MIN_TIME_STEP`] to [`MAX_TIME_STEP`], and a move that
    /// needs more than the world's `max_linear_speed` or
    /// `max_angular_speed` (the step would hold the body to them, and it
    /// would not arrive).
    pub fn move_kinematic(
        &mut self,
        handle: BodyHandle,
        position: Vec3,
        orientation: Quat,
        dt: f32,
    ) -> Result<(), Error> {
        let (linear, angular) = self.kinematic_velocities(handle, position, orientation, dt)?;
        self.bodies.set_velocity(handle, linear, angular)?;
        self.wake_islands_of(handle);
        Ok(())
    }

    /// The linear (m/s) and angular (rad/s) velocities, world, that
    /// [`World::move_kinematic`] would set for the same arguments, or its
    /// refusal; changes nothing. A caller moving several bodies checks
    /// them all first, so that a refused one leaves every body (and every
    /// island's sleep) as it was.
    pub fn kinematic_velocities(
        &self,
        handle: BodyHandle,
        position: Vec3,
        orientation: Quat,
        dt: f32,
    ) -> Result<(Vec3, Vec3), Error> {
        let _mode = DefaultFloatMode::enter();
        let i = self.bodies.index(handle)?;
        if self.bodies.kind[i] != BodyKind::Kinematic {
            return Err(Error::WrongKind(
                "move_kinematic needs a kinematic body (switch it with World::set_body_kind)",
            ));
        }
        check_coordinate("position", position)?;
        check_unit_quat("orientation", orientation)?;
        check_positive("time step", dt)?;
        if !(MIN_TIME_STEP..=MAX_TIME_STEP).contains(&dt) {
            return Err(Error::OutOfRange("time step (1e-6 s to 1 s)"));
        }
        let travel = position.as_dvec3() - self.bodies.precise_position(i);
        let linear = (travel / f64::from(dt)).as_vec3();
        let angular = integrate::angular_velocity(
            orientation.normalize_portable(),
            self.bodies.orientation[i],
            dt,
        );
        let (max_linear, max_angular) =
            (self.config.max_linear_speed, self.config.max_angular_speed);
        if linear.length_squared() > max_linear * max_linear {
            return Err(Error::OutOfRange(
                "position (reaching it in dt needs more than max_linear_speed)",
            ));
        }
        if angular.length_squared() > max_angular * max_angular {
            return Err(Error::OutOfRange(
                "orientation (reaching it in dt needs more than max_angular_speed)",
            ));
        }
        Ok((linear, angular))
    }
}
