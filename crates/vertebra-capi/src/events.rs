//! What a step did: the frame in one call with the collision layer, the
//! contact events per pair of bodies, each contact's impulses, every
//! joint's force and torque, the joints that broke, a joint's residual
//! error and a body's island (`docs/contacts.md`, "Events";
//! `docs/joints.md`, "Forces and breaking").

use vertebra_collide::{ContactEnded, ContactEvents, Touching};
use vertebra_world::{BrokenJoint, ContactImpulse, JointForce};

use crate::collide::{VtCollisions, with_layer};
use crate::contact::VtContact;
use crate::error::{Failure, VtResult};
use crate::ffi::{copy_out, enter, out};
use crate::joint::VtJointDesc;
use crate::query::VtRagdollPart;
use crate::types::{VtBody, VtJoint, VtVec3};
use crate::world::{VtWorld, with_world};

/// A pair of bodies touching in the last step.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtTouching {
    /// The first body (the lower slot).
    pub body_a: VtBody,
    /// The second body.
    pub body_b: VtBody,
    /// `body_a`'s ragdoll and bone, if a ragdoll's.
    pub part_a: VtRagdollPart,
    /// `body_b`'s ragdoll and bone, if a ragdoll's.
    pub part_b: VtRagdollPart,
    /// The step's normal impulse over the pair's contacts (N s).
    pub impulse: f32,
    /// The friction impulse on `body_b` (N s, world).
    pub friction: VtVec3,
    /// The point of the contact that pushed hardest (m, world).
    pub point: VtVec3,
    /// Its normal, out of `body_a` into `body_b` (unit, world).
    pub normal: VtVec3,
    /// How fast the pair closed when its contacts were found (m/s).
    pub closing_speed: f32,
}

impl From<&Touching> for VtTouching {
    fn from(t: &Touching) -> Self {
        Self {
            body_a: t.body_a.into(),
            body_b: t.body_b.into(),
            part_a: t.part_a.into(),
            part_b: t.part_b.into(),
            impulse: t.impulse,
            friction: t.friction.into(),
            point: t.point.into(),
            normal: t.normal.into(),
            closing_speed: t.closing_speed,
        }
    }
}

/// A pair of bodies that stopped touching in the last step.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtContactEnded {
    /// The first body (may be gone).
    pub body_a: VtBody,
    /// The second body (may be gone).
    pub body_b: VtBody,
    /// `body_a`'s ragdoll and bone, if the layer still knows it.
    pub part_a: VtRagdollPart,
    /// `body_b`'s ragdoll and bone, if the layer still knows it.
    pub part_b: VtRagdollPart,
}

impl From<&ContactEnded> for VtContactEnded {
    fn from(e: &ContactEnded) -> Self {
        Self {
            body_a: e.body_a.into(),
            body_b: e.body_b.into(),
            part_a: e.part_a.into(),
            part_b: e.part_b.into(),
        }
    }
}

/// The impulses one contact applied over the last step.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtContactImpulse {
    /// Along its normal, pushing `body_b` (N s, at least 0).
    pub normal: f32,
    /// Friction on `body_b` (N s, world).
    pub friction: VtVec3,
}

impl From<&ContactImpulse> for VtContactImpulse {
    fn from(i: &ContactImpulse) -> Self {
        Self {
            normal: i.normal,
            friction: i.friction.into(),
        }
    }
}

/// A joint's mean force and torque over the last step it was solved in.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtJointForce {
    /// The force on `body_b` (N, world).
    pub force: VtVec3,
    /// The torque on `body_b` about the anchor (N m, world).
    pub torque: VtVec3,
}

impl From<JointForce> for VtJointForce {
    fn from(f: JointForce) -> Self {
        Self {
            force: f.force.into(),
            torque: f.torque.into(),
        }
    }
}

/// A joint that broke in the last step.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtBrokenJoint {
    /// Its handle (stale now).
    pub joint: VtJoint,
    /// Its description as it was.
    pub desc: VtJointDesc,
    /// The force and torque that broke it.
    pub load: VtJointForce,
}

impl From<&BrokenJoint> for VtBrokenJoint {
    fn from(b: &BrokenJoint) -> Self {
        Self {
            joint: b.joint.into(),
            desc: (&b.desc).into(),
            load: b.load.into(),
        }
    }
}

/// One joint's residual error.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct VtJointResidual {
    /// Anchor separation (cm).
    pub linear_cm: f32,
    /// Angular error (rad): limit overshoot and held rotations' error.
    pub angular_rad: f32,
    /// The part of `angular_rad` that is limit overshoot (rad).
    pub limit_rad: f32,
}

/// A whole frame of `dt` seconds with the layer: the contacts found and
/// handed to the world, the world's step, then `vt_collisions_after_step`
/// (fast bodies swept against static geometry, the contact events, the
/// query tree). Refused before anything changes for a time step the world
/// refuses, a world the layer does not serve, a collider whose body is
/// gone. A steady frame allocates nothing.
///
/// # Safety
/// `collisions` and `world` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_step(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
    dt: f32,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let mut world = enter(world)?;
            Ok(layer.collisions.step(&mut world.world, dt)?)
        })
    }
}

/// What follows a step whose contacts `vt_collisions_update` found:
/// continuous collision, the contact events and the query tree. Refused
/// (`VT_RESULT_WORLD_MISMATCH`), nothing changed, when the world's last
/// step did not solve the contacts the layer last found for it.
///
/// # Safety
/// `collisions` and `world` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_after_step(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let mut world = enter(world)?;
            Ok(layer.collisions.after_step(&mut world.world)?)
        })
    }
}

