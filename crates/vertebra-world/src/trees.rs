//! The trees of the direct solve (`SolverConfig::joints` =
//! [`JointSolver::Direct`](crate::JointSolver::Direct)): each bin's awake
//! joints and rods split into trees over its dynamic bodies, the trees
//! grouped by shape, eight of a shape to a block
//! (`vertebra_kernels::direct`).
//!
//! Joints are taken in key order (joints by slot, then rods by slot) and
//! join their dynamic bodies' sets; a set holds at most one joint to a
//! static or kinematic body (its tree's root). A joint whose two sides are
//! already joined, or that would give a set a second such joint, closes a
//! loop (two hands on one pole, a body between two anchors) and stays
//! iterative, whole. A tree's shape is its joints' kinds and bodies,
//! numbered in the order the joints name them, so two ragdolls built by
//! the same code share one (a crowd of one humanoid is one topology).
//! Built with the layout, never per step.

use core::f32::consts::PI;
use std::collections::BTreeMap;

use vertebra_kernels::body::LaneBlock;
use vertebra_kernels::body::StartLane;
use vertebra_kernels::direct::{
    BodyNode, JointLane, JointNode, JointRows, SwingRows, Topology, TreeBlock,
};
use vertebra_kernels::direct::{NodeKind, split};
use vertebra_kernels::limited::LimitLane;
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;
use vertebra_store::{BodyHandle, BodyKind, BodyStore};

use crate::joint::{JointDesc, JointKind, Swing, ellipse_semi_axis};
use crate::rod::RodDesc;

/// A joint (or rod) of a tree: where its lane is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Place {
    /// The block.
    pub block: usize,
    /// The joint's index in the block's joints.
    pub joint: usize,
    /// The lane.
    pub lane: usize,
}

/// A body of a tree: where its lane is, and which tree it is of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct BodyPlace {
    /// The block.
    pub block: usize,
    /// The body's index in the block's bodies.
    pub body: usize,
    /// The lane.
    pub lane: usize,
    /// The tree (an index into `Trees::members`).
    pub tree: usize,
}

/// Every tree of the layout.
#[derive(Clone, Debug, Default)]
pub(crate) struct Trees {
    /// The shapes, in the order first met.
    pub topologies: Vec<Topology>,
    /// The blocks, bin after bin.
    pub blocks: Vec<TreeBlock>,
    /// For each joint slot in a tree, its place.
    pub joints: Vec<Option<Place>>,
    /// For each rod slot in a tree, its place.
    pub rods: Vec<Option<Place>>,
    /// For each body slot in a tree, its place.
    pub bodies: Vec<Option<BodyPlace>>,
    /// Each tree's bodies (slots), in the order its joints name them.
    pub members: Vec<Vec<usize>>,
    /// No two lanes of any blocks write one row: blocks may run at once.
    pub disjoint: bool,
    /// Each shape's place in `topologies`.
    shapes: BTreeMap<Shape, usize>,
}

/// A tree's joints in key order: their rows and their bodies' places in
/// the tree (`None`: static or kinematic).
type Shape = Vec<(JointRows, Option<u32>, Option<u32>)>;

/// An edge of the graph: a joint or a rod.
#[derive(Clone, Copy, Debug)]
enum Edge {
    Joint(usize),
    Rod(usize),
}

/// Where a tree's piece goes: its block (in `Trees::blocks`) and lane,
/// and the tree's body and edge of each of the piece's bodies and joints.
struct Lane<'a> {
    block: usize,
    lane: usize,
    tree: usize,
    bodies: &'a [u32],
    joints: &'a [u32],
}

/// A tree found in a bin: its edges in key order and its bodies in the
/// order they name them.
struct Found {
    edges: Vec<Edge>,
    bodies: Vec<usize>,
    shape: Shape,
}

