//! Scene queries of the collision layer: rays, swept spheres and
//! capsules, overlaps and shots, each naming the body hit and, for a
//! ragdoll's, the ragdoll and bone (`docs/contacts.md`, "Queries").

use vertebra_collide::{CollisionGroups, Overlap, QueryFilter, QueryHit, QueryShape, RagdollPart};

use crate::collide::{VtCollisions, with_layer};
use crate::error::Failure;
use crate::error::VtResult;
use crate::ffi::{call, copy_out, enter, out, read};
use crate::types::{VtBody, VtTransform, VtVec3, flag, pick};
use crate::world::VtWorld;

/// Which colliders a query sees. Start from `vt_query_filter_default`
/// (sees everything); zeroed memory sees nothing (no group, no kind).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtQueryFilter {
    /// The query's groups (a bit set): it sees a collider when
    /// `filter & collider.membership` and `collider.filter & membership`
    /// are both non-zero.
    pub membership: u32,
    /// The groups it sees.
    pub filter: u32,
    /// Non-zero: `exclude_body`'s colliders are passed through.
    pub has_exclude_body: u32,
    /// A body passed through (the shooter's own).
    pub exclude_body: VtBody,
    /// Non-zero: the ragdoll named `exclude_ragdoll` is passed through.
    pub has_exclude_ragdoll: u32,
    /// A ragdoll passed through, by its first body (`vt_ragdoll_first_body`).
    pub exclude_ragdoll: VtBody,
    /// Non-zero: static bodies' colliders are seen.
    pub static_bodies: u32,
    /// Non-zero: kinematic bodies' colliders are seen.
    pub kinematic_bodies: u32,
    /// Non-zero: dynamic bodies' colliders are seen.
    pub dynamic_bodies: u32,
}

impl From<VtQueryFilter> for QueryFilter {
    fn from(f: VtQueryFilter) -> Self {
        QueryFilter {
            groups: CollisionGroups {
                membership: f.membership,
                filter: f.filter,
            },
            exclude_body: flag(f.has_exclude_body).then(|| f.exclude_body.into()),
            exclude_ragdoll: flag(f.has_exclude_ragdoll).then(|| f.exclude_ragdoll.into()),
            static_bodies: flag(f.static_bodies),
            kinematic_bodies: flag(f.kinematic_bodies),
            dynamic_bodies: flag(f.dynamic_bodies),
        }
    }
}

/// A query shape's kind.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtQueryShapeKind {
    /// A sphere of `radius`.
    Sphere = 0,
    /// A capsule: the segment `-half_segment .. half_segment` (query
    /// frame) swept by `radius`.
    Capsule = 1,
}

/// A query's shape (posed by the call's transform).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtQueryShape {
    /// A `VtQueryShapeKind`.
    pub kind: u32,
    /// Radius (m, positive).
    pub radius: f32,
    /// Capsule: half its core segment (m, query frame).
    pub half_segment: VtVec3,
}

impl TryFrom<VtQueryShape> for QueryShape {
    type Error = Failure;
    fn try_from(s: VtQueryShape) -> Result<Self, Failure> {
        Ok(match pick(s.kind, "shape.kind", &[0, 1])? {
            0 => QueryShape::Sphere { radius: s.radius },
            _ => QueryShape::Capsule {
                half_segment: s.half_segment.into(),
                radius: s.radius,
            },
        })
    }
}

/// Which ragdoll and bone a body is.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VtRagdollPart {
    /// Non-zero: the body is a ragdoll's (the fields below hold).
    pub present: u32,
    /// The ragdoll, named by its first body (`vt_ragdoll_first_body`).
    pub ragdoll: VtBody,
    /// The body's index in the ragdoll's description
    /// (`vt_ragdoll_desc_body_name` names its bone).
    pub bone: u32,
}

impl From<Option<RagdollPart>> for VtRagdollPart {
    fn from(p: Option<RagdollPart>) -> Self {
        p.map_or_else(Self::default, |p| Self {
            present: 1,
            ragdoll: p.ragdoll.into(),
            bone: p.bone,
        })
    }
}

