//! A ragdoll in and out of the set with its colliders, in one call each:
//! built in the world with its capsules ([`Collisions::build_ragdoll`]),
//! added as built ([`Collisions::add_ragdoll`]), re-created at a pose with
//! its colliders moved to the new bodies
//! ([`Collisions::recreate_ragdoll`]), removed with them
//! ([`Collisions::remove_ragdoll`]); each records the ragdoll's parts,
//! which hits and events name.
//!
//! Its own file because it is the crate's glue to `vertebra_ragdoll`: the
//! only file that builds or removes a ragdoll, and the only one that turns
//! the world's refusals into a `RagdollError`.

use std::collections::HashMap;

use vertebra_math::DefaultFloatMode;
use vertebra_ragdoll::{BuildOptions, Ragdoll, RagdollDesc, RagdollError};
use vertebra_world::{BodyHandle, Error, World};

use crate::collider::{Collider, ColliderShape, solid};
use crate::filter::ordered;
use crate::part::{Parts, RagdollPart};
use crate::set::Collisions;

impl Collisions {
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
}

/// A refusal of the set's own check on the world, in a ragdoll call.
fn unserved(error: Error) -> RagdollError {
    RagdollError::World {
        context: "the collision set".into(),
        error,
    }
}