impl Trees {
    /// Lays out the trees of one bin's joints and rods (`Some` when awake
    /// and in the bin) for `backend`; returns the range of blocks they
    /// take and whether those blocks are solved together (the trees cut
    /// into pieces, [`plan`]); else each block is solved on its own.
    pub fn append(
        &mut self,
        joints: &[Option<JointDesc>],
        rods: &[Option<RodDesc>],
        bodies: &BodyStore,
        backend: Backend,
    ) -> (core::ops::Range<usize>, bool) {
        let first = self.blocks.len();
        let found = find(joints, rods, bodies);
        let wholes: Vec<usize> = found.iter().map(|f| self.whole(f)).collect();
        let first_tree = self.members.len();
        self.members.extend(found.iter().map(|f| f.bodies.clone()));
        let descs = (joints, rods, bodies);
        let Some(most) = plan(&self.topologies, &wholes, backend) else {
            let mut by_shape: BTreeMap<usize, Vec<(usize, &Found)>> = BTreeMap::new();
            for (t, (tree, &topology)) in found.iter().zip(&wholes).enumerate() {
                by_shape
                    .entry(topology)
                    .or_default()
                    .push((first_tree + t, tree));
            }
            for (topology, trees) in by_shape {
                for chunk in trees.chunks(BLOCK_LANES) {
                    let shape = &self.topologies[topology];
                    let mut block = TreeBlock::padding(topology as u32, shape);
                    let index = self.blocks.len();
                    for (lane, &(t, tree)) in chunk.iter().enumerate() {
                        let whole = Lane {
                            block: index,
                            lane,
                            tree: t,
                            bodies: &(0..tree.bodies.len() as u32).collect::<Vec<_>>(),
                            joints: &(0..tree.edges.len() as u32).collect::<Vec<_>>(),
                        };
                        self.set_lane(&mut block, &whole, tree, descs);
                    }
                    self.blocks.push(block);
                }
            }
            return (first..self.blocks.len(), false);
        };
        let cut: Vec<(Topology, Vec<u32>)> = (wholes.iter())
            .map(|&t| (self.topologies[t].clone(), self.topologies[t].cuts(most)))
            .collect();
        let trees: Vec<(&Topology, Vec<u32>)> = cut.iter().map(|(t, c)| (t, c.clone())).collect();
        let (mut blocks, placed) = split::lay_out(&trees, &mut self.topologies);
        for (t, (tree, pieces)) in found.iter().zip(&placed).enumerate() {
            for p in pieces {
                let lane = Lane {
                    block: first + p.block,
                    lane: p.lane,
                    tree: first_tree + t,
                    bodies: &p.piece.bodies,
                    joints: &p.piece.joints,
                };
                self.set_lane(&mut blocks[p.block], &lane, tree, descs);
            }
        }
        self.blocks.append(&mut blocks);
        (first..self.blocks.len(), true)
    }

    /// The topology of a whole found tree (added if new).
    fn whole(&mut self, found: &Found) -> usize {
        let next = self.topologies.len();
        let topology = *self.shapes.entry(found.shape.clone()).or_insert(next);
        if topology == next {
            let shape = Topology::new(found.bodies.len(), &found.shape);
            self.topologies.push(shape.expect("a found tree is a tree"));
        }
        topology
    }

    /// Checks that no row is written by two lanes (the trees are apart by
    /// construction; this is what lets their blocks run at once).
    pub fn check_disjoint(&mut self) {
        let mut written = std::collections::BTreeSet::new();
        self.disjoint = (self.blocks.iter())
            .flat_map(|b| &b.bodies)
            .flat_map(|n| n.write)
            .filter(|&w| w != vertebra_math::row::NO_WRITE)
            .all(|w| written.insert(w));
    }

    /// Writes a tree's piece (or the whole tree) into its lane: each of
    /// the piece's bodies and joints from the tree's.
    fn set_lane(
        &mut self,
        block: &mut TreeBlock,
        at: &Lane,
        tree: &Found,
        (joints, rods, bodies): (&[Option<JointDesc>], &[Option<RodDesc>], &BodyStore),
    ) {
        let lane = at.lane;
        block.padding &= !(1 << lane);
        for (k, &i) in at.bodies.iter().enumerate() {
            let node = &mut block.bodies[k];
            let slot = tree.bodies[i as usize];
            node.set(lane, slot as u32 + 1, true, 1.0, glam::Mat3::IDENTITY);
            set_mass(node, lane, bodies);
            let place = BodyPlace {
                block: at.block,
                body: k,
                lane,
                tree: at.tree,
            };
            if self.bodies.len() <= slot {
                self.bodies.resize(slot + 1, None);
            }
            self.bodies[slot] = Some(place);
        }
        for (k, &j) in at.joints.iter().enumerate() {
            let place = Some(Place {
                block: at.block,
                joint: k,
                lane,
            });
            let lane_data = match tree.edges[j as usize] {
                Edge::Joint(slot) => {
                    put(&mut self.joints, slot, place);
                    joint_lane(joints[slot].as_ref().expect("a tree's joint is awake"))
                }
                Edge::Rod(slot) => {
                    put(&mut self.rods, slot, place);
                    rod_lane(rods[slot].as_ref().expect("a tree's rod is awake"))
                }
            };
            block.joints[k].set(lane, &lane_data);
            block.soft |= lane_data.softness != LimitLane::HARD;
            block.driven |= lane_data.drive.is_some();
        }
    }

