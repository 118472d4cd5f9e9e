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
//! most 9 x 9. Derivation and the handling of joints to static or
//! kinematic bodies (a tree's root) in `docs/direct.md`.
//!
//! A [`Topology`] is the elimination order of one tree's shape, computed
//! once; a [`TreeBlock`] holds up to eight trees of that shape, one per
//! lane (a crowd of one humanoid goes eight at a time), and the pass
//! solves them lane by lane with the same lane-generic code on every
//! backend.

pub mod drive;
pub mod ldl;
pub mod load;
pub mod pin;
pub mod rows;
mod solve;
pub mod split;

use bytemuck::{Pod, Zeroable};
use vertebra_math::block::{BLOCK_LANES, LaneSlices, QuatBlock, Vec3Block, for_live_slices};
use vertebra_math::row::NO_WRITE;
use vertebra_math::{Backend, Lane, LaneKernel, Sym3};

use crate::body::{BodyPairs, BodyRows, LaneBlock, PairLane};
use crate::driven::DriveLane;
use crate::limited::{LimitLane, SoftnessBlock};
use crate::pass::SubstepScale;
use drive::{DRIVE_RECORD, DriveNode};
use ldl::{MAX, PACKED};
use rows::{Geometry, LIMIT_RECORD, MAX_DRIVE_ROWS, MAX_LIMITS, MAX_OPTIONAL};
pub use rows::{JointRows, SwingRows};

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

/// A node's child: another node of its tree, or a port (a subtree laid
/// out in another block, whose Schur complement the block copies in).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Child {
    /// Node `index` of the same topology.
    Node(u32),
    /// Port `index` of the block ([`TreeBlock::ports`]).
    Port(u32),
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
    /// Every node's children, in the order their complements are taken
    /// (a body's joints by joint index, ports among them where the
    /// joints they stand for were; a joint's one body): node `n`'s are
    /// `children[starts[n]..starts[n + 1]]`.
    pub children: Vec<Child>,
    /// Where each node's children start in `children` (one more entry
    /// than nodes).
    pub starts: Vec<u32>,
    /// How many ports.
    pub ports: usize,
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
            let past = sides.iter().flatten().max() >= Some(&(bodies as u32));
            if past || sides == [None, None] {
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
        let mut nodes = Vec::with_capacity(count);
        for &n in &order {
            let kind = match (n as usize).checked_sub(bodies) {
                None => NodeKind::Body { index: n },
                Some(j) => {
                    let (rows, a, b) = joints[j];
                    NodeKind::Joint {
                        index: j as u32,
                        rows,
                        a: node_of(&place, a),
                        b: node_of(&place, b),
                    }
                }
            };
            let up = parent[n as usize];
            nodes.push(Node {
                kind,
                parent: if up == NONE { NONE } else { place[up as usize] },
            });
        }
        let mut keys = Vec::with_capacity(nodes.len());
        for node in &nodes {
            keys.push(match node.kind {
                NodeKind::Joint { index, .. } => index,
                NodeKind::Body { .. } => 0,
            });
        }
        let children = children_in_order(&nodes, &keys, &[]);
        Ok(Self::with_children(
            nodes,
            bodies,
            joints.len(),
            children,
            0,
        ))
    }

    /// A topology from its nodes and their children (as
    /// [`children_in_order`] gives them).
    pub(crate) fn with_children(
        nodes: Vec<Node>,
        bodies: usize,
        joints: usize,
        children: Vec<Vec<Child>>,
        ports: usize,
    ) -> Self {
        let mut starts = vec![0u32];
        let mut flat = Vec::new();
        for list in children {
            flat.extend(list);
            starts.push(flat.len() as u32);
        }
        Self {
            nodes,
            bodies,
            joints,
            children: flat,
            starts,
            ports,
        }
    }

    /// Node `n`'s children, in the order its block takes them.
    #[inline(always)]
    pub fn children(&self, n: usize) -> &[Child] {
        &self.children[self.starts[n] as usize..self.starts[n + 1] as usize]
    }

    /// A node's unknowns: 6 for a body, its rows for a joint.
    pub fn size(&self, n: usize) -> usize {
        match self.nodes[n].kind {
            NodeKind::Body { .. } => 6,
            NodeKind::Joint { rows, .. } => rows.count(),
        }
    }
}

