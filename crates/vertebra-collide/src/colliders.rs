//! The set's colliders in and out: one collider ([`Collisions::add`]), a
//! body group with its jointed pairs ([`Collisions::add_jointed`]), every
//! collider of a body ([`Collisions::remove_body`]), and the list as it is
//! ([`Collisions::colliders`], [`Collisions::shapes`]).
//!
//! Its own file because it is the one place the list changes outside the
//! ragdoll calls (`ragdoll.rs`) and the snapshot (`snapshot.rs`), each
//! change counted in the set's version; the collider itself, and what
//! makes one refused, is `collider.rs`'s.

use parry3d::shape::SharedShape;
use vertebra_math::DefaultFloatMode;
use vertebra_world::{BodyHandle, Error, Shape};

use crate::collider::{Collider, ColliderShape};
use crate::set::Collisions;

impl Collisions {
    /// Adds a collider; returns its index in [`Collisions::colliders`]
    /// (until a collider before it is removed). `Err(Error::Collider)`,
    /// naming the index it would have had and its body, for a degenerate
    /// shape or one beyond
    /// [`MAX_COLLIDER_EXTENT`](crate::MAX_COLLIDER_EXTENT), a non-unit
    /// plane normal or bad friction and restitution. Its
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

    /// The colliders.
    pub fn colliders(&self) -> impl Iterator<Item = &Collider> {
        self.colliders.iter().map(|c| &c.0)
    }

    /// The colliders with their parry geometry (body frame), for handing
    /// the same shapes to another engine.
    pub fn shapes(&self) -> impl Iterator<Item = (&Collider, &SharedShape)> {
        self.colliders.iter().map(|(c, s)| (c, s))
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
}