    /// Writes a joint's new settings into its tree lane (its kind and
    /// bodies unchanged), if it has one.
    pub fn update_joint(&mut self, slot: usize, desc: &JointDesc) {
        if let Some(Some(p)) = self.joints.get(slot) {
            self.blocks[p.block].joints[p.joint].set(p.lane, &joint_lane(desc));
        }
    }

    /// As [`Trees::update_joint`], for a rod.
    pub fn update_rod(&mut self, slot: usize, desc: &RodDesc) {
        if let Some(Some(p)) = self.rods.get(slot) {
            self.blocks[p.block].joints[p.joint].set(p.lane, &rod_lane(desc));
        }
    }

    /// Whether a joint's equality parts are solved here.
    pub fn has_joint(&self, slot: usize) -> bool {
        matches!(self.joints.get(slot), Some(Some(_)))
    }

    /// Whether a rod's curve and length are solved here.
    pub fn has_rod(&self, slot: usize) -> bool {
        matches!(self.rods.get(slot), Some(Some(_)))
    }
}

/// What one node of a block costs per solve, in instructions, on a
/// slice of up to four lanes (the scalar path's one, SSE4.1's four,
/// AVX2's half) and of eight (AVX2): the reference humanoid's direct
/// solve measured by callgrind (`docs/performance.md`, "Lanes within one
/// ragdoll"). Only their ratio and the port's matter.
const NODE_NARROW: u64 = 1_900;
/// See [`NODE_NARROW`].
const NODE_WIDE: u64 = 2_300;
/// What a port costs per lane and solve (a piece's complement copied in,
/// its parent's unknowns out).
const PORT: u64 = 150;

/// Whether to cut a bin's trees into pieces (their limbs side by side in
/// lanes), and where: `Some(most)` cuts every tree at the joints whose
/// subtrees hold at most `most` nodes (`Topology::cuts`), `None` lays
/// each tree out whole (eight of a shape to a block, a crowd's layout).
/// The choice is the cheapest by [`cost`] of every `most` the trees'
/// subtrees offer; the results are the same bits either way.
fn plan(topologies: &[Topology], trees: &[usize], backend: Backend) -> Option<usize> {
    let width = backend.lanes();
    if width == 1 {
        return None;
    }
    let mut counts: BTreeMap<usize, usize> = BTreeMap::new();
    for &t in trees {
        *counts.entry(t).or_default() += 1;
    }
    let whole = (counts.iter())
        .map(|(&t, &n)| cost(topologies[t].nodes.len(), n, width))
        .sum::<u64>();
    let mut candidates = std::collections::BTreeSet::new();
    for &t in counts.keys() {
        let sizes = topologies[t].subtree_sizes();
        let joints = (topologies[t].nodes.iter().enumerate())
            .filter(|(_, node)| matches!(node.kind, NodeKind::Joint { .. }));
        candidates.extend(joints.map(|(n, _)| sizes[n]));
    }
    let mut best = (whole, None);
    for most in candidates {
        let mut shapes: Vec<(Topology, usize)> = Vec::new();
        let mut ports = 0;
        for (&t, &n) in &counts {
            let cuts = topologies[t].cuts(most);
            ports += cuts.len() * n;
            for piece in topologies[t].split(&cuts) {
                match shapes.iter_mut().find(|(s, _)| *s == piece.topology) {
                    Some((_, count)) => *count += n,
                    None => shapes.push((piece.topology, n)),
                }
            }
        }
        let total = (shapes.iter())
            .map(|(s, n)| cost(s.nodes.len(), *n, width))
            .sum::<u64>()
            + ports as u64 * PORT;
        if total < best.0 {
            best = (total, Some(most));
        }
    }
    best.1
}

