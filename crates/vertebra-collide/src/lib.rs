//! Collision detection for vertebra, on `parry3d` (the field's library,
//! glam-based like us): colliders on bodies, a sort-and-sweep broad phase,
//! parry's contact manifolds as the narrow phase, and collision filtering;
//! the result is the `Contact` list the core solver takes. An engine with
//! its own collision detection skips this crate and calls
//! `World::set_contacts` itself.
//!
//! Static geometry (ground, walls, boxes) is static bodies with colliders.
//! Pairs of bodies that are never tested: the same body; two bodies that
//! are both static or kinematic; pairs excluded by [`Collisions::exclude`]
//! (a ragdoll's jointed pairs: `Ragdoll::non_colliding_pairs`); pairs
//! whose [`CollisionGroups`] do not match (set per collider, per body with
//! [`Collisions::set_body_groups`], per ragdoll with
//! [`Collisions::set_ragdoll_groups`]); and two bodies of one ragdoll whose
//! self-collision is off ([`Collisions::set_ragdoll_self_collision`]).
//!
//! A ragdoll comes in and goes out with its colliders in one call:
//! [`Collisions::build_ragdoll`] builds it in the world and adds its
//! capsules, [`Collisions::remove_ragdoll`] removes its bodies, joints and
//! colliders. Removal is the set's business too: a body's colliders go
//! with [`Collisions::remove_body`] (before or after `World::remove_body`). A collider whose body is gone makes
//! [`Collisions::find_contacts`] refuse with [`Error::Collider`], naming the
//! collider and its body. The set is saved and restored alongside the world
//! with [`Collisions::snapshot`] and [`Collisions::restore`].
//!
//! A set serves one world's run of states (its `Timeline`): a world that
//! restored a snapshot is refused ([`Error::WorldMismatch`]) until the
//! set's own snapshot taken with the world's is restored after it, and a
//! set's snapshot is refused for a world whose bodies are not those it was
//! taken with. Restore both, the world first; [`Collisions::attach`]
//! declares a set right for a world as it is.
//!
//! # Quick start: a game's frame
//!
//! What a game wires in, from the switch to physics to a limb torn off
//! (`README.md` shows the same example; `docs/contacts.md` and
//! `docs/joints.md` say why each setting is what it is):
//!
//! ```
//! use glam::{Quat, Vec3};
//! use vertebra_collide::{Collider, ColliderShape, Collisions, QueryFilter};
//! use vertebra_ragdoll::{
//!     BuildOptions, DriveSettings, RagdollDesc, Skeleton, SkeletonMapper, SpineMapping,
//!     SpineMode, Transform, Transition,
//! };
//! use vertebra_world::{BodyDesc, Shape, SolverConfig, Spring, World};
//!
//! # fn main() -> Result<(), vertebra_ragdoll::RagdollError> {
//! // The world's default: every joint of a ragdoll solved at once (exact
//! // through long chains and heavy hands), one substep of eight iterations,
//! // contacts relaxed, islands that fall asleep.
//! let mut world = World::new(SolverConfig::default())?;
//! let mut collisions = Collisions::new();
//!
//! // The level: a ground plane and a wall 10 cm thick, static.
//! let ground = world.add_body(BodyDesc::fixed())?;
//! collisions.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))?;
//! let wall = world.add_body(BodyDesc::fixed().with_position(Vec3::new(1.5, 1.0, 0.0)))?;
//! let slab = Shape::Box { half_extents: Vec3::new(0.05, 1.0, 2.0) };
//! collisions.add(Collider::new(wall, ColliderShape::Solid(slab)))?;
//!
//! // The switch from animation: the engine's skeleton (63 bones) at its
//! // last two frames maps onto the ragdoll's bodies, which are built there
//! // with the animation's velocities, joints made at that pose (no pop).
//! let skeleton = Skeleton::reference();
//! let mut desc = RagdollDesc::reference_humanoid();
//! // The left elbow tears past 2 kN (a description file says it with
//! // `break_force = 2000.0` on the joint).
//! let elbow = desc.joint_index("elbow_l").expect("an elbow");
//! desc.joints[elbow].breaking = Some(vertebra_world::JointBreaking {
//!     force: 2000.0,
//!     torque: f32::INFINITY,
//! });
//! let mapper = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod)?;
//! let place = Transform::new(Vec3::ZERO, Quat::IDENTITY);
//! let dt = 1.0 / 60.0;
//! let previous = skeleton.bind_pose();
//! let mut current = previous.clone();
//! current.bones[0].translation.x += 0.05; // stumbling toward the wall
//! let bodies = |pose: &vertebra_ragdoll::LocalPose| {
//!     mapper.map_to_ragdoll(&pose.to_model(&skeleton)?, place)
//! };
//! let (now, before) = (bodies(&current)?, bodies(&previous)?);
//! let options = BuildOptions::at_switch(SpineMode::Rod);
//! let ragdoll = collisions.build_ragdoll(&mut world, &desc, options, &now, Some((&before, dt)))?;
//! let transition =
//!     Transition::new(&mapper, &ragdoll, &world, &current, place, SpineMapping::Arc, 0.3)?;
//! // Muscles: powered toward the animation's pose, weak enough to yield.
//! ragdoll.drive_to(&mut world, &now, &DriveSettings::uniform(Spring::compliant(1e-2)))?;
//!
//! let (mut thuds, mut torn) = (0, false);
//! for frame in 1..=120 {
//!     // The whole frame: contacts found, the step, fast limbs kept out
//!     // of the wall, the contact events, the query tree.
//!     collisions.step(&mut world, dt)?;
//!     // Which bone hit the floor how hard: a thud per bone.
//!     for hit in collisions.events().began() {
//!         if let (true, Some(part)) = (hit.body_a == ground, hit.part_b) {
//!             let bone = &desc.bodies[part.bone as usize].name;
//!             assert!(hit.impulse > 0.0 && !bone.is_empty());
//!             thuds += 1;
//!         }
//!     }
//!     if frame == 30 {
//!         // A bullet at the chest: the bone it hits, where, and its push.
//!         let chest = ragdoll.bodies[desc.body_index("chest").expect("a chest")]
//!             .expect("a body");
//!         let aim = world.body(chest)?.position;
//!         let hit = collisions.shoot(
//!             &mut world,
//!             aim - Vec3::X * 3.0,
//!             Vec3::X,
//!             10.0,
//!             30.0, // N s
//!             &QueryFilter::default(),
//!         )?;
//!         let part = hit.and_then(|h| h.part).expect("a bone was hit");
//!         assert_eq!(Some(part.ragdoll), ragdoll.first_body());
//!         // Then the left forearm yanked hard (120 N s): the elbow tears
//!         // in the next frame's step.
//!         let forearm = ragdoll.bodies[desc.body_index("forearm_l").expect("a forearm")]
//!             .expect("a body");
//!         world.apply_impulse(forearm, Vec3::new(0.0, 120.0, 0.0))?;
//!     }
//!     for broken in world.broken_joints() {
//!         assert_eq!(Some(broken.joint), ragdoll.joints[elbow]);
//!         assert!(frame > 30, "torn by the yank, not before");
//!         torn = true;
//!     }
//!     // The engine's skeleton read back, every one of its bones.
//!     let since = frame as f32 * dt;
//!     let pose = transition.skeleton_pose(&mapper, &ragdoll, &world, &current, place, since)?;
//!     assert_eq!(pose.bones.len(), skeleton.bones().len());
//! }
//! assert!(thuds > 0 && torn);
//! # Ok(())
//! # }
//! ```