/// Every node's children in the order the solve takes them: a body's
/// joints by `keys` (each node's joint index in the whole tree; `ports`:
/// `(body node, joint index, port)`, a port in place of a joint laid out
/// elsewhere), a joint's one child body. The order is part of the
/// arithmetic: a tree gives the same bits however it is laid out.
pub(crate) fn children_in_order(
    nodes: &[Node],
    keys: &[u32],
    ports: &[(u32, u32, u32)],
) -> Vec<Vec<Child>> {
    let mut keyed: Vec<Vec<(u32, Child)>> = vec![Vec::new(); nodes.len()];
    for (n, node) in nodes.iter().enumerate() {
        if node.parent != NONE {
            keyed[node.parent as usize].push((keys[n], Child::Node(n as u32)));
        }
    }
    for &(node, joint, index) in ports {
        keyed[node as usize].push((joint, Child::Port(index)));
    }
    let mut children = Vec::with_capacity(keyed.len());
    for mut list in keyed {
        // Keys are joint indices, distinct among a node's children.
        list.sort_unstable();
        let mut ordered = Vec::with_capacity(list.len());
        for (_, child) in list {
            ordered.push(child);
        }
        children.push(ordered);
    }
    children
}

/// The node of body `i` (`NONE` for none: static or kinematic).
fn node_of(place: &[u32], i: Option<u32>) -> u32 {
    match i {
        Some(i) => place[i as usize],
        None => NONE,
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
    /// How far the tree's solves moved the body this step (never read by
    /// the solve): the sum of every applied `dp` (m, world) and turn (rad,
    /// world), from which [`load::LoadPass`] reads each joint's load.
    pub moved: [[f32; BLOCK_LANES]; 6],
}

impl BodyNode {
    /// Zeroes `moved`, as a step begins.
    pub fn reset_moved(&mut self) {
        self.moved = [[0.0; BLOCK_LANES]; 6];
    }

    /// The body-frame inertia (kg m^2) of lanes `start ..`.
    #[inline(always)]
    pub(crate) fn inertia_lanes<L: Lane>(&self, start: usize) -> Sym3<L> {
        Sym3::from_entries(solve::load::<L, 6>(&self.inertia, start))
    }

    /// `lane`'s `moved`: the displacement (m) and turn (rad), world.
    pub fn moved(&self, lane: usize) -> (glam::Vec3, glam::Vec3) {
        let m = &self.moved;
        (
            glam::Vec3::new(m[0][lane], m[1][lane], m[2][lane]),
            glam::Vec3::new(m[3][lane], m[4][lane], m[5][lane]),
        )
    }

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
    /// The elliptical cone's semi-axes, `sin(theta_y / 2)` and
    /// `sin(theta_z / 2)` (1: none).
    pub ellipse: [[f32; BLOCK_LANES]; 2],
    /// The pyramid's ranges about Y and Z, `[min, max]` each (rad).
    pub pyramid: [[[f32; BLOCK_LANES]; 2]; 2],
    /// The limits' softness (all zero: hard; `parts::limit`).
    pub softness: SoftnessBlock,
    /// Each limit row's violation at the substep's start (`C_0`: a soft
    /// limit's damping, a hard limit's return; [`StartPass`]).
    pub limit_start: [[f32; BLOCK_LANES]; MAX_LIMITS],
    /// Each limit row's multiplier accumulated over the substep (a soft
    /// limit's spring force; reset by [`StartPass`]).
    pub limit_lambda: [[f32; BLOCK_LANES]; MAX_LIMITS],
    /// The tree's share of the joint's mean force on `b` over the last
    /// step (N, world; [`load::LoadPass`]; never read by the solve).
    pub force: Vec3Block,
    /// Its share of the mean torque on `b` about `b`'s anchor (N m,
    /// world).
    pub torque: Vec3Block,
    /// The joint's drive, held by its drive rows ([`drive`]).
    pub drive: DriveNode,
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
    /// The socket's twist range, a hinge's range or the rod's twist limit
    /// (rad; `[-pi, pi]` for none).
    pub twist: [f32; 2],
    /// The elliptical cone's semi-axes `[sin(theta_y / 2), sin(theta_z /
    /// 2)]` (`[1, 1]` for none).
    pub ellipse: [f32; 2],
    /// The pyramid's ranges about Y and Z (rad; `[-pi, pi]` for none).
    pub pyramid: [[f32; 2]; 2],
    /// The limits' softness ([`LimitLane::HARD`]: hard).
    pub softness: LimitLane,
    /// The drive, if any (a socket's or a hinge's).
    pub drive: Option<DriveLane>,
}

impl JointLane {
    /// The null rows, no anchors, identity frames and no limits: padding,
    /// and the base a lane's own fields are written over.
    pub const FREE: Self = Self {
        body_a: 0,
        body_b: 0,
        anchor_a: glam::Vec3::ZERO,
        anchor_b: glam::Vec3::ZERO,
        frame_a: glam::Quat::IDENTITY,
        frame_b: glam::Quat::IDENTITY,
        rest_length: 0.0,
        swing_max: core::f32::consts::PI,
        twist: [-core::f32::consts::PI, core::f32::consts::PI],
        ellipse: [1.0, 1.0],
        pyramid: [[-core::f32::consts::PI, core::f32::consts::PI]; 2],
        softness: LimitLane::HARD,
        drive: None,
    };
}

/// Padding: null rows, nothing measured.
impl LaneBlock for JointNode {
    type Lane = JointLane;
    const PADDING: JointLane = JointLane::FREE;

    /// Writes one joint into `lane` (the tree's solve writes the bodies,
    /// never the node's pass: no row written).
    fn set(&mut self, lane: usize, j: &JointLane) {
        let pair = PairLane {
            body_a: j.body_a,
            body_b: j.body_b,
            dynamic_a: false,
            dynamic_b: false,
        };
        self.bodies.set(lane, &pair);
        self.anchor_a.set(lane, j.anchor_a);
        self.anchor_b.set(lane, j.anchor_b);
        self.frame_a.set(lane, j.frame_a);
        self.frame_b.set(lane, j.frame_b);
        self.rest_length[lane] = j.rest_length;
        self.swing_max[lane] = j.swing_max;
        (self.twist_min[lane], self.twist_max[lane]) = (j.twist[0], j.twist[1]);
        for (axis, semi) in self.ellipse.iter_mut().zip(j.ellipse) {
            axis[lane] = semi;
        }
        for (axis, range) in self.pyramid.iter_mut().zip(j.pyramid) {
            (axis[0][lane], axis[1][lane]) = (range[0], range[1]);
        }
        self.softness.set(lane, &j.softness);
        self.drive.set(lane, j.drive.as_ref());
    }
}

impl JointNode {
    /// Whether the lane's limits are soft.
    pub fn is_soft(&self, lane: usize) -> bool {
        self.softness.get(lane) != LimitLane::HARD
    }

    /// The lanes from `start` whose limits are soft.
    #[inline(always)]
    fn soft_lanes<L: Lane>(&self, start: usize) -> L::Mask {
        let s = &self.softness;
        let sum = L::load(&s.compliance[start..])
            + L::load(&s.period2[start..])
            + L::load(&s.damping_time[start..]);
        sum.gt(L::splat(0.0))
    }

    #[inline(always)]
    fn geometry<L: Lane>(&self, start: usize, scale: SubstepScale) -> Geometry<L> {
        Geometry {
            anchor_a: self.anchor_a.load(start),
            anchor_b: self.anchor_b.load(start),
            frame_a: self.frame_a.load(start),
            frame_b: self.frame_b.load(start),
            rest_length: L::load(&self.rest_length[start..]),
            swing_max: L::load(&self.swing_max[start..]),
            ellipse: load_pair(&self.ellipse, start),
            pyramid: [
                load_pair(&self.pyramid[0], start),
                load_pair(&self.pyramid[1], start),
            ],
            twist: [
                L::load(&self.twist_min[start..]),
                L::load(&self.twist_max[start..]),
            ],
            softness: self
                .softness
                .lanes(start, L::splat(scale.inv_h), L::splat(scale.inv_h2)),
            drive_target: self.drive.settings.target.load(start),
            start: self.bodies.start(start),
        }
    }
}

/// Two arrays' lanes from `start`.
#[inline(always)]
fn load_pair<L: Lane>(r: &[[f32; BLOCK_LANES]; 2], start: usize) -> [L; 2] {
    [L::load(&r[0][start..]), L::load(&r[1][start..])]
}

/// Values a node's measured block holds ([`NodeScratch::measured`]).
pub const MEASURED: usize = 7;

/// A node's working values in each lane.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct NodeScratch {
    /// The block's factors (packed lower triangle: `L` below the
    /// diagonal, `1 / D` on it), kept while the node is clean.
    pub factors: [[f32; BLOCK_LANES]; PACKED],
    /// The right-hand side, its children's taken (kept with the factors).
    pub b: [[f32; BLOCK_LANES]; MAX],
    /// The node's unknowns after the substitution: a body's `(dp,
    /// dtheta)` (m, rad, world), a joint's multipliers.
    pub x: [[f32; BLOCK_LANES]; MAX],
    /// Minus the Schur complement the node passes to its parent (packed,
    /// the parent's size): the parent adds it to its block.
    pub minus: [[f32; BLOCK_LANES]; PACKED],
    /// Minus what the node adds to its parent's right-hand side.
    pub minus_b: [[f32; BLOCK_LANES]; MAX],
    /// The block as the solve measured it: a body's mass and world
    /// inertia (`m, xx, xy, xz, yy, yz, zz`), a joint's errors up to its
    /// limit rows (theirs are in `limits`).
    pub measured: [[f32; BLOCK_LANES]; MEASURED],
    /// The Jacobian coupling the node to its parent: a joint's rows on
    /// its parent body (for the root joint, on its static or kinematic
    /// side), or a body's parent joint's rows on the body, row by row.
    pub coupling: [[f32; BLOCK_LANES]; MAX * 6],
    /// A joint's limit rows as measured (held or not): each row's signed
    /// distance past its limit, its angular Jacobians on a and b and its
    /// generalised inverse mass (`c, J_a, J_b, w`: eight values a row),
    /// which predict where the solve's step takes it.
    pub limits: [[f32; BLOCK_LANES]; MAX_LIMITS * LIMIT_RECORD],
    /// A joint's drive rows as measured: each row's error, generalised
    /// inverse mass and target (`c, w, T`: [`DRIVE_RECORD`] values a row).
    pub drive: [[f32; BLOCK_LANES]; MAX_DRIVE_ROWS * DRIVE_RECORD],
    /// A joint's optional rows held in this solve (1) or not (0): its
    /// limits' active set, then its drive's rows (held where the lane has
    /// a drive).
    pub active: [[f32; BLOCK_LANES]; MAX_OPTIONAL],
    /// The active set the last settle chose: a crossing lane's next
    /// pass, and the next solve's start.
    pub next: [[f32; BLOCK_LANES]; MAX_OPTIONAL],
    /// The active set of the solve's first pass (a restart's).
    pub first: [[f32; BLOCK_LANES]; MAX_OPTIONAL],
}

