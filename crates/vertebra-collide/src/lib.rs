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
//!     SpineMode, Strength, Transform, Transition,
//! };
//! use vertebra_world::{BodyDesc, Shape, SolverConfig, World};
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
//! ragdoll.drive_to(&mut world, &now, &DriveSettings::uniform(Strength::Compliance(1e-2)))?;
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

mod broad_phase;
mod collider;
mod continuous;
mod detect;
mod detection;
mod events;
mod frame;
mod groups;
mod islands;
mod manifold;
mod narrow_phase;
mod pairing;
mod part;
mod pose;
mod query;
mod snapshot;

use std::collections::{HashMap, HashSet};

use glam::{Quat, Vec3};
use parry3d::bounding_volume::Aabb;
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use vertebra_math::DefaultFloatMode;
use vertebra_ragdoll::{BuildOptions, Ragdoll, RagdollDesc, RagdollError};
use vertebra_world::{BodyHandle, BodyKind, Contact, Error, Shape, Timeline, World};

pub use collider::{Collider, ColliderShape, CollisionGroups, MAX_COLLIDER_EXTENT, collider_pose};
pub use events::{ContactEnded, ContactEvents, Touching};
pub use groups::MAX_SELF_COLLISION_GROUPS;
pub use part::RagdollPart;
pub use query::{Overlap, QueryFilter, QueryHit, QueryShape};
pub use snapshot::CollisionSnapshot;

use collider::solid;
use detection::Detection;
use part::Parts;

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

/// A refusal of the set's own check on the world, in a ragdoll call.
fn unserved(error: Error) -> RagdollError {
    RagdollError::World {
        context: "the collision set".into(),
        error,
    }
}