/// One of the last step's event lists, `list` of the layer's events, into
/// `items` (room for `capacity`), their number into `count`, as
/// `vt_collisions_began` says; `what` names `items` in a refusal.
///
/// # Safety
/// `collisions` is live; `items` points to `capacity` writable items;
/// `count` is writable.
unsafe fn copy_events<E, T: for<'e> From<&'e E>>(
    collisions: *mut VtCollisions,
    list: fn(&ContactEvents) -> &[E],
    items: *mut T,
    capacity: usize,
    count: *mut usize,
    what: &str,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let events = list(layer.collisions.events()).iter().map(T::from);
            copy_out(events, items, capacity, count, what)
        })
    }
}

/// The pairs that began touching in the last step (with the impulse and
/// speed of the hit) into `began` (room for `capacity`), their number into
/// `count`; `VT_RESULT_BUFFER_TOO_SMALL` (only `count` written) when they
/// do not fit.
///
/// # Safety
/// `collisions` is live; `began` points to `capacity` writable items;
/// `count` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_began(
    collisions: *mut VtCollisions,
    began: *mut VtTouching,
    capacity: usize,
    count: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        copy_events(
            collisions,
            ContactEvents::began,
            began,
            capacity,
            count,
            "began",
        )
    }
}

/// The pairs that stopped touching in the last step, as
/// `vt_collisions_began`.
///
/// # Safety
/// As `vt_collisions_began`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_ended(
    collisions: *mut VtCollisions,
    ended: *mut VtContactEnded,
    capacity: usize,
    count: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        copy_events(
            collisions,
            ContactEvents::ended,
            ended,
            capacity,
            count,
            "ended",
        )
    }
}

/// Every pair touching with contacts the last step solved, with the
/// step's impulses, as `vt_collisions_began`.
///
/// # Safety
/// As `vt_collisions_began`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_touching(
    collisions: *mut VtCollisions,
    touching: *mut VtTouching,
    capacity: usize,
    count: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        copy_events(
            collisions,
            ContactEvents::touching,
            touching,
            capacity,
            count,
            "touching",
        )
    }
}

/// The contacts the last step solved (in the order set) into `contacts`
/// and each one's impulses into `impulses` (both room for `capacity`),
/// their number into `count`; `VT_RESULT_BUFFER_TOO_SMALL` (only `count`
/// written) when they do not fit.
///
/// # Safety
/// `world` is live; `contacts` and `impulses` each point to `capacity`
/// writable items; `count` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_solved_contacts(
    world: *mut VtWorld,
    contacts: *mut VtContact,
    impulses: *mut VtContactImpulse,
    capacity: usize,
    count: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let solved = w.solved_contacts().iter().map(VtContact::from);
            copy_out(solved, contacts, capacity, count, "contacts")?;
            let made = w.contact_impulses().iter().map(VtContactImpulse::from);
            copy_out(made, impulses, capacity, count, "impulses")
        })
    }
}

/// Writes `joint`'s mean force and torque over the last step it was solved
/// in into `load` (zero before its first step).
///
/// # Safety
/// `world` is live; `load` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_joint_force(
    world: *mut VtWorld,
    joint: VtJoint,
    load: *mut VtJointForce,
) -> VtResult {
    // SAFETY: the function's contract.
    let place = unsafe { out(load, "load") };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let force = w.joint_force(joint.into()).map_err(Failure::from)?;
            place?.done(force.into())
        })
    }
}

/// The joints the last step broke into `broken` (room for `capacity`),
/// their number into `count`, as `vt_collisions_began`.
///
/// # Safety
/// `world` is live; `broken` points to `capacity` writable items; `count`
/// is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_broken_joints(
    world: *mut VtWorld,
    broken: *mut VtBrokenJoint,
    capacity: usize,
    count: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let items = w.broken_joints().iter().map(VtBrokenJoint::from);
            copy_out(items, broken, capacity, count, "broken")
        })
    }
}

/// Writes `joint`'s residual error at the world's poses now into
/// `residual` (measured on the spot unless the last step measured it).
///
/// # Safety
/// `world` is live; `residual` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_joint_residual(
    world: *mut VtWorld,
    joint: VtJoint,
    residual: *mut VtJointResidual,
) -> VtResult {
    // SAFETY: the function's contract.
    let place = unsafe { out(residual, "residual") };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let handle = joint.into();
            w.joint(handle).map_err(Failure::from)?;
            let residuals = match w.residuals() {
                Some(r) => r,
                None => w.measure_residuals(),
            };
            let found = residuals.joints.iter().find(|r| r.joint == handle);
            let r = found.map_or_else(VtJointResidual::default, |r| VtJointResidual {
                linear_cm: r.linear_cm,
                angular_rad: r.angular_rad,
                limit_rad: r.limit_rad,
            });
            place?.done(r)
        })
    }
}

/// Writes `body`'s island into `island` and 1 into `present`, or 0 into
/// `present` for a body in none (static, or no island kept: sleeping off).
///
/// # Safety
/// `world` is live; `island` and `present` are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_island(
    world: *mut VtWorld,
    body: VtBody,
    island: *mut u32,
    present: *mut u32,
) -> VtResult {
    // SAFETY: the function's contract.
    let places = unsafe { (out(island, "island"), out(present, "present")) };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (island, present) = (places.0?, places.1?);
            let found = w.island(body.into()).map_err(Failure::from)?;
            if let Some(k) = found {
                island.set(k);
            }
            present.done(u32::from(found.is_some()))
        })
    }
}
