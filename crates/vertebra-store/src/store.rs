//! The structure-of-arrays body store: one array per quantity, indexed by
//! the body handle's slot.

use glam::{DVec3, Mat3, Quat, Vec3};

use crate::error::{
    Error, MAX_COORDINATE, check_coordinate, check_finite, check_point, check_unit_quat,
};
use crate::handle::{Handle, Slots};
use crate::shape::MassProperties;

/// Marker for body handles.
#[derive(Debug)]
pub enum BodyTag {}

/// A stable reference to a body.
pub type BodyHandle = Handle<BodyTag>;

/// How a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum BodyKind {
    /// Moved by gravity, forces and constraints.
    Dynamic,
    /// Moved only by its own velocity, which the caller sets; infinite mass.
    Kinematic,
    /// Never moves; infinite mass.
    Static,
}

/// Everything needed to create a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyDesc {
    /// How the body moves.
    pub kind: BodyKind,
    /// Centre of mass, world frame (m).
    pub position: Vec3,
    /// Orientation of the body frame in the world (unit quaternion).
    pub orientation: Quat,
    /// Velocity of the centre of mass, world frame (m/s).
    pub linear_velocity: Vec3,
    /// Angular velocity, world frame (rad/s).
    pub angular_velocity: Vec3,
    /// Mass and inertia; required for dynamic bodies, ignored otherwise.
    pub mass: Option<MassProperties>,
    /// Linear damping rate (1/s): velocity scales by 1 / (1 + h c) per
    /// substep of h seconds.
    pub linear_damping: f32,
    /// Angular damping rate (1/s), as `linear_damping`.
    pub angular_damping: f32,
}

impl BodyDesc {
    /// A dynamic body at the origin, at rest, with the given mass properties.
    pub fn dynamic(mass: MassProperties) -> Self {
        Self {
            mass: Some(mass),
            ..Self::of_kind(BodyKind::Dynamic)
        }
    }

    /// A kinematic body at the origin, at rest.
    pub fn kinematic() -> Self {
        Self::of_kind(BodyKind::Kinematic)
    }

    /// A static body at the origin.
    pub fn fixed() -> Self {
        Self::of_kind(BodyKind::Static)
    }

    fn of_kind(kind: BodyKind) -> Self {
        Self {
            kind,
            position: Vec3::ZERO,
            orientation: Quat::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            mass: None,
            linear_damping: 0.0,
            angular_damping: 0.0,
        }
    }

    /// With the centre of mass at `position` (m, world).
    pub fn with_position(mut self, position: Vec3) -> Self {
        self.position = position;
        self
    }

    /// With the given orientation.
    pub fn with_orientation(mut self, orientation: Quat) -> Self {
        self.orientation = orientation;
        self
    }

    /// With the given linear (m/s) and angular (rad/s) velocities, world frame.
    pub fn with_velocity(mut self, linear: Vec3, angular: Vec3) -> Self {
        self.linear_velocity = linear;
        self.angular_velocity = angular;
        self
    }

    /// With linear and angular damping rates (1/s).
    pub fn with_damping(mut self, linear: f32, angular: f32) -> Self {
        self.linear_damping = linear;
        self.angular_damping = angular;
        self
    }

    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), Error> {
        check_coordinate("position", self.position)?;
        check_unit_quat("orientation", self.orientation)?;
        check_finite("linear velocity", self.linear_velocity)?;
        check_finite("angular velocity", self.angular_velocity)?;
        for (what, d) in [
            ("linear damping", self.linear_damping),
            ("angular damping", self.angular_damping),
        ] {
            if !d.is_finite() {
                return Err(Error::NonFinite(what));
            }
            if d < 0.0 {
                return Err(Error::NonPositive(what));
            }
        }
        match (self.kind, self.mass) {
            (BodyKind::Dynamic, Some(m)) => m.validate(),
            (BodyKind::Dynamic, None) => Err(Error::NonPositive("mass")),
            _ => Ok(()),
        }
    }
}

/// Position, orientation and velocities of a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState {
    /// Centre of mass, world frame (m).
    pub position: Vec3,
    /// Orientation (unit quaternion).
    pub orientation: Quat,
    /// Velocity of the centre of mass, world frame (m/s).
    pub linear_velocity: Vec3,
    /// Angular velocity, world frame (rad/s).
    pub angular_velocity: Vec3,
}

