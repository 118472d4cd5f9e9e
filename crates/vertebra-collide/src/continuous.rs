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
//! capsule's radius, a box's smallest half extent) is swept from its pose
//! before the step to its pose after it against every static solid
//! collider, and if it would have passed into one it is put back where it
//! was 2 to 3 mm short of its first touch (`SKIN`), its velocity kept,
//! for the next step's contacts to stop.
//!
//! **The sweep** moves the translation linearly and the rotation by the
//! normalised linear blend of the two orientations (Box2D's sweep), and
//! finds the first touch (a gap under 10 um, `CONTACT`) by conservative
//! advancement (Mirtich): from the
//! core's distance `d` to the static solid at time `t`, no point of it can
//! close that gap before `t + d / s`, where `s` bounds the speed of every
//! point of the core over the blend, `|dx| + 4 tan(theta / 4) r_max` (the
//! blend turns fastest at its middle, `4 tan(theta / 4)` for a whole turn
//! of `theta`, at most 1.28 `theta`). Every operation in it has the same
//! bits on every target (the portable quaternion operations; parry's
//! distance between poses made relative first, as the contacts are), so
//! a world with fast bodies steps the same everywhere; parry's nonlinear
//! cast takes its rotations from the platform's sine and cosine and
//! glam's per-target quaternion product.
//!
//! **What is swept is the body's core**: its collider shrunk by half its
//! thickness (a capsule or sphere of half the radius, a box inset by half
//! its smallest half extent). A body that only sinks into a wall or floor
//! by less than that (a ragdoll landing 1 cm deep) is left to the contacts
//! alone: no pose is changed, so worlds whose bodies never pass that deep
//! (every paper scene) step bit for bit as without the sweep. A core that starts
//! the step within `SKIN` of static geometry (a limb pressed against a
//! wall, or put back against it the step before) is swept instead as a
//! ball of a quarter of its thickness at its centre (Box2D v3's fallback):
//! it may slide along the wall or leave it, not cross it; a ball that
//! starts within `SKIN` too stays where it started if its step would end
//! nearer. One whose ball starts inside is left alone (putting it back to
//! its start would not get it out). Ground planes (half spaces) cannot be
//! passed through: their contacts push out of any depth.

use glam::{Quat, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::shape::{Ball, Capsule, Cuboid, Shape as ParryShape};
use vertebra_math::PortableQuat;
use vertebra_world::{BodyHandle, BodyKind, Error, Shape, World};

use crate::collider::ColliderShape;
use crate::pose::relative_pose;
use crate::set::Collisions;

/// How far short of a static solid (m) a swept core (or centre ball) is
/// put back: the advancement aims for this gap and stops within
/// `SKIN / 2` above it, never below. A probe that starts the step nearer
/// than `SKIN` is treated as touching already.
const SKIN: f32 = 2e-3;

/// A probe this near a solid (m) touches it: parry's distances between
/// our shapes are good to about this.
const CONTACT: f32 = 1e-5;

/// Advancements before a sweep settles for the time it reached: still
/// `SKIN` short of the touch, so a body is never put back past it.
const MAX_ADVANCES: usize = 32;

/// A body's motion over the step, from its pose before (`t` = 0) to its
/// pose after (`t` = 1).
struct Sweep {
    from: Vec3,
    by: Vec3,
    start: Quat,
    /// The orientation after, on the same side as `start` (`start . end`
    /// >= 0), so the blend takes the shorter way.
    end: Quat,
    /// A bound on the speed of every point within `reach` of the body's
    /// centre (m per unit of `t`).
    speed: f32,
}

impl Sweep {
    fn new(before: &Pose, position: Vec3, orientation: Quat, reach: f32) -> Self {
        let cos_half = before.rotation.dot_portable(orientation);
        let end = if cos_half < 0.0 {
            -orientation
        } else {
            orientation
        };
        // 4 tan(theta / 4) = 4 sin(theta / 2) / (1 + cos(theta / 2)).
        let c = cos_half.abs().min(1.0);
        let turn_rate = 4.0 * (1.0 - c * c).sqrt() / (1.0 + c);
        let by = position - before.translation;
        Self {
            from: before.translation,
            by,
            start: before.rotation,
            end,
            speed: by.length() + turn_rate * reach,
        }
    }

    /// The pose at `t` in `[0, 1]`.
    fn at(&self, t: f32) -> Pose {
        let blend = self.start * (1.0 - t) + self.end * t;
        Pose::from_parts(self.from + self.by * t, blend.normalize_portable())
    }
}

/// A body's motion is fast when it exceeds this fraction of its thickness
/// in a step. Box2D v3 sweeps from half; at half, a limb of the 30-ragdoll
/// drop (rod spines, direct joints) turning at 9 rad/s while pressed 3 cm
/// into an obstacle of the pit is swept and nudged (a core grazing the
/// box at the step's start, not a body passing through), which moves
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
        let mut first: Vec<(BodyHandle, f32, Sweep)> = Vec::new();
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
            let reach = shape.compute_local_bounding_sphere().radius;
            let turn = start.rotation.angle_between_portable(now.orientation);
            let moved = (now.position - start.translation).length() + turn * reach;
            if moved.is_nan() || moved <= FAST * thickness(&solid) {
                continue;
            }
            let sweep = Sweep::new(&start, now.position, now.orientation, reach);
            let end = Pose::from_parts(now.position, now.orientation);
            let swept = shape.compute_aabb(&start).merged(&shape.compute_aabb(&end));
            if let Some(t) = self.first_touch(statics, &solid, &sweep, &swept) {
                first.push((collider.body, t, sweep));
            }
        }
        // A body's earliest touch over its colliders, bodies in slot order.
        first.sort_by(|x, y| (x.0.index().cmp(&y.0.index())).then(x.1.total_cmp(&y.1)));
        first.dedup_by_key(|x| x.0);
        out.extend(first.into_iter().map(|(body, t, sweep)| {
            let pose = sweep.at(t);
            (body, pose.translation, pose.rotation)
        }));
    }

    /// The earliest time in `(0, 1)` at which `solid`'s core, moving by
    /// `sweep` over the step (time 1), touches a static solid collider
    /// whose bounds meet `swept`.
    fn first_touch(
        &self,
        statics: &[(usize, Aabb, Pose)],
        solid: &Shape,
        sweep: &Sweep,
        swept: &Aabb,
    ) -> Option<f32> {
        let mut first: Option<f32> = None;
        for &(k, bounds, pose) in statics {
            if !bounds.intersects(swept) {
                continue;
            }
            let shape = self.colliders[k].1.as_ref();
            let touch = match with_core(solid, |core| advance(core, shape, &pose, sweep)) {
                Ok(touch) => touch,
                Err(_) => hold_centre(&centre(solid), shape, &pose, sweep),
            };
            if let Some(t) = touch {
                first = Some(first.map_or(t, |f| f.min(t)));
            }
        }
        first
    }
}

