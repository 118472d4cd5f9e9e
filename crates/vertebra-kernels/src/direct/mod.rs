//! The direct solve: every equality row of a tree of jointed bodies
//! projected at once, exactly for the linearised rows (Baraff 1996,
//! "Linear-time dynamics using Lagrange multipliers"; in XPBD form, Müller
//! et al. 2020).
//!
//! One iteration solves, for the rows' errors `C` and Jacobians `J`
//! ([`rows`]), the bodies' mass matrices `M` (world) and the rows'
//! compliance (zero: every equality part is hard),
//!
//! ```text
//!  [ M   -J^T ] [ dx      ]   [ 0 ]
//!  [ -J   0   ] [ dlambda ] = [ C ]
//! ```
//!
//! so that `C + J dx = 0` with `dx = M^-1 J^T dlambda`: the same step as
//! the parts' `dlambda = -C / (J M^-1 J^T)`, for every row of the tree
//! together. The matrix's graph (a node per body, a node per joint, an
//! edge where a joint touches a body) is the tree itself, so eliminating
//! the nodes leaves first adds nothing outside the tree (no fill-in):
//! each node's diagonal block takes its children's Schur complements,
//! `D_p -= A^T D_c^-1 A`, and is factored ([`ldl`]); one pass back from
//! the root gives every node's unknown. O(bodies), with dense blocks of at
//! most 6 x 6. Derivation and the handling of joints to static or
//! kinematic bodies (a tree's root) in `docs/direct.md`.
//!
//! A [`Topology`] is the elimination order of one tree's shape, computed
//! once; a [`TreeBlock`] holds up to eight trees of that shape, one per
//! lane (a crowd of one humanoid goes eight at a time), and the pass
//! solves them lane by lane with the same lane-generic code on every
//! backend.

pub mod ldl;
pub mod rows;

use bytemuck::{Pod, Zeroable};
use vertebra_math::block::{BLOCK_LANES, LaneSlices, QuatBlock, Vec3Block, for_live_slices};
use vertebra_math::row::NO_WRITE;
use vertebra_math::{Lane, LaneKernel, Sym3, Vec3};

use crate::body::{BodyLanes, BodyPairs, BodyRows};
use ldl::{MAX, PACKED, at};
pub use rows::JointRows;
use rows::{Geometry, Rows};

/// No node: the root's parent, or a joint's side on a static or kinematic
/// body.
pub const NONE: u32 = u32::MAX;

/// One node of a tree, in elimination order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Node {
    /// What the node is.
    pub kind: NodeKind,
    /// The node after which it is eliminated, that its block couples to
    /// ([`NONE`] for the root).
    pub parent: u32,
}

/// A body or a joint of a tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NodeKind {
    /// Body `index` of the tree's block (`TreeBlock::bodies`).
    Body {
        /// Its place in the block's bodies.
        index: u32,
    },
    /// Joint `index` of the tree's block (`TreeBlock::joints`).
    Joint {
        /// Its place in the block's joints.
        index: u32,
        /// Its rows.
        rows: JointRows,
        /// The node of its body a ([`NONE`]: static or kinematic).
        a: u32,
        /// The node of its body b.
        b: u32,
    },
}

/// A tree's shape: its nodes leaves first, each after its children, the
/// root last.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Topology {
    /// The nodes in elimination order.
    pub nodes: Vec<Node>,
    /// How many bodies.
    pub bodies: usize,
    /// How many joints.
    pub joints: usize,
}

/// Why a set of joints is not a tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TopologyError {
    /// A body or joint is not reached from the root (more than one tree).
    Disconnected,
    /// The joints close a loop (through the bodies, or through two joints
    /// to static or kinematic bodies).
    Loop,
    /// A joint names a body past the count, or no body at all.
    BadJoint,
}

