//! Scene queries: rays, swept spheres and capsules, and overlaps against
//! the colliders at the bodies' current poses (Jolt's `NarrowPhaseQuery`,
//! Rapier's `QueryPipeline`), each answer naming the body and, for a
//! ragdoll's body, the ragdoll and bone ([`RagdollPart`]).
//!
//! **Always the poses now.** The set keeps a bounding-volume tree of its
//! solid colliders (parry's `Bvh`), refreshed by
//! [`Collisions::refresh_queries`] (which [`Collisions::after_step`] and
//! [`Collisions::step`] call). A query checks that the tree is of the
//! world as it is (its `Timeline`, `World::pose_version` and the set's
//! colliders); when it is not (a body moved or added since, say), the query
//! tests every collider instead: slower, never stale. Planes (half spaces)
//! are tested by every query.
//!
//! **Exactly the brute force's answer.** The tree only prunes: a ray's
//! nearest hit is the least distance over every collider the filter
//! passes, ties to the lowest collider index, the same as testing each
//! collider in turn (`tests/queries.rs` checks it against a brute force
//! over the 30-ragdoll pile).

use core::cell::Cell;

use glam::{Quat, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhNode};
use parry3d::query::{Ray, ShapeCastOptions};
use parry3d::shape::{Ball, Capsule, Shape as ParryShape};
use vertebra_math::{DefaultFloatMode, PortableQuat};
use vertebra_store::{check_point, check_unit_quat, check_unit_vec};
use vertebra_world::{BodyHandle, BodyKind, Error, MAX_COORDINATE, World};

use crate::collider::{ColliderShape, CollisionGroups, MAX_COLLIDER_EXTENT};
use crate::part::RagdollPart;
use crate::pose::relative_pose;
use crate::set::Collisions;

/// Which colliders a query sees (Rapier's `QueryFilter`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueryFilter {
    /// The query's own groups: it sees a collider when
    /// `groups.filter & collider.membership != 0` and
    /// `collider.filter & groups.membership != 0` (the pair rule of
    /// [`CollisionGroups`]). Every group by default.
    pub groups: CollisionGroups,
    /// A body whose colliders it passes through (the shooter's own).
    pub exclude_body: Option<BodyHandle>,
    /// A ragdoll (by [`RagdollPart::ragdoll`]) whose bodies it passes
    /// through.
    pub exclude_ragdoll: Option<BodyHandle>,
    /// Whether it sees static bodies' colliders (the level).
    pub static_bodies: bool,
    /// Whether it sees kinematic bodies' colliders.
    pub kinematic_bodies: bool,
    /// Whether it sees dynamic bodies' colliders.
    pub dynamic_bodies: bool,
}

impl Default for QueryFilter {
    /// Sees every collider.
    fn default() -> Self {
        Self {
            groups: CollisionGroups::default(),
            exclude_body: None,
            exclude_ragdoll: None,
            static_bodies: true,
            kinematic_bodies: true,
            dynamic_bodies: true,
        }
    }
}

/// A query's shape, posed in the world at the query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum QueryShape {
    /// A sphere of `radius` (m) about the query's position.
    Sphere {
        /// Radius (m), positive and at most [`MAX_COLLIDER_EXTENT`].
        radius: f32,
    },
    /// A capsule: the segment from `-half_segment` to `half_segment` (m, in
    /// the query's frame) swept by a sphere of `radius`.
    Capsule {
        /// Half of its core segment (m, query frame).
        half_segment: Vec3,
        /// Radius (m), positive.
        radius: f32,
    },
}

/// Where a ray or a swept shape first touched a collider.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueryHit {
    /// The collider's index in [`Collisions::colliders`].
    pub collider: usize,
    /// Its body.
    pub body: BodyHandle,
    /// The ragdoll and bone of the body, if it is a ragdoll's.
    pub part: Option<RagdollPart>,
    /// The point hit, on the collider's surface (m, world).
    pub point: Vec3,
    /// The collider's outward surface normal there (unit, world; for a ray
    /// starting inside a collider, the ray's reverse direction).
    pub normal: Vec3,
    /// How far along the query's direction the hit is (m): the ray's
    /// length to the point, or how far the shape moved before it touched.
    pub distance: f32,
}