/// Bodies as structure of arrays. Index `i` of every array belongs to the
/// body whose handle has slot `i`; freed slots keep stale data until reused.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct BodyStore {
    slots: Slots,
    /// How each body moves.
    pub kind: Vec<BodyKind>,
    /// Centres of mass (m, world): the `f32` nearest to each body's
    /// coordinate, which the step keeps to double precision (see
    /// [`BodyStore::precise_position`]).
    pub position: Vec<Vec3>,
    /// What each coordinate has beyond its `f32` (m): `position +
    /// position_low` is the body's coordinate. A body moving 3 mm per step
    /// at x = 100 km, where an `f32` resolves 7.8 mm, moves here until the
    /// sum carries into `position`.
    position_low: Vec<Vec3>,
    /// Orientations.
    pub orientation: Vec<Quat>,
    /// Linear velocities (m/s, world).
    pub linear_velocity: Vec<Vec3>,
    /// Angular velocities (rad/s, world).
    pub angular_velocity: Vec<Vec3>,
    /// Masses (kg); 0 for kinematic and static bodies.
    pub mass: Vec<f32>,
    /// Inverse masses (1/kg); 0 for kinematic and static bodies.
    pub inverse_mass: Vec<f32>,
    /// Inertia tensors (kg m^2, body frame); zero for infinite mass.
    pub inertia: Vec<Mat3>,
    /// Inverse inertia tensors (body frame); zero for infinite mass.
    pub inverse_inertia: Vec<Mat3>,
    /// Force accumulated for the next step (N, world), cleared by the step.
    pub force: Vec<Vec3>,
    /// Torque accumulated for the next step (N m, world), cleared by the step.
    pub torque: Vec<Vec3>,
    /// Linear damping rates (1/s).
    pub linear_damping: Vec<f32>,
    /// Angular damping rates (1/s).
    pub angular_damping: Vec<f32>,
}

impl BodyStore {
    /// Whether slot `i`'s position, orientation and velocities are all
    /// finite (stale slots included: they hold the last values written).
    pub fn is_finite(&self, i: usize) -> bool {
        self.position[i].is_finite()
            && self.orientation[i].is_finite()
            && self.linear_velocity[i].is_finite()
            && self.angular_velocity[i].is_finite()
    }

    /// Whether every array has one entry per slot (a decoded snapshot is
    /// checked with this before it is used).
    pub fn is_consistent(&self) -> bool {
        let n = self.slots.capacity();
        [
            self.kind.len(),
            self.position.len(),
            self.position_low.len(),
            self.orientation.len(),
            self.linear_velocity.len(),
            self.angular_velocity.len(),
            self.mass.len(),
            self.inverse_mass.len(),
            self.inertia.len(),
            self.inverse_inertia.len(),
            self.force.len(),
            self.torque.len(),
            self.linear_damping.len(),
            self.angular_damping.len(),
        ]
        .iter()
        .all(|&len| len == n)
            && self.slots.is_consistent()
    }

    /// Adds a body after validating `desc`; nothing changes on error.
    pub fn insert(&mut self, desc: &BodyDesc) -> Result<BodyHandle, Error> {
        desc.validate()?;
        let handle: BodyHandle = self.slots.insert();
        let i = handle.index();
        if i == self.kind.len() {
            self.grow();
        }
        let (mass, inertia) = match (desc.kind, desc.mass) {
            (BodyKind::Dynamic, Some(m)) => (m.mass, m.inertia),
            _ => (0.0, Mat3::ZERO),
        };
        let dynamic = desc.kind == BodyKind::Dynamic;
        let (velocity, spin) = match desc.kind {
            BodyKind::Static => (Vec3::ZERO, Vec3::ZERO),
            _ => (desc.linear_velocity, desc.angular_velocity),
        };
        self.kind[i] = desc.kind;
        self.position[i] = desc.position;
        self.position_low[i] = Vec3::ZERO;
        self.orientation[i] = desc.orientation.normalize();
        self.linear_velocity[i] = velocity;
        self.angular_velocity[i] = spin;
        self.mass[i] = mass;
        self.inverse_mass[i] = if dynamic { 1.0 / mass } else { 0.0 };
        self.inertia[i] = inertia;
        self.inverse_inertia[i] = if dynamic {
            inertia.inverse()
        } else {
            Mat3::ZERO
        };
        self.force[i] = Vec3::ZERO;
        self.torque[i] = Vec3::ZERO;
        self.linear_damping[i] = desc.linear_damping;
        self.angular_damping[i] = desc.angular_damping;
        Ok(handle)
    }

    fn grow(&mut self) {
        self.kind.push(BodyKind::Static);
        self.position.push(Vec3::ZERO);
        self.position_low.push(Vec3::ZERO);
        self.orientation.push(Quat::IDENTITY);
        self.linear_velocity.push(Vec3::ZERO);
        self.angular_velocity.push(Vec3::ZERO);
        self.mass.push(0.0);
        self.inverse_mass.push(0.0);
        self.inertia.push(Mat3::ZERO);
        self.inverse_inertia.push(Mat3::ZERO);
        self.force.push(Vec3::ZERO);
        self.torque.push(Vec3::ZERO);
        self.linear_damping.push(0.0);
        self.angular_damping.push(0.0);
    }

    /// Removes a body; `StaleHandle` if it was already gone.
    pub fn remove(&mut self, handle: BodyHandle) -> Result<(), Error> {
        if self.slots.remove(handle) {
            Ok(())
        } else {
            Err(Error::StaleHandle("body"))
        }
    }

    /// `Ok(slot index)` for a live handle.
    pub fn index(&self, handle: BodyHandle) -> Result<usize, Error> {
        if self.slots.contains(handle) {
            Ok(handle.index())
        } else {
            Err(Error::StaleHandle("body"))
        }
    }

