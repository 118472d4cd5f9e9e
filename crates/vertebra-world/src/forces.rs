//! Joint forces and torques, read after every step, and the joints that
//! break on them.
//!
//! Each joint lane records what its parts did to its bodies over the step
//! (`vertebra_kernels::reaction`: the positional impulse on `b` and the
//! measured body's turn); the joints a tree of the direct solve holds get
//! their share from the tree's bodies (`trees.rs`). After the step the
//! world turns each record into the mean force (N) and torque (N m) over
//! the step on `body_b`, about the joint's anchor, in the world frame, and
//! keeps them by slot: a game reads them for damage, haptics, a rope's
//! tension. A joint with [`JointBreaking`](crate::JointBreaking)
//! thresholds past either is removed at the end of the step and named in
//! [`World::broken_joints`] with what broke it. The solve never reads the
//! records, so reading them changes no bit of any world; breaking is
//! decided from bit-exact records in slot order, so a joint breaks in the
//! same step on every backend and thread count.

use glam::{DVec3, Vec3};
use vertebra_kernels::direct::{Child, NONE, NodeKind, TreeBlock};
use vertebra_kernels::reaction::force_and_torque;
use vertebra_math::block::BLOCK_LANES;

use crate::joint::{JointDesc, JointHandle, JointKind};
use crate::{Error, World};

/// A joint's force and torque over the last step it was solved in.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointForce {
    /// The mean force on `body_b` (N, world): what the joint pulled it
    /// with; `body_a` took its opposite.
    pub force: Vec3,
    /// The mean torque on `body_b` about the joint's anchor (N m, world):
    /// its limits', axes', lock's and drive's, the force's own moment
    /// left out.
    pub torque: Vec3,
}

/// A joint that broke in the last step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrokenJoint {
    /// Its handle (stale now).
    pub joint: JointHandle,
    /// Its description, as it was.
    pub desc: JointDesc,
    /// The force and torque that broke it.
    pub load: JointForce,
}

impl World {
    /// `joint`'s force and torque over the last step (zero before its
    /// first; while its island sleeps, those of the last step it was
    /// solved in). Refused for a stale or foreign handle.
    pub fn joint_force(&self, joint: JointHandle) -> Result<JointForce, Error> {
        self.joint_slots.check(joint, "joint")?;
        Ok(self
            .joint_forces
            .get(joint.index())
            .copied()
            .unwrap_or_default())
    }

    /// The joints that broke in the last step, in slot order (see
    /// [`JointBreaking`](crate::JointBreaking)).
    pub fn broken_joints(&self) -> &[BrokenJoint] {
        &self.broken
    }
}

/// The angular impulse (kg m^2 rad, world) that turns `body` by `turn`
/// (rad, world) at its orientation now: `R I R^T turn`, applied as two
/// rotations about the body's own inertia, not as a world tensor.
fn angular_impulse(world: &World, body: usize, turn: Vec3) -> Vec3 {
    let q = world.bodies.orientation[body];
    q * (world.bodies.inertia[body] * (q.conjugate() * turn))
}

/// Every laid-out joint's force and torque from its lane's record, for a
/// step of `dt` in substeps of `h` (s), into `world.joint_forces` by slot.
pub(crate) fn read(world: &mut World, h: f32, dt: f32) {
    let mut momenta = core::mem::take(&mut world.subtree_momenta);
    momenta.fill(world);
    world.subtree_momenta = momenta;
    let mut forces = core::mem::take(&mut world.joint_forces);
    forces.resize(world.joints.len(), super::JointForce::default());
    for (slot, desc) in world.joints.iter().enumerate() {
        let Some(desc) = desc else { continue };
        if world.islands.holds_asleep(desc.body_a, desc.body_b) {
            continue; // not solved: the last solved step's stand
        }
        let layout = &world.layout;
        let record = match desc.kind {
            JointKind::Socket(_) => {
                let (block, lane) = layout.sockets.place[slot];
                layout.sockets.blocks[block].reaction.get(lane)
            }
            JointKind::Hinge { .. } => {
                let (block, lane) = layout.hinges.place[slot];
                layout.hinges.blocks[block].reaction.get(lane)
            }
            JointKind::Fixed => {
                let (block, lane) = layout.fixed.place[slot];
                layout.fixed.blocks[block].reaction.get(lane)
            }
        };
        let (a, b) = (desc.body_a.index(), desc.body_b.index());
        let measured_b = world.bodies.inverse_mass[b] > 0.0;
        let (body, anchor) = if measured_b {
            (b, desc.anchor_b)
        } else {
            (a, desc.anchor_a)
        };
        let arm = world.bodies.orientation[body] * anchor;
        let (impulse, turn) = record;
        let angular = angular_impulse(world, body, turn);
        let (force, torque) = force_and_torque((impulse, angular), arm, measured_b, (h, dt));
        let tree = tree_load(world, slot, desc, (h, dt));
        forces[slot] = JointForce {
            force: force + tree.force,
            torque: torque + tree.torque,
        };
    }
    world.joint_forces = forces;
}

