//! A collider: a shape on a body, with its friction, restitution and
//! collision groups ([`Collider`], [`ColliderShape`], [`CollisionGroups`]),
//! and the checks that turn it into parry's geometry or refuse it (a
//! degenerate shape, one beyond [`MAX_COLLIDER_EXTENT`], a non-unit plane
//! normal, bad friction or restitution).
//!
//! Its own file because it is the one type every other part of the crate
//! takes (the set holds them, detection and queries read them, the
//! snapshot saves them) and it needs nothing of the crate: the bottom
//! layer. Which pairs of colliders are tested is `filter.rs`'s and
//! `groups.rs`'s; the set's list of them is `colliders.rs`'s.

use glam::{Quat, Vec3};
use parry3d::shape::SharedShape;
use vertebra_math::DefaultFloatMode;
use vertebra_world::{BodyHandle, Error, Shape, World};

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
    pub(crate) fn geometry(&self) -> Result<SharedShape, Error> {
        let shape = match self.shape {
            ColliderShape::Solid(s) => solid(s)?,
            ColliderShape::Plane(n) => {
                vertebra_store::check_unit_vec("plane normal", n)?;
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
    pub(crate) fn refused(&self, index: usize, reason: Error) -> Error {
        Error::Collider {
            index,
            body: self.body,
            reason: Box::new(reason),
        }
    }
}

/// The parry geometry of a solid (body frame), or why it is refused: a
/// degenerate shape or one beyond [`MAX_COLLIDER_EXTENT`].
pub(crate) fn solid(shape: Shape) -> Result<SharedShape, Error> {
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

/// The world pose of a body's collider frame (for callers drawing them).
pub fn collider_pose(world: &World, body: BodyHandle) -> Result<(Vec3, Quat), Error> {
    let _mode = DefaultFloatMode::enter();
    world.body(body).map(|s| (s.position, s.orientation))
}
