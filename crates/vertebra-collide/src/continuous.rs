//! Continuous collision for fast bodies against static geometry (Box2D
//! v3's `b2SolveContinuous`, Jolt's `EMotionQuality::LinearCast`): a limb
//! flung at 50 m/s does not pass through a 10 cm wall.
//!
//! Speculative contacts (the detection's margin grows with each body's
//! speed) stop a body that flies straight at a wall. They do not stop one
//! whose path the step bends: a limb swung by its joints, spinning, or
//! thrown mid-step by a ragdoll it is joined to, can move a metre in a
//! step along a path no contact found at the step's start foresaw. So
//! after the step, each **fast** body (an awake dynamic body whose motion
//! in the step, `|dx| + |dtheta| r_max` with `r_max` its collider's
//! reach from its centre of mass, exceeds its **thickness**: a sphere's or
//! capsule's radius, a box's smallest half extent) is swept from its pose before the step to its pose after it
//! (translation and rotation together: parry's nonlinear shape cast)
//! against every static solid collider, and if it would have passed into
//! one it is put back where it first touched, its velocity kept, for the
//! next step's contacts to stop.
//!
//! **What is swept is the body's core**: its collider shrunk by half its
//! thickness (a capsule or sphere of half the radius, a box inset by half
//! its smallest half extent). A body that only sinks into a wall or floor
//! by less than that (a ragdoll landing 1 cm deep) is left to the contacts
//! exactly as before: no pose is changed, so worlds whose bodies never
//! pass that deep (every paper scene) keep every bit. A core already
//! inside static geometry at the step's start is left alone (putting it
//! back to its start would not get it out). Ground planes (half spaces)
//! cannot be passed through: their contacts push out of any depth.