/// Where a ray or swept shape first touched a collider.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtQueryHit {
    /// The collider's index in the layer.
    pub collider: usize,
    /// Its body.
    pub body: VtBody,
    /// The body's ragdoll and bone, if a ragdoll's.
    pub part: VtRagdollPart,
    /// The point hit, on the collider's surface (m, world).
    pub point: VtVec3,
    /// The collider's outward normal there (unit, world).
    pub normal: VtVec3,
    /// How far along the direction (m).
    pub distance: f32,
}

impl From<QueryHit> for VtQueryHit {
    fn from(h: QueryHit) -> Self {
        Self {
            collider: h.collider,
            body: h.body.into(),
            part: h.part.into(),
            point: h.point.into(),
            normal: h.normal.into(),
            distance: h.distance,
        }
    }
}

/// A collider a shape overlaps.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtOverlap {
    /// The collider's index in the layer.
    pub collider: usize,
    /// Its body.
    pub body: VtBody,
    /// The body's ragdoll and bone, if a ragdoll's.
    pub part: VtRagdollPart,
}

impl From<Overlap> for VtOverlap {
    fn from(o: Overlap) -> Self {
        Self {
            collider: o.collider,
            body: o.body.into(),
            part: o.part.into(),
        }
    }
}

/// Writes a filter that sees every collider into `filter`.
///
/// # Safety
/// `filter` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_query_filter_default(filter: *mut VtQueryFilter) -> VtResult {
    call(|| {
        let f = QueryFilter::default();
        let none = VtBody::default();
        // SAFETY: the function's contract.
        unsafe { out(filter, "filter") }?.done(VtQueryFilter {
            membership: f.groups.membership,
            filter: f.groups.filter,
            has_exclude_body: 0,
            exclude_body: none,
            has_exclude_ragdoll: 0,
            exclude_ragdoll: none,
            static_bodies: 1,
            kinematic_bodies: 1,
            dynamic_bodies: 1,
        })
    })
}

/// Builds the layer's query tree from the world's poses now (queries until
/// a body moves prune through it; without it they test every collider,
/// with the same answers). `vt_collisions_step` and
/// `vt_collisions_after_step` refresh it.
///
/// # Safety
/// `collisions` and `world` are live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_refresh_queries(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
) -> VtResult {
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let world = enter(world)?;
            Ok(layer.collisions.refresh_queries(&world.world)?)
        })
    }
}

/// A hit written into `hit` with `found` 1, or `found` 0 (and `hit`
/// untouched) for none.
///
/// # Safety
/// `hit` and `found` are writable.
unsafe fn write_hit(
    result: Option<QueryHit>,
    hit: *mut VtQueryHit,
    found: *mut u32,
) -> Result<(), Failure> {
    // SAFETY: the caller's contract.
    let (hit, found) = unsafe { (out(hit, "hit")?, out(found, "found")?) };
    if let Some(h) = result {
        hit.set(h.into());
    }
    found.done(u32::from(result.is_some()))
}

/// Casts a ray from `origin` along `direction` (unit) up to `max_distance`
/// (m) through the colliders `filter` passes: the first hit into `hit`
/// and 1 into `found`, or 0 into `found`. Refused, unchanged, for an origin
/// out of range, a direction not unit, a negative or NaN distance, a world
/// the layer does not serve, a collider whose body is gone.
///
/// # Safety
/// `collisions` and `world` are live; `filter` is readable; `hit` and
/// `found` are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_cast_ray(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
    origin: VtVec3,
    direction: VtVec3,
    max_distance: f32,
    filter: *const VtQueryFilter,
    hit: *mut VtQueryHit,
    found: *mut u32,
) -> VtResult {
    // SAFETY: the function's contract.
    let filter = unsafe { read(filter, "filter") };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let world = enter(world)?;
            let filter = QueryFilter::from(filter?);
            let result = layer.collisions.cast_ray(
                &world.world,
                origin.into(),
                direction.into(),
                max_distance,
                &filter,
            )?;
            write_hit(result, hit, found)
        })
    }
}