impl NodeScratch {
    /// All zero.
    pub const ZERO: Self = Self {
        factors: [[0.0; BLOCK_LANES]; PACKED],
        b: [[0.0; BLOCK_LANES]; MAX],
        x: [[0.0; BLOCK_LANES]; MAX],
        minus: [[0.0; BLOCK_LANES]; PACKED],
        minus_b: [[0.0; BLOCK_LANES]; MAX],
        measured: [[0.0; BLOCK_LANES]; MEASURED],
        coupling: [[0.0; BLOCK_LANES]; MAX * 6],
        limits: [[0.0; BLOCK_LANES]; MAX_LIMITS * LIMIT_RECORD],
        drive: [[0.0; BLOCK_LANES]; MAX_DRIVE_ROWS * DRIVE_RECORD],
        active: [[0.0; BLOCK_LANES]; MAX_OPTIONAL],
        next: [[0.0; BLOCK_LANES]; MAX_OPTIONAL],
        first: [[0.0; BLOCK_LANES]; MAX_OPTIONAL],
    };
}

/// Where a lane's value comes from in another block of the same pass:
/// the block's place in the pass's blocks, its lane and its node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Source {
    /// The block (an index into [`PositionPass::blocks`]).
    pub block: u32,
    /// The lane.
    pub lane: u8,
    /// The node.
    pub node: u32,
}