/// The share of joint `slot` (`desc`) that a tree of the direct solve
/// holds (zero for a joint no tree holds): the tree moved each body by
/// `M^-1 J^T lambda` over the step, so the bodies on the joint's child
/// side of the tree moved by the joint's impulse alone (every other joint
/// among them pulls two of them, equal and opposite): its force is their
/// summed `m dp`, its torque about the anchor their summed
/// `I dtheta + (x - anchor) x m dp`, turned to `body_b`'s side. The sums
/// below every node are [`SubtreeMomenta`]'s.
fn tree_load(world: &World, slot: usize, desc: &JointDesc, (h, dt): (f32, f32)) -> JointForce {
    let trees = &world.layout.trees;
    let Some(Some(place)) = trees.joints.get(slot) else {
        return JointForce::default();
    };
    let block = &trees.blocks[place.block];
    let topology = &trees.topologies[block.topology as usize];
    let NodeKind::Joint { b, .. } = topology.nodes[place.node].kind else {
        return JointForce::default();
    };
    let below = world
        .subtree_momenta
        .at(place.block, place.node, place.lane);
    let bodies = &world.bodies;
    let ib = desc.body_b.index();
    let anchor = bodies.position[ib] + bodies.orientation[ib] * desc.anchor_b;
    let angular = below.angular - anchor.as_dvec3().cross(below.linear);
    // `body_b` is on the child side when it is the joint's child node.
    let b_below = b != NONE && topology.children(place.node).contains(&Child::Node(b));
    let side = if b_below { 1.0 } else { -1.0 };
    let scale = side / (h * dt);
    JointForce {
        force: below.linear.as_vec3() * scale,
        torque: angular.as_vec3() * scale,
    }
}

/// The momentum a tree's solves gave a set of its bodies over the step:
/// summed `m dp` (N s h) and summed `I dtheta + x x m dp` about the world
/// origin, in `f64` so that moving it to a joint's anchor
/// (`L - anchor x P`) keeps the `f32` inputs' precision far from the
/// origin.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Momentum {
    linear: DVec3,
    angular: DVec3,
}

/// Every tree node's subtree momentum, lane by lane, filled once a step
/// in one pass (scratch of the step; it allocates only as the trees
/// grow): the nodes come in elimination order, a node's children before
/// it, and a port's subtree lies in an earlier block of its pass, so each
/// sum is its own body's momentum plus its children's, already summed.
#[derive(Clone, Debug, Default)]
pub(crate) struct SubtreeMomenta {
    /// Node `n` of block `b` in lane `l`: `sums[starts[b] + n * 8 + l]`.
    sums: Vec<Momentum>,
    starts: Vec<usize>,
}

impl SubtreeMomenta {
    /// Node `node`'s subtree momentum in `lane` of tree block `block`.
    fn at(&self, block: usize, node: usize, lane: usize) -> Momentum {
        self.sums[self.starts[block] + node * BLOCK_LANES + lane]
    }

    /// Sums every tree block's nodes, blocks in order.
    fn fill(&mut self, world: &World) {
        let trees = &world.layout.trees;
        self.sums.clear();
        self.starts.clear();
        for (index, block) in trees.blocks.iter().enumerate() {
            let topology = &trees.topologies[block.topology as usize];
            let start = self.sums.len();
            self.starts.push(start);
            let count = topology.nodes.len() * BLOCK_LANES;
            self.sums.resize(start + count, Momentum::default());
            // Port sources name blocks of the pass, which starts at its
            // bin's first tree block.
            let pass = (world.layout.bins.iter())
                .find(|bin| bin.trees.contains(&index))
                .map_or(0, |bin| bin.trees.start);
            for (n, node) in topology.nodes.iter().enumerate() {
                for lane in (0..BLOCK_LANES).filter(|l| block.padding & (1 << l) == 0) {
                    let mut sum = match node.kind {
                        NodeKind::Body { index } => own(world, block, index as usize, lane),
                        NodeKind::Joint { .. } => Momentum::default(),
                    };
                    for &child in topology.children(n) {
                        let below = match child {
                            Child::Node(c) => Some(self.at(index, c as usize, lane)),
                            Child::Port(p) => (block.ports[p as usize].source[lane])
                                .filter(|s| pass + (s.block as usize) < index)
                                .map(|s| {
                                    self.at(
                                        pass + s.block as usize,
                                        s.node as usize,
                                        s.lane as usize,
                                    )
                                }),
                        };
                        if let Some(below) = below {
                            sum.linear += below.linear;
                            sum.angular += below.angular;
                        }
                    }
                    self.sums[start + n * BLOCK_LANES + lane] = sum;
                }
            }
        }
    }
}

/// Body `index` of `block`'s momentum in `lane` (see [`Momentum`]).
fn own(world: &World, block: &TreeBlock, index: usize, lane: usize) -> Momentum {
    let bodies = &world.bodies;
    let body = &block.bodies[index];
    let i = body.row[lane] as usize - 1;
    let (dp, turn) = body.moved(lane);
    let p = dp * bodies.mass[i];
    let angular = angular_impulse(world, i, turn).as_dvec3();
    let linear = p.as_dvec3();
    Momentum {
        linear,
        angular: angular + bodies.position[i].as_dvec3().cross(linear),
    }
}

/// Removes every joint whose force or torque this step passed its
/// thresholds, in slot order, into `world.broken`.
pub(crate) fn break_joints(world: &mut World) {
    world.broken.clear();
    for slot in 0..world.joints.len() {
        // The description is copied only for a breakable joint.
        let breakable = world.joints[slot].as_ref().filter(|d| d.breaking.is_some());
        let Some(desc) = breakable.copied() else {
            continue;
        };
        let Some(limits) = desc.breaking else {
            continue;
        };
        if world.islands.holds_asleep(desc.body_a, desc.body_b) {
            continue;
        }
        let load = world.joint_forces[slot];
        if load.force.length() > limits.force || load.torque.length() > limits.torque {
            let joint = world
                .joint_slots
                .handle_at(slot)
                .expect("a described joint is live");
            world.remove_joint(joint).expect("a live joint is removed");
            world.broken.push(BrokenJoint { joint, desc, load });
        }
    }
}