/// A ball of a quarter of the solid's thickness at its centre: what is
/// swept when the core starts touching (Box2D v3's fallback), so a limb
/// pressed against a wall, or put back against it the step before, is
/// still kept from crossing it while it may slide along it.
fn centre(shape: &Shape) -> Ball {
    Ball::new(0.25 * thickness(shape))
}

/// The centre ball's sweep (`centre`): advanced as a core is; one that
/// starts within [`SKIN`] of `shape` (pressed in by its joints step after
/// step) stays where it started (time 0) if its step ends nearer, and is
/// let go if it slides along or away; one that starts inside is left
/// alone.
fn hold_centre(ball: &Ball, shape: &dyn ParryShape, pose: &Pose, sweep: &Sweep) -> Option<f32> {
    match advance(ball, shape, pose, sweep) {
        Ok(touch) => touch,
        Err(start) if start > 0.0 => {
            let end = gap(ball, shape, pose, sweep, 1.0).ok()?;
            (end < start).then_some(0.0)
        }
        Err(_) => None,
    }
}

/// `probe`'s distance (m) to `shape` at `pose` at time `t` of `sweep`,
/// the poses made relative first (module docs).
fn gap(
    probe: &dyn ParryShape,
    shape: &dyn ParryShape,
    pose: &Pose,
    sweep: &Sweep,
    t: f32,
) -> Result<f32, ()> {
    let relative = relative_pose(&sweep.at(t), pose);
    parry3d::query::distance(&Pose::IDENTITY, probe, &relative, shape)
        .map(|d| d.distance)
        .map_err(|_| ())
}

/// Conservative advancement of `probe` along `sweep` toward `shape` at
/// `pose` (module docs): `Ok(Some(t))` when the probe touches `shape` in
/// the step (comes within [`CONTACT`]), with the time `t` in `(0, 1)` it
/// was still [`SKIN`] to `1.5 SKIN` short of it (or the time
/// [`MAX_ADVANCES`] reached, still short); `Ok(None)` when it never
/// touches; `Err(gap)` with its gap at the start when that is `SKIN` or
/// less (`-1` when parry has no distance for the pair).
fn advance(
    probe: &dyn ParryShape,
    shape: &dyn ParryShape,
    pose: &Pose,
    sweep: &Sweep,
) -> Result<Option<f32>, f32> {
    let gap_at = |t| gap(probe, shape, pose, sweep, t).map_err(|()| -1.0);
    let start = gap_at(0.0)?;
    if start <= SKIN {
        return Err(start);
    }
    // To SKIN short of the solid, where the probe would be put back ...
    let Some((short, gap)) = approach(&gap_at, sweep.speed, 0.0, start, (SKIN, 1.5 * SKIN))? else {
        return Ok(None);
    };
    // ... if it goes on to touch it in the step.
    let touches = approach(&gap_at, sweep.speed, short, gap, (0.0, CONTACT))?.is_some();
    Ok(touches.then_some(short))
}

/// Advances from time `t` (gap `gap`) toward `target` (m): the first
/// time at or after `t` with a gap of `within` or less (never below
/// `target`), with that gap, or `None` when the step ends first; after
/// [`MAX_ADVANCES`] the time reached.
fn approach(
    gap_at: &impl Fn(f32) -> Result<f32, f32>,
    speed: f32,
    mut t: f32,
    mut gap: f32,
    (target, within): (f32, f32),
) -> Result<Option<(f32, f32)>, f32> {
    for _ in 0..MAX_ADVANCES {
        if gap <= within {
            return Ok(Some((t, gap)));
        }
        t += (gap - target) / speed;
        if t >= 1.0 {
            return Ok(None);
        }
        gap = gap_at(t)?;
    }
    Ok(Some((t, gap)))
}
