//! Bodies: shapes and mass, adding and removing, their state, kinds,
//! forces, impulses and sleep.

use glam::{Mat3, Quat, Vec3};
use vertebra_world::{BodyDesc, BodyKind, BodyState, MassProperties, Shape};

use crate::error::{Failure, VtResult};
use crate::ffi::{call, out, read};
use crate::types::{VtBody, VtQuat, VtVec3, flag, pick};
use crate::world::{VtWorld, with_world};

/// How a body moves.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtBodyKind {
    /// Moved by the solver.
    Dynamic = 0,
    /// Moved by the game (`vt_world_move_kinematic`); infinite mass.
    Kinematic = 1,
    /// Never moves.
    Static = 2,
}

const KINDS: [BodyKind; 3] = [BodyKind::Dynamic, BodyKind::Kinematic, BodyKind::Static];

/// A shape's kind.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtShapeKind {
    /// A ball of `radius`.
    Sphere = 0,
    /// A box of `half_extents`.
    Box = 1,
    /// The segment from `-half_segment` to `+half_segment` swept by a ball
    /// of `radius`.
    Capsule = 2,
}

/// A solid shape in its body's frame, centred on the centre of mass (m).
/// Only the fields of its kind are read.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtShape {
    /// A `VtShapeKind`.
    pub kind: u32,
    /// Sphere and capsule radius (m).
    pub radius: f32,
    /// Box half extents along the body axes (m).
    pub half_extents: VtVec3,
    /// Capsule: half the core segment, centre to one end (m, body frame).
    pub half_segment: VtVec3,
}

/// Mass (kg) and inertia tensor (kg m^2, body frame, about the centre of
/// mass; symmetric, so its nine numbers read the same by rows or columns).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtMassProperties {
    /// Mass (kg).
    pub mass: f32,
    /// Inertia tensor, column by column.
    pub inertia: [f32; 9],
}

/// A body to add.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtBodyDesc {
    /// A `VtBodyKind`.
    pub kind: u32,
    /// Centre of mass (m, world).
    pub position: VtVec3,
    /// Orientation of the body frame in the world (unit).
    pub orientation: VtQuat,
    /// Velocity of the centre of mass (m/s, world).
    pub linear_velocity: VtVec3,
    /// Angular velocity (rad/s, world).
    pub angular_velocity: VtVec3,
    /// Non-zero: `mass` holds the body's mass (required for a dynamic body;
    /// ignored for a static one).
    pub has_mass: u32,
    /// Mass properties (`vt_shape_mass_properties` makes them from a shape).
    pub mass: VtMassProperties,
    /// Linear damping rate (1/s).
    pub linear_damping: f32,
    /// Angular damping rate (1/s).
    pub angular_damping: f32,
}

/// A body's state.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtBodyState {
    /// Centre of mass (m, world).
    pub position: VtVec3,
    /// Orientation (unit).
    pub orientation: VtQuat,
    /// Velocity of the centre of mass (m/s, world).
    pub linear_velocity: VtVec3,
    /// Angular velocity (rad/s, world).
    pub angular_velocity: VtVec3,
}

impl TryFrom<VtShape> for Shape {
    type Error = Failure;
    fn try_from(s: VtShape) -> Result<Self, Failure> {
        Ok(match pick(s.kind, "shape.kind", &[0, 1, 2])? {
            0 => Shape::Sphere { radius: s.radius },
            1 => Shape::Box {
                half_extents: s.half_extents.into(),
            },
            _ => Shape::Capsule {
                half_segment: s.half_segment.into(),
                radius: s.radius,
            },
        })
    }
}

impl From<Shape> for VtShape {
    fn from(shape: Shape) -> Self {
        let mut out = VtShape {
            kind: 0,
            radius: 0.0,
            half_extents: VtVec3::default(),
            half_segment: VtVec3::default(),
        };
        match shape {
            Shape::Sphere { radius } => out.radius = radius,
            Shape::Box { half_extents } => {
                out.kind = 1;
                out.half_extents = half_extents.into();
            }
            Shape::Capsule {
                half_segment,
                radius,
            } => {
                out.kind = 2;
                out.half_segment = half_segment.into();
                out.radius = radius;
            }
        }
        out
    }
}

