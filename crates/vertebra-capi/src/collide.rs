//! The collision layer (`vertebra-collide`, on parry3d): colliders on
//! bodies, filtering, and the contacts it finds handed to the world
//! (`docs/contacts.md`).

use vertebra_collide::{Collider, ColliderShape, CollisionGroups, CollisionSnapshot, Collisions};
use vertebra_world::Contact;

use crate::body::{VtShape, VtShapeKind};
use crate::error::{Failure, VtResult};
use crate::ffi::{Object, boxed, call, enter, free, optional, out, read, slice};
use crate::snapshot::VtBytes;
use crate::types::{VtBody, VtVec3, pick};
use crate::world::VtWorld;

/// Colliders and the contacts they make (opaque; `vt_collisions_create`,
/// `vt_collisions_destroy`).
pub struct VtCollisions {
    pub(crate) collisions: Collisions,
    /// The contact list handed to the world and back each update, kept so
    /// that a steady update allocates nothing.
    contacts: Vec<Contact>,
    /// The overlaps a query finds, kept likewise.
    pub(crate) overlaps: Vec<vertebra_collide::Overlap>,
    poisoned: bool,
}

impl Object for VtCollisions {
    const NAME: &'static str = "collisions";
    fn poisoned(&mut self) -> &mut bool {
        &mut self.poisoned
    }
}

/// A collider's geometry kind.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtColliderKind {
    /// A body shape (`shape`).
    Solid = 0,
    /// The half space below the plane through the body's origin with the
    /// outward unit normal `plane_normal` (body frame): the ground.
    Plane = 1,
}

/// A collider on a body.
///
/// Start every one from `vt_collider_default`, which makes it collide with
/// everything, then set its shape (or `kind` and `plane_normal`). A
/// zero-initialised `VtCollider` (`= {0}`, `memset`, C++ `{}`) has
/// `membership` and `filter` 0: it is in no group and collides with
/// nothing, so its body falls through the ground without an error.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtCollider {
    /// The body it moves with.
    pub body: VtBody,
    /// A `VtColliderKind`.
    pub kind: u32,
    /// Solid: the shape (body frame, centred on the centre of mass).
    pub shape: VtShape,
    /// Plane: the outward unit normal (body frame).
    pub plane_normal: VtVec3,
    /// Friction coefficient (a pair uses the geometric mean), >= 0.
    pub friction: f32,
    /// Restitution (a pair uses the larger), in [0, 1].
    pub restitution: f32,
    /// The groups it is in (a bit set; all ones from
    /// `vt_collider_default`, 0 is in no group and collides with nothing).
    pub membership: u32,
    /// The groups it collides with: a pair is tested when each one's
    /// membership meets the other's filter (all ones from
    /// `vt_collider_default`; 0 collides with nothing).
    pub filter: u32,
}

impl TryFrom<VtCollider> for Collider {
    type Error = Failure;
    fn try_from(c: VtCollider) -> Result<Self, Failure> {
        let shape = match pick(c.kind, "collider.kind", &[0, 1])? {
            0 => ColliderShape::Solid(c.shape.try_into()?),
            _ => ColliderShape::Plane(c.plane_normal.into()),
        };
        Ok(Collider {
            body: c.body.into(),
            shape,
            friction: c.friction,
            restitution: c.restitution,
            groups: CollisionGroups {
                membership: c.membership,
                filter: c.filter,
            },
        })
    }
}

/// Writes into `collider` a collider on `body` that collides with
/// everything, as the Rust API's `Collider::new` makes one: in every group
/// and colliding with every group (`membership` and `filter` all ones),
/// friction 0.6, no restitution, `kind` solid. Its shape is left for the
/// caller: `shape` is a sphere of radius 0 (m), which `vt_collisions_add`
/// refuses, so a collider whose shape was forgotten is never added; for
/// the ground set `kind` to `VT_COLLIDER_KIND_PLANE` (`plane_normal` is
/// already +y, body frame). Start every `VtCollider` here rather than from
/// zeroed memory, whose groups are 0: it would collide with nothing.
///
/// # Safety
/// `collider` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collider_default(body: VtBody, collider: *mut VtCollider) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let result = unsafe { out(collider, "collider") }?;
        let rust = Collider::new(body.into(), ColliderShape::Plane(glam::Vec3::Y));
        result.set(VtCollider {
            body,
            kind: VtColliderKind::Solid as u32,
            shape: VtShape {
                kind: VtShapeKind::Sphere as u32,
                radius: 0.0,
                half_extents: VtVec3::default(),
                half_segment: VtVec3::default(),
            },
            plane_normal: VtVec3 {
                x: 0.0,
                y: 1.0,
                z: 0.0,
            },
            friction: rust.friction,
            restitution: rust.restitution,
            membership: rust.groups.membership,
            filter: rust.groups.filter,
        });
        Ok(())
    })
}

/// Runs `body` on the layer at `collisions` inside [`call`].
///
/// # Safety
/// `collisions` is null or live, used by no other call at once.
pub(crate) unsafe fn with_layer(
    collisions: *mut VtCollisions,
    body: impl FnOnce(&mut VtCollisions) -> Result<(), Failure>,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let mut layer = unsafe { enter(collisions) }?;
        body(&mut layer)
    })
}

/// Makes an empty collision layer (free it with `vt_collisions_destroy`).
///
/// # Safety
/// `collisions` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_create(collisions: *mut *mut VtCollisions) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        unsafe { out(collisions, "collisions") }?.set(boxed(VtCollisions {
            collisions: Collisions::new(),
            contacts: Vec::new(),
            overlaps: Vec::new(),
            poisoned: false,
        }));
        Ok(())
    })
}

