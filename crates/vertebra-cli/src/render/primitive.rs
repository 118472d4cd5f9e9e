//! Rays and the four primitives, each with its exact ray intersection:
//! the sphere and the plane in closed form, the capsule as the nearest of
//! its three surface pieces (the cylinder between the end planes, the two
//! end hemispheres), the oriented box by slabs in its own frame.

use glam::{Quat, Vec3};

/// Below this, a direction counts as parallel to a plane, slab or axis.
const PARALLEL: f32 = 1e-9;

/// A half line: `origin + t dir` for `t >= 0` (m, world; `dir` of unit
/// length).
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    /// The point `t` metres along the ray.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Where a ray meets a surface: its distance along the ray (m) and the
/// surface's outward unit normal there (world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub normal: Vec3,
}

/// A surface the renderer draws (m, world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
    /// A ball.
    Sphere { centre: Vec3, radius: f32 },
    /// The segment `a`..`b` swept by a ball of `radius`.
    Capsule { a: Vec3, b: Vec3, radius: f32 },
    /// A box turned by `rotation` about its centre.
    Box {
        centre: Vec3,
        rotation: Quat,
        half_extents: Vec3,
    },
    /// The plane `normal . p = offset` (`normal` of unit length; the
    /// outward side is the one it points to).
    Plane { normal: Vec3, offset: f32 },
}

impl Primitive {
    /// The nearest hit with `t` in `(t_min, t_max)`: from outside the
    /// entry, from inside the exit.
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        let nearest = |a: Option<Hit>, b: Option<Hit>| match (a, b) {
            (Some(x), Some(y)) => Some(if y.t < x.t { y } else { x }),
            (x, y) => x.or(y),
        };
        match *self {
            Primitive::Sphere { centre, radius } => {
                sphere(ray, centre, radius, t_min, t_max, |_| true)
            }
            Primitive::Capsule { a, b, radius } => {
                let axis = b - a;
                let side = match cylinder(ray, a, axis, radius, t_min, t_max) {
                    // Outside the infinite cylinder that holds the capsule:
                    // a miss.
                    Side::Missed => return None,
                    // Entering the cylinder between the end planes: the
                    // capsule's entry (nothing of it lies nearer).
                    Side::Entry(hit) => return Some(hit),
                    Side::Other(hit) => hit,
                };
                let cap_a = sphere(ray, a, radius, t_min, t_max, |p| (p - a).dot(axis) <= 0.0);
                let cap_b = sphere(ray, b, radius, t_min, t_max, |p| (p - b).dot(axis) >= 0.0);
                nearest(nearest(side, cap_a), cap_b)
            }
            Primitive::Box {
                centre,
                rotation,
                half_extents,
            } => oriented_box(ray, centre, rotation, half_extents, t_min, t_max),
            Primitive::Plane { normal, offset } => {
                let along = normal.dot(ray.dir);
                if along.abs() < PARALLEL {
                    return None;
                }
                let t = (offset - normal.dot(ray.origin)) / along;
                (t > t_min && t < t_max).then_some(Hit { t, normal })
            }
        }
    }

    /// Whether every number in it is finite and every size positive (a
    /// plane's normal of unit length).
    pub fn is_valid(&self) -> bool {
        match *self {
            Primitive::Sphere { centre, radius } => {
                centre.is_finite() && radius.is_finite() && radius > 0.0
            }
            Primitive::Capsule { a, b, radius } => {
                a.is_finite() && b.is_finite() && radius.is_finite() && radius > 0.0
            }
            Primitive::Box {
                centre,
                rotation,
                half_extents,
            } => {
                centre.is_finite()
                    && rotation.is_finite()
                    && rotation.is_normalized()
                    && half_extents.is_finite()
                    && half_extents.min_element() > 0.0
            }
            Primitive::Plane { normal, offset } => {
                normal.is_finite() && normal.is_normalized() && offset.is_finite()
            }
        }
    }

    /// Its axis-aligned bounds (min, max), or `None` for the unbounded
    /// plane.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        match *self {
            Primitive::Sphere { centre, radius } => Some((centre - radius, centre + radius)),
            Primitive::Capsule { a, b, radius } => Some((a.min(b) - radius, a.max(b) + radius)),
            Primitive::Box {
                centre,
                rotation,
                half_extents,
            } => {
                let m = glam::Mat3::from_quat(rotation);
                let reach = m.x_axis.abs() * half_extents.x
                    + m.y_axis.abs() * half_extents.y
                    + m.z_axis.abs() * half_extents.z;
                Some((centre - reach, centre + reach))
            }
            Primitive::Plane { .. } => None,
        }
    }
}