/// A port: where a body's child subtree, laid out in another block (an
/// earlier one of the same pass), hands it its Schur complement.
#[derive(Clone, Debug, PartialEq)]
pub struct Port {
    /// Each lane's subtree root (a joint node), `None` for a lane
    /// without one.
    pub source: [Option<Source>; BLOCK_LANES],
    /// Its `NodeScratch::minus`, copied in before the block is
    /// eliminated.
    pub minus: [[f32; BLOCK_LANES]; PACKED],
    /// Its `NodeScratch::minus_b`.
    pub minus_b: [[f32; BLOCK_LANES]; MAX],
    /// The lanes whose subtree was eliminated again this pass.
    pub dirty: u8,
    /// Its subtree's momentum over the step, copied in before the block's
    /// [`load::LoadPass`].
    pub momentum: load::MomentumBlock,
}

impl Port {
    /// A port with no subtree in any lane.
    pub fn empty() -> Self {
        Self {
            source: [None; BLOCK_LANES],
            minus: [[0.0; BLOCK_LANES]; PACKED],
            minus_b: [[0.0; BLOCK_LANES]; MAX],
            dirty: 0,
            momentum: [Vec3Block::ZERO; 2],
        }
    }
}

/// Up to eight trees of one [`Topology`], one per lane; or up to eight
/// pieces of trees (a subtree and the trunk it hangs from laid out in
/// blocks of their own, joined by [`Port`]s and [`TreeBlock::parent`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TreeBlock {
    /// Which topology (the world's list).
    pub topology: u32,
    /// Bit `i` set: lane `i` holds no tree.
    pub padding: u32,
    /// Some lane has a soft limit (its rows then carry compliance and
    /// damping, and [`StartPass`] measures their start).
    pub soft: bool,
    /// Some lane has a drive (its joints' drive rows are then measured
    /// and held).
    pub driven: bool,
    /// The next solve chooses its limits' active set afresh (the limits
    /// violated then), as the first of a substep does ([`StartPass`] sets
    /// it); a later one starts from the set the solve before settled on.
    pub fresh: bool,
    /// The bodies, in the topology's body order.
    pub bodies: Vec<BodyNode>,
    /// The joints, in the topology's joint order.
    pub joints: Vec<JointNode>,
    /// One per node.
    pub scratch: Vec<NodeScratch>,
    /// Per node, the lanes whose block must be factored again this pass
    /// (a limit row taken or let go, in it or below it).
    pub dirty: Vec<u8>,
    /// Per joint node, the lanes holding each optional row this pass.
    pub held: Vec<[u8; MAX_OPTIONAL]>,
    /// The lanes whose active set crossed in the last settle (after the
    /// passes, `end_unsettled` joins its own flags across pieces here).
    pub crossing: [f32; BLOCK_LANES],
    /// The lanes whose solve started again this solve
    /// (`solve::restart`).
    pub restarted: u8,
    /// The lanes whose pins had not settled when their passes ran out
    /// (`end_unsettled`).
    pub unsettled: u8,
    /// Each lane's tree's largest body step in the solve's first pass
    /// (`step_sizes`, the largest over the tree's pieces; set in solves
    /// where some block takes pins).
    pub first_step: [f32; BLOCK_LANES],
    /// The topology's ports, each lane's subtree.
    pub ports: Vec<Port>,
    /// Where each lane's root joint's parent body is solved, for a piece
    /// hanging from a trunk laid out in a later block (`None`: a static
    /// or kinematic body, which does not move).
    pub parent: [Option<Source>; BLOCK_LANES],
    /// That parent body's unknowns, copied in before the block's
    /// substitution (zero for none).
    pub parent_x: [[f32; BLOCK_LANES]; 6],
    /// Per node, its subtree's momentum over the step, about a body's
    /// centre ([`load::LoadPass`]; never read by the solve).
    pub momenta: Vec<load::MomentumBlock>,
    /// Per body (in the topology's body order), its pins: contacts with
    /// static or kinematic bodies solved as rows of the tree's solve
    /// ([`pin`]); empty for a block that takes none.
    pub pins: Vec<pin::PinNode>,
}