mod continuous;
mod events;
mod frame;
mod groups;
mod pairing;
mod query;
mod snapshot;

use std::collections::{HashMap, HashSet};
use vertebra_math::PortableQuat;

use glam::{Quat, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::query::{
    ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher, TrackedContact,
};
use parry3d::shape::{
    PackedFeatureId, PolygonalFeature, Shape as ParryShape, ShapeType, SharedShape,
};
use vertebra_math::DefaultFloatMode;
use vertebra_ragdoll::{BuildOptions, Ragdoll, RagdollDesc, RagdollError};
use vertebra_world::{
    BodyHandle, BodyKind, Contact, Error, MAX_COORDINATE, Shape, Timeline, World,
};

pub use events::{ContactEnded, ContactEvents, Touching};
pub use groups::MAX_SELF_COLLISION_GROUPS;
pub use query::{Overlap, QueryFilter, QueryHit, QueryShape};
pub use snapshot::CollisionSnapshot;

/// The ragdoll part of each body the set knows as a ragdoll's, by slot
/// (looked up for every hit and every touching pair: an index and a
/// handle compare, no hashing).
#[derive(Clone, Debug, Default)]
pub(crate) struct Parts {
    by_slot: Vec<Option<(BodyHandle, RagdollPart)>>,
}

impl Parts {
    /// `body`'s part, if the set knows it.
    pub(crate) fn get(&self, body: BodyHandle) -> Option<RagdollPart> {
        match self.by_slot.get(body.index()) {
            Some(Some((b, part))) if *b == body => Some(*part),
            _ => None,
        }
    }

    /// Records `body`'s part.
    pub(crate) fn insert(&mut self, body: BodyHandle, part: RagdollPart) {
        if self.by_slot.len() <= body.index() {
            self.by_slot.resize(body.index() + 1, None);
        }
        self.by_slot[body.index()] = Some((body, part));
    }

    /// Forgets `body`'s part (nothing to forget is not an error).
    pub(crate) fn remove(&mut self, body: BodyHandle) {
        if self.get(body).is_some() {
            self.by_slot[body.index()] = None;
        }
    }

    /// Every body's part, in slot order.
    pub(crate) fn iter(&self) -> impl Iterator<Item = (BodyHandle, RagdollPart)> + '_ {
        self.by_slot.iter().flatten().copied()
    }
}

/// Which ragdoll and bone a body is, in hits and events.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct RagdollPart {
    /// The ragdoll, named by its first body (`Ragdoll::first_body`).
    pub ragdoll: BodyHandle,
    /// The body's index in the ragdoll's description
    /// (`Ragdoll::description().bodies[bone]`, whose `name` is the
    /// bone's).
    pub bone: u32,
}

/// Which colliders may touch (Rapier's `InteractionGroups`): a pair is
/// tested when each one's `membership` meets the other's `filter` (both
/// bit sets): `a.membership & b.filter != 0 && b.membership & a.filter !=
/// 0`. The default is every group, colliding with every group.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct CollisionGroups {
    /// The groups this collider is in.
    pub membership: u32,
    /// The groups it collides with.
    pub filter: u32,
}

impl Default for CollisionGroups {
    fn default() -> Self {
        Self {
            membership: u32::MAX,
            filter: u32::MAX,
        }
    }
}

/// A collider's geometry, in its body's frame (centred on the centre of
/// mass, as the store's shapes are).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ColliderShape {
    /// A body shape: sphere, box or capsule.
    Solid(Shape),
    /// The half space below the plane through the body's origin with the
    /// given outward unit normal (body frame): the ground.
    Plane(Vec3),
}

/// A collider on a body.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Collider {
    /// The body it moves with.
    pub body: BodyHandle,
    /// Its geometry.
    pub shape: ColliderShape,
    /// Friction coefficient (a pair uses the geometric mean).
    pub friction: f32,
    /// Restitution (a pair uses the larger).
    pub restitution: f32,
    /// Filtering.
    pub groups: CollisionGroups,
}

impl Collider {
    /// A collider of `shape` on `body`, friction 0.6, no restitution, in
    /// every group.
    pub fn new(body: BodyHandle, shape: ColliderShape) -> Self {
        Self {
            body,
            shape,
            friction: 0.6,
            restitution: 0.0,
            groups: CollisionGroups::default(),
        }
    }