impl Topology {
    /// The elimination order of `bodies` bodies joined by `joints` (each
    /// its rows and its two bodies' indices, `None` for a static or
    /// kinematic one). The root is the joint to a static or kinematic body
    /// if there is one (at most one: two would close a loop through the
    /// ground), else body 0.
    pub fn new(
        bodies: usize,
        joints: &[(JointRows, Option<u32>, Option<u32>)],
    ) -> Result<Self, TopologyError> {
        let count = bodies + joints.len();
        // Adjacency: body i is node i, joint j node bodies + j.
        let mut adjacent: Vec<Vec<u32>> = vec![Vec::new(); count];
        let mut grounded = None;
        for (j, &(_, a, b)) in joints.iter().enumerate() {
            let node = (bodies + j) as u32;
            let sides = [a, b];
            if sides.iter().flatten().any(|&i| i as usize >= bodies) || sides == [None, None] {
                return Err(TopologyError::BadJoint);
            }
            if sides.contains(&None) {
                if grounded.is_some() {
                    return Err(TopologyError::Loop);
                }
                grounded = Some(node);
            }
            for &i in sides.iter().flatten() {
                adjacent[i as usize].push(node);
                adjacent[node as usize].push(i);
            }
        }
        if count == 0 {
            return Err(TopologyError::Disconnected);
        }
        let root = grounded.unwrap_or(0);
        let mut parent = vec![NONE; count];
        let mut seen = vec![false; count];
        let mut order = Vec::with_capacity(count);
        // Depth first from the root; the reverse of the visit order puts
        // every node after its children.
        let mut stack = vec![root];
        seen[root as usize] = true;
        while let Some(n) = stack.pop() {
            order.push(n);
            for &m in &adjacent[n as usize] {
                if m == parent[n as usize] {
                    continue;
                }
                if seen[m as usize] {
                    return Err(TopologyError::Loop);
                }
                seen[m as usize] = true;
                parent[m as usize] = n;
                stack.push(m);
            }
        }
        if order.len() != count {
            return Err(TopologyError::Disconnected);
        }
        order.reverse();
        let mut place = vec![0u32; count];
        for (k, &n) in order.iter().enumerate() {
            place[n as usize] = k as u32;
        }
        let node_of = |n: u32| if n == NONE { NONE } else { place[n as usize] };
        let nodes = order
            .iter()
            .map(|&n| {
                let kind = match (n as usize).checked_sub(bodies) {
                    None => NodeKind::Body { index: n },
                    Some(j) => {
                        let (rows, a, b) = joints[j];
                        NodeKind::Joint {
                            index: j as u32,
                            rows,
                            a: a.map_or(NONE, node_of),
                            b: b.map_or(NONE, node_of),
                        }
                    }
                };
                Node {
                    kind,
                    parent: node_of(parent[n as usize]),
                }
            })
            .collect();
        Ok(Self {
            nodes,
            bodies,
            joints: joints.len(),
        })
    }

    /// A node's unknowns: 6 for a body, its rows for a joint.
    fn size(&self, n: usize) -> usize {
        match self.nodes[n].kind {
            NodeKind::Body { .. } => 6,
            NodeKind::Joint { rows, .. } => rows.count(),
        }
    }
}

/// One body of a tree in each lane: its row, and its mass properties
/// (copied from the store as each step begins).
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct BodyNode {
    /// The row read.
    pub row: [u32; BLOCK_LANES],
    /// The row written ([`NO_WRITE`] for padding).
    pub write: [u32; BLOCK_LANES],
    /// Mass (kg).
    pub mass: [f32; BLOCK_LANES],
    /// Inertia in the body frame (kg m^2): `xx yy zz xy xz yz`.
    pub inertia: [[f32; BLOCK_LANES]; 6],
}

impl BodyNode {
    /// Padding: the null row, written nowhere, a unit mass and inertia
    /// (so that its blocks stay regular).
    pub fn padding() -> Self {
        let mut node = Self::zeroed();
        for lane in 0..BLOCK_LANES {
            node.set(lane, 0, false, 1.0, glam::Mat3::IDENTITY);
        }
        node
    }

    /// Sets `lane`: row `row` (written when `write`), its mass (kg) and
    /// body-frame inertia (kg m^2).
    pub fn set(&mut self, lane: usize, row: u32, write: bool, mass: f32, inertia: glam::Mat3) {
        self.row[lane] = row;
        self.write[lane] = if write { row } else { NO_WRITE };
        self.set_mass(lane, mass, inertia);
    }