impl TreeBlock {
    /// A block of padding lanes for a topology.
    pub fn padding(topology: u32, shape: &Topology) -> Self {
        Self {
            topology,
            padding: (1 << BLOCK_LANES) - 1,
            soft: false,
            driven: false,
            fresh: true,
            bodies: vec![BodyNode::padding(); shape.bodies],
            joints: vec![JointNode::padding(); shape.joints],
            scratch: vec![NodeScratch::ZERO; shape.nodes.len()],
            dirty: vec![0; shape.nodes.len()],
            held: vec![[0; MAX_OPTIONAL]; shape.nodes.len()],
            crossing: [0.0; BLOCK_LANES],
            restarted: 0,
            unsettled: 0,
            first_step: [0.0; BLOCK_LANES],
            ports: vec![Port::empty(); shape.ports],
            parent: [None; BLOCK_LANES],
            parent_x: [[0.0; BLOCK_LANES]; 6],
            momenta: vec![[Vec3Block::ZERO; 2]; shape.nodes.len()],
            pins: Vec::new(),
        }
    }

    /// Gives every body of the block its (empty) pin slots.
    pub fn take_pins(&mut self) {
        self.pins = vec![pin::PinNode::empty(); self.bodies.len()];
    }

    /// Whether the block's bodies take pins.
    pub fn pinned(&self) -> bool {
        !self.pins.is_empty()
    }