/// A collider a shape overlaps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Overlap {
    /// The collider's index in [`Collisions::colliders`].
    pub collider: usize,
    /// Its body.
    pub body: BodyHandle,
    /// The ragdoll and bone of the body, if it is a ragdoll's.
    pub part: Option<RagdollPart>,
}

/// The longest query (m): twice the world's range.
const MAX_QUERY_DISTANCE: f32 = 2.0 * MAX_COORDINATE;

/// How much the tree's leaves are loosened (m): a ray grazing a collider's
/// surface where it meets its bounds still enters them, whatever the
/// rounding of either, so pruning never drops a hit.
const LEAF_MARGIN: f32 = 1.0e-4;

/// A ray with its direction's reciprocals, for the tree's slab tests.
struct SlabRay {
    origin: Vec3,
    inverse: Vec3,
}

impl SlabRay {
    fn new(origin: Vec3, direction: Vec3) -> Self {
        // 1 / d per axis, exact: the same bits everywhere.
        Self {
            origin,
            inverse: Vec3::ONE / direction,
        }
    }

    /// Where the ray enters `node`'s bounds (negative when it starts
    /// inside), or `f32::MAX` when it misses them.
    fn entry(&self, node: &BvhNode) -> f32 {
        let (mins, maxs) = (node.mins(), node.maxs());
        let (mut near, mut far) = (f32::NEG_INFINITY, f32::INFINITY);
        for axis in 0..3 {
            let (o, inv) = (self.origin[axis], self.inverse[axis]);
            let (lo, hi) = (mins[axis], maxs[axis]);
            if inv.is_infinite() {
                // Parallel to the slab: inside it all along, or never.
                if !(lo..=hi).contains(&o) {
                    return f32::MAX;
                }
                continue;
            }
            let (a, b) = ((lo - o) * inv, (hi - o) * inv);
            near = near.max(a.min(b));
            far = far.min(a.max(b));
        }
        if near <= far && far >= 0.0 {
            near
        } else {
            f32::MAX
        }
    }
}

impl QueryFilter {
    /// Whether the filter passes collider `index` of `set` in `world`.
    fn passes(&self, set: &Collisions, world: &World, index: usize) -> bool {
        let c = &set.colliders[index].0;
        let kind = world.bodies().kind[c.body.index()];
        let kind_seen = match kind {
            BodyKind::Static => self.static_bodies,
            BodyKind::Kinematic => self.kinematic_bodies,
            BodyKind::Dynamic => self.dynamic_bodies,
        };
        kind_seen
            && self.groups.filter & c.groups.membership != 0
            && c.groups.filter & self.groups.membership != 0
            && self.exclude_body != Some(c.body)
            && (self.exclude_ragdoll.is_none()
                || set.part(c.body).map(|p| p.ragdoll) != self.exclude_ragdoll)
    }
}

impl QueryShape {
    /// Checks the shape's sizes.
    fn validate(&self) -> Result<(), Error> {
        let (radius, half) = match *self {
            QueryShape::Sphere { radius } => (radius, Vec3::ZERO),
            QueryShape::Capsule {
                half_segment,
                radius,
            } => (radius, half_segment),
        };
        if !radius.is_finite() || !half.is_finite() {
            return Err(Error::NonFinite("query shape"));
        }
        if radius <= 0.0 {
            return Err(Error::NonPositive("query shape radius"));
        }
        if radius + half.length() > MAX_COLLIDER_EXTENT {
            return Err(Error::OutOfRange("query shape size (at most 1e4 m)"));
        }
        Ok(())
    }

    /// Runs `f` with the shape as parry's (on the stack: a query allocates
    /// nothing).
    fn with<R>(&self, f: impl FnOnce(&dyn ParryShape) -> R) -> R {
        match *self {
            QueryShape::Sphere { radius } => f(&Ball::new(radius)),
            QueryShape::Capsule {
                half_segment,
                radius,
            } => f(&Capsule::new(-half_segment, half_segment, radius)),
        }
    }
}

