//! The joints' loads from a step of direct solves: what each joint of a
//! tree did to its bodies, read once the step is over.
//!
//! The solves moved every body of a tree by `M^-1 J^T lambda`, and each
//! [`BodyNode::moved`](super::BodyNode) sums what they moved it by. The
//! bodies below a joint (its child side, down to the leaves) moved by its
//! impulse alone: every other joint among them pulls two of them, equal
//! and opposite. So the joint's impulse on its child side is the summed
//! momentum of that subtree, `P = sum m dp`, and its angular impulse
//! about a point `o` is `sum I dtheta + (x - o) x m dp`.
//!
//! One pass over the nodes in elimination order (children first) sums
//! every subtree once. Each sum is kept about a body's centre of mass,
//! never the world origin: a body node's about its own, a joint node's
//! moved to its parent body's (`L + (x_c - x_p) x P`, the two centres'
//! offset measured as the kernels measure a pair, from the step's start
//! gap and the displacements since), so every lever arm is a bone's
//! length and `f32` keeps the precision however far from the origin the
//! tree is. A port's subtree, summed in an earlier block of the same
//! solve, is copied in before its block's pass, as its complement is in
//! the solve. The arithmetic is the whole tree's, node for node in the
//! same order, so a tree cut into pieces gives the same bits as whole,
//! and every backend the same bits.
//!
//! A joint's load is then its child side's sum about `b`'s anchor
//! (`L - r x P`, `r` from the child's centre to the anchor), turned to
//! `b`: the mean force (N) and torque (N m) on `b` over the step, the
//! impulses divided by `h dt` (positional impulses summed over substeps of
//! `h`, a step of `dt`).

use vertebra_math::block::{LaneSlices, Vec3Block, for_live_slices};
use vertebra_math::{Backend, Lane, LaneKernel, Vec3};

use super::solve::load;
use super::{Child, NONE, NodeKind, Topology, TreeBlock};
use crate::body::{BodyLanes, BodyRows};

/// A subtree's momentum in each lane: its summed `m dp` (kg m) and its
/// summed angular impulse about a body's centre of mass (kg m^2 rad),
/// world.
pub type MomentumBlock = [Vec3Block; 2];

/// The loads of every tree in `blocks`, after a step: the blocks of one
/// [`super::PositionPass`] (a block's ports name earlier blocks of the
/// same slice).
pub struct LoadPass<'a> {
    /// The blocks.
    pub blocks: &'a mut [TreeBlock],
    /// Their topologies, by `TreeBlock::topology`.
    pub topologies: &'a [Topology],
    /// Body rows, as the step left them.
    pub rows: &'a BodyRows,
    /// `1 / (h dt)` (1/s^2): a step's summed positional impulse (kg m)
    /// to its mean force (N).
    pub scale: f32,
}

impl LoadPass<'_> {
    /// Runs the pass on `backend` (every backend gives the same bits).
    pub fn run(self, backend: Backend) {
        for k in 0..self.blocks.len() {
            take_ports(self.blocks, k);
            let block = &mut self.blocks[k];
            backend.dispatch(Loads {
                topology: &self.topologies[block.topology as usize],
                block,
                rows: self.rows,
                scale: self.scale,
            });
        }
    }
}

/// Copies into block `k`'s ports their subtrees' momenta, from the
/// earlier blocks they lie in (zero for a lane without one).
fn take_ports(blocks: &mut [TreeBlock], k: usize) {
    let (before, rest) = blocks.split_at_mut(k);
    let block = &mut rest[0];
    for port in block.ports.iter_mut() {
        for (lane, source) in port.source.iter().enumerate() {
            for (k, to) in port.momentum.iter_mut().enumerate() {
                let from = match source {
                    Some(s) => {
                        before[s.block as usize].momenta[s.node as usize][k].get(s.lane as usize)
                    }
                    None => glam::Vec3::ZERO,
                };
                to.set(lane, from);
            }
        }
    }
}