    /// Whether the block's solves may take passes of their own: it takes
    /// pins, or has drives (whose caps take a pass).
    pub fn takes_passes(&self) -> bool {
        self.pinned() || self.driven
    }

    /// The lanes holding a tree (or a piece of one).
    pub fn live(&self) -> u8 {
        !(self.padding as u8)
    }
}

/// One direct solve of every tree in `blocks`, which are solved together:
/// a block's ports and parent name earlier and later blocks of the same
/// slice (pieces of trees come before the trunks they hang from).
pub struct PositionPass<'a> {
    /// The blocks.
    pub blocks: &'a mut [TreeBlock],
    /// Their topologies, by `TreeBlock::topology`.
    pub topologies: &'a [Topology],
    /// Body rows, read and written.
    pub rows: &'a BodyRows,
    /// The substep's time scale (the soft limits').
    pub scale: SubstepScale,
    /// How many times a solve may factor a tree, its active set settled
    /// between (at least once; [`MAX_PASSES`] for a closing solve). The
    /// set a solve leaves is where the next starts from, whatever the
    /// bound.
    pub passes: usize,
}

impl PositionPass<'_> {
    /// Runs the solve on `backend`. Each phase enters the backend on its
    /// own ([`Backend::dispatch`] per block and phase): a phase is then a
    /// function of its own for each instruction set, where one kernel
    /// holding all five, every joint kind's rows unrolled in each, made one
    /// function per backend that took the optimiser minutes to compile.
    pub fn run(self, backend: Backend) {
        let PositionPass {
            blocks,
            topologies,
            rows,
            scale,
            passes,
        } = self;
        let on = (backend, topologies, rows, scale);
        for block in blocks.iter_mut() {
            run_phase(on, block, Phase::Measure);
            let live = block.live();
            block.dirty.fill(live);
        }
        // Pins and drives reaching their caps take their own passes, lane
        // by lane, past the limits' bound (`solve::join_crossings`).
        let own = blocks.iter().any(TreeBlock::takes_passes);
        let pinned = blocks.iter().any(TreeBlock::pinned);
        let most = if own {
            passes.max(pin::PIN_PASSES)
        } else {
            passes.max(1)
        };
        // A drive's cap found as the pins' passes run out takes one more,
        // or (on pins) starts the solve's passes again (`solve::restart`).
        let mut last = most + 1;
        for block in blocks.iter_mut() {
            block.restarted = 0;
            block.unsettled = 0;
        }
        for pass in 1.. {
            solve_pass(on, blocks, pass == 1);
            if pass == 1 && pinned {
                for block in blocks.iter_mut() {
                    block.first_step = step_sizes(block, topologies);
                }
                solve::join_across_pieces(blocks, first_step_of, larger);
            }
            let bounds = solve::Bounds { pass, passes, most };
            if !solve::join_crossings(blocks, bounds) || pass >= last {
                break;
            }
            for block in blocks.iter_mut() {
                let topology = &topologies[block.topology as usize];
                solve::take_crossings(block, topology);
                if pinned && pass == most && solve::restart(block) != 0 {
                    last = most + pin::PIN_PASSES + 1;
                }
            }
        }
        if pinned && end_unsettled(blocks, topologies) {
            solve_pass(on, blocks, false);
        }
        for block in blocks.iter_mut() {
            solve::adopt(block);
            run_phase(on, block, Phase::Finish);
            block.fresh = false;
        }
    }
}

/// One pass of a [`PositionPass`] over every block: the active set held,
/// the trees factored (leaves first, across the blocks' ports) and
/// solved (roots first), and the next active set settled.
fn solve_pass(on: PhaseOn<'_>, blocks: &mut [TreeBlock], first_pass: bool) {
    let topologies = on.1;
    for block in blocks.iter_mut() {
        solve::hold(block, &topologies[block.topology as usize], first_pass);
    }
    for k in 0..blocks.len() {
        solve::take_ports(blocks, k);
        run_phase(on, &mut blocks[k], Phase::Eliminate);
    }
    for k in (0..blocks.len()).rev() {
        solve::take_parent(blocks, k);
        run_phase(on, &mut blocks[k], Phase::Substitute);
    }
    for block in blocks.iter_mut() {
        block.dirty.fill(0);
        block.crossing = [0.0; BLOCK_LANES];
        run_phase(on, block, Phase::Settle);
    }
}