impl From<VtMassProperties> for MassProperties {
    fn from(m: VtMassProperties) -> Self {
        MassProperties {
            mass: m.mass,
            inertia: Mat3::from_cols_array(&m.inertia),
        }
    }
}

impl From<BodyState> for VtBodyState {
    fn from(s: BodyState) -> Self {
        Self {
            position: s.position.into(),
            orientation: s.orientation.into(),
            linear_velocity: s.linear_velocity.into(),
            angular_velocity: s.angular_velocity.into(),
        }
    }
}

impl TryFrom<&VtBodyDesc> for BodyDesc {
    type Error = Failure;
    fn try_from(d: &VtBodyDesc) -> Result<Self, Failure> {
        Ok(BodyDesc {
            kind: pick(d.kind, "body.kind", &KINDS)?,
            position: d.position.into(),
            orientation: d.orientation.into(),
            linear_velocity: d.linear_velocity.into(),
            angular_velocity: d.angular_velocity.into(),
            mass: flag(d.has_mass).then(|| d.mass.into()),
            linear_damping: d.linear_damping,
            angular_damping: d.angular_damping,
        })
    }
}

/// The mass properties of `shape` with `mass` kg spread evenly through it.
///
/// # Safety
/// `shape` is readable; `mass_properties` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_shape_mass_properties(
    shape: *const VtShape,
    mass: f32,
    mass_properties: *mut VtMassProperties,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (shape, result) = unsafe {
            (
                read(shape, "shape")?,
                out(mass_properties, "mass_properties")?,
            )
        };
        let m = Shape::try_from(shape)?.mass_properties_with_mass(mass)?;
        result.set(VtMassProperties {
            mass: m.mass,
            inertia: m.inertia.to_cols_array(),
        });
        Ok(())
    })
}

/// Writes a body description of `kind` at the origin, at rest, unrotated,
/// undamped, without mass into `desc`.
///
/// # Safety
/// `desc` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_body_desc_default(kind: u32, desc: *mut VtBodyDesc) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let result = unsafe { out(desc, "desc") }?;
        pick(kind, "kind", &KINDS)?;
        result.set(VtBodyDesc {
            kind,
            position: VtVec3::default(),
            orientation: Quat::IDENTITY.into(),
            linear_velocity: VtVec3::default(),
            angular_velocity: VtVec3::default(),
            has_mass: 0,
            mass: VtMassProperties {
                mass: 0.0,
                inertia: [0.0; 9],
            },
            linear_damping: 0.0,
            angular_damping: 0.0,
        });
        Ok(())
    })
}

/// Adds a body and writes its handle into `body`.
///
/// # Safety
/// `world` is a live world; `desc` is readable; `body` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_add_body(
    world: *mut VtWorld,
    desc: *const VtBodyDesc,
    body: *mut VtBody,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe { (read(desc, "desc"), out(body, "body")) };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (desc, body) = (inputs.0?, inputs.1?);
            body.set(w.add_body(BodyDesc::try_from(&desc)?)?.into());
            Ok(())
        })
    }
}

/// Removes a body (refused while a joint or rod uses it).
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_remove_body(world: *mut VtWorld, body: VtBody) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { with_world(world, |w| Ok(w.remove_body(body.into())?)) }
}

/// Writes a body's state into `state`.
///
/// # Safety
/// `world` is a live world; `state` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_body_state(
    world: *mut VtWorld,
    body: VtBody,
    state: *mut VtBodyState,
) -> VtResult {
    // SAFETY: the function's contract.
    let state = unsafe { out(state, "state") };
    // SAFETY: the function's contract.
    unsafe { with_world(world, |w| state?.done(w.body(body.into())?.into())) }
}

