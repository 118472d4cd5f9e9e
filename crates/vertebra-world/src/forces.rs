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

use glam::{Mat3, Vec3};
use vertebra_kernels::direct::{Child, NONE, NodeKind};
use vertebra_kernels::reaction::force_and_torque;

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

/// A body's world inertia tensor (kg m^2) at its orientation now.
fn world_inertia(world: &World, body: usize) -> Mat3 {
    let r = Mat3::from_quat(world.bodies.orientation[body]);
    r * world.bodies.inertia[body] * r.transpose()
}

/// Every laid-out joint's force and torque from its lane's record, for a
/// step of `dt` in substeps of `h` (s), into `world.joint_forces` by slot.
pub(crate) fn read(world: &mut World, h: f32, dt: f32) {
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
        let (force, torque) =
            force_and_torque(record, world_inertia(world, body), arm, measured_b, (h, dt));
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
/// `I dtheta + (x - anchor) x m dp`, turned to `body_b`'s side. The
/// child side may lie in pieces laid out in other blocks of the pass
/// (`vertebra_kernels::direct::split`): their ports lead there.
fn tree_load(world: &World, slot: usize, desc: &JointDesc, (h, dt): (f32, f32)) -> JointForce {
    let trees = &world.layout.trees;
    let Some(Some(place)) = trees.joints.get(slot) else {
        return JointForce::default();
    };
    let block = &trees.blocks[place.block];
    let topology = &trees.topologies[block.topology as usize];
    let joint = topology.nodes.iter().position(
        |node| matches!(node.kind, NodeKind::Joint { index, .. } if index as usize == place.joint),
    );
    let Some(joint) = joint else {
        return JointForce::default();
    };
    let NodeKind::Joint { b, .. } = topology.nodes[joint].kind else {
        return JointForce::default();
    };
    let bodies = &world.bodies;
    let ib = desc.body_b.index();
    let anchor = bodies.position[ib] + bodies.orientation[ib] * desc.anchor_b;
    // Port sources name blocks of the pass, which starts at its bin's
    // first tree block.
    let pass = (world.layout.bins.iter())
        .find(|bin| bin.trees.contains(&place.block))
        .map_or(0, |bin| bin.trees.start);
    let mut sum = ChildSide {
        world,
        pass,
        anchor,
        impulse: Vec3::ZERO,
        angular: Vec3::ZERO,
    };
    sum.add_below(place.block, place.lane, joint);
    // `body_b` is on the child side when it is the joint's child node.
    let b_below = b != NONE && topology.children(joint).contains(&Child::Node(b));
    let side = if b_below { 1.0 } else { -1.0 };
    let scale = side / (h * dt);
    JointForce {
        force: sum.impulse * scale,
        torque: sum.angular * scale,
    }
}

/// The summed momentum the tree's solves gave the bodies below a node
/// (`tree_load`).
struct ChildSide<'a> {
    world: &'a World,
    /// The pass's first block (port sources count from it).
    pass: usize,
    /// The point the angular momentum is taken about (m, world).
    anchor: Vec3,
    /// Summed `m dp` (N s h).
    impulse: Vec3,
    /// Summed `I dtheta + (x - anchor) x m dp` about `anchor`.
    angular: Vec3,
}

impl ChildSide<'_> {
    /// Adds every body of node `n`'s subtree in `lane` of block `block`,
    /// and of the pieces its ports lead to (a tree's depth bounds the
    /// recursion).
    fn add_below(&mut self, block: usize, lane: usize, n: usize) {
        let trees = &self.world.layout.trees;
        let tree_block = &trees.blocks[block];
        let topology = &trees.topologies[tree_block.topology as usize];
        if let NodeKind::Body { index } = topology.nodes[n].kind {
            let bodies = &self.world.bodies;
            let body = &tree_block.bodies[index as usize];
            let i = body.row[lane] as usize - 1;
            let (dp, turn) = body.moved(lane);
            let p = dp * bodies.mass[i];
            self.impulse += p;
            self.angular +=
                world_inertia(self.world, i) * turn + (bodies.position[i] - self.anchor).cross(p);
        }
        for &child in topology.children(n) {
            match child {
                Child::Node(c) => self.add_below(block, lane, c as usize),
                Child::Port(p) => {
                    if let Some(s) = tree_block.ports[p as usize].source[lane] {
                        let at = self.pass + s.block as usize;
                        self.add_below(at, s.lane as usize, s.node as usize);
                    }
                }
            }
        }
    }
}

/// Removes every joint whose force or torque this step passed its
/// thresholds, in slot order, into `world.broken`.
pub(crate) fn break_joints(world: &mut World) {
    world.broken.clear();
    for slot in 0..world.joints.len() {
        let Some(desc) = world.joints[slot] else {
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