/// Where a tree's pins had not settled when their passes ran out and its
/// last pass moves it further than its first by more than [`WILD_STEP`]
/// ([`step_sizes`] over the whole tree: the largest of its pieces', so a
/// tree cut into pieces decides as it would whole), the tree starts again
/// from its first pass's active set (`solve::start_again`) for one pass
/// more, the solve's last. Returns whether any tree did.
///
/// The passes between are steps of a search that had not converged, and
/// one can move a tree far more than the solve asks: a sliding pin pushes
/// with `mu lambda_n` of the pass before, and a pass that pressed a 1 kg
/// foot deep under a 70 kg tree gives the next a friction that turns the
/// foot by radians (two limp ragdolls resting on each other on pins threw
/// a forearm off at 17 m/s). The first pass's set is the pins as they
/// stand, with no friction yet where they slide: ending there wherever
/// the pins had not settled let a walking ragdoll's feet slip (its hips
/// 5.8 cm off its animation), so a tree keeps a last pass that moves it
/// about as far as its first.
fn end_unsettled(blocks: &mut [TreeBlock], topologies: &[Topology]) -> bool {
    for block in blocks.iter_mut() {
        block.crossing = step_sizes(block, topologies);
    }
    solve::join_across_pieces(blocks, solve::crossing_of, larger);
    for block in blocks.iter_mut() {
        for (lane, c) in block.crossing.iter_mut().enumerate() {
            let further = *c > block.first_step[lane] + WILD_STEP;
            *c = f32::from(u8::from(further));
        }
    }
    let mut again = false;
    for block in blocks.iter_mut() {
        for (lane, c) in block.crossing.iter_mut().enumerate() {
            if *c == 0.0 {
                block.unsettled &= !(1 << lane);
            }
            *c = 0.0;
        }
        if block.unsettled != 0 {
            solve::start_again(block, block.unsettled);
            again = true;
        }
    }
    again
}

/// Each lane's largest body step in the pass just solved: the larger of
/// its turn (rad) and its move over [`STEP_LENGTH`].
fn step_sizes(block: &TreeBlock, topologies: &[Topology]) -> [f32; BLOCK_LANES] {
    let topology = &topologies[block.topology as usize];
    let mut sizes = [0.0f32; BLOCK_LANES];
    for (n, node) in topology.nodes.iter().enumerate() {
        if let NodeKind::Body { .. } = node.kind {
            let x = &block.scratch[n].x;
            for (lane, size) in sizes.iter_mut().enumerate() {
                let moved = length(x[0][lane], x[1][lane], x[2][lane]);
                let turned = length(x[3][lane], x[4][lane], x[5][lane]);
                *size = size.max(moved / STEP_LENGTH).max(turned);
            }
        }
    }
    sizes
}

/// A block's [`TreeBlock::first_step`].
fn first_step_of(block: &mut TreeBlock) -> &mut [f32; BLOCK_LANES] {
    &mut block.first_step
}

/// Keeps the larger of `mine` and `theirs` in `mine`.
fn larger(mine: &mut f32, theirs: f32) {
    *mine = mine.max(theirs);
}

/// The length of `(x, y, z)`.
fn length(x: f32, y: f32, z: f32) -> f32 {
    (x * x + y * y + z * z).sqrt()
}

/// How much further than its first pass a tree's last may move it
/// ([`step_sizes`]) before an unsettled solve ends on its first pass's
/// set: well above the differences between the passes of a tree at rest
/// (gravity's step is 2.7 mm a substep at 60 Hz), well below the passes
/// that threw bodies (tenths of a radian to radians).
const WILD_STEP: f32 = 0.05;

/// The length a body's move is measured against its turn by (m): a tenth
/// of a metre counts as a radian.
const STEP_LENGTH: f32 = 0.1;

/// The fastest a hard limit found past its bound is brought back (rad/s,
/// or swing sines per second for an ellipse): a substep removes at most
/// `MAX_LIMIT_RETURN_SPEED h` of what it finds at its first solve. A pose
/// taken from an animation that bends a joint far past its ragdoll limit
/// then comes back over a few frames instead of being thrown back in one
/// substep (a rod spine created 0.8 rad past its bend limit came back at
/// 3.3 m/s). At 60 Hz a substep takes back 0.067 rad (3.8 degrees): every
/// violation a pile's impacts leave (under 2 degrees) is taken back whole.
pub const MAX_LIMIT_RETURN_SPEED: f32 = 4.0;

/// How many times a closing solve may factor its tree with a changed
/// active set (`solve::settle`: a row crossed its limit): the first, then
/// up to this many less one.
pub const MAX_PASSES: usize = 4;

