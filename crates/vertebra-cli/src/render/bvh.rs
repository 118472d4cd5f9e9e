//! A bounding volume hierarchy over the bounded primitives: a binary tree
//! of axis-aligned boxes, each node split at the median of its
//! primitives' centres along its longest side, at most [`LEAF`] primitives
//! a leaf. A ray visits a node only when it meets the node's box, the
//! nearer child first, so it tests a handful of the pile's ~350
//! primitives instead of all of them.

use glam::Vec3;

use super::primitive::Ray;

/// The most primitives in a leaf.
const LEAF: usize = 2;

/// The deepest a tree of `u32` primitives gets (a median split halves
/// each level).
const MAX_DEPTH: usize = 64;

struct Node {
    min: Vec3,
    max: Vec3,
    /// A leaf: `items[first .. first + count]`; an inner node (`count`
    /// 0): its children at `first` and `first + 1`.
    first: u32,
    count: u32,
}

/// The tree over primitives given by their bounds.
pub struct Bvh {
    nodes: Vec<Node>,
    /// Primitive indices, leaf by leaf.
    items: Vec<u32>,
}

impl Bvh {
    /// The tree over `bounds` (min, max per primitive; every number
    /// finite). The same bounds give the same tree.
    pub fn new(bounds: &[(Vec3, Vec3)]) -> Self {
        let mut tree = Self {
            nodes: Vec::new(),
            items: (0..bounds.len() as u32).collect(),
        };
        if !bounds.is_empty() {
            tree.nodes.push(Node {
                min: Vec3::ZERO,
                max: Vec3::ZERO,
                first: 0,
                count: 0,
            });
            tree.split(0, 0, bounds.len(), bounds);
        }
        tree
    }

    /// Makes node `at` over `items[start..end]`, splitting it while it
    /// holds more than a leaf.
    fn split(&mut self, at: usize, start: usize, end: usize, bounds: &[(Vec3, Vec3)]) {
        let range = &mut self.items[start..end];
        let (min, max) = range
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &i| {
                (lo.min(bounds[i as usize].0), hi.max(bounds[i as usize].1))
            });
        self.nodes[at].min = min;
        self.nodes[at].max = max;
        if range.len() <= LEAF {
            self.nodes[at].first = start as u32;
            self.nodes[at].count = range.len() as u32;
            return;
        }
        let extent = max - min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let centre = |i: u32| {
            let (lo, hi) = bounds[i as usize];
            (lo[axis] + hi[axis], i)
        };
        range.sort_unstable_by(|&p, &q| {
            let (a, b) = (centre(p), centre(q));
            a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))
        });
        let middle = start + range.len() / 2;
        let children = self.nodes.len();
        for _ in 0..2 {
            self.nodes.push(Node {
                min,
                max,
                first: 0,
                count: 0,
            });
        }
        self.nodes[at].first = children as u32;
        self.split(children, start, middle, bounds);
        self.split(children + 1, middle, end, bounds);
    }

    /// Calls `test(primitive, t_max)` for every primitive whose leaf box
    /// `ray` meets within `(0, t_max)`, nearer boxes first; `test` returns
    /// the new `t_max` (a hit's distance, which prunes the boxes beyond
    /// it) or `None` to stop.
    pub fn walk(&self, ray: &Ray, mut t_max: f32, mut test: impl FnMut(usize, f32) -> Option<f32>) {
        if self.nodes.is_empty() {
            return;
        }
        // 1/d, held finite: a component of 0 gives +-1e30, so a ray in
        // a slab's boundary plane gets 0 there, never 0 * inf = NaN.
        let safe = |d: f32| d.signum() / d.abs().max(1e-30);
        let inverse = Vec3::new(safe(ray.dir.x), safe(ray.dir.y), safe(ray.dir.z));
        let mut stack = [0u32; MAX_DEPTH];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let node = &self.nodes[stack[depth] as usize];
            if entry(node, ray, inverse, t_max).is_none() {
                continue;
            }
            if node.count > 0 {
                let (first, count) = (node.first as usize, node.count as usize);
                for &item in &self.items[first..first + count] {
                    match test(item as usize, t_max) {
                        Some(t) => t_max = t,
                        None => return,
                    }
                }
                continue;
            }
            let (a, b) = (node.first, node.first + 1);
            let (ta, tb) = (
                entry(&self.nodes[a as usize], ray, inverse, t_max),
                entry(&self.nodes[b as usize], ray, inverse, t_max),
            );
            // Push the farther child first so the nearer is popped first.
            let (near, far) = if tb.unwrap_or(f32::INFINITY) < ta.unwrap_or(f32::INFINITY) {
                (b, a)
            } else {
                (a, b)
            };
            for child in [far, near] {
                stack[depth] = child;
                depth += 1;
            }
        }
    }
}

/// Where `ray` enters `node`'s box within `(0, t_max)` (0 from inside),
/// or `None`; `inverse` is the ray direction's (finite) reciprocal.
fn entry(node: &Node, ray: &Ray, inverse: Vec3, t_max: f32) -> Option<f32> {
    let t1 = (node.min - ray.origin) * inverse;
    let t2 = (node.max - ray.origin) * inverse;
    let near = t1.min(t2).max_element().max(0.0);
    let far = t1.max(t2).min_element().min(t_max);
    (near <= far).then_some(near)
}
