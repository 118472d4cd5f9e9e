//! The structure-of-arrays body store: one array per quantity, indexed by
//! the body handle's slot.

use glam::{DVec3, Mat3, Quat, Vec3};
use vertebra_math::PortableQuat;

use crate::error::{
    Error, MAX_COORDINATE, check_coordinate, check_finite, check_point, check_unit_quat,
};
use crate::handle::BodyHandle;
use crate::shape::MassProperties;
use crate::slots::Slots;

/// How a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum BodyKind {
    /// Moved by gravity, forces and constraints.
    Dynamic,
    /// Moved only by its own velocity, which the caller sets
    /// (`World::move_kinematic` sets the velocity that reaches a pose);
    /// infinite mass to everything that touches it.
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
    /// Mass and inertia: required for a dynamic body; optional for a
    /// kinematic one (the mass it moves with if it is made dynamic; it has
    /// infinite mass while kinematic); ignored for a static one.
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

    /// A kinematic body at the origin, at rest, without mass properties
    /// (see [`BodyDesc::with_mass`] for one that can become dynamic).
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

    /// With mass properties: a dynamic body's, or the mass a kinematic
    /// body moves with once it is made dynamic (`World::set_body_kind`).
    pub fn with_mass(mut self, mass: MassProperties) -> Self {
        self.mass = Some(mass);
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
            (BodyKind::Dynamic | BodyKind::Kinematic, Some(m)) => m.validate(),
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
///
/// The columns are public to be read in bulk, as a renderer or a game's
/// own systems read a structure of arrays. A world hands out its store
/// only as `&BodyStore`: its bodies change through the world's calls,
/// which check what they are given. A store of one's own can be written
/// freely and is checked whole by [`BodyStore::validate`].
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
    /// Masses (kg): a dynamic body's; a kinematic body's own, which it
    /// moves with again once made dynamic (0 for one that has none); 0 for
    /// static bodies. Only a dynamic body's mass acts: sum `m v` over
    /// dynamic bodies for momentum.
    pub mass: Vec<f32>,
    /// Inverse masses (1/kg); 0 for kinematic and static bodies (infinite
    /// mass).
    pub inverse_mass: Vec<f32>,
    /// Inertia tensors (kg m^2, body frame), kept as the masses are.
    pub inertia: Vec<Mat3>,
    /// Inverse inertia tensors (body frame); zero for kinematic and static
    /// bodies.
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

    /// An empty store whose handles carry `lineage` (see [`Slots`]).
    pub fn with_lineage(lineage: u32) -> Self {
        Self {
            slots: Slots::new(lineage),
            ..Self::default()
        }
    }

    /// Checks a store that did not come from [`BodyStore::insert`] (a
    /// decoded snapshot): the slot table, one entry per slot in every
    /// array, and every slot (live or freed: the step uploads them all)
    /// holding what `insert` makes of a valid [`BodyDesc`] and the step
    /// keeps: the description's checks, masses and inertia with their
    /// inverses computed as `insert` computes them (inverses zero for
    /// kinematic and static bodies, masses zero for static ones), a static
    /// body at rest, finite pending forces.
    /// The error (`CorruptSnapshot`) names the body's slot and the reason.
    pub fn validate(&self) -> Result<(), Error> {
        self.slots.validate("body")?;
        let n = self.slots.capacity();
        let lengths = [
            ("kind", self.kind.len()),
            ("position", self.position.len()),
            ("position low part", self.position_low.len()),
            ("orientation", self.orientation.len()),
            ("linear velocity", self.linear_velocity.len()),
            ("angular velocity", self.angular_velocity.len()),
            ("mass", self.mass.len()),
            ("inverse mass", self.inverse_mass.len()),
            ("inertia", self.inertia.len()),
            ("inverse inertia", self.inverse_inertia.len()),
            ("force", self.force.len()),
            ("torque", self.torque.len()),
            ("linear damping", self.linear_damping.len()),
            ("angular damping", self.angular_damping.len()),
        ];
        if let Some((what, len)) = lengths.iter().find(|&&(_, len)| len != n) {
            return Err(Error::CorruptSnapshot(format!(
                "bodies: {len} {what} entries for {n} slots"
            )));
        }
        (0..n).try_for_each(|i| {
            self.validate_slot(i)
                .map_err(|why| Error::CorruptSnapshot(format!("body {i}: {why}")))
        })
    }

    /// Slot `i` against what `insert` would have stored; the reason on error.
    fn validate_slot(&self, i: usize) -> Result<(), String> {
        let desc = self.desc(i);
        desc.validate().map_err(|e| e.to_string())?;
        let derived = Derived::of(&desc);
        let cols = |m: Mat3| m.to_cols_array().to_vec();
        let pairs = [
            (
                "mass of a static body is not zero",
                vec![self.mass[i]],
                vec![derived.mass],
            ),
            (
                "inertia of a static body, or of a kinematic body without mass, is not zero",
                cols(self.inertia[i]),
                cols(derived.inertia),
            ),
            (
                "inverse mass is not 1/mass (0 for kinematic and static bodies)",
                vec![self.inverse_mass[i]],
                vec![derived.inverse_mass],
            ),
            (
                "inverse inertia is not the inertia's inverse (0 for kinematic and static bodies)",
                cols(self.inverse_inertia[i]),
                cols(derived.inverse_inertia),
            ),
        ];
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        if let Some((why, _, _)) = pairs
            .iter()
            .find(|(_, stored, expected)| bits(stored) != bits(expected))
        {
            return Err((*why).into());
        }
        if self.kind[i] == BodyKind::Static
            && (self.linear_velocity[i] != Vec3::ZERO || self.angular_velocity[i] != Vec3::ZERO)
        {
            return Err("a static body moves".into());
        }
        self.check_low_part(i)?;
        check_finite("accumulated force", self.force[i]).map_err(|e| e.to_string())?;
        check_finite("accumulated torque", self.torque[i]).map_err(|e| e.to_string())
    }

    /// Slot `i`'s low position part is what `displace` leaves: finite, and
    /// no larger than a unit in the last place of the coordinate.
    fn check_low_part(&self, i: usize) -> Result<(), String> {
        let (high, low) = (self.position[i], self.position_low[i]);
        let ulp = |x: f32| f32::from_bits(x.abs().to_bits() + 1) - x.abs();
        let fits = (0..3).all(|k| low[k].abs() <= ulp(high[k]));
        if low.is_finite() && fits {
            Ok(())
        } else {
            Err("the position's low part is larger than the position's last digit".into())
        }
    }

    /// Slot `i` as the description `insert` would have been given.
    fn desc(&self, i: usize) -> BodyDesc {
        BodyDesc {
            kind: self.kind[i],
            position: self.position[i],
            orientation: self.orientation[i],
            linear_velocity: self.linear_velocity[i],
            angular_velocity: self.angular_velocity[i],
            mass: self.has_own_mass(i).then_some(MassProperties {
                mass: self.mass[i],
                inertia: self.inertia[i],
            }),
            linear_damping: self.linear_damping[i],
            angular_damping: self.angular_damping[i],
        }
    }

    /// Makes the handles this store issues from now on newer than every
    /// handle `other` issued (see [`Slots::issue_after`]).
    pub fn issue_after(&mut self, other: &BodyStore) {
        self.slots.issue_after(&other.slots);
    }

    /// Adds a body after validating `desc`; nothing changes on error.
    pub fn insert(&mut self, desc: &BodyDesc) -> Result<BodyHandle, Error> {
        desc.validate()?;
        let handle: BodyHandle = self.slots.insert();
        let i = handle.index();
        if i == self.kind.len() {
            self.grow();
        }
        let derived = Derived::of(desc);
        let (velocity, spin) = match desc.kind {
            BodyKind::Static => (Vec3::ZERO, Vec3::ZERO),
            _ => (desc.linear_velocity, desc.angular_velocity),
        };
        self.kind[i] = desc.kind;
        self.position[i] = desc.position;
        self.position_low[i] = Vec3::ZERO;
        self.orientation[i] = desc.orientation.normalize_portable();
        self.linear_velocity[i] = velocity;
        self.angular_velocity[i] = spin;
        self.mass[i] = derived.mass;
        self.inverse_mass[i] = derived.inverse_mass;
        self.inertia[i] = derived.inertia;
        self.inverse_inertia[i] = derived.inverse_inertia;
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

    /// Removes a body; `StaleHandle` if it was already gone,
    /// `ForeignHandle` for another world's handle.
    pub fn remove(&mut self, handle: BodyHandle) -> Result<(), Error> {
        self.index(handle)?;
        self.slots.remove(handle);
        Ok(())
    }

    /// `Ok(slot index)` for a live handle; `StaleHandle` for a removed
    /// body, `ForeignHandle` for another world's handle.
    pub fn index(&self, handle: BodyHandle) -> Result<usize, Error> {
        self.slots.check(handle, "body")
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
        self.orientation[i] = orientation.normalize_portable();
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

    /// Whether slot `i` holds mass properties: every dynamic body, and a
    /// kinematic one created with them or made kinematic from dynamic.
    fn has_own_mass(&self, i: usize) -> bool {
        match self.kind[i] {
            BodyKind::Dynamic => true,
            BodyKind::Kinematic => self.mass[i] != 0.0,
            BodyKind::Static => false,
        }
    }

    /// Switches a body between dynamic and kinematic (as Jolt's
    /// `SetMotionType`). Its mass and inertia stay, so a body made
    /// kinematic goes back to dynamic with its own mass; its velocities
    /// stay as they are (a body made kinematic moves on at its velocity
    /// until the caller sets another; one made dynamic starts with its
    /// current velocity); pending forces act if it is dynamic when the
    /// next step runs. The same kind again changes nothing. Refused with
    /// nothing changed ([`Error::WrongKind`]): a static body, a change to
    /// static, and a kinematic body without mass properties made dynamic.
    pub fn set_kind(&mut self, handle: BodyHandle, kind: BodyKind) -> Result<(), Error> {
        let i = self.index(handle)?;
        match (self.kind[i], kind) {
            (BodyKind::Static, _) => {
                return Err(Error::WrongKind(
                    "kind: a static body stays static (only dynamic and kinematic bodies switch)",
                ));
            }
            (_, BodyKind::Static) => {
                return Err(Error::WrongKind(
                    "kind: no body becomes static at run time (remove it and add a static body)",
                ));
            }
            (BodyKind::Kinematic, BodyKind::Dynamic) if !self.has_own_mass(i) => {
                return Err(Error::WrongKind(
                    "kind: a kinematic body without mass cannot become dynamic \
                     (create it with BodyDesc::with_mass)",
                ));
            }
            _ => {}
        }
        self.kind[i] = kind;
        let derived = Derived::of(&self.desc(i));
        self.inverse_mass[i] = derived.inverse_mass;
        self.inverse_inertia[i] = derived.inverse_inertia;
        Ok(())
    }
}

/// Mass, inertia and their inverses as `insert` stores them: the
/// description's for a dynamic body; for a kinematic one its own mass and
/// inertia (zero without) with zero inverses (infinite mass); all zero for
/// a static one.
struct Derived {
    mass: f32,
    inverse_mass: f32,
    inertia: Mat3,
    inverse_inertia: Mat3,
}

impl Derived {
    fn of(desc: &BodyDesc) -> Self {
        match (desc.kind, desc.mass) {
            (BodyKind::Dynamic, Some(m)) => Self {
                mass: m.mass,
                inverse_mass: 1.0 / m.mass,
                inertia: m.inertia,
                inverse_inertia: m.inertia.inverse(),
            },
            (BodyKind::Kinematic, Some(m)) => Self {
                mass: m.mass,
                inverse_mass: 0.0,
                inertia: m.inertia,
                inverse_inertia: Mat3::ZERO,
            },
            _ => Self {
                mass: 0.0,
                inverse_mass: 0.0,
                inertia: Mat3::ZERO,
                inverse_inertia: Mat3::ZERO,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Shape;

    fn store_with_a_body(x: f32) -> BodyStore {
        let mass = Shape::Sphere { radius: 0.1 }
            .mass_properties_with_mass(1.0)
            .expect("valid sphere");
        let mut store = BodyStore::default();
        let desc = BodyDesc::dynamic(mass).with_position(Vec3::new(x, 0.0, 0.0));
        store.insert(&desc).expect("valid body");
        store
    }

    /// What `displace` leaves passes, whatever the coordinate; a low part
    /// beyond the coordinate's last digit, or not finite, is refused.
    #[test]
    fn a_decoded_low_part_must_be_what_displace_leaves() {
        for x in [0.0, 1.0, 1.0e5, 1.0e6] {
            let mut store = store_with_a_body(x);
            for _ in 0..100 {
                store.displace(0, Vec3::new(0.0033, -1.0e-9, 7.0e-4));
                store.validate().expect("displace keeps the invariant");
            }
        }
        for low in [f32::NAN, f32::INFINITY, 0.01] {
            let mut store = store_with_a_body(1.0e5);
            store.position_low[0].x = low;
            let error = store.validate().expect_err("refused").to_string();
            assert!(error.contains("body 0: the position's low part"), "{error}");
        }
    }
}