/// A step of a [`PositionPass`], run on every live slice of a block.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Each node's block and rows where the tree stands.
    Measure,
    /// Leaves first: each dirty node's block factored and its complement
    /// passed up.
    Eliminate,
    /// Root first: every node's unknowns.
    Substitute,
    /// The limits' next active set and the lanes where it crossed.
    Settle,
    /// The held limits' multipliers kept, the bodies moved.
    Finish,
}

/// The phases as [`PhaseRun`]'s constant.
const MEASURE: u8 = 0;
const ELIMINATE: u8 = 1;
const SUBSTITUTE: u8 = 2;
const SETTLE: u8 = 3;
const FINISH: u8 = 4;

/// What a phase runs on: the backend, the topologies, the body rows and
/// the substep's time scale.
type PhaseOn<'a> = (Backend, &'a [Topology], &'a BodyRows, SubstepScale);

/// Runs `phase` on every live slice of `block`, on `backend`.
fn run_phase((backend, topologies, rows, scale): PhaseOn<'_>, block: &mut TreeBlock, phase: Phase) {
    let topology = &topologies[block.topology as usize];
    macro_rules! run {
        ($p:expr) => {
            backend.dispatch(PhaseRun::<{ $p }> {
                topology,
                block,
                rows,
                scale,
            })
        };
    }
    match phase {
        Phase::Measure => run!(MEASURE),
        Phase::Eliminate => run!(ELIMINATE),
        Phase::Substitute => run!(SUBSTITUTE),
        Phase::Settle => run!(SETTLE),
        Phase::Finish => run!(FINISH),
    }
}

/// Phase `P` of a [`PositionPass`] on one block: a kernel of its own.
struct PhaseRun<'a, const P: u8> {
    topology: &'a Topology,
    block: &'a mut TreeBlock,
    rows: &'a BodyRows,
    scale: SubstepScale,
}

impl<const P: u8> LaneKernel for PhaseRun<'_, P> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(mut self) {
        let padding = self.block.padding;
        for_live_slices::<L, _>(padding, &mut self);
    }
}

impl<const P: u8> LaneSlices for PhaseRun<'_, P> {
    #[inline(always)]
    fn slice<L: Lane>(&mut self, start: usize) {
        let (topology, rows, scale) = (self.topology, self.rows, self.scale);
        match P {
            MEASURE => solve::measure::<L>(self.block, topology, rows, start, scale),
            ELIMINATE => solve::eliminate::<L>(self.block, topology, start, scale),
            SUBSTITUTE => solve::substitute::<L>(self.block, topology, start),
            SETTLE => solve::settle::<L>(self.block, topology, start, scale),
            _ => {
                solve::accumulate::<L>(self.block, topology, start, scale);
                solve::apply::<L>(self.block, topology, rows, start);
            }
        }
    }
}

/// The trees' substep start, before the bodies are predicted: every limit
/// row's multiplier reset, the next solve's active set chosen afresh, and
/// every limit row's violation measured (a soft limit's damping `C_0`, as
/// `crate::limited::Starts` measures the parts'; a hard limit's
/// return from far past, [`MAX_LIMIT_RETURN_SPEED`]); every drive's
/// error measured and its target advanced (`drive::DriveNode::start`).
pub struct StartPass<'a> {
    /// The blocks.
    pub blocks: &'a mut [TreeBlock],
    /// Their topologies.
    pub topologies: &'a [Topology],
    /// Body rows, read.
    pub rows: &'a BodyRows,
    /// The substep (s).
    pub h: f32,
}

impl LaneKernel for StartPass<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        for block in self.blocks.iter_mut() {
            block.fresh = true;
            for joint in block.joints.iter_mut() {
                joint.limit_lambda = [[0.0; BLOCK_LANES]; MAX_LIMITS];
            }
            let padding = block.padding;
            let mut starts = Starts {
                topology: &self.topologies[block.topology as usize],
                block,
                rows: self.rows,
                h: self.h,
            };
            for_live_slices::<L, _>(padding, &mut starts);
        }
    }
}

/// One block of a [`StartPass`].
struct Starts<'a> {
    topology: &'a Topology,
    block: &'a mut TreeBlock,
    rows: &'a BodyRows,
    h: f32,
}

impl LaneSlices for Starts<'_> {
    #[inline(always)]
    fn slice<L: Lane>(&mut self, start: usize) {
        solve::start_limits::<L>(self.block, self.topology, self.rows, start, self.h);
    }
}