    /// Its parry geometry (body frame), or why it is refused: a degenerate
    /// shape or one beyond [`MAX_COLLIDER_EXTENT`], a non-unit plane
    /// normal, bad friction or restitution.
    fn geometry(&self) -> Result<SharedShape, Error> {
        let shape = match self.shape {
            ColliderShape::Solid(s) => solid(s)?,
            ColliderShape::Plane(n) => {
                vertebra_world::check_unit_vec("plane normal", n)?;
                SharedShape::halfspace(n.normalize())
            }
        };
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(Error::NonPositive("collider friction"));
        }
        if !(0.0..=1.0).contains(&self.restitution) {
            return Err(Error::OutOfRange("collider restitution (0 to 1)"));
        }
        Ok(shape)
    }

    /// `reason` as the refusal of this collider at `index`.
    fn refused(&self, index: usize, reason: Error) -> Error {
        Error::Collider {
            index,
            body: self.body,
            reason: Box::new(reason),
        }
    }
}

/// The parry geometry of a solid (body frame), or why it is refused: a
/// degenerate shape or one beyond [`MAX_COLLIDER_EXTENT`].
fn solid(shape: Shape) -> Result<SharedShape, Error> {
    shape.validate()?;
    check_extent(&shape)?;
    Ok(match shape {
        Shape::Sphere { radius } => SharedShape::ball(radius),
        Shape::Box { half_extents: h } => SharedShape::cuboid(h.x, h.y, h.z),
        Shape::Capsule {
            half_segment,
            radius,
        } => SharedShape::capsule(-half_segment, half_segment, radius),
    })
}

/// The largest size (m) of a collider: a sphere's radius, a box's half
/// extent, a capsule's half segment plus radius. 10 km is larger than any
/// level's floor, and at 1e4 m an `f32` still resolves a millimetre; far
/// beyond it parry's contact points are no longer finite (1e30 gave NaN).
pub const MAX_COLLIDER_EXTENT: f32 = 1.0e4;

/// Checks a solid's size against [`MAX_COLLIDER_EXTENT`] (after
/// `Shape::validate`: finite and positive).
fn check_extent(shape: &Shape) -> Result<(), Error> {
    let extent = match *shape {
        Shape::Sphere { radius } => radius,
        Shape::Box { half_extents } => half_extents.max_element(),
        Shape::Capsule {
            half_segment,
            radius,
        } => half_segment.length() + radius,
    };
    if extent > MAX_COLLIDER_EXTENT {
        return Err(Error::OutOfRange("collider size (at most 1e4 m)"));
    }
    Ok(())
}

/// Checks a prediction margin (m): finite, not negative.
fn check_prediction(prediction: f32) -> Result<(), Error> {
    if !prediction.is_finite() {
        return Err(Error::NonFinite("collision prediction"));
    }
    if prediction < 0.0 {
        return Err(Error::NonPositive("collision prediction"));
    }
    Ok(())
}

/// All colliders and the rules for which pairs are tested.
#[derive(Clone, Default)]
pub struct Collisions {
    colliders: Vec<(Collider, SharedShape)>,
    excluded: HashSet<(BodyHandle, BodyHandle)>,
    prediction: f32,
    /// Bodies of ragdolls whose self-collision is off, each with its
    /// ragdoll's group: two bodies of one group are never tested.
    apart: HashMap<BodyHandle, u64>,
    /// The group the next ragdoll whose self-collision goes off gets.
    next_apart: u64,
    /// The ragdoll and bone of every ragdoll body the set added
    /// (`build_ragdoll`, `add_ragdoll`).
    parts: Parts,
    /// The pairs of bodies touching after the last step the events saw,
    /// in ascending order (`events.rs`).
    touching: Vec<(BodyHandle, BodyHandle)>,
    /// Counts every change to the colliders (added, removed, moved to
    /// other bodies, restored): with the world's, when the query tree and
    /// a detection's record still hold. Not part of the set's state.
    version: u64,
    /// What the last `find_contacts_into` found, for `after_step`
    /// (`frame.rs`). Not part of the set's state.
    found: frame::Found,
    /// The last step's events (`events.rs`). Output, not state.
    events: ContactEvents,
    /// The scene queries' tree (`query.rs`). Not part of the set's state.
    tree: query::QueryTree,
    /// The list [`Collisions::step`] finds contacts into (working memory).
    frame_contacts: Vec<Contact>,
    /// Scratch of continuous collision: the bodies it puts back.
    moves: Vec<(BodyHandle, Vec3, Quat)>,
    /// Scratch of continuous collision: the static solids, their bounds
    /// and poses.
    statics: Vec<(usize, Aabb, Pose)>,
    /// The world's run of states the set serves, once it has served one
    /// (`pairing.rs`). Not part of the set's state: never saved; a clone
    /// serves the same world.
    serves: Option<Timeline>,
    /// Working memory of [`Collisions::find_contacts_into`] (not part of
    /// the set's state: never saved, and a clone's starts empty in effect,
    /// as every call rewrites it).
    scratch: Detection,
}

/// A detection's working memory, kept between calls so that a steady
/// scene's detection allocates nothing.
#[derive(Clone, Default)]
struct Detection {
    /// Each collider's body pose.
    poses: Vec<Pose>,
    /// How far each collider's body can move in the step (m).
    reach: Vec<f32>,
    /// Each collider's bounds, loosened by the prediction and its reach.
    aabbs: Vec<Aabb>,
    /// The solid colliders in sweep order.
    solids: Vec<usize>,
    /// The candidate pairs of collider indices, ascending.
    pairs: Vec<(usize, usize)>,
    /// Parry's output for one pair.
    manifolds: Vec<ContactManifold<(), ()>>,
    /// Each collider's body moves on its own (awake and dynamic, or
    /// kinematic with a velocity).
    acts: Vec<bool>,
    /// Each collider's body's island while it sleeps, else `NO_ISLAND`.
    asleep_in: Vec<u32>,
    /// Per island id: [`UNTOUCHED`], [`WAKING`] (touched by the last
    /// round's contacts: its pairs are found in this round) or [`DONE`].
    islands: Vec<u8>,
}

