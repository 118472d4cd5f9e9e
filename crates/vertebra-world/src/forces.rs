//! Joint forces and torques, read after every step, and the joints that
//! break on them.
//!
//! Each joint lane records what its parts did to its bodies over the step
//! (`vertebra_kernels::reaction`: the positional impulse on `b` and the
//! measured body's turn); the joints a tree of the direct solve holds get
//! their share from the tree's bodies, summed over each subtree in lanes
//! (`vertebra_kernels::direct::load`). After the step the
//! world turns each record into the mean force (N) and torque (N m) over
//! the step on `body_b`, about the joint's anchor, in the world frame, and
//! keeps them by slot: a game reads them for damage, haptics, a rope's
//! tension. A joint with [`JointBreaking`](crate::JointBreaking)
//! thresholds past either is removed at the end of the step and named in
//! [`World::broken_joints`] with what broke it. The solve never reads the
//! records, so reading them changes no bit of any world; breaking is
//! decided from bit-exact records in slot order, so a joint breaks in the
//! same step on every backend and thread count.

use glam::Vec3;
use vertebra_kernels::direct::load::LoadPass;
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

/// The angular impulse (kg m^2 rad, world) that turns `body` by `turn`
/// (rad, world) at its orientation now: `R I R^T turn`, applied as two
/// rotations about the body's own inertia, not as a world tensor.
fn angular_impulse(world: &World, body: usize, turn: Vec3) -> Vec3 {
    let q = world.bodies.orientation[body];
    q * (world.bodies.inertia[body] * (q.conjugate() * turn))
}

/// Every laid-out joint's force and torque from its lane's record and its
/// tree's share, for a step of `dt` in substeps of `h` (s), into
/// `world.joint_forces` by slot.
pub(crate) fn read(world: &mut World, h: f32, dt: f32) {
    tree_loads(world, 1.0 / (h * dt));
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
        let tree = tree_load(world, slot);
        forces[slot] = JointForce {
            force: force + tree.force,
            torque: torque + tree.torque,
        };
    }
    world.joint_forces = forces;
}

/// Every tree's joints' loads, bin by bin (a bin's blocks are solved
/// together: its ports name blocks of its own), `scale` being `1 / (h
/// dt)`.
fn tree_loads(world: &mut World, scale: f32) {
    let (layout, rows) = (&mut world.layout, world.rows.get());
    for bin in &layout.bins {
        LoadPass {
            blocks: &mut layout.trees.blocks[bin.trees.clone()],
            topologies: &layout.trees.topologies,
            rows,
            scale,
        }
        .run(world.backend);
    }
}

/// The share of joint `slot` that a tree of the direct solve holds (zero
/// for a joint no tree holds).
fn tree_load(world: &World, slot: usize) -> JointForce {
    let trees = &world.layout.trees;
    let Some(Some(place)) = trees.joints.get(slot) else {
        return JointForce::default();
    };
    let joint = &trees.blocks[place.block].joints[place.joint];
    JointForce {
        force: joint.force.get(place.lane),
        torque: joint.torque.get(place.lane),
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