/// Frees a collision layer (null does nothing).
///
/// # Safety
/// `collisions` is null or live, and not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_destroy(collisions: *mut VtCollisions) {
    // SAFETY: the function's contract.
    unsafe { free(collisions) }
}

/// Adds a collider and writes its index into `index` (null: not wanted).
/// Refused, naming the collider, for a degenerate shape, a non-unit plane
/// normal, or friction or restitution out of range.
///
/// # Safety
/// `collisions` is live; `collider` is readable; `index` is null or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_add(
    collisions: *mut VtCollisions,
    collider: *const VtCollider,
    index: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    let collider = unsafe { read(collider, "collider") };
    // The place for the index is checked before the collider goes in: a
    // refused call adds nothing.
    // SAFETY: the function's contract.
    let index = unsafe { optional(index, "index") };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let (collider, index) = (collider?, index?);
            let added = layer.collisions.add(collider.try_into()?)?;
            if let Some(index) = index {
                index.set(added);
            }
            Ok(())
        })
    }
}

/// Never lets two bodies collide.
///
/// # Safety
/// `collisions` is live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_exclude(
    collisions: *mut VtCollisions,
    a: VtBody,
    b: VtBody,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            layer.collisions.exclude(a.into(), b.into());
            Ok(())
        })
    }
}

/// Sets the groups of every collider on `body`.
///
/// # Safety
/// `collisions` is live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_set_body_groups(
    collisions: *mut VtCollisions,
    body: VtBody,
    membership: u32,
    filter: u32,
) -> VtResult {
    let groups = CollisionGroups { membership, filter };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            Ok(layer.collisions.set_body_groups(body.into(), groups)?)
        })
    }
}

/// Removes every collider on `body` (and its exclusions).
///
/// # Safety
/// `collisions` is live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_remove_body(
    collisions: *mut VtCollisions,
    body: VtBody,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            layer.collisions.remove_body(body.into());
            Ok(())
        })
    }
}

/// Sets the speculative margin (m, finite, not negative): pairs closer
/// than it make contacts before they touch.
///
/// # Safety
/// `collisions` is live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_set_prediction(
    collisions: *mut VtCollisions,
    margin: f32,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            Ok(layer.collisions.set_prediction(margin)?)
        })
    }
}

/// Finds the contacts of the world's current poses for a step of `dt`
/// seconds and hands them to the world for its next step (in place of
/// `vt_world_set_contacts`). A steady update allocates nothing.
///
/// A layer serves one world as its state runs on: after
/// `vt_world_restore`, restore the layer's snapshot taken with the
/// world's (`vt_collisions_restore`), or every call of the layer that
/// takes the world is refused with `VT_RESULT_WORLD_MISMATCH` (the
/// world's bodies may not be those the layer knows: a restored ragdoll
/// would have no colliders). A new layer refuses a restored world too;
/// `vt_collisions_attach` declares a layer right for the world as it is.
///
/// # Safety
/// `collisions` and `world` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_update(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
    dt: f32,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let mut world = enter(world)?;
            let VtCollisions {
                collisions,
                contacts,
                ..
            } = layer;
            collisions.find_contacts_into(&world.world, dt, contacts)?;
            Ok(world.world.swap_contacts(contacts)?)
        })
    }
}

/// Writes a snapshot of the layer (colliders, groups, exclusions, and the
/// identity of `world`'s bodies) into `snapshot`, owned by the caller
/// (`vt_bytes_destroy`). Take it with `vt_world_snapshot` of the world it
/// serves, at the same moment, and restore the two together (the world
/// first). `VT_RESULT_WORLD_MISMATCH` for a world the layer does not serve
/// (see `vt_collisions_update`).
///
/// # Safety
/// `collisions` and `world` are live; `snapshot` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_snapshot(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
    snapshot: *mut *mut VtBytes,
) -> VtResult {
    // SAFETY: the function's contract.
    let snapshot = unsafe { out(snapshot, "snapshot") };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let world = enter(world)?;
            let bytes = layer.collisions.snapshot(&world.world)?.as_bytes().to_vec();
            snapshot?.set(boxed(VtBytes { bytes }));
            Ok(())
        })
    }
}

/// Restores the layer from `length` bytes of its snapshot, checked against
/// `world` (restore the world first, from its snapshot taken with the
/// layer's): refused, unchanged, for a collider on a body the world lacks,
/// damaged bytes, or a world whose bodies are not those the snapshot was
/// taken with (`VT_RESULT_WORLD_MISMATCH`: a world snapshot of another
/// moment). The layer serves `world` from then on.
///
/// # Safety
/// `collisions` and `world` are live; `data` points to `length` readable
/// bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_restore(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
    data: *const u8,
    length: usize,
) -> VtResult {
    // SAFETY: the function's contract.
    let data = unsafe { slice(data, length, "data") };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let world = enter(world)?;
            let snapshot = CollisionSnapshot::from_bytes(data?.to_vec());
            Ok(layer.collisions.restore(&snapshot, &world.world)?)
        })
    }
}

/// Declares that the layer, as it is, serves `world` from now on: for a
/// world restored without the layer's snapshot when the layer is known to
/// be right for it (colliders added for the bodies of a world restored from
/// a snapshot taken before the layer existed). Refused, unchanged, naming
/// the collider, when a collider's body is not in `world`. Restoring the
/// layer's snapshot taken with the world's is the usual way.
///
/// # Safety
/// `collisions` and `world` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_attach(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let world = enter(world)?;
            Ok(layer.collisions.attach(&world.world)?)
        })
    }
}