/// A collider whose body does not sleep.
const NO_ISLAND: u32 = u32::MAX;
const UNTOUCHED: u8 = 0;
const WAKING: u8 = 1;
const DONE: u8 = 2;

/// Makes `manifolds` what parry gets for a new pair (at most one manifold,
/// as new: every query starts from the same state, whatever pair came
/// before) while keeping its points' memory: our colliders are convex, so
/// parry fills exactly the first manifold, and a manifold's normal seeds
/// its search (a reused one would change contacts).
fn fresh(manifolds: &mut Vec<ContactManifold<(), ()>>) {
    manifolds.truncate(1);
    if let Some(m) = manifolds.first_mut() {
        let mut points = core::mem::take(&mut m.points);
        points.clear();
        *m = ContactManifold {
            points,
            ..ContactManifold::new()
        };
    }
}

fn ordered(a: BodyHandle, b: BodyHandle) -> (BodyHandle, BodyHandle) {
    if a.index() <= b.index() {
        (a, b)
    } else {
        (b, a)
    }
}

impl Collisions {
    /// No colliders yet; a 1 cm prediction margin.
    pub fn new() -> Self {
        Self {
            prediction: 0.01,
            ..Self::default()
        }
    }

    /// The prediction margin (m): contacts are made for gaps up to this
    /// size too, on top of how far each body can move in the step (see
    /// [`Collisions::find_contacts`]).
    pub fn prediction(&self) -> f32 {
        self.prediction
    }

    /// Sets the prediction margin (m, finite, not negative); `Err` (and no
    /// change) otherwise.
    pub fn set_prediction(&mut self, margin: f32) -> Result<(), Error> {
        check_prediction(margin)?;
        self.prediction = margin;
        Ok(())
    }

    /// Adds a collider; returns its index in [`Collisions::colliders`]
    /// (until a collider before it is removed). `Err(Error::Collider)`,
    /// naming the index it would have had and its body, for a degenerate
    /// shape or one beyond [`MAX_COLLIDER_EXTENT`], a non-unit plane normal
    /// or bad friction and restitution. Its
    /// body must be live in the world the set is used with when contacts
    /// are found.
    pub fn add(&mut self, collider: Collider) -> Result<usize, Error> {
        let _mode = DefaultFloatMode::enter();
        let index = self.colliders.len();
        let shape = collider
            .geometry()
            .map_err(|e| collider.refused(index, e))?;
        self.colliders.push((collider, shape));
        self.version += 1;
        Ok(index)
    }

    /// Adds a solid collider per `(body, shape)` (default friction and
    /// groups) and never tests the `excluded` pairs: how a ragdoll joins
    /// (see [`Collisions::add_ragdoll`]). All or nothing: every collider is
    /// checked before any is added; the first refused is named.
    pub fn add_jointed(
        &mut self,
        shapes: &[(BodyHandle, Shape)],
        excluded: &[(BodyHandle, BodyHandle)],
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        let start = self.colliders.len();
        let checked = shapes
            .iter()
            .enumerate()
            .map(|(k, &(body, shape))| {
                let collider = Collider::new(body, ColliderShape::Solid(shape));
                let geometry = collider.geometry();
                geometry
                    .map(|g| (collider, g))
                    .map_err(|e| collider.refused(start + k, e))
            })
            .collect::<Result<Vec<_>, _>>()?;
        self.colliders.extend(checked);
        self.version += 1;
        for &(a, b) in excluded {
            self.exclude(a, b);
        }
        Ok(())
    }

