//! Contacts fed to the solver by the engine's own collision detection
//! (or by the collision layer, `vt_collisions_update`).

use vertebra_world::Contact;

use crate::error::{Failure, VtResult};
use crate::ffi::{out, slice, slice_mut};
use crate::types::{VtBody, VtVec3};
use crate::world::{VtWorld, with_world};

/// A contact between two bodies for the next step. The normal's sign is
/// the contact's meaning: it points out of `body_a` into `body_b`. Some
/// engines give theirs the other way: exchanging the bodies means flipping
/// the normal too, or the contact pushes the bodies into each other (the
/// world cannot tell: it does not know the bodies' shapes).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtContact {
    /// The first body.
    pub body_a: VtBody,
    /// The second body.
    pub body_b: VtBody,
    /// The contact point, midway between the surfaces (m, world).
    pub point: VtVec3,
    /// The normal out of `body_a` into `body_b`: the direction the contact
    /// pushes `body_b` (unit, world).
    pub normal: VtVec3,
    /// Penetration depth along the normal (m); negative for a gap.
    pub depth: f32,
    /// Friction coefficient (static and dynamic), >= 0.
    pub friction: f32,
    /// Restitution, in [0, 1].
    pub restitution: f32,
}

impl From<&VtContact> for Contact {
    fn from(c: &VtContact) -> Self {
        Contact {
            body_a: c.body_a.into(),
            body_b: c.body_b.into(),
            point: c.point.into(),
            normal: c.normal.into(),
            depth: c.depth,
            friction: c.friction,
            restitution: c.restitution,
        }
    }
}

impl From<&Contact> for VtContact {
    fn from(c: &Contact) -> Self {
        Self {
            body_a: c.body_a.into(),
            body_b: c.body_b.into(),
            point: c.point.into(),
            normal: c.normal.into(),
            depth: c.depth,
            friction: c.friction,
            restitution: c.restitution,
        }
    }
}

/// Sets the contacts for the next step (`count` of them; they replace the
/// last set). Refused whole, naming the contact, if any is invalid.
///
/// # Safety
/// `world` is a live world; `contacts` points to `count` readable contacts.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_contacts(
    world: *mut VtWorld,
    contacts: *const VtContact,
    count: usize,
) -> VtResult {
    // SAFETY: the function's contract.
    let contacts = unsafe { slice(contacts, count, "contacts") };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let contacts: Vec<Contact> = contacts?.iter().map(Contact::from).collect();
            w.set_contacts(&contacts).map_err(Failure::from)
        })
    }
}

/// Copies the world's current contacts into `contacts` (room for
/// `capacity`) and writes their number into `count`; refused
/// (`VT_RESULT_BUFFER_TOO_SMALL`, only `count` written) when they do not
/// fit. Pass a null `contacts` and 0 to ask the number.
///
/// # Safety
/// `world` is a live world; `contacts` points to `capacity` writable
/// contacts; `count` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_contacts(
    world: *mut VtWorld,
    contacts: *mut VtContact,
    capacity: usize,
    count: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    let count = unsafe { out(count, "count") };
    // SAFETY: the function's contract.
    unsafe {
        with_world(world, |w| {
            let (have, count) = (w.contacts(), count?);
            if capacity < have.len() {
                count.set(have.len());
                return Err(Failure::new(
                    VtResult::BufferTooSmall,
                    format!("contacts holds {capacity}; the world has {}", have.len()),
                ));
            }
            let place = slice_mut(contacts, have.len(), "contacts")?;
            for (to, from) in place.iter_mut().zip(have) {
                *to = from.into();
            }
            count.done(have.len())
        })
    }
}