/// What `count` trees (or pieces) of `nodes` nodes cost per solve, laid
/// out eight to a block on a backend of `width` lanes.
fn cost(nodes: usize, count: usize, width: usize) -> u64 {
    let slices = |lanes: usize| -> u64 {
        match width {
            8 if lanes <= 4 => NODE_NARROW,
            8 => NODE_WIDE,
            _ => lanes.div_ceil(width) as u64 * NODE_NARROW,
        }
    };
    let (full, rest) = (count / BLOCK_LANES, count % BLOCK_LANES);
    let blocks = full as u64 * slices(BLOCK_LANES) + if rest > 0 { slices(rest) } else { 0 };
    nodes as u64 * blocks
}

fn put(places: &mut Vec<Option<Place>>, slot: usize, place: Option<Place>) {
    if places.len() <= slot {
        places.resize(slot + 1, None);
    }
    places[slot] = place;
}

/// A body's mass (kg) and body-frame inertia (kg m^2) into its lane.
pub(crate) fn set_mass(node: &mut BodyNode, lane: usize, bodies: &BodyStore) {
    let i = node.row[lane] as usize - 1;
    node.set_mass(lane, bodies.mass[i], bodies.inertia[i]);
}

/// A joint's lane, with every limit the direct solve holds: a socket's
/// swing (cone, ellipse or pyramid) and twist range, a hinge's range, hard
/// or soft; and its drive (a fixed joint takes none).
fn joint_lane(d: &JointDesc) -> JointLane {
    let free = [-PI, PI];
    let mut lane = JointLane {
        body_a: d.body_a.index() as u32 + 1,
        body_b: d.body_b.index() as u32 + 1,
        anchor_a: d.anchor_a,
        anchor_b: d.anchor_b,
        frame_a: vertebra_math::PortableQuat::normalize_portable(d.frame_a),
        frame_b: vertebra_math::PortableQuat::normalize_portable(d.frame_b),
        ..JointLane::FREE
    };
    match d.kind {
        JointKind::Socket(limits) => {
            match limits.swing {
                Swing::Free => {}
                Swing::Cone(half) => lane.swing_max = half,
                Swing::Ellipse { y, z } => {
                    lane.ellipse = [ellipse_semi_axis(y), ellipse_semi_axis(z)]
                }
                Swing::Pyramid { y, z } => lane.pyramid = [y, z],
            }
            lane.twist = limits.twist.unwrap_or(free);
            lane.softness = limits.softness.lane();
        }
        JointKind::Hinge { range, softness } => {
            lane.twist = range.unwrap_or(free);
            lane.softness = softness.lane();
        }
        JointKind::Fixed => {}
    }
    lane.drive = d.drive.map(|drive| drive.lane());
    lane
}

/// A rod's lane: its points are the centres of mass (zero anchors).
fn rod_lane(d: &RodDesc) -> JointLane {
    JointLane {
        body_a: d.body_a.index() as u32 + 1,
        body_b: d.body_b.index() as u32 + 1,
        anchor_a: glam::Vec3::ZERO,
        anchor_b: glam::Vec3::ZERO,
        frame_a: vertebra_math::PortableQuat::normalize_portable(d.frame_a),
        frame_b: vertebra_math::PortableQuat::normalize_portable(d.frame_b),
        rest_length: d.rest_length,
        swing_max: d.bend_limit.unwrap_or(PI),
        twist: d.twist_limit.unwrap_or([-PI, PI]),
        ..JointLane::FREE
    }
}

fn rows_of(d: &JointDesc) -> JointRows {
    let driven = d.drive.is_some();
    match &d.kind {
        JointKind::Socket(limits) => JointRows::Socket(
            match limits.swing {
                Swing::Free | Swing::Cone(_) => SwingRows::Cone,
                Swing::Ellipse { .. } => SwingRows::Ellipse,
                Swing::Pyramid { .. } => SwingRows::Pyramid,
            },
            driven,
        ),
        JointKind::Hinge { .. } => JointRows::Hinge(driven),
        JointKind::Fixed => JointRows::Fixed,
    }
}

