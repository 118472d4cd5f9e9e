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

use vertebra_kernels::body::StartLane;
use vertebra_kernels::direct::{
    BodyNode, JointLane, JointNode, JointRows, SwingRows, Topology, TreeBlock,
};
use vertebra_kernels::limited::LimitLane;
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

/// A tree found in a bin: its edges in key order and its bodies in the
/// order they name them.
struct Found {
    edges: Vec<Edge>,
    bodies: Vec<usize>,
    shape: Shape,
}

impl Trees {
    /// Lays out the trees of one bin's joints and rods (`Some` when awake
    /// and in the bin); returns the range of blocks they take.
    pub fn append(
        &mut self,
        joints: &[Option<JointDesc>],
        rods: &[Option<RodDesc>],
        bodies: &BodyStore,
    ) -> core::ops::Range<usize> {
        let first = self.blocks.len();
        let mut by_shape: BTreeMap<usize, Vec<Found>> = BTreeMap::new();
        for found in find(joints, rods, bodies) {
            let next = self.topologies.len();
            let topology = *self.shapes.entry(found.shape.clone()).or_insert(next);
            if topology == next {
                let shape = Topology::new(found.bodies.len(), &found.shape);
                self.topologies.push(shape.expect("a found tree is a tree"));
            }
            by_shape.entry(topology).or_default().push(found);
        }
        for (topology, trees) in by_shape {
            for chunk in trees.chunks(BLOCK_LANES) {
                let shape = &self.topologies[topology];
                let mut block = TreeBlock::padding(topology as u32, shape);
                for (lane, tree) in chunk.iter().enumerate() {
                    self.set_lane(&mut block, lane, tree, joints, rods, bodies);
                }
                self.blocks.push(block);
            }
        }
        first..self.blocks.len()
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

    fn set_lane(
        &mut self,
        block: &mut TreeBlock,
        lane: usize,
        tree: &Found,
        joints: &[Option<JointDesc>],
        rods: &[Option<RodDesc>],
        bodies: &BodyStore,
    ) {
        block.padding &= !(1 << lane);
        for (k, &i) in tree.bodies.iter().enumerate() {
            let node = &mut block.bodies[k];
            node.set(lane, i as u32 + 1, true, 1.0, glam::Mat3::IDENTITY);
            set_mass(node, lane, bodies);
        }
        let index = self.blocks.len();
        for (k, edge) in tree.edges.iter().enumerate() {
            let place = Some(Place {
                block: index,
                joint: k,
                lane,
            });
            let lane_data = match *edge {
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
/// or soft.
fn joint_lane(d: &JointDesc) -> JointLane {
    let free = [-PI, PI];
    let mut lane = JointLane {
        body_a: d.body_a.index() as u32 + 1,
        body_b: d.body_b.index() as u32 + 1,
        anchor_a: d.anchor_a,
        anchor_b: d.anchor_b,
        frame_a: d.frame_a.normalize(),
        frame_b: d.frame_b.normalize(),
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
    lane
}

/// A rod's lane: its points are the centres of mass (zero anchors).
fn rod_lane(d: &RodDesc) -> JointLane {
    JointLane {
        body_a: d.body_a.index() as u32 + 1,
        body_b: d.body_b.index() as u32 + 1,
        anchor_a: glam::Vec3::ZERO,
        anchor_b: glam::Vec3::ZERO,
        frame_a: d.frame_a.normalize(),
        frame_b: d.frame_b.normalize(),
        rest_length: d.rest_length,
        swing_max: d.bend_limit.unwrap_or(PI),
        twist: d.twist_limit.unwrap_or([-PI, PI]),
        ..JointLane::FREE
    }
}

fn rows_of(kind: &JointKind) -> JointRows {
    match kind {
        JointKind::Socket(limits) => JointRows::Socket(match limits.swing {
            Swing::Free | Swing::Cone(_) => SwingRows::Cone,
            Swing::Ellipse { .. } => SwingRows::Ellipse,
            Swing::Pyramid { .. } => SwingRows::Pyramid,
        }),
        JointKind::Hinge { .. } => JointRows::Hinge,
        JointKind::Fixed => JointRows::Fixed,
    }
}

/// The trees of one bin's joints and rods, in key order of their first
/// edge.
fn find(joints: &[Option<JointDesc>], rods: &[Option<RodDesc>], bodies: &BodyStore) -> Vec<Found> {
    let edges = (joints.iter().enumerate())
        .filter_map(|(s, d)| d.map(|d| (Edge::Joint(s), rows_of(&d.kind), d.body_a, d.body_b)))
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
impl crate::layout::StartBlock for TreeBlock {
    fn start(&mut self, bodies: &BodyStore) {
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
