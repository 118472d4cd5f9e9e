//! What is drawn: objects (a primitive and its paint), checked once, the
//! bounded ones under a [`Bvh`], the planes apart; the nearest hit along
//! a ray, and whether anything blocks one.

use glam::Vec3;

use super::bvh::Bvh;
use super::primitive::{Hit, Primitive, Ray};

/// How a surface is coloured (linear RGB, 0 to 1 each).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Paint {
    /// One colour.
    Plain(Vec3),
    /// Squares of `size` metres over the world's x and z, alternating
    /// `a` and `b` (a floor).
    Checker { a: Vec3, b: Vec3, size: f32 },
}

impl Paint {
    /// The colour at `point` (m, world).
    pub fn at(&self, point: Vec3) -> Vec3 {
        match *self {
            Paint::Plain(c) => c,
            Paint::Checker { a, b, size } => {
                let cell = (point.x / size).floor() + (point.z / size).floor();
                if cell.rem_euclid(2.0) < 1.0 { a } else { b }
            }
        }
    }

    fn is_valid(&self) -> bool {
        let colour = |c: Vec3| c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0;
        match *self {
            Paint::Plain(c) => colour(c),
            Paint::Checker { a, b, size } => {
                colour(a) && colour(b) && size.is_finite() && size > 0.0
            }
        }
    }
}

/// A primitive and its paint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Object {
    pub primitive: Primitive,
    pub paint: Paint,
}

/// Objects ready to be ray cast.
pub struct Scene {
    /// The bounded objects, indexed by the tree, then the planes.
    objects: Vec<Object>,
    bounded: usize,
    bvh: Bvh,
}

impl Scene {
    /// The scene of `objects`; refused, naming the first bad object by
    /// its index, when one holds a non-finite number, a size not above 0,
    /// a plane normal not of unit length, or a colour outside 0 to 1.
    pub fn new(objects: Vec<Object>) -> Result<Self, String> {
        if let Some((k, o)) = objects
            .iter()
            .enumerate()
            .find(|(_, o)| !(o.primitive.is_valid() && o.paint.is_valid()))
        {
            return Err(format!("render: object {k} is not drawable: {o:?}"));
        }
        let (mut bounded, planes): (Vec<_>, Vec<_>) = objects
            .into_iter()
            .partition(|o| o.primitive.bounds().is_some());
        let boxes: Vec<_> = bounded
            .iter()
            .filter_map(|o| o.primitive.bounds())
            .collect();
        let count = bounded.len();
        bounded.extend(planes);
        Ok(Self {
            objects: bounded,
            bounded: count,
            bvh: Bvh::new(&boxes),
        })
    }

    /// The nearest hit along `ray` within `(t_min, t_max)`, and the index
    /// of the object it hit ([`Self::object`]).
    pub fn closest(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<(Hit, usize)> {
        let mut best: Option<(Hit, usize)> = None;
        let mut consider = |k: usize, t_max: f32| {
            let hit = self.objects[k].primitive.intersect(ray, t_min, t_max);
            if let Some(hit) = hit {
                best = Some((hit, k));
            }
            hit.map(|h| h.t).or(Some(t_max))
        };
        let mut t_max = t_max;
        for k in self.bounded..self.objects.len() {
            t_max = consider(k, t_max).unwrap_or(t_max);
        }
        self.bvh.walk(ray, t_max, consider);
        best
    }

    /// Object `k` (as [`Self::closest`] numbers them).
    pub fn object(&self, k: usize) -> &Object {
        &self.objects[k]
    }

    /// Whether anything lies along `ray` within `(t_min, t_max)`.
    pub fn blocked(&self, ray: &Ray, t_min: f32, t_max: f32) -> bool {
        let any = |o: &Object| o.primitive.intersect(ray, t_min, t_max).is_some();
        if self.objects[self.bounded..].iter().any(any) {
            return true;
        }
        let mut found = false;
        self.bvh.walk(ray, t_max, |k, t| {
            found = any(&self.objects[k]);
            (!found).then_some(t)
        });
        found
    }
}