    /// Sets `lane`'s mass (kg) and body-frame inertia (kg m^2).
    pub fn set_mass(&mut self, lane: usize, mass: f32, inertia: glam::Mat3) {
        self.mass[lane] = mass;
        let m = inertia;
        let entries = [
            m.x_axis.x, m.y_axis.y, m.z_axis.z, m.y_axis.x, m.z_axis.x, m.z_axis.y,
        ];
        for (e, v) in self.inertia.iter_mut().zip(entries) {
            e[lane] = v;
        }
    }
}

/// One joint of a tree in each lane: its bodies, where its points started
/// and what its rows are measured from.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct JointNode {
    /// The two bodies' rows and the pair's start of step (only the rows
    /// read are used: the tree's bodies write themselves).
    pub bodies: BodyPairs,
    /// Anchor on a (m, a's body frame; zero for a rod).
    pub anchor_a: Vec3Block,
    /// Anchor on b (m, b's body frame).
    pub anchor_b: Vec3Block,
    /// Joint frame (a rod's material frame) in a's body frame.
    pub frame_a: QuatBlock,
    /// The same in b's body frame.
    pub frame_b: QuatBlock,
    /// A rod's rest length (m).
    pub rest_length: [f32; BLOCK_LANES],
    /// The swing cone's half-angle (the rod's bend limit; rad; pi: none).
    pub swing_max: [f32; BLOCK_LANES],
    /// The twist range's low end (a hinge's range; the rod's twist
    /// limit; rad).
    pub twist_min: [f32; BLOCK_LANES],
    /// The twist range's high end (rad).
    pub twist_max: [f32; BLOCK_LANES],
}

/// A joint's geometry in one lane, as the world lays it out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLane {
    /// Row of body a.
    pub body_a: u32,
    /// Row of body b.
    pub body_b: u32,
    /// Anchor on a (m, a's body frame).
    pub anchor_a: glam::Vec3,
    /// Anchor on b (m, b's body frame).
    pub anchor_b: glam::Vec3,
    /// Frame on a (body frame).
    pub frame_a: glam::Quat,
    /// Frame on b (body frame).
    pub frame_b: glam::Quat,
    /// A rod's rest length (m; 0 for a joint).
    pub rest_length: f32,
    /// The hard swing cone's half-angle, or the rod's bend limit (rad; pi
    /// for none).
    pub swing_max: f32,
    /// The hard twist range, a hinge's hard range or the rod's twist limit
    /// (rad; `[-pi, pi]` for none).
    pub twist: [f32; 2],
}

impl JointNode {
    /// Padding: null rows, nothing measured.
    pub fn padding() -> Self {
        let mut node = Self::zeroed();
        for lane in 0..BLOCK_LANES {
            node.set(
                lane,
                &JointLane {
                    body_a: 0,
                    body_b: 0,
                    anchor_a: glam::Vec3::ZERO,
                    anchor_b: glam::Vec3::ZERO,
                    frame_a: glam::Quat::IDENTITY,
                    frame_b: glam::Quat::IDENTITY,
                    rest_length: 0.0,
                    swing_max: core::f32::consts::PI,
                    twist: [-core::f32::consts::PI, core::f32::consts::PI],
                },
            );
        }
        node
    }

    /// Writes one joint into `lane`.
    pub fn set(&mut self, lane: usize, j: &JointLane) {
        self.bodies.set(lane, j.body_a, j.body_b, false, false);
        self.anchor_a.set(lane, j.anchor_a);
        self.anchor_b.set(lane, j.anchor_b);
        self.frame_a.set(lane, j.frame_a);
        self.frame_b.set(lane, j.frame_b);
        self.rest_length[lane] = j.rest_length;
        self.swing_max[lane] = j.swing_max;
        (self.twist_min[lane], self.twist_max[lane]) = (j.twist[0], j.twist[1]);
    }