/// Moves a body to a pose at once (a teleport; velocities kept).
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_body_pose(
    world: *mut VtWorld,
    body: VtBody,
    position: VtVec3,
    orientation: VtQuat,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            Ok(w.set_body_pose(body.into(), position.into(), orientation.into())?)
        })
    }
}

/// Sets a body's velocities (m/s and rad/s, world).
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_body_velocity(
    world: *mut VtWorld,
    body: VtBody,
    linear: VtVec3,
    angular: VtVec3,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            Ok(w.set_body_velocity(body.into(), linear.into(), angular.into())?)
        })
    }
}

/// Switches a body between dynamic and kinematic (`VtBodyKind`; static
/// bodies stay static).
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_body_kind(
    world: *mut VtWorld,
    body: VtBody,
    kind: u32,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            Ok(w.set_body_kind(body.into(), pick(kind, "kind", &KINDS)?)?)
        })
    }
}

/// Moves a kinematic body to a pose over the next step of `dt` seconds
/// (its velocities are set to arrive there).
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_move_kinematic(
    world: *mut VtWorld,
    body: VtBody,
    position: VtVec3,
    orientation: VtQuat,
    dt: f32,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            Ok(w.move_kinematic(body.into(), position.into(), orientation.into(), dt)?)
        })
    }
}

/// What a push does to a body.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtPush {
    /// A force (N) at the centre of mass, over the next step.
    Force = 0,
    /// A torque (N m) over the next step.
    Torque = 1,
    /// An impulse (N s) at the centre of mass, now.
    Impulse = 2,
    /// An angular impulse (N m s), now.
    AngularImpulse = 3,
}

/// Pushes a dynamic body: `vector` is a force, torque, impulse or angular
/// impulse as `push` (a `VtPush`) says, in the world frame. Forces and
/// torques act over the next step and are then cleared.
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_push(
    world: *mut VtWorld,
    body: VtBody,
    push: u32,
    vector: VtVec3,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (body, v) = (body.into(), Vec3::from(vector));
            Ok(match pick(push, "push", &[0, 1, 2, 3])? {
                0 => w.add_force(body, v),
                1 => w.add_torque(body, v),
                2 => w.apply_impulse(body, v),
                _ => w.apply_angular_impulse(body, v),
            }?)
        })
    }
}

/// Pushes a dynamic body at a world point (m): a force (N) over the next
/// step, or an impulse (N s) now, as `push` says (`VT_PUSH_FORCE` or
/// `VT_PUSH_IMPULSE`).
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_push_at(
    world: *mut VtWorld,
    body: VtBody,
    push: u32,
    vector: VtVec3,
    point: VtVec3,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (body, v, p) = (body.into(), Vec3::from(vector), Vec3::from(point));
            match push {
                0 => Ok(w.add_force_at(body, v, p)?),
                2 => Ok(w.apply_impulse_at(body, v, p)?),
                _ => Err(Failure::new(
                    VtResult::InvalidEnum,
                    format!("push is {push}; at a point it takes VT_PUSH_FORCE or VT_PUSH_IMPULSE"),
                )),
            }
        })
    }
}

/// Wakes a body's island.
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_wake(world: *mut VtWorld, body: VtBody) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { with_world(world, |w| Ok(w.wake(body.into())?)) }
}

/// Writes 1 into `asleep` if the body's island sleeps, else 0.
///
/// # Safety
/// `world` is a live world; `asleep` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_is_asleep(
    world: *mut VtWorld,
    body: VtBody,
    asleep: *mut u32,
) -> VtResult {
    // SAFETY: the function's contract.
    let asleep = unsafe { out(asleep, "asleep") };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            asleep?.done(u32::from(w.is_asleep(body.into())?))
        })
    }
}

/// Lets a body's island sleep (non-zero) or keeps it awake (0).
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_sleep_allowed(
    world: *mut VtWorld,
    body: VtBody,
    allowed: u32,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            Ok(w.set_sleep_allowed(body.into(), flag(allowed))?)
        })
    }
}