/// Sweeps `shape`, posed at `pose`, along `direction` (unit) up to
/// `max_distance` (m): the first collider `filter` passes that it touches
/// into `hit` (distance 0 for one it starts in) and 1 into `found`, or 0.
/// Refused as `vt_collisions_cast_ray`, and for a shape of a bad kind or
/// size or a rotation not unit.
///
/// # Safety
/// `collisions` and `world` are live; `shape` and `filter` are readable;
/// `hit` and `found` are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_cast_shape(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
    shape: *const VtQueryShape,
    pose: VtTransform,
    direction: VtVec3,
    max_distance: f32,
    filter: *const VtQueryFilter,
    hit: *mut VtQueryHit,
    found: *mut u32,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe { (read(shape, "shape"), read(filter, "filter")) };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let world = enter(world)?;
            let (shape, filter) = (
                QueryShape::try_from(inputs.0?)?,
                QueryFilter::from(inputs.1?),
            );
            let (position, rotation) = pose.into();
            let result = layer.collisions.cast_shape(
                &world.world,
                shape,
                position,
                rotation,
                direction.into(),
                max_distance,
                &filter,
            )?;
            write_hit(result, hit, found)
        })
    }
}

/// Every collider `filter` passes that `shape`, posed at `pose`, overlaps,
/// by collider index, into `overlaps` (room for `capacity`), their number
/// into `count`; refused (`VT_RESULT_BUFFER_TOO_SMALL`, only `count`
/// written) when they do not fit. Refused as `vt_collisions_cast_shape`.
///
/// # Safety
/// `collisions` and `world` are live; `shape` and `filter` are readable;
/// `overlaps` points to `capacity` writable items; `count` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_overlaps(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
    shape: *const VtQueryShape,
    pose: VtTransform,
    filter: *const VtQueryFilter,
    overlaps: *mut VtOverlap,
    capacity: usize,
    count: *mut usize,
) -> VtResult {
    // SAFETY: the function's contract.
    let inputs = unsafe { (read(shape, "shape"), read(filter, "filter")) };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let world = enter(world)?;
            let (shape, filter) = (
                QueryShape::try_from(inputs.0?)?,
                QueryFilter::from(inputs.1?),
            );
            let (position, rotation) = pose.into();
            let mut found = core::mem::take(&mut layer.overlaps);
            let result = layer.collisions.overlaps(
                &world.world,
                shape,
                position,
                rotation,
                &filter,
                &mut found,
            );
            let written = result.map_err(Failure::from).and_then(|()| {
                let items = found.iter().map(|&o| VtOverlap::from(o));
                copy_out(items, overlaps, capacity, count, "overlaps")
            });
            layer.overlaps = found;
            written
        })
    }
}

/// A shot: `vt_collisions_cast_ray`, and the impulse `impulse * direction`
/// (N s) applied to the dynamic body hit at the point hit, in one call (a
/// static or kinematic body stops the shot and takes nothing). Refused as
/// `vt_collisions_cast_ray`, and for a negative or non-finite impulse;
/// nothing changed on a refusal.
///
/// # Safety
/// As `vt_collisions_cast_ray`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_shoot(
    collisions: *mut VtCollisions,
    world: *mut VtWorld,
    origin: VtVec3,
    direction: VtVec3,
    max_distance: f32,
    impulse: f32,
    filter: *const VtQueryFilter,
    hit: *mut VtQueryHit,
    found: *mut u32,
) -> VtResult {
    // SAFETY: the function's contract.
    let filter = unsafe { read(filter, "filter") };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            let mut world = enter(world)?;
            let filter = QueryFilter::from(filter?);
            // The outputs are checked before the impulse is applied: a
            // refused call changes nothing.
            let (place, flag) = (out(hit, "hit")?, out(found, "found")?);
            let result = layer.collisions.shoot(
                &mut world.world,
                origin.into(),
                direction.into(),
                max_distance,
                impulse,
                &filter,
            )?;
            if let Some(h) = result {
                place.set(h.into());
            }
            flag.done(u32::from(result.is_some()))
        })
    }
}

/// Writes which ragdoll and bone `body` is into `part` (`present` 0 for a
/// body the layer knows as no ragdoll's).
///
/// # Safety
/// `collisions` is live; `part` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_collisions_body_part(
    collisions: *mut VtCollisions,
    body: VtBody,
    part: *mut VtRagdollPart,
) -> VtResult {
    // SAFETY: the function's contract.
    let place = unsafe { out(part, "part") };
    // SAFETY: the function's contract.
    unsafe {
        with_layer(collisions, |layer| {
            place?.done(layer.collisions.part(body.into()).into())
        })
    }
}