    #[inline(always)]
    fn geometry<L: Lane>(&self, start: usize) -> Geometry<L> {
        Geometry {
            anchor_a: self.anchor_a.load(start),
            anchor_b: self.anchor_b.load(start),
            frame_a: self.frame_a.load(start),
            frame_b: self.frame_b.load(start),
            rest_length: L::load(&self.rest_length[start..]),
            swing_max: L::load(&self.swing_max[start..]),
            twist: [
                L::load(&self.twist_min[start..]),
                L::load(&self.twist_max[start..]),
            ],
            start: self.bodies.start(start),
        }
    }
}

/// A node's working values in each lane, rewritten every iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct NodeScratch {
    /// The diagonal block (packed lower triangle), then its factors.
    pub diagonal: [[f32; BLOCK_LANES]; PACKED],
    /// The right-hand side, then the node's unknowns.
    pub rhs: [[f32; BLOCK_LANES]; MAX],
    /// The block coupling it to its parent: the joint's rows (of the
    /// node or of its parent) against the body's six unknowns, row by row.
    pub coupling: [[f32; BLOCK_LANES]; MAX * 6],
}

impl NodeScratch {
    /// All zero.
    pub const ZERO: Self = Self {
        diagonal: [[0.0; BLOCK_LANES]; PACKED],
        rhs: [[0.0; BLOCK_LANES]; MAX],
        coupling: [[0.0; BLOCK_LANES]; MAX * 6],
    };
}

/// Up to eight trees of one [`Topology`], one per lane.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeBlock {
    /// Which topology (the world's list).
    pub topology: u32,
    /// Bit `i` set: lane `i` holds no tree.
    pub padding: u32,
    /// The bodies, in the topology's body order.
    pub bodies: Vec<BodyNode>,
    /// The joints, in the topology's joint order.
    pub joints: Vec<JointNode>,
    /// One per node.
    pub scratch: Vec<NodeScratch>,
}

impl TreeBlock {
    /// A block of padding lanes for a topology.
    pub fn padding(topology: u32, shape: &Topology) -> Self {
        Self {
            topology,
            padding: (1 << BLOCK_LANES) - 1,
            bodies: vec![BodyNode::padding(); shape.bodies],
            joints: vec![JointNode::padding(); shape.joints],
            scratch: vec![NodeScratch::ZERO; shape.nodes.len()],
        }
    }
}

/// One direct solve of every tree in `blocks`.
pub struct PositionPass<'a> {
    /// The blocks.
    pub blocks: &'a mut [TreeBlock],
    /// Their topologies, by `TreeBlock::topology`.
    pub topologies: &'a [Topology],
    /// Body rows, read and written.
    pub rows: &'a BodyRows,
}

impl LaneKernel for PositionPass<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        for block in self.blocks.iter_mut() {
            let padding = block.padding;
            let mut slices = Slices {
                topology: &self.topologies[block.topology as usize],
                block,
                rows: self.rows,
            };
            for_live_slices::<L, _>(padding, &mut slices);
        }
    }
}

/// One block of a [`PositionPass`].
struct Slices<'a> {
    topology: &'a Topology,
    block: &'a mut TreeBlock,
    rows: &'a BodyRows,
}

impl LaneSlices for Slices<'_> {
    #[inline(always)]
    fn slice<L: Lane>(&mut self, start: usize) {
        let (topology, rows) = (self.topology, self.rows);
        assemble::<L>(self.block, topology, rows, start);
        eliminate::<L>(self.block, topology, start);
        substitute::<L>(self.block, topology, start);
        apply::<L>(self.block, topology, rows, start);
    }
}

/// Loads `n` lanes-values from scratch arrays.
#[inline(always)]
fn load<L: Lane, const N: usize>(src: &[[f32; BLOCK_LANES]], start: usize) -> [L; N] {
    let mut out = [L::splat(0.0); N];
    for (o, s) in out.iter_mut().zip(src) {
        *o = L::load(&s[start..]);
    }
    out
}

/// Stores lane values into scratch arrays.
#[inline(always)]
fn store<L: Lane>(values: &[L], dst: &mut [[f32; BLOCK_LANES]], start: usize) {
    for (v, d) in values.iter().zip(dst) {
        v.store(&mut d[start..]);
    }
}