/// A query's pose and travel, checked: a position in the world's range, a
/// unit orientation and direction, a distance in `[0, MAX_QUERY_DISTANCE]`.
fn check_travel(origin: Vec3, direction: Vec3, max_distance: f32) -> Result<Vec3, Error> {
    check_point("query origin", origin)?;
    check_unit_vec("query direction", direction)?;
    if max_distance.is_nan() || max_distance < 0.0 {
        return Err(Error::NonPositive("query distance"));
    }
    Ok(direction.normalize())
}

impl Collisions {
    /// The ragdoll and bone `body` is, if the set knows it as a ragdoll's
    /// (`build_ragdoll`, `add_ragdoll`).
    pub fn part(&self, body: BodyHandle) -> Option<RagdollPart> {
        self.parts.get(body)
    }

    /// Builds the query tree from the colliders at `world`'s poses now.
    /// Queries after it, until a body moves or a collider is added or
    /// removed, prune through the tree; without it they test every
    /// collider (the same answers, slower). [`Collisions::after_step`]
    /// calls it. `Err(WorldMismatch)` for a world the set does not serve;
    /// `Err(Collider)` for a collider whose body is gone.
    pub fn refresh_queries(&mut self, world: &World) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        self.check_serves(world)?;
        let stamp = (world.timeline(), world.pose_version(), self.version);
        if self.tree.stamp == Some(stamp) {
            return Ok(());
        }
        let (mut bounds, mut leaves) = (
            core::mem::take(&mut self.tree.bounds),
            core::mem::take(&mut self.tree.leaves),
        );
        bounds.clear();
        leaves.clear();
        self.tree.planes.clear();
        for (index, (c, shape)) in self.colliders.iter().enumerate() {
            let s = world.body(c.body).map_err(|e| c.refused(index, e))?;
            match c.shape {
                ColliderShape::Solid(_) => {
                    let pose = Pose::from_parts(s.position, s.orientation);
                    bounds.push(shape.compute_aabb(&pose).loosened(LEAF_MARGIN));
                    leaves.push(index);
                }
                ColliderShape::Plane(_) => self.tree.planes.push(index),
            }
        }
        if self.tree.built_for == Some(self.version) {
            // The same leaves, moved: refit (no allocation once grown).
            for (leaf, aabb) in bounds.iter().enumerate() {
                self.tree
                    .bvh
                    .insert_or_update_partially(*aabb, leaf as u32, 0.0);
            }
            self.tree.bvh.refit(&mut self.tree.workspace);
        } else {
            self.tree.bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &bounds);
            self.tree.built_for = Some(self.version);
        }
        (self.tree.bounds, self.tree.leaves) = (bounds, leaves);
        self.tree.stamp = Some(stamp);
        Ok(())
    }

    /// Whether the tree holds `world` as it is now.
    fn tree_fresh(&self, world: &World) -> bool {
        self.tree.stamp == Some((world.timeline(), world.pose_version(), self.version))
    }

    /// Collider `index`'s pose now (its body's live: checked first, by
    /// [`Collisions::check_queryable`]).
    fn pose_of(&self, world: &World, index: usize) -> Pose {
        let (bodies, i) = (world.bodies(), self.colliders[index].0.body.index());
        Pose::from_parts(bodies.position[i], bodies.orientation[i])
    }

    /// Refuses a world the set does not serve, or with a collider whose
    /// body is gone (by its index). A fresh tree vouches for the bodies:
    /// none was removed since it was built (that changes the world's pose
    /// version), so only a query without one checks them all.
    fn check_queryable(&self, world: &World) -> Result<(), Error> {
        self.check_serves(world)?;
        if self.tree_fresh(world) {
            return Ok(());
        }
        for (index, (c, _)) in self.colliders.iter().enumerate() {
            world.body(c.body).map_err(|e| c.refused(index, e))?;
        }
        Ok(())
    }

    /// Calls `visit` with every collider whose bounds may meet `region`
    /// (planes always), in no particular order: through the tree when it
    /// is fresh, else all of them.
    fn candidates(&self, world: &World, region: &Aabb, mut visit: impl FnMut(usize)) {
        if self.tree_fresh(world) {
            self.tree.planes.iter().copied().for_each(&mut visit);
            for leaf in self.tree.bvh.intersect_aabb(region) {
                visit(self.tree.leaves[leaf as usize]);
            }
        } else {
            (0..self.colliders.len()).for_each(visit);
        }
    }

    /// The first collider the ray from `origin` along `direction` (unit,
    /// world) meets within `max_distance` (m), among those `filter`
    /// passes: the body, its ragdoll and bone, the point, the surface
    /// normal and the distance. A ray starting inside a collider hits it
    /// at distance 0. `Ok(None)`: nothing in reach. Refused, with nothing
    /// changed: a world the set does not serve (`WorldMismatch`), a
    /// collider whose body is gone (`Collider`), an origin out of range,
    /// a direction not unit, a negative or NaN distance (an infinite one
    /// is held to twice the world's range).
    pub fn cast_ray(
        &self,
        world: &World,
        origin: Vec3,
        direction: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
    ) -> Result<Option<QueryHit>, Error> {
        let _mode = DefaultFloatMode::enter();
        let direction = check_travel(origin, direction, max_distance)?;
        self.check_queryable(world)?;
        let reach = max_distance.min(MAX_QUERY_DISTANCE);
        let ray = Ray::new(origin, direction);
        // The nearest hit so far: its distance, collider and normal.
        let best: Cell<Option<(f32, usize, Vec3)>> = Cell::new(None);
        let test = |k: usize| {
            if !filter.passes(self, world, k) {
                return;
            }
            let limit = best.get().map_or(reach, |b| b.0);
            let pose = self.pose_of(world, k);
            if let Some(hit) = self.colliders[k]
                .1
                .cast_ray_and_get_normal(&pose, &ray, limit, true)
            {
                let better = match best.get() {
                    None => true,
                    Some((t, j, _)) => hit.time_of_impact < t || (hit.time_of_impact == t && k < j),
                };
                if better {
                    let normal = if hit.time_of_impact == 0.0 {
                        -direction
                    } else {
                        hit.normal
                    };
                    best.set(Some((hit.time_of_impact, k, normal)));
                }
            }
        };
        if self.tree_fresh(world) {
            self.tree.planes.iter().for_each(|&k| test(k));
            // Nearest bounds first, each entered no later than the best
            // hit so far (`next_down`: a tie is entered too, so that the
            // lower index wins it, as over every collider).
            let slabs = SlabRay::new(origin, direction);
            self.tree.bvh.find_best(
                best.get().map_or(reach, |b| b.0),
                |node, _| {
                    let t = slabs.entry(node);
                    if t == f32::MAX { t } else { t.next_down() }
                },
                |leaf, _| {
                    test(self.tree.leaves[leaf as usize]);
                    best.get().map(|b| b.0)
                },
            );
        } else {
            (0..self.colliders.len()).for_each(test);
        }
        let best = best.get();
        Ok(best.map(|(distance, k, normal)| {
            let body = self.colliders[k].0.body;
            QueryHit {
                collider: k,
                body,
                part: self.part(body),
                point: origin + direction * distance,
                normal,
                distance,
            }
        }))
    }

    /// The first collider `shape`, at `position` and `orientation`, meets
    /// when moved along `direction` (unit, world) up to `max_distance`
    /// (m), among those `filter` passes (a sphere or capsule swept through
    /// the scene: a thick bullet, a limb's path, a camera's). A shape that
    /// overlaps a collider where it starts hits it at distance 0. Refused
    /// as [`Collisions::cast_ray`], and for a shape of a non-positive,
    /// non-finite or too large size, or an orientation not unit.
    #[allow(clippy::too_many_arguments)]
    pub fn cast_shape(
        &self,
        world: &World,
        shape: QueryShape,
        position: Vec3,
        orientation: Quat,
        direction: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
    ) -> Result<Option<QueryHit>, Error> {
        let _mode = DefaultFloatMode::enter();
        shape.validate()?;
        check_unit_quat("query orientation", orientation)?;
        let direction = check_travel(position, direction, max_distance)?;
        self.check_queryable(world)?;
        let reach = max_distance.min(MAX_QUERY_DISTANCE);
        let start = Pose::from_parts(position, orientation.normalize_portable());
        shape.with(|query| {
            let at_start = query.compute_aabb(&start);
            let end = Pose::from_parts(position + direction * reach, start.rotation);
            let swept = at_start.merged(&query.compute_aabb(&end));
            let options = ShapeCastOptions {
                max_time_of_impact: reach,
                target_distance: 0.0,
                stop_at_penetration: true,
                compute_impact_geometry_on_penetration: true,
            };
            let mut best: Option<(f32, usize, Vec3, Vec3)> = None;
            self.candidates(world, &swept, |k| {
                if !filter.passes(self, world, k) {
                    return;
                }
                let (_, other) = &self.colliders[k];
                let pose = self.pose_of(world, k);
                // In the query's frame, composed as the contacts are: the
                // same bits on every target.
                let Ok(Some(hit)) = parry3d::query::cast_shapes(
                    &Pose::IDENTITY,
                    start.rotation.inverse() * direction,
                    query,
                    &relative_pose(&start, &pose),
                    Vec3::ZERO,
                    other.as_ref(),
                    options,
                ) else {
                    return;
                };
                let t = hit.time_of_impact;
                if best.is_none_or(|(bt, j, ..)| t < bt || (t == bt && k < j)) {
                    let normal = pose.rotation * hit.normal2;
                    let normal = if normal.is_normalized() {
                        normal
                    } else {
                        -direction
                    };
                    best = Some((t, k, pose * hit.witness2, normal));
                }
            });
            Ok(best.map(|(distance, k, point, normal)| {
                let body = self.colliders[k].0.body;
                QueryHit {
                    collider: k,
                    body,
                    part: self.part(body),
                    point,
                    normal,
                    distance,
                }
            }))
        })
    }

    /// Every collider `shape` overlaps at `position` and `orientation`,
    /// among those `filter` passes, into `out` (emptied first; its
    /// capacity kept), by collider index: an explosion's reach, a trigger,
    /// what a teleport would land in. Refused as
    /// [`Collisions::cast_shape`] (`out` left empty).
    pub fn overlaps(
        &self,
        world: &World,
        shape: QueryShape,
        position: Vec3,
        orientation: Quat,
        filter: &QueryFilter,
        out: &mut Vec<Overlap>,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        out.clear();
        shape.validate()?;
        check_point("query position", position)?;
        check_unit_quat("query orientation", orientation)?;
        self.check_queryable(world)?;
        let pose = Pose::from_parts(position, orientation.normalize_portable());
        shape.with(|query| {
            let region = query.compute_aabb(&pose);
            self.candidates(world, &region, |k| {
                if !filter.passes(self, world, k) {
                    return;
                }
                let other = self.pose_of(world, k);
                let touching = parry3d::query::intersection_test(
                    &Pose::IDENTITY,
                    query,
                    &relative_pose(&pose, &other),
                    self.colliders[k].1.as_ref(),
                )
                .is_ok_and(|i| i.intersecting);
                if touching {
                    let body = self.colliders[k].0.body;
                    out.push(Overlap {
                        collider: k,
                        body,
                        part: self.part(body),
                    });
                }
            });
        });
        out.sort_unstable_by_key(|o| o.collider);
        Ok(())
    }

    /// A shot: [`Collisions::cast_ray`], and the impulse
    /// `impulse * direction` (N s) applied to the body hit at the point
    /// hit (`World::apply_impulse_at`), in one call: a bullet striking a
    /// ragdoll's bone, which turns and pushes that bone. A static or
    /// kinematic body hit stops the shot and takes nothing. Refused as
    /// [`Collisions::cast_ray`], and for a negative or non-finite impulse;
    /// nothing changed on a refusal.
    pub fn shoot(
        &self,
        world: &mut World,
        origin: Vec3,
        direction: Vec3,
        max_distance: f32,
        impulse: f32,
        filter: &QueryFilter,
    ) -> Result<Option<QueryHit>, Error> {
        let _mode = DefaultFloatMode::enter();
        if !impulse.is_finite() {
            return Err(Error::NonFinite("shot impulse"));
        }
        if impulse < 0.0 {
            return Err(Error::NonPositive("shot impulse"));
        }
        let hit = self.cast_ray(world, origin, direction, max_distance, filter)?;
        if let Some(h) = &hit
            && world.bodies().kind[h.body.index()] == BodyKind::Dynamic
        {
            world.apply_impulse_at(h.body, direction.normalize() * impulse, h.point)?;
        }
        Ok(hit)
    }
}