    /// Whether `handle` names a live body.
    pub fn contains(&self, handle: BodyHandle) -> bool {
        self.slots.contains(handle)
    }

    /// The live body at slot `index`, if any.
    pub fn handle_at(&self, index: usize) -> Option<BodyHandle> {
        self.slots.handle_at(index)
    }

    /// Slots ever allocated; arrays have this length.
    pub fn capacity(&self) -> usize {
        self.kind.len()
    }

    /// Live bodies.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// No live bodies.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Whether slot `index` holds a live body.
    pub fn is_live(&self, index: usize) -> bool {
        self.slots.is_live(index)
    }

    /// The state of a body.
    pub fn state(&self, handle: BodyHandle) -> Result<BodyState, Error> {
        let i = self.index(handle)?;
        Ok(BodyState {
            position: self.position[i],
            orientation: self.orientation[i],
            linear_velocity: self.linear_velocity[i],
            angular_velocity: self.angular_velocity[i],
        })
    }

    /// Teleports a body (centre of mass in m, world; unit orientation).
    pub fn set_pose(
        &mut self,
        handle: BodyHandle,
        position: Vec3,
        orientation: Quat,
    ) -> Result<(), Error> {
        let i = self.index(handle)?;
        check_coordinate("position", position)?;
        check_unit_quat("orientation", orientation)?;
        self.position[i] = position;
        self.position_low[i] = Vec3::ZERO;
        self.orientation[i] = orientation.normalize();
        Ok(())
    }

    /// Slot `i`'s centre of mass in double precision (m, world): the
    /// coordinate the step integrates, of which `position[i]` is the
    /// nearest `f32`.
    pub fn precise_position(&self, i: usize) -> DVec3 {
        self.position[i].as_dvec3() + self.position_low[i].as_dvec3()
    }

    /// The low parts of every coordinate (m), in slot order: for hashing
    /// and checking the full state.
    pub fn position_low(&self) -> &[Vec3] {
        &self.position_low
    }

    /// Moves slot `i` by `displacement` (m, world), in double precision,
    /// and keeps it inside the world: a coordinate beyond
    /// [`MAX_COORDINATE`] is held at it, and the velocity that carried it
    /// out is stopped on that axis (the world's edge is a wall, so a body
    /// there keeps a pose and contacts the API accepts).
    pub fn displace(&mut self, i: usize, displacement: Vec3) {
        let moved = self.precise_position(i) + displacement.as_dvec3();
        let edge = f64::from(MAX_COORDINATE);
        let inside = moved.clamp(DVec3::splat(-edge), DVec3::splat(edge));
        let held = moved.cmpne(inside);
        let v = self.linear_velocity[i];
        let outward = held & (v.as_dvec3() * (moved - inside)).cmpgt(DVec3::ZERO);
        self.linear_velocity[i] = Vec3::select(outward, Vec3::ZERO, v);
        let high = inside.as_vec3();
        self.position[i] = high;
        self.position_low[i] = (inside - high.as_dvec3()).as_vec3();
    }

    /// Sets a body's velocities (m/s and rad/s, world); a static body keeps zero.
    pub fn set_velocity(
        &mut self,
        handle: BodyHandle,
        linear: Vec3,
        angular: Vec3,
    ) -> Result<(), Error> {
        let i = self.index(handle)?;
        check_finite("linear velocity", linear)?;
        check_finite("angular velocity", angular)?;
        if self.kind[i] != BodyKind::Static {
            self.linear_velocity[i] = linear;
            self.angular_velocity[i] = angular;
        }
        Ok(())
    }

    /// Adds a force (N, world) through the centre of mass for the next step.
    pub fn add_force(&mut self, handle: BodyHandle, force: Vec3) -> Result<(), Error> {
        let i = self.index(handle)?;
        check_finite("force", force)?;
        let total = self.force[i] + force;
        check_finite("accumulated force", total)?;
        self.force[i] = total;
        Ok(())
    }

    /// Adds a force (N, world) at a world point (m) for the next step.
    pub fn add_force_at(
        &mut self,
        handle: BodyHandle,
        force: Vec3,
        point: Vec3,
    ) -> Result<(), Error> {
        let i = self.index(handle)?;
        check_finite("force", force)?;
        check_point("point", point)?;
        let total = self.force[i] + force;
        let torque = self.torque[i] + (point - self.position[i]).cross(force);
        check_finite("accumulated force", total)?;
        check_finite("accumulated torque", torque)?;
        self.force[i] = total;
        self.torque[i] = torque;
        Ok(())
    }

    /// Adds a torque (N m, world) for the next step.
    pub fn add_torque(&mut self, handle: BodyHandle, torque: Vec3) -> Result<(), Error> {
        let i = self.index(handle)?;
        check_finite("torque", torque)?;
        let total = self.torque[i] + torque;
        check_finite("accumulated torque", total)?;
        self.torque[i] = total;
        Ok(())
    }

    /// Whether the body is dynamic, or the error for a stale handle.
    pub fn is_dynamic(&self, handle: BodyHandle) -> Result<bool, Error> {
        Ok(self.kind[self.index(handle)?] == BodyKind::Dynamic)
    }
}