/// Every node's starting block: a body's mass matrix (world), a joint's
/// zero (hard rows) with its errors on the right, and each joint's
/// Jacobians written where the tree couples it to each body.
#[inline(always)]
fn assemble<L: Lane>(block: &mut TreeBlock, topology: &Topology, rows: &BodyRows, start: usize) {
    let zero = L::splat(0.0);
    for (n, node) in topology.nodes.iter().enumerate() {
        let mut diagonal = [zero; PACKED];
        let mut rhs = [zero; MAX];
        match node.kind {
            NodeKind::Body { index } => {
                let body = &block.bodies[index as usize];
                let q = BodyLanes::<L>::gather(rows, &body.row[start..]).q;
                let mass = L::load(&body.mass[start..]);
                let [xx, yy, zz, xy, xz, yz] = load::<L, 6>(&body.inertia, start);
                let inertia = Sym3 {
                    xx,
                    yy,
                    zz,
                    xy,
                    xz,
                    yz,
                }
                .rotated(q);
                for k in 0..3 {
                    diagonal[at(k, k)] = mass;
                }
                diagonal[at(3, 3)] = inertia.xx;
                diagonal[at(4, 3)] = inertia.xy;
                diagonal[at(5, 3)] = inertia.xz;
                diagonal[at(4, 4)] = inertia.yy;
                diagonal[at(5, 4)] = inertia.yz;
                diagonal[at(5, 5)] = inertia.zz;
            }
            NodeKind::Joint {
                index,
                rows: kind,
                a,
                b,
            } => {
                let joint = &block.joints[index as usize];
                let (body_a, body_b) = joint.bodies.gather::<L>(rows, start);
                let measured = Rows::measure(kind, &body_a, &body_b, &joint.geometry(start));
                let count = kind.count();
                rhs[..count].copy_from_slice(&measured.c[..count]);
                // The coupling to body `side` sits with whichever of the two
                // is the other's child.
                for (side, jacobian) in [(a, &measured.ja), (b, &measured.jb)] {
                    if side == NONE {
                        continue;
                    }
                    let holder = if node.parent == side {
                        n
                    } else {
                        side as usize
                    };
                    let mut flat = [zero; MAX * 6];
                    for (r, row) in jacobian.iter().take(count).enumerate() {
                        flat[r * 6..r * 6 + 6].copy_from_slice(row);
                    }
                    store(
                        &flat[..count * 6],
                        &mut block.scratch[holder].coupling,
                        start,
                    );
                }
            }
        }
        let scratch = &mut block.scratch[n];
        store(&diagonal, &mut scratch.diagonal, start);
        store(&rhs, &mut scratch.rhs, start);
    }
}