use glam::{Quat, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::query::NonlinearRigidMotion;
use parry3d::shape::{Ball, Capsule, Cuboid, Shape as ParryShape};
use vertebra_world::{BodyHandle, BodyKind, Error, Shape, World};

use crate::{ColliderShape, Collisions};

/// A body's motion is fast when it exceeds this fraction of its thickness
/// in a step. Box2D v3 sweeps from half; at half, a limb of the 30-ragdoll
/// drop (rod spines, direct joints) turning at 9 rad/s while pressed 3 cm
/// into an obstacle of the pit was swept and nudged (a core grazing the
/// box at the step's start, not a body passing through), which moved
/// every bit of the scene after it. A body moving less than its thickness
/// in a step meets its speculative contacts before its core can reach
/// the far side of anything as thick as it is.
const FAST: f32 = 1.0;

/// A solid's thickness (m): its radius, or a box's smallest half extent.
fn thickness(shape: &Shape) -> f32 {
    match *shape {
        Shape::Sphere { radius } | Shape::Capsule { radius, .. } => radius,
        Shape::Box { half_extents } => half_extents.min_element(),
    }
}

/// Runs `f` with the solid's core: shrunk by half its thickness.
fn with_core<R>(shape: &Shape, f: impl FnOnce(&dyn ParryShape) -> R) -> R {
    let inset = 0.5 * thickness(shape);
    match *shape {
        Shape::Sphere { radius } => f(&Ball::new(radius - inset)),
        Shape::Capsule {
            half_segment,
            radius,
        } => f(&Capsule::new(-half_segment, half_segment, radius - inset)),
        Shape::Box { half_extents } => f(&Cuboid::new(half_extents - Vec3::splat(inset))),
    }
}

impl Collisions {
    /// The bodies continuous collision would put back after `world`'s last
    /// step, with where (the pose at the first touch of a core), in slot
    /// order: what [`Collisions::after_step`] applies. For tests and
    /// tools; the same sweep, nothing changed.
    pub fn continuous_bodies(&self, world: &World) -> Vec<(BodyHandle, Vec3, Quat)> {
        let mut out = Vec::new();
        self.sweep(world, &mut out, &mut Vec::new());
        out
    }

    /// Sweeps every fast body (see the module docs) and puts back those
    /// that would have passed into static geometry.
    pub(crate) fn sweep_fast_bodies(&mut self, world: &mut World) -> Result<(), Error> {
        let mut moves = core::mem::take(&mut self.moves);
        let mut statics = core::mem::take(&mut self.statics);
        self.sweep(world, &mut moves, &mut statics);
        self.statics = statics;
        let result = moves.iter().try_for_each(|&(body, position, orientation)| {
            world.set_body_pose(body, position, orientation)
        });
        self.moves = moves;
        result
    }

    /// The first touch of each fast body's cores into `out` (emptied
    /// first), in slot order; `statics` is working memory (the static
    /// solids with their bounds and poses, gathered once).
    fn sweep(
        &self,
        world: &World,
        out: &mut Vec<(BodyHandle, Vec3, Quat)>,
        statics: &mut Vec<(usize, Aabb, Pose)>,
    ) {
        out.clear();
        statics.clear();
        if self.found.version != self.version || self.found.before.len() != self.colliders.len() {
            // The colliders changed between detection and now: their
            // poses before the step are not known.
            return;
        }
        for (k, (c, shape)) in self.colliders.iter().enumerate() {
            let solid = matches!(c.shape, ColliderShape::Solid(_));
            if !solid || world.bodies().kind[c.body.index()] != BodyKind::Static {
                continue;
            }
            if let Ok(s) = world.body(c.body) {
                let pose = Pose::from_parts(s.position, s.orientation);
                statics.push((k, shape.compute_aabb(&pose), pose));
            }
        }
        if statics.is_empty() {
            return;
        }
        let mut first: Vec<(BodyHandle, f32, NonlinearRigidMotion)> = Vec::new();
        for (k, (collider, shape)) in self.colliders.iter().enumerate() {
            let (Some(start), ColliderShape::Solid(solid)) = (self.found.before[k], collider.shape)
            else {
                continue;
            };
            let Ok(now) = world.body(collider.body) else {
                continue;
            };
            if world.bodies().kind[collider.body.index()] != BodyKind::Dynamic {
                continue;
            }
            // The shortest arc from the pose before to the pose after.
            let turn = now.orientation * start.rotation.inverse();
            let turn = if turn.w < 0.0 { -turn } else { turn };
            let reach = shape.compute_local_bounding_sphere().radius;
            let moved =
                (now.position - start.translation).length() + turn.to_axis_angle().1.abs() * reach;
            if moved.is_nan() || moved <= FAST * thickness(&solid) {
                continue;
            }
            let motion = NonlinearRigidMotion::new(
                start,
                Vec3::ZERO,
                now.position - start.translation,
                turn.to_scaled_axis(),
            );
            let end = Pose::from_parts(now.position, now.orientation);
            let swept = shape.compute_aabb(&start).merged(&shape.compute_aabb(&end));
            if let Some(t) = self.first_touch(statics, &solid, &motion, &swept) {
                first.push((collider.body, t, motion));
            }
        }
        // A body's earliest touch over its colliders, bodies in slot order.
        first.sort_by(|x, y| (x.0.index().cmp(&y.0.index())).then(x.1.total_cmp(&y.1)));
        first.dedup_by_key(|x| x.0);
        out.extend(first.into_iter().map(|(body, t, motion)| {
            let pose = motion.position_at_time(t);
            (body, pose.translation, pose.rotation.normalize())
        }));
    }

    /// The earliest time in `(0, 1)` at which `solid`'s core, moving by
    /// `motion` over the step (time 1), touches a static solid collider
    /// whose bounds meet `swept`.
    fn first_touch(
        &self,
        statics: &[(usize, Aabb, Pose)],
        solid: &Shape,
        motion: &NonlinearRigidMotion,
        swept: &Aabb,
    ) -> Option<f32> {
        let mut first: Option<f32> = None;
        for &(k, bounds, pose) in statics {
            if !bounds.intersects(swept) {
                continue;
            }
            let shape = &self.colliders[k].1;
            let fixed = NonlinearRigidMotion::constant_position(pose);
            let hit = with_core(solid, |core| {
                parry3d::query::cast_shapes_nonlinear(
                    motion,
                    core,
                    &fixed,
                    shape.as_ref(),
                    0.0,
                    1.0,
                    true,
                )
            });
            if let Ok(Some(hit)) = hit
                && hit.time_of_impact > 0.0
                && hit.time_of_impact < 1.0
            {
                first = Some(first.map_or(hit.time_of_impact, |t| t.min(hit.time_of_impact)));
            }
        }
        first
    }
}