/// The roots of `t^2 + 2 b t + c = 0` with `t` in `(t_min, t_max)` whose
/// points pass `keep`, nearest first.
fn roots(
    ray: &Ray,
    b: f32,
    c: f32,
    t_min: f32,
    t_max: f32,
    keep: impl Fn(Vec3) -> bool,
) -> Option<f32> {
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    [-b - s, -b + s]
        .into_iter()
        .find(|&t| t > t_min && t < t_max && keep(ray.at(t)))
}

/// The ray against the sphere (`centre`, `radius`), only the points that
/// pass `keep` (a capsule's hemisphere).
fn sphere(
    ray: &Ray,
    centre: Vec3,
    radius: f32,
    t_min: f32,
    t_max: f32,
    keep: impl Fn(Vec3) -> bool,
) -> Option<Hit> {
    let oc = ray.origin - centre;
    let t = roots(
        ray,
        oc.dot(ray.dir),
        oc.length_squared() - radius * radius,
        t_min,
        t_max,
        keep,
    )?;
    Some(Hit {
        t,
        normal: (ray.at(t) - centre) / radius,
    })
}

/// What the ray meets of a capsule's cylinder side.
enum Side {
    /// The ray misses the infinite cylinder, so the capsule too.
    Missed,
    /// The ray's first point on the infinite cylinder, within `(t_min,
    /// t_max)` and between the end planes.
    Entry(Hit),
    /// Otherwise: the nearest hit on the side between the end planes, if
    /// any (from inside, past an end plane, or parallel to the axis).
    Other(Option<Hit>),
}

/// The ray against the side of the cylinder of `radius` about `a`..`a +
/// axis`, between its end planes. A ray parallel to the axis meets the
/// side nowhere or everywhere: `Other(None)`, the caps give its hits.
fn cylinder(ray: &Ray, a: Vec3, axis: Vec3, radius: f32, t_min: f32, t_max: f32) -> Side {
    let length2 = axis.length_squared();
    if length2 < PARALLEL {
        return Side::Other(None);
    }
    let u = axis / length2.sqrt();
    let across = |v: Vec3| v - u * v.dot(u);
    let (d, o) = (across(ray.dir), across(ray.origin - a));
    let a2 = d.length_squared();
    if a2 < PARALLEL {
        return Side::Other(None);
    }
    // t^2 + 2 b t + c = 0: the ray's distance from the axis is `radius`.
    let (b, c) = (d.dot(o) / a2, (o.length_squared() - radius * radius) / a2);
    if b * b - c < 0.0 {
        return Side::Missed;
    }
    let inside = |p: Vec3| (0.0..=length2).contains(&(p - a).dot(axis));
    let hit = |t: f32| Hit {
        t,
        normal: across(ray.at(t) - a) / radius,
    };
    let first = -b - (b * b - c).sqrt();
    if first > t_min && first < t_max && inside(ray.at(first)) {
        return Side::Entry(hit(first));
    }
    Side::Other(roots(ray, b, c, t_min, t_max, inside).map(hit))
}

/// The ray against the box by slabs in the box's frame: the entry, or
/// the exit from inside.
fn oriented_box(
    ray: &Ray,
    centre: Vec3,
    rotation: Quat,
    half: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<Hit> {
    let back = rotation.inverse();
    let (o, d) = (back * (ray.origin - centre), back * ray.dir);
    let (mut near, mut far) = ((f32::NEG_INFINITY, 0), (f32::INFINITY, 0));
    for axis in 0..3 {
        if d[axis].abs() < PARALLEL {
            if o[axis].abs() > half[axis] {
                return None;
            }
            continue;
        }
        let t1 = (-half[axis] - o[axis]) / d[axis];
        let t2 = (half[axis] - o[axis]) / d[axis];
        let (lo, hi) = (t1.min(t2), t1.max(t2));
        if lo > near.0 {
            near = (lo, axis);
        }
        if hi < far.0 {
            far = (hi, axis);
        }
    }
    if near.0 > far.0 {
        return None;
    }
    // Entering, the normal faces against the ray; leaving, along it.
    let (t, axis, sign) = if near.0 > t_min {
        (near.0, near.1, -d[near.1].signum())
    } else {
        (far.0, far.1, d[far.1].signum())
    };
    if !(t > t_min && t < t_max) {
        return None;
    }
    let mut normal = Vec3::ZERO;
    normal[axis] = sign;
    Some(Hit {
        t,
        normal: rotation * normal,
    })
}