/// Leaves first: each node's block factored, its Schur complement and its
/// right-hand side passed to its parent. For a joint child with rows `J`
/// against its parent body, `D_p -= J^T D^-1 J` and `b_p += J^T D^-1 b`;
/// for a body child against its parent joint's rows `J`,
/// `D_p -= J D^-1 J^T` and `b_p += J D^-1 b` (the coupling block is `-J`).
#[inline(always)]
fn eliminate<L: Lane>(block: &mut TreeBlock, topology: &Topology, start: usize) {
    let zero = L::splat(0.0);
    for (n, node) in topology.nodes.iter().enumerate() {
        let size = topology.size(n);
        let mut factors = load::<L, PACKED>(&block.scratch[n].diagonal, start);
        ldl::factor(&mut factors, size);
        store(&factors, &mut block.scratch[n].diagonal, start);
        if node.parent == NONE {
            continue;
        }
        let p = node.parent as usize;
        let mut y = load::<L, MAX>(&block.scratch[n].rhs, start);
        ldl::solve(&factors, size, &mut y);
        let j = load::<L, { MAX * 6 }>(&block.scratch[n].coupling, start);
        let mut parent = load::<L, PACKED>(&block.scratch[p].diagonal, start);
        let mut parent_rhs = load::<L, MAX>(&block.scratch[p].rhs, start);
        match node.kind {
            NodeKind::Joint { .. } => {
                // X = D^-1 J, column by column (6 columns of `size` rows).
                let mut x = [[zero; MAX]; 6];
                for (c, column) in x.iter_mut().enumerate() {
                    for r in 0..size {
                        column[r] = j[r * 6 + c];
                    }
                    ldl::solve(&factors, size, column);
                }
                for r in 0..6 {
                    for s in 0..=r {
                        let mut sum = zero;
                        for i in 0..size {
                            sum += j[i * 6 + r] * x[s][i];
                        }
                        parent[at(r, s)] -= sum;
                    }
                    let mut sum = zero;
                    for i in 0..size {
                        sum += j[i * 6 + r] * y[i];
                    }
                    parent_rhs[r] += sum;
                }
            }
            NodeKind::Body { .. } => {
                let rows = topology.size(p);
                // X = D^-1 J^T, row by row of J (each a 6-vector).
                let mut x = [[zero; MAX]; MAX];
                for (r, xr) in x.iter_mut().enumerate().take(rows) {
                    xr.copy_from_slice(&j[r * 6..r * 6 + 6]);
                    ldl::solve(&factors, 6, xr);
                }
                for r in 0..rows {
                    for s in 0..=r {
                        let mut sum = zero;
                        for c in 0..6 {
                            sum += j[r * 6 + c] * x[s][c];
                        }
                        parent[at(r, s)] -= sum;
                    }
                    let mut sum = zero;
                    for c in 0..6 {
                        sum += j[r * 6 + c] * y[c];
                    }
                    parent_rhs[r] += sum;
                }
            }
        }
        store(&parent, &mut block.scratch[p].diagonal, start);
        store(&parent_rhs, &mut block.scratch[p].rhs, start);
    }
}

/// Root first: each node's unknowns from its factored block, its
/// right-hand side and its parent's unknowns (`x = D^-1 (b + J x_p)` for
/// a joint, `D^-1 (b + J^T x_p)` for a body), kept in `rhs`.
#[inline(always)]
fn substitute<L: Lane>(block: &mut TreeBlock, topology: &Topology, start: usize) {
    for (n, node) in topology.nodes.iter().enumerate().rev() {
        let size = topology.size(n);
        let factors = load::<L, PACKED>(&block.scratch[n].diagonal, start);
        let mut x = load::<L, MAX>(&block.scratch[n].rhs, start);
        if node.parent != NONE {
            let p = node.parent as usize;
            let xp = load::<L, MAX>(&block.scratch[p].rhs, start);
            let j = load::<L, { MAX * 6 }>(&block.scratch[n].coupling, start);
            match node.kind {
                NodeKind::Joint { .. } => {
                    for (r, xr) in x.iter_mut().enumerate().take(size) {
                        for c in 0..6 {
                            *xr += j[r * 6 + c] * xp[c];
                        }
                    }
                }
                NodeKind::Body { .. } => {
                    for r in 0..topology.size(p) {
                        for c in 0..6 {
                            x[c] += j[r * 6 + c] * xp[r];
                        }
                    }
                }
            }
        }
        ldl::solve(&factors, size, &mut x);
        store(&x[..size], &mut block.scratch[n].rhs, start);
    }
}

/// Moves every body by its unknowns: `p += dp`, turned by the world
/// rotation vector `dtheta` (`q += 1/2 (dtheta, 0) q`, renormalised, as
/// every part turns a body).
#[inline(always)]
fn apply<L: Lane>(block: &mut TreeBlock, topology: &Topology, rows: &BodyRows, start: usize) {
    for (n, node) in topology.nodes.iter().enumerate() {
        let NodeKind::Body { index } = node.kind else {
            continue;
        };
        let body = &block.bodies[index as usize];
        let mut lanes = BodyLanes::<L>::gather(rows, &body.row[start..]);
        let x = load::<L, MAX>(&block.scratch[n].rhs, start);
        lanes.p += Vec3::new(x[0], x[1], x[2]);
        let turn = lanes.q.inverse_rotate(Vec3::new(x[3], x[4], x[5]));
        lanes.q = lanes.q.integrate_local(turn, L::splat(1.0));
        lanes.scatter_pose(rows, &body.write[start..]);
    }
}
