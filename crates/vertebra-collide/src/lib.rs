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
//! [`Error::Collider`]: vertebra_world::Error::Collider
//! [`Error::WorldMismatch`]: vertebra_world::Error::WorldMismatch
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

mod broad_phase;
mod collider;
mod colliders;
mod contact_events;
mod continuous;
mod detect;
mod detection;
mod events;
mod filter;
mod found;
mod frame;
mod groups;
mod islands;
mod manifold;
mod narrow_phase;
mod pairing;
mod part;
mod pose;
mod query;
mod query_tree;
mod ragdoll;
mod set;
mod snapshot;

pub use collider::{Collider, ColliderShape, CollisionGroups, MAX_COLLIDER_EXTENT, collider_pose};
pub use contact_events::{ContactEnded, ContactEvents, Touching};
pub use groups::MAX_SELF_COLLISION_GROUPS;
pub use part::RagdollPart;
pub use query::{Overlap, QueryFilter, QueryHit, QueryShape};
pub use set::Collisions;
pub use snapshot::CollisionSnapshot;