/// One block of a [`LoadPass`].
struct Loads<'a> {
    topology: &'a Topology,
    block: &'a mut TreeBlock,
    rows: &'a BodyRows,
    scale: f32,
}

impl LaneKernel for Loads<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(mut self) {
        let padding = self.block.padding;
        for_live_slices::<L, _>(padding, &mut self);
    }
}

impl LaneSlices for Loads<'_> {
    #[inline(always)]
    fn slice<L: Lane>(&mut self, start: usize) {
        let topology = self.topology;
        for (n, node) in topology.nodes.iter().enumerate() {
            let sum = match node.kind {
                NodeKind::Body { index } => self.body::<L>(n, index as usize, start),
                NodeKind::Joint { index, b, .. } => {
                    let Some(&Child::Node(child)) = topology.children(n).first() else {
                        unreachable!("a joint's child is a body of its block");
                    };
                    self.joint::<L>(index as usize, child, child == b && b != NONE, start)
                }
            };
            self.block.momenta[n][0].store(start, sum.0);
            self.block.momenta[n][1].store(start, sum.1);
        }
    }
}

impl Loads<'_> {
    /// Body node `n` (body `index` of the block): its own momentum plus
    /// its children's (each already about its centre), about its centre.
    #[inline(always)]
    fn body<L: Lane>(&self, n: usize, index: usize, start: usize) -> (Vec3<L>, Vec3<L>) {
        let block = &*self.block;
        let body = &block.bodies[index];
        let q = BodyLanes::<L>::gather(self.rows, &body.row[start..]).q;
        let [dx, dy, dz, tx, ty, tz] = load::<L, 6>(&body.moved, start);
        let (dp, turn) = (Vec3::new(dx, dy, dz), Vec3::new(tx, ty, tz));
        let inertia = body.inertia_lanes::<L>(start);
        let mut linear = dp.scale(L::load(&body.mass[start..]));
        let mut angular = q.rotate(inertia.mul_vec(q.inverse_rotate(turn)));
        // The pins moved the body too: their impulses are the ground's, not
        // a joint's.
        if let Some(pins) = block.pins.get(index) {
            let [x, y, z, ax, ay, az] = load::<L, 6>(&pins.impulse, start);
            linear -= Vec3::new(x, y, z);
            angular -= Vec3::new(ax, ay, az);
        }
        for &child in self.topology.children(n) {
            let below = match child {
                Child::Node(c) => &block.momenta[c as usize],
                Child::Port(p) => &block.ports[p as usize].momentum,
            };
            linear += below[0].load(start);
            angular += below[1].load(start);
        }
        (linear, angular)
    }

    /// Joint `index` of the block over its child body node `child` (`b`
    /// when `child_is_b`, else `a`): its load on `b` into the joint, and
    /// its child side's momentum moved to its parent body's centre, for
    /// the parent.
    #[inline(always)]
    fn joint<L: Lane>(
        &mut self,
        index: usize,
        child: u32,
        child_is_b: bool,
        start: usize,
    ) -> (Vec3<L>, Vec3<L>) {
        let below = &self.block.momenta[child as usize];
        let (linear, angular) = (below[0].load::<L>(start), below[1].load::<L>(start));
        let joint = &mut self.block.joints[index];
        let (a, b) = joint.bodies.gather::<L>(self.rows, start);
        let pair = joint.bodies.start::<L>(start);
        // From a's centre to b's now, and from b's centre to its anchor.
        let centres = pair.gap - pair.arm_b + pair.arm_a + (b.p - a.p);
        let anchor = b.q.rotate(joint.anchor_b.load(start));
        // From the child's centre to b's anchor, and to its parent's.
        let (arm, up) = if child_is_b {
            (anchor, -centres)
        } else {
            (centres + anchor, centres)
        };
        let torque = angular - arm.cross(linear);
        let scale = L::splat(if child_is_b { self.scale } else { -self.scale });
        joint.force.store(start, linear.scale(scale));
        joint.torque.store(start, torque.scale(scale));
        (linear, angular - up.cross(linear))
    }
}