    /// Adds a ragdoll's capsules (one per body, default friction and
    /// groups), its jointed pairs never tested. All or nothing; a removed
    /// ragdoll (which has no bodies to add) is refused, naming it
    /// (`RagdollError::Removed`).
    pub fn add_ragdoll(&mut self, ragdoll: &Ragdoll) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        ragdoll.check_not_removed()?;
        self.add_jointed(&ragdoll.collision_shapes(), &ragdoll.non_colliding_pairs())?;
        self.register_parts(ragdoll);
        Ok(())
    }

    /// Builds a ragdoll in `world` (see `Ragdoll::build`) and adds its
    /// capsules to this set (as [`Collisions::add_ragdoll`]: one per body,
    /// default friction and groups, jointed pairs never tested), in one
    /// call: how a ragdoll joins a world with collision detection. All or
    /// nothing: every capsule is checked as a collider before the build,
    /// and a refused build leaves the world as it was, so on error the
    /// world and the set are unchanged (the error names the body); refused
    /// too for a world the set does not serve (`WorldMismatch`, see
    /// [`Collisions::attach`]). Its inverse is [`Collisions::remove_ragdoll`].
    pub fn build_ragdoll(
        &mut self,
        world: &mut World,
        desc: &RagdollDesc,
        options: BuildOptions,
        pose: &vertebra_ragdoll::Pose,
        previous: Option<(&vertebra_ragdoll::Pose, f32)>,
    ) -> Result<Ragdoll, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.check_serves(world).map_err(unserved)?;
        let geometries = desc
            .bodies
            .iter()
            .map(|def| {
                solid(def.shape()).map_err(|e| RagdollError::World {
                    context: format!("body `{}` as a collider", def.name),
                    error: e,
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let ragdoll = Ragdoll::build(world, desc, options, pose, previous)?;
        for ((body, def), geometry) in ragdoll.bodies.iter().zip(&desc.bodies).zip(geometries) {
            if let Some(body) = *body {
                let collider = Collider::new(body, ColliderShape::Solid(def.shape()));
                self.colliders.push((collider, geometry));
            }
        }
        for (a, b) in ragdoll.non_colliding_pairs() {
            self.exclude(a, b);
        }
        self.version += 1;
        self.register_parts(&ragdoll);
        self.serve(world);
        Ok(ragdoll)
    }

    /// Removes a ragdoll from `world` (its joints and bodies, see
    /// `Ragdoll::remove`) and its bodies' colliders, excluded pairs and
    /// self-collision setting from this set, in one call: the inverse of
    /// [`Collisions::build_ragdoll`] (and of `Ragdoll::build` followed by
    /// [`Collisions::add_ragdoll`]). All or nothing: when the ragdoll cannot be
    /// removed (a body or joint already gone, a body held by another
    /// joint), or the set does not serve `world` (`WorldMismatch`), the
    /// world, the set and the ragdoll are unchanged.
    pub fn remove_ragdoll(
        &mut self,
        world: &mut World,
        ragdoll: &mut Ragdoll,
    ) -> Result<(), RagdollError> {
        self.check_serves(world).map_err(unserved)?;
        let bodies: Vec<BodyHandle> = ragdoll.bodies.iter().flatten().copied().collect();
        ragdoll.remove(world)?;
        for body in bodies {
            self.remove_body(body);
        }
        self.serve(world);
        Ok(())
    }

    /// Re-creates a ragdoll at `pose` (see `Ragdoll::recreate`) and moves
    /// its colliders, excluded pairs and self-collision setting from the
    /// old bodies to the new ones (friction, groups and any extra
    /// colliders kept, in their places in the set). All or nothing, as
    /// `Ragdoll::recreate`; refused with nothing changed for a world the
    /// set does not serve (`WorldMismatch`).
    pub fn recreate_ragdoll(
        &mut self,
        world: &mut World,
        ragdoll: &mut Ragdoll,
        pose: &vertebra_ragdoll::Pose,
        previous: Option<(&vertebra_ragdoll::Pose, f32)>,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.check_serves(world).map_err(unserved)?;
        let old = ragdoll.bodies.clone();
        ragdoll.recreate(world, pose, previous)?;
        let moved: HashMap<BodyHandle, BodyHandle> = old
            .iter()
            .zip(&ragdoll.bodies)
            .filter_map(|(&from, &to)| Some((from?, to?)))
            .collect();
        let to = |body: BodyHandle| moved.get(&body).copied().unwrap_or(body);
        for (collider, _) in &mut self.colliders {
            collider.body = to(collider.body);
        }
        self.excluded = self
            .excluded
            .iter()
            .map(|&(a, b)| ordered(to(a), to(b)))
            .collect();
        self.apart = self.apart.iter().map(|(&b, &g)| (to(b), g)).collect();
        let moved_parts: Vec<_> = (self.parts.iter())
            .map(|(b, p)| {
                let part = RagdollPart {
                    ragdoll: to(p.ragdoll),
                    bone: p.bone,
                };
                (to(b), part)
            })
            .collect();
        self.parts = Parts::default();
        for (body, part) in moved_parts {
            self.parts.insert(body, part);
        }
        self.version += 1;
        self.serve(world);
        Ok(())
    }

    /// Never tests the pair `(a, b)` (e.g. a joint's two bodies).
    pub fn exclude(&mut self, a: BodyHandle, b: BodyHandle) {
        self.excluded.insert(ordered(a, b));
    }

    /// The colliders.
    pub fn colliders(&self) -> impl Iterator<Item = &Collider> {
        self.colliders.iter().map(|c| &c.0)
    }

    /// The colliders with their parry geometry (body frame), for handing
    /// the same shapes to another engine.
    pub fn shapes(&self) -> impl Iterator<Item = (&Collider, &SharedShape)> {
        self.colliders.iter().map(|(c, s)| (c, s))
    }

    /// Whether the pair `(a, b)` is never tested (either order).
    pub fn is_excluded(&self, a: BodyHandle, b: BodyHandle) -> bool {
        self.excluded.contains(&ordered(a, b))
    }

    /// Forgets the colliders, excluded pairs and self-collision setting of
    /// `body` (before or after removing it from the world); the colliders
    /// after them move down in [`Collisions::colliders`]. Nothing to forget
    /// is not an error.
    pub fn remove_body(&mut self, body: BodyHandle) {
        self.colliders.retain(|c| c.0.body != body);
        self.excluded.retain(|&(a, b)| a != body && b != body);
        self.apart.remove(&body);
        self.parts.remove(body);
        self.version += 1;
    }

    /// Records `ragdoll`'s bodies as its parts (hits and events name them
    /// by it).
    fn register_parts(&mut self, ragdoll: &Ragdoll) {
        let Some(first) = ragdoll.first_body() else {
            return;
        };
        for (bone, body) in ragdoll.bodies.iter().enumerate() {
            if let Some(body) = *body {
                let bone = bone as u32;
                self.parts.insert(
                    body,
                    RagdollPart {
                        ragdoll: first,
                        bone,
                    },
                );
            }
        }
    }

    /// Every contact between the colliders at the bodies' current poses, in
    /// a deterministic order; feed them to `World::set_contacts` before a
    /// step of `dt` seconds. Contacts are speculative: a pair is caught up
    /// to `prediction` plus how far its bodies can close in within `dt`
    /// (linear speed plus angular speed times the collider's extent), so a
    /// fast body meets the floor instead of passing into it; a gap does
    /// nothing until it closes. `Err(Error::Collider)` names the first
    /// collider whose body is no longer in `world` (remove a body's
    /// colliders with [`Collisions::remove_body`]); `Err(WorldMismatch)`
    /// for a world the set does not serve: one that restored a snapshot
    /// since without the set's own restored after it, or another world
    /// (see [`Collisions::attach`]). Allocates its list and
    /// working memory every call: a game's loop uses
    /// [`Collisions::find_contacts_into`].
    pub fn find_contacts(&self, world: &World, dt: f32) -> Result<Vec<Contact>, Error> {
        let _mode = DefaultFloatMode::enter();
        let mut contacts = Vec::new();
        self.detect(world, dt, &mut Detection::default(), &mut contacts)?;
        Ok(contacts)
    }

    /// [`Collisions::find_contacts`] into `contacts` (emptied first, and
    /// empty on error), with the set's own working memory (bounds, sweep
    /// order, pairs, parry's manifolds) kept from call to call: once it and
    /// `contacts` have grown to the scene's size, a call allocates nothing.
    /// Hand the list to the world without a copy with
    /// `World::swap_contacts`, which gives back the world's previous
    /// list for the next call.
    pub fn find_contacts_into(
        &mut self,
        world: &World,
        dt: f32,
        contacts: &mut Vec<Contact>,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        // Taken out and put back (moving a vector allocates nothing), so
        // that the detection reads the set while it writes its memory.
        let mut scratch = core::mem::take(&mut self.scratch);
        let found = self.detect(world, dt, &mut scratch, contacts);
        self.scratch = scratch;
        if found.is_ok() {
            self.serve(world);
            let mut record = core::mem::take(&mut self.found);
            record.record(self, world, contacts);
            self.found = record;
        }
        found
    }

    /// Every contact into `contacts` (emptied first), with `scratch` as
    /// working memory.
    fn detect(
        &self,
        world: &World,
        dt: f32,
        scratch: &mut Detection,
        contacts: &mut Vec<Contact>,
    ) -> Result<(), Error> {
        contacts.clear();
        self.check_serves(world)?;
        vertebra_world::check_positive("time step", dt)?;
        self.sleep_state(world, scratch)?;
        if !scratch.acts.contains(&true) {
            // Every body asleep or still (a settled pile): no pair has a
            // body that moves, so no bounds, sweep or round is needed.
            return Ok(());
        }
        scratch.poses.clear();
        scratch.reach.clear();
        for (index, (c, shape)) in self.colliders.iter().enumerate() {
            let s = world.body(c.body).map_err(|e| c.refused(index, e))?;
            scratch
                .poses
                .push(Pose::from_parts(s.position, s.orientation));
            let extent = shape.compute_local_bounding_sphere().radius;
            let extent = if extent.is_finite() { extent } else { 0.0 };
            scratch
                .reach
                .push((s.linear_velocity.length() + s.angular_velocity.length() * extent) * dt);
        }
        self.bounds(scratch);
        // Pairs where a body moves; then, round after round, the pairs of
        // the sleeping islands those contacts touch (the step wakes them,
        // and they need their contacts with the ground and each other).
        let mut first = true;
        loop {
            self.candidate_pairs(world, scratch, first);
            first = false;
            let from = contacts.len();
            self.narrow(scratch, contacts);
            if !wake_touched(scratch, world, &contacts[from..]) {
                return Ok(());
            }
        }
    }

    /// Each collider's body's sleep state into `scratch`.
    fn sleep_state(&self, world: &World, scratch: &mut Detection) -> Result<(), Error> {
        scratch.acts.clear();
        scratch.asleep_in.clear();
        scratch.islands.clear();
        for (index, (c, _)) in self.colliders.iter().enumerate() {
            let refused = |e| c.refused(index, e);
            let s = world.body(c.body).map_err(refused)?;
            let asleep = world.is_asleep(c.body).map_err(refused)?;
            let moving = s.linear_velocity != Vec3::ZERO || s.angular_velocity != Vec3::ZERO;
            scratch
                .acts
                .push(match world.bodies().kind[c.body.index()] {
                    BodyKind::Dynamic => !asleep,
                    BodyKind::Kinematic => moving,
                    BodyKind::Static => false,
                });
            let island = world.island(c.body).map_err(refused)?.filter(|_| asleep);
            let island = island.unwrap_or(NO_ISLAND);
            if island != NO_ISLAND && scratch.islands.len() <= island as usize {
                scratch.islands.resize(island as usize + 1, UNTOUCHED);
            }
            scratch.asleep_in.push(island);
        }
        Ok(())
    }

    /// Every pair's contacts into `contacts` (appended).
    fn narrow(&self, scratch: &mut Detection, contacts: &mut Vec<Contact>) {
        let (poses, reach) = (&scratch.poses, &scratch.reach);
        for &(i, j) in &scratch.pairs {
            let ((ci, si), (cj, sj)) = (&self.colliders[i], &self.colliders[j]);
            fresh(&mut scratch.manifolds);
            let relative = relative_pose(&poses[i], &poses[j]);
            let prediction = self.prediction + reach[i] + reach[j];
            let on_plane = plane_manifold(
                &relative,
                si.as_ref(),
                sj.as_ref(),
                prediction,
                &mut scratch.manifolds,
            );
            if !on_plane
                && DefaultQueryDispatcher
                    .contact_manifolds(
                        &relative,
                        si.as_ref(),
                        sj.as_ref(),
                        prediction,
                        &mut scratch.manifolds,
                        &mut None,
                    )
                    .is_err()
            {
                continue; // a pair parry has no algorithm for (none of ours)
            }
            let friction = (ci.friction * cj.friction).sqrt();
            let restitution = ci.restitution.max(cj.restitution);
            for m in &scratch.manifolds {
                push_manifold(
                    contacts,
                    m,
                    (ci.body, &poses[i]),
                    (cj.body, &poses[j]),
                    friction,
                    restitution,
                );
            }
        }
    }

    /// Each collider's bounds, and the solids in sweep order.
    fn bounds(&self, scratch: &mut Detection) {
        let (poses, reach) = (&scratch.poses, &scratch.reach);
        scratch.aabbs.clear();
        scratch.aabbs.extend((0..self.colliders.len()).map(|k| {
            self.colliders[k]
                .1
                .compute_aabb(&poses[k])
                .loosened(self.prediction + reach[k])
        }));
        let aabbs = &scratch.aabbs;
        let is_plane = |k: usize| matches!(self.colliders[k].0.shape, ColliderShape::Plane(_));
        let solids = &mut scratch.solids;
        solids.clear();
        solids.extend((0..self.colliders.len()).filter(|&k| !is_plane(k)));
        // Unstable but in place (no buffer): the index breaks ties, so the
        // order is the one a stable sort gives.
        solids
            .sort_unstable_by(|&a, &b| aabbs[a].mins.x.total_cmp(&aabbs[b].mins.x).then(a.cmp(&b)));
    }

    /// Into `scratch.pairs`, the pairs of collider indices whose bounds
    /// overlap and that may collide (sort-and-sweep along x for solids,
    /// every solid against every plane), of this round: in the `first`,
    /// those with a body that moves on its own; in each later one, those
    /// of the islands the last round woke (and of no island woken before).
    fn candidate_pairs(&self, world: &World, scratch: &mut Detection, first: bool) {
        let (aabbs, solids) = (&scratch.aabbs, &scratch.solids);
        let is_plane = |k: usize| matches!(self.colliders[k].0.shape, ColliderShape::Plane(_));
        let pairs = &mut scratch.pairs;
        pairs.clear();
        for (n, &a) in solids.iter().enumerate() {
            for &b in &solids[n + 1..] {
                if aabbs[b].mins.x > aabbs[a].maxs.x {
                    break;
                }
                if aabbs[a].intersects(&aabbs[b]) {
                    pairs.push((a.min(b), a.max(b)));
                }
            }
        }
        for plane in (0..self.colliders.len()).filter(|&k| is_plane(k)) {
            pairs.extend(solids.iter().map(|&s| (plane.min(s), plane.max(s))));
        }
        let (acts, asleep_in, islands) = (&scratch.acts, &scratch.asleep_in, &scratch.islands);
        let mark = |k: usize| {
            let island = asleep_in[k];
            (island != NO_ISLAND).then(|| islands[island as usize])
        };
        let in_round = |a: usize, b: usize| {
            if first {
                return acts[a] || acts[b];
            }
            let (ma, mb) = (mark(a), mark(b));
            !(acts[a] || acts[b])
                && (ma == Some(WAKING) || mb == Some(WAKING))
                && ma != Some(DONE)
                && mb != Some(DONE)
        };
        pairs.retain(|&(a, b)| in_round(a, b) && self.may_collide(world, a, b));
        pairs.sort_unstable();
    }

    fn may_collide(&self, world: &World, a: usize, b: usize) -> bool {
        let (ca, cb) = (&self.colliders[a].0, &self.colliders[b].0);
        let dynamic = |h: BodyHandle| world.bodies().kind[h.index()] == BodyKind::Dynamic;
        ca.body != cb.body
            && (dynamic(ca.body) || dynamic(cb.body))
            && !self.excluded.contains(&ordered(ca.body, cb.body))
            && ca.groups.membership & cb.groups.filter != 0
            && cb.groups.membership & ca.groups.filter != 0
            && !self.kept_apart(ca.body, cb.body)
    }
}

/// Marks the sleeping islands `found` touches (the step will wake them) as
/// waking, and those that were waking as done; true when any island is
/// newly waking.
fn wake_touched(scratch: &mut Detection, world: &World, found: &[Contact]) -> bool {
    for mark in &mut scratch.islands {
        if *mark == WAKING {
            *mark = DONE;
        }
    }
    // The contacts' bodies are live: they were just read.
    let marks = scratch.islands.len();
    let island_of = |body: BodyHandle| {
        let asleep = world.is_asleep(body).unwrap_or(false);
        let island = world.island(body).ok().flatten().filter(|_| asleep)?;
        Some(island as usize).filter(|&k| k < marks)
    };
    let mut woke = false;
    for c in found {
        for island in [island_of(c.body_a), island_of(c.body_b)]
            .into_iter()
            .flatten()
        {
            if scratch.islands[island] == UNTOUCHED {
                scratch.islands[island] = WAKING;
                woke = true;
            }
        }
    }
    woke
}

/// `b` in `a`'s frame: parry's `a.inv_mul(b)`, with the rotations composed
/// by [`PortableQuat::mul_portable`] (glam's product has other bits on
/// other targets) and the translation turned as parry turns it (`Quat *
/// Vec3`, the same bits everywhere).
pub(crate) fn relative_pose(a: &Pose, b: &Pose) -> Pose {
    let turn = a.rotation.inverse();
    Pose::from_parts(
        turn * (b.translation - a.translation),
        turn.mul_portable(b.rotation),
    )
}

/// A half space against a box or capsule (the ground under a body), into
/// `manifolds[0]`; false (nothing done) for any other pair. This is parry's
/// `contact_manifold_halfspace_pfm` (0.31), which its dispatcher runs for
/// these pairs, step for step (so the contacts are its bits), except that
/// it writes into the manifold's point vector instead of a new one: parry
/// takes the old vector away every call (to carry impulses over, which we
/// do not keep), which cost an allocation per body on the ground per frame.
fn plane_manifold(
    pos12: &Pose,
    shape1: &dyn ParryShape,
    shape2: &dyn ParryShape,
    prediction: f32,
    manifolds: &mut Vec<ContactManifold<(), ()>>,
) -> bool {
    let polygonal =
        |s: &dyn ParryShape| matches!(s.shape_type(), ShapeType::Cuboid | ShapeType::Capsule);
    let (pos12, halfspace, (pfm, border_radius), flipped) =
        match (shape1.as_halfspace(), shape2.as_halfspace()) {
            (Some(h), None) if polygonal(shape2) => match shape2.as_polygonal_feature_map() {
                Some(p) => (*pos12, h, p, false),
                None => return false,
            },
            (None, Some(h)) if polygonal(shape1) => match shape1.as_polygonal_feature_map() {
                Some(p) => (pos12.inverse(), h, p, true),
                None => return false,
            },
            _ => return false,
        };
    if manifolds.is_empty() {
        manifolds.push(ContactManifold::new());
    }
    let manifold = &mut manifolds[0];
    let normal1_2 = pos12.rotation.inverse() * halfspace.normal;
    let mut feature2 = PolygonalFeature::default();
    pfm.local_support_feature(-normal1_2, &mut feature2);
    for k in 0..feature2.num_vertices {
        let vtx2 = feature2.vertices[k];
        let vtx2_1 = pos12 * vtx2;
        let dist_to_plane = vtx2_1.dot(halfspace.normal);
        if dist_to_plane - border_radius <= prediction {
            manifold.points.push(TrackedContact::flipped(
                vtx2_1 - halfspace.normal * dist_to_plane,
                vtx2 - normal1_2 * border_radius,
                PackedFeatureId::face(0),
                feature2.vids[k],
                dist_to_plane - border_radius,
                flipped,
            ));
        }
    }
    (manifold.local_n1, manifold.local_n2) = if flipped {
        (-normal1_2, halfspace.normal)
    } else {
        (halfspace.normal, -normal1_2)
    };
    true
}

/// A manifold's points as solver contacts: the normal from the first shape
/// to the second, the point midway between the surfaces, depth = -distance,
/// held to the depths the world accepts (`MAX_COORDINATE` either way): a
/// body a million metres under a ground plane is as deep as a contact
/// gets, and the rest of the list is still accepted.
fn push_manifold(
    out: &mut Vec<Contact>,
    m: &ContactManifold<(), ()>,
    (body_a, pose_a): (BodyHandle, &Pose),
    (body_b, pose_b): (BodyHandle, &Pose),
    friction: f32,
    restitution: f32,
) {
    let normal = (pose_a.rotation * m.local_n1).normalize();
    for point in &m.points {
        let pa = pose_a.transform_point(point.local_p1);
        let pb = pose_b.transform_point(point.local_p2);
        out.push(Contact {
            body_a,
            body_b,
            point: (pa + pb) * 0.5,
            normal,
            depth: (-point.dist).clamp(-MAX_COORDINATE, MAX_COORDINATE),
            friction,
            restitution,
        });
    }
}

/// A refusal of the set's own check on the world, in a ragdoll call.
fn unserved(error: Error) -> RagdollError {
    RagdollError::World {
        context: "the collision set".into(),
        error,
    }
}

/// The world pose of a body's collider frame (for callers drawing them).
pub fn collider_pose(world: &World, body: BodyHandle) -> Result<(Vec3, Quat), Error> {
    let _mode = DefaultFloatMode::enter();
    world.body(body).map(|s| (s.position, s.orientation))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Poses of a shape around a plane through the origin: a grid of
    /// heights, tilts and turns (resting, touching, apart, half sunk).
    fn poses() -> impl Iterator<Item = Pose> {
        (0..9).flat_map(|h| {
            (0..7).flat_map(move |t| {
                (0..5).map(move |r| {
                    let height = -0.3 + 0.09 * h as f32;
                    let tilt = Quat::from_rotation_x(0.37 * t as f32);
                    let turn = Quat::from_rotation_y(1.3 * r as f32);
                    Pose::from_parts(Vec3::new(0.2, height, -0.1), turn * tilt)
                })
            })
        })
    }

    /// Parry's manifolds for a new pair.
    fn parry(
        pos12: &Pose,
        s1: &dyn ParryShape,
        s2: &dyn ParryShape,
    ) -> Vec<ContactManifold<(), ()>> {
        let mut manifolds = Vec::new();
        DefaultQueryDispatcher
            .contact_manifolds(pos12, s1, s2, 0.05, &mut manifolds, &mut None)
            .unwrap();
        manifolds
    }

    /// A manifold's normals and points, bit for bit.
    fn bits(m: &ContactManifold<(), ()>) -> Vec<u32> {
        let v = |v: Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        let mut out = [v(m.local_n1), v(m.local_n2)].concat();
        for p in &m.points {
            out.extend(v(p.local_p1));
            out.extend(v(p.local_p2));
            out.extend([p.dist.to_bits(), p.fid1.0, p.fid2.0]);
        }
        out
    }

    #[test]
    fn the_ground_makes_parrys_contacts_bit_for_bit_in_a_kept_manifold() {
        let plane = SharedShape::halfspace(Vec3::new(0.0, 0.6, 0.8));
        let solids = [
            SharedShape::capsule(Vec3::new(0.0, -0.2, 0.0), Vec3::new(0.0, 0.2, 0.0), 0.06),
            SharedShape::cuboid(0.3, 0.15, 0.2),
        ];
        let mut kept = Vec::new();
        let mut points = 0;
        for solid in &solids {
            for pose in poses() {
                for (s1, s2, pos12) in [(&plane, solid, pose), (solid, &plane, pose.inverse())] {
                    fresh(&mut kept);
                    assert!(plane_manifold(
                        &pos12,
                        s1.as_ref(),
                        s2.as_ref(),
                        0.05,
                        &mut kept
                    ));
                    let expected = parry(&pos12, s1.as_ref(), s2.as_ref());
                    assert_eq!(kept.len(), 1);
                    assert_eq!(bits(&kept[0]), bits(&expected[0]), "{pose:?}");
                    points += kept[0].points.len();
                }
            }
        }
        assert!(points > 100, "the grid makes contacts: {points}");
        // Other pairs are parry's to make.
        let ball = SharedShape::ball(0.1);
        let pose = Pose::from_parts(Vec3::Y * 0.05, Quat::IDENTITY);
        assert!(!plane_manifold(
            &pose,
            plane.as_ref(),
            ball.as_ref(),
            0.05,
            &mut kept
        ));
        assert!(!plane_manifold(
            &pose,
            solids[0].as_ref(),
            solids[1].as_ref(),
            0.05,
            &mut kept
        ));
    }
}