/// The trees of one bin's joints and rods, in key order of their first
/// edge.
fn find(joints: &[Option<JointDesc>], rods: &[Option<RodDesc>], bodies: &BodyStore) -> Vec<Found> {
    let edges = (joints.iter().enumerate())
        .filter_map(|(s, d)| d.map(|d| (Edge::Joint(s), rows_of(&d), d.body_a, d.body_b)))
        .chain(
            (rods.iter().enumerate())
                .filter_map(|(s, d)| d.map(|d| (Edge::Rod(s), JointRows::Rod, d.body_a, d.body_b))),
        );
    let dynamic = |h: BodyHandle| bodies.kind[h.index()] == BodyKind::Dynamic;
    // Union-find over body slots; a set holds at most one joint to a
    // static or kinematic body (a second would close a loop through them).
    let mut parent: Vec<usize> = (0..bodies.capacity()).collect();
    let mut grounded = vec![false; bodies.capacity()];
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut tree_edges = Vec::new();
    for (edge, rows, a, b) in edges {
        let joined = match (dynamic(a), dynamic(b)) {
            (false, false) => continue,
            (true, true) => {
                let (ra, rb) = (root(&mut parent, a.index()), root(&mut parent, b.index()));
                let apart = ra != rb && !(grounded[ra] && grounded[rb]);
                if apart {
                    parent[ra] = rb;
                    grounded[rb] |= grounded[ra];
                }
                apart
            }
            (da, _) => {
                let r = root(&mut parent, if da { a.index() } else { b.index() });
                !core::mem::replace(&mut grounded[r], true)
            }
        };
        // A joint that would close a loop is iterated whole.
        if joined {
            tree_edges.push((edge, rows, a, b));
        }
    }
    // Group the edges by tree.
    let mut trees: Vec<Found> = Vec::new();
    let mut tree_of: BTreeMap<usize, usize> = BTreeMap::new();
    let mut owner: BTreeMap<usize, usize> = BTreeMap::new();
    for &(edge, rows, a, b) in &tree_edges {
        let body = if dynamic(a) { a.index() } else { b.index() };
        let set = root(&mut parent, body);
        let t = *tree_of.entry(set).or_insert_with(|| {
            trees.push(Found {
                edges: Vec::new(),
                bodies: Vec::new(),
                shape: Vec::new(),
            });
            trees.len() - 1
        });
        let tree = &mut trees[t];
        let mut local = |h: BodyHandle| {
            dynamic(h).then(|| {
                *owner.entry(h.index()).or_insert_with(|| {
                    tree.bodies.push(h.index());
                    tree.bodies.len() - 1
                }) as u32
            })
        };
        let (la, lb) = (local(a), local(b));
        tree.edges.push(edge);
        tree.shape.push((rows, la, lb));
    }
    trees
}

/// Each lane's start of step: its joints' points (a rod's centres) as
/// the step begins, and its bodies' mass properties as they are now.
impl crate::start::StartBlock for TreeBlock {
    fn start(&mut self, bodies: &BodyStore) {
        for node in &mut self.bodies {
            node.reset_moved();
        }
        for pins in &mut self.pins {
            pins.start_step();
        }
        for lane in (0..BLOCK_LANES).filter(|l| self.padding & (1 << l) == 0) {
            for node in &mut self.bodies {
                set_mass(node, lane, bodies);
            }
            for joint in &mut self.joints {
                start_joint(joint, lane, bodies);
            }
        }
    }
}

fn start_joint(joint: &mut JointNode, lane: usize, bodies: &BodyStore) {
    let pose = |row: u32| {
        let i = row as usize - 1;
        (bodies.precise_position(i), bodies.orientation[i])
    };
    let pairs = &mut joint.bodies;
    let ((pa, qa), (pb, qb)) = (pose(pairs.body_a[lane]), pose(pairs.body_b[lane]));
    let (la, lb) = (joint.anchor_a.get(lane), joint.anchor_b.get(lane));
    pairs.set_start(lane, &StartLane::new(pa, qa, la, pb, qb, lb));
}
