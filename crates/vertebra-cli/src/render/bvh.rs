//! A bounding volume hierarchy over the bounded primitives: a binary tree
//! of axis-aligned boxes, at most [`LEAF`] primitives a leaf. Each node's
//! primitives, sorted by their centres along one axis, are cut in two
//! where the surface area heuristic is least (the children's box areas
//! times their counts, over every axis and cut: MacDonald and Booth,
//! "Heuristics for ray tracing using space subdivision", 1990), so a long
//! wall does not widen the boxes of the bodies beside it. A ray visits a
//! node only when it meets the node's box, the nearer child first, so it
//! tests a handful of the pile's ~350 primitives instead of all of them.

use glam::Vec3;

use super::primitive::Ray;

/// The most primitives in a leaf.
const LEAF: usize = 2;

/// Levels cut by the heuristic; below them, at the median (which halves
/// each level), so no tree of `u32` primitives is deeper than 24 + 32.
const HEURISTIC_LEVELS: usize = 24;

/// The walk's stack: one entry more than the deepest tree.
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
            tree.split(0, 0, bounds.len(), 0, bounds);
        }
        tree
    }

    /// Makes node `at`, `level` deep, over `items[start..end]`, splitting
    /// it while it holds more than a leaf.
    fn split(
        &mut self,
        at: usize,
        start: usize,
        end: usize,
        level: usize,
        bounds: &[(Vec3, Vec3)],
    ) {
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
        let (axis, cut) = if level < HEURISTIC_LEVELS {
            cheapest_cut(range, bounds)
        } else {
            let extent = max - min;
            (extent.max_position(), range.len() / 2)
        };
        sort_along(range, axis, bounds);
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
        self.split(children, start, start + cut, level + 1, bounds);
        self.split(children + 1, start + cut, end, level + 1, bounds);
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
        // Nodes to visit with where the ray enters their boxes: one
        // whose entry lies beyond a hit found since it was pushed is
        // skipped untested.
        let mut stack = [(0u32, 0f32); MAX_DEPTH];
        let mut depth = match entry(&self.nodes[0], ray, inverse, t_max) {
            Some(t) => {
                stack[0] = (0, t);
                1
            }
            None => 0,
        };
        while depth > 0 {
            depth -= 1;
            let (at, t_entry) = stack[depth];
            if t_entry > t_max {
                continue;
            }
            let node = &self.nodes[at as usize];
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
            let children = [
                (a, entry(&self.nodes[a as usize], ray, inverse, t_max)),
                (b, entry(&self.nodes[b as usize], ray, inverse, t_max)),
            ];
            // Push the farther child first so the nearer is popped first.
            let [near, far] = if children[1].1.unwrap_or(f32::INFINITY)
                < children[0].1.unwrap_or(f32::INFINITY)
            {
                [children[1], children[0]]
            } else {
                children
            };
            for (child, t) in [far, near] {
                if let Some(t) = t {
                    stack[depth] = (child, t);
                    depth += 1;
                }
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

/// `items` sorted by their boxes' centres along `axis` (ties by index).
fn sort_along(items: &mut [u32], axis: usize, bounds: &[(Vec3, Vec3)]) {
    let centre = |i: u32| bounds[i as usize].0[axis] + bounds[i as usize].1[axis];
    items.sort_unstable_by(|&p, &q| centre(p).total_cmp(&centre(q)).then(p.cmp(&q)));
}

/// The axis and the count before the cut (1 to `len - 1`) whose halves'
/// box areas times counts sum least.
fn cheapest_cut(items: &mut [u32], bounds: &[(Vec3, Vec3)]) -> (usize, usize) {
    let area = |(lo, hi): (Vec3, Vec3)| {
        let e = (hi - lo).max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    };
    let grow = |(lo, hi): (Vec3, Vec3), i: u32| {
        let (a, b) = bounds[i as usize];
        (lo.min(a), hi.max(b))
    };
    let empty = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let n = items.len();
    let mut best = (f32::INFINITY, 0, n / 2);
    for axis in 0..3 {
        sort_along(items, axis, bounds);
        // right[k]: the cost of items[k..].
        let mut right = vec![0.0; n];
        let mut reach = empty;
        for k in (1..n).rev() {
            reach = grow(reach, items[k]);
            right[k] = area(reach) * (n - k) as f32;
        }
        let mut reach = empty;
        for k in 1..n {
            reach = grow(reach, items[k - 1]);
            let cost = area(reach) * k as f32 + right[k];
            if cost < best.0 {
                best = (cost, axis, k);
            }
        }
    }
    (best.1, best.2)
}
