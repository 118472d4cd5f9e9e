//! The solver's constraint layout: every awake joint in a lane of a block
//! of its type, the blocks ordered by colour, then the overflow set. A
//! sleeping island's joints keep their colours but are not laid out.
//! Rebuilt only when the colouring changes (a joint added or removed, a
//! joined body's kind changed: lanes cache which bodies are dynamic) or an
//! island falls asleep or wakes, never per step.
//!
//! Colouring keys: a joint is its slot, a rod its slot plus [`ROD_KEY`].
//! Each joint kind has its own blocks (sockets of the plain and the shaped
//! path apart, driven and undriven apart), so that no lane pays for a part
//! it does not use; inside a colour the order of the blocks changes no
//! result (they share no dynamic body).

use core::f32::consts::PI;
use core::ops::Range;
use std::collections::BTreeSet;
use vertebra_math::PortableQuat;

use vertebra_kernels::body::{BodyPairs, JointFrames, LaneBlock, PairLane};
use vertebra_kernels::fixed::{FixedBlock, FixedLane};
use vertebra_kernels::hinge::{HingeBlock, HingeLane};
use vertebra_kernels::rod::{RodBlock, RodLane};
use vertebra_kernels::socket::{ShapedLimits, SocketBlock, SocketLane};
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;
use vertebra_scheduler::{Colouring, MAX_COLOURS};
use vertebra_store::{BodyHandle, BodyKind, BodyStore};

use crate::bins::Bins;
use crate::joint::{JointDesc, JointKind, LimitSoftness, Swing, SwingTwist};
use crate::kinds::{BlockKind, Group, JointBlock, Vector};
use crate::rod::RodDesc;
use crate::start::start_blocks;
use crate::trees::Trees;

/// Added to a rod's slot to make its colouring key.
pub(crate) const ROD_KEY: u64 = 1 << 32;

/// Blocks of one joint type, with each slot's place.
#[derive(Clone, Debug)]
pub(crate) struct Blocks<B> {
    pub blocks: Vec<B>,
    /// For each joint slot, its (block, lane).
    pub place: Vec<(usize, usize)>,
}

impl<B> Default for Blocks<B> {
    fn default() -> Self {
        Self {
            blocks: Vec::new(),
            place: Vec::new(),
        }
    }
}

impl<B: Copy> Blocks<B> {
    /// Lays out `slots` in blocks of eight: first those `held` (whose
    /// equality parts the direct solve holds), then the rest, never two
    /// of these in one block. So a block is `BodyPairs::direct` exactly
    /// when its joints are held, whatever else shares its colour (which
    /// depends on the solve bins, so on the worker count): which parts a
    /// joint gets never depends on its neighbours in a block.
    fn append(
        &mut self,
        slots: impl Iterator<Item = usize> + Clone,
        held: impl Fn(usize) -> bool,
        padding: B,
        mut set: impl FnMut(&mut B, usize, usize),
    ) -> Range<usize> {
        let start = self.blocks.len();
        let apart = slots.clone().filter(|&s| held(s));
        self.append_packed(apart, padding, &mut set);
        self.append_packed(slots.filter(|&s| !held(s)), padding, set);
        start..self.blocks.len()
    }

    /// Lays out `slots` in blocks of eight, in order.
    fn append_packed(
        &mut self,
        slots: impl Iterator<Item = usize>,
        padding: B,
        mut set: impl FnMut(&mut B, usize, usize),
    ) {
        for (k, slot) in slots.enumerate() {
            let lane = k % BLOCK_LANES;
            if lane == 0 {
                self.blocks.push(padding);
            }
            let block = self.blocks.len() - 1;
            set(&mut self.blocks[block], lane, slot);
            if self.place.len() <= slot {
                self.place.resize(slot + 1, (0, 0));
            }
            self.place[slot] = (block, lane);
        }
    }
}

/// One solve bin's joints (`bins.rs`): its colours, then its overflow
/// set.
#[derive(Clone, Debug, Default)]
pub(crate) struct Bin {
    /// The bin's non-empty colours, in colour order.
    pub colours: Vec<Group>,
    /// The bin's part of the overflow set (solved by the scalar kernel).
    pub overflow: Group,
    /// The bin's tree blocks (`Layout::trees`; none unless the direct
    /// solve is on).
    pub trees: Range<usize>,
    /// The bin's trees are cut into pieces laid out across its blocks,
    /// which are then solved together (one chunk); else each block is a
    /// solve of its own.
    pub trees_joined: bool,
}

#[derive(Clone, Debug, Default)]
pub(crate) struct Layout {
    pub sockets: Blocks<SocketBlock>,
    pub hinges: Blocks<HingeBlock>,
    pub fixed: Blocks<FixedBlock>,
    pub rods: Blocks<RodBlock>,
    /// The direct solve's trees (empty for the iterative one).
    pub trees: Trees,
    /// Per solve bin (bin 0 first), its blocks: each bin's blocks follow
    /// the bin before's in every kind's vector.
    pub bins: Vec<Bin>,
    /// How many colours hold awake joints, in any bin.
    pub colour_count: usize,
    /// Every colour passed [`crate::parallel::colour_is_disjoint`]: its
    /// blocks may run on several threads.
    pub disjoint: bool,
}

impl Layout {
    /// Lays out every coloured joint; `joints[slot]`, `rods[slot]` are
    /// `Some` when live. The joints of bin `k` (their awake dynamic
    /// body's, `bins`; all of them in bin 0 when `bins` is empty) go to
    /// `bins[k]`, colour by colour. With `direct` (the backend the trees
    /// are laid out for), each bin's trees too (`trees.rs`), laid out first so that the joints they hold take
    /// blocks of their own, which are marked so (`BodyPairs::direct`).
    pub fn build(
        colouring: &Colouring,
        joints: &[Option<JointDesc>],
        rods: &[Option<RodDesc>],
        bodies: &BodyStore,
        asleep: &[bool],
        (bins, direct): (&Bins, Option<Backend>),
    ) -> Self {
        let mut layout = Self::default();
        let awake = |a: BodyHandle, b: BodyHandle| !(asleep[a.index()] || asleep[b.index()]);
        let bin = |a: BodyHandle, b: BodyHandle| {
            let row = |h: BodyHandle| h.index() as u32 + 1;
            bins.of_rows(row(a), row(b))
        };
        let mut used = [false; MAX_COLOURS];
        for k in 0..bins.count.max(1) as u32 {
            let joints: Vec<_> = joints
                .iter()
                .map(|d| d.filter(|d| awake(d.body_a, d.body_b) && bin(d.body_a, d.body_b) == k))
                .collect();
            let rods: Vec<_> = rods
                .iter()
                .map(|d| d.filter(|d| awake(d.body_a, d.body_b) && bin(d.body_a, d.body_b) == k))
                .collect();
            let mut bin = Bin::default();
            // The trees first: their joints take blocks of their own.
            if let Some(backend) = direct {
                (bin.trees, bin.trees_joined) =
                    layout.trees.append(&joints, &rods, bodies, backend);
            }
            for (c, used) in used.iter_mut().enumerate() {
                let group = layout.append(colouring.colour(c), &joints, &rods, bodies);
                if !group.is_empty() {
                    *used = true;
                    bin.colours.push(group);
                }
            }
            bin.overflow = layout.append(colouring.overflow(), &joints, &rods, bodies);
            layout.bins.push(bin);
        }
        layout.trees.check_disjoint();
        layout.mark_direct(joints, rods);
        layout.colour_count = used.iter().filter(|&&u| u).count();
        let mut reads = Vec::new();
        layout.disjoint = (layout.bins.iter())
            .flat_map(|b| &b.colours)
            .all(|g| crate::parallel::colour_is_disjoint(layout.pairs(g), &mut reads));
        layout
    }

    /// Marks every block whose live lanes' equality parts the trees all
    /// solve.
    fn mark_direct(&mut self, joints: &[Option<JointDesc>], rods: &[Option<RodDesc>]) {
        fn mark<B>(
            blocks: &mut Blocks<B>,
            slots: impl Iterator<Item = usize>,
            pairs: impl Fn(&mut B) -> &mut BodyPairs,
        ) {
            let mut held = vec![0u32; blocks.blocks.len()];
            for slot in slots {
                let (block, lane) = blocks.place[slot];
                held[block] |= 1 << lane;
            }
            for (block, held) in blocks.blocks.iter_mut().zip(held) {
                let pairs = pairs(block);
                let live = !pairs.padding & ((1 << BLOCK_LANES) - 1);
                pairs.direct = u32::from(held == live);
            }
        }
        let trees = &self.trees;
        let held = |kind: fn(&JointKind) -> bool| {
            (joints.iter().enumerate())
                .filter(move |(s, d)| trees.has_joint(*s) && d.is_some_and(|d| kind(&d.kind)))
                .map(|(s, _)| s)
        };
        mark(
            &mut self.sockets,
            held(|k| matches!(k, JointKind::Socket(_))),
            |b| &mut b.bodies,
        );
        mark(
            &mut self.hinges,
            held(|k| matches!(k, JointKind::Hinge { .. })),
            |b| &mut b.bodies,
        );
        mark(&mut self.fixed, held(|k| *k == JointKind::Fixed), |b| {
            &mut b.bodies
        });
        let rod_slots = (0..rods.len()).filter(|&s| trees.has_rod(s));
        mark(&mut self.rods, rod_slots, |b| &mut b.bodies);
    }

    /// The body pairs of every block of bin `bin` (its colours and its
    /// overflow set).
    pub fn bin_pairs<'a>(&'a self, bin: &'a Bin) -> impl Iterator<Item = &'a BodyPairs> + 'a {
        (bin.colours.iter())
            .chain(core::iter::once(&bin.overflow))
            .flat_map(|g| self.pairs(g))
    }

    /// The body pairs of every block of `group`.
    fn pairs<'a>(&'a self, g: &'a Group) -> impl Iterator<Item = &'a BodyPairs> + Clone + 'a {
        g.kinds()
            .flat_map(move |(kind, range)| range.clone().map(move |b| self.block_pairs(kind, b)))
    }

    /// Block `block` of `kind`'s vector: its body pairs.
    fn block_pairs(&self, kind: BlockKind, block: usize) -> &BodyPairs {
        match kind.vector() {
            Vector::Sockets => self.sockets.blocks[block].pairs(),
            Vector::Hinges => self.hinges.blocks[block].pairs(),
            Vector::Fixed => self.fixed.blocks[block].pairs(),
            Vector::Rods => self.rods.blocks[block].pairs(),
        }
    }

    /// Zeroes the multipliers every joint block accumulates over a
    /// substep.
    pub fn reset_lambdas(&mut self) {
        self.sockets
            .blocks
            .iter_mut()
            .for_each(JointBlock::reset_lambdas);
        self.hinges
            .blocks
            .iter_mut()
            .for_each(JointBlock::reset_lambdas);
        self.fixed
            .blocks
            .iter_mut()
            .for_each(JointBlock::reset_lambdas);
        self.rods
            .blocks
            .iter_mut()
            .for_each(JointBlock::reset_lambdas);
    }

    /// Writes a joint's new settings into its lane in place (its kind and
    /// drive presence unchanged, so its blocks are), keeping its drive's
    /// multiplier.
    pub fn update_joint(&mut self, slot: usize, desc: &JointDesc, bodies: &BodyStore) {
        self.trees.update_joint(slot, desc);
        match desc.kind {
            JointKind::Socket(limits) => {
                let (block, lane) = self.sockets.place[slot];
                let block = &mut self.sockets.blocks[block];
                let lambda = block.drive.lambda.get(lane);
                block.set(lane, &socket_lane(desc, &limits, bodies));
                block.drive.lambda.set(lane, lambda);
            }
            JointKind::Hinge { range, softness } => {
                let (block, lane) = self.hinges.place[slot];
                let block = &mut self.hinges.blocks[block];
                let lambda = block.drive.lambda.get(lane);
                block.set(lane, &hinge_lane(desc, range, softness, bodies));
                block.drive.lambda.set(lane, lambda);
            }
            JointKind::Fixed => {
                let (block, lane) = self.fixed.place[slot];
                self.fixed.blocks[block].set(lane, &fixed_lane(desc, bodies));
            }
        }
    }

    /// Writes a rod's new settings into its lane in place (its bodies
    /// unchanged), keeping its multipliers.
    pub fn update_rod(&mut self, slot: usize, desc: &RodDesc, bodies: &BodyStore) {
        self.trees.update_rod(slot, desc);
        let (block, lane) = self.rods.place[slot];
        let block = &mut self.rods.blocks[block];
        let lambdas = (block.bend_lambda[lane], block.twist_lambda[lane]);
        block.set(lane, &rod_lane(desc, bodies));
        (block.bend_lambda[lane], block.twist_lambda[lane]) = lambdas;
    }

    /// The layout with its step started ([`Layout::start_step`]).
    pub fn started(mut self, bodies: &BodyStore) -> Self {
        self.start_step(bodies);
        self
    }

    /// Measures where every joint's bodies stand as the step begins (the
    /// rows then hold displacements from there): each socket's anchors,
    /// each rod's chord between centres of mass. Each block alone
    /// ([`crate::start::StartBlock`]): the step does it in chunks on its
    /// workers.
    pub fn start_step(&mut self, bodies: &BodyStore) {
        start_blocks(&mut self.sockets.blocks, bodies);
        start_blocks(&mut self.hinges.blocks, bodies);
        start_blocks(&mut self.fixed.blocks, bodies);
        start_blocks(&mut self.rods.blocks, bodies);
        start_blocks(&mut self.trees.blocks, bodies);
    }

    fn append(
        &mut self,
        keys: &BTreeSet<u64>,
        joints: &[Option<JointDesc>],
        rods: &[Option<RodDesc>],
        bodies: &BodyStore,
    ) -> Group {
        let joint = |slot: usize| joints[slot].as_ref().expect("awake joints are laid out");
        // A sleeping joint is `None` here: coloured, not laid out.
        let joint_slots = || {
            keys.iter()
                .filter(|&&k| k < ROD_KEY)
                .map(|&k| k as usize)
                .filter(|&s| joints[s].is_some())
        };
        let of_kind =
            |kind: BlockKind| joint_slots().filter(move |&s| block_kind(joint(s)) == kind);
        let rod_slots = keys
            .iter()
            .filter(|&&k| k >= ROD_KEY)
            .map(|&k| (k - ROD_KEY) as usize)
            .filter(|&s| rods[s].is_some());
        let trees = &self.trees;
        let held = |s: usize| trees.has_joint(s);
        let mut group = Group::default();
        for kind in BlockKind::ALL {
            let range = match kind.vector() {
                Vector::Sockets => {
                    let set = |block: &mut SocketBlock, lane: usize, slot: usize| {
                        let d = joint(slot);
                        if let JointKind::Socket(limits) = &d.kind {
                            block.set(lane, &socket_lane(d, limits, bodies));
                        }
                    };
                    (self.sockets).append(of_kind(kind), held, SocketBlock::padding(), set)
                }
                Vector::Hinges => {
                    let set = |block: &mut HingeBlock, lane: usize, slot: usize| {
                        let d = joint(slot);
                        if let JointKind::Hinge { range, softness } = d.kind {
                            block.set(lane, &hinge_lane(d, range, softness, bodies));
                        }
                    };
                    (self.hinges).append(of_kind(kind), held, HingeBlock::padding(), set)
                }
                Vector::Fixed => {
                    let set = |block: &mut FixedBlock, lane: usize, slot: usize| {
                        block.set(lane, &fixed_lane(joint(slot), bodies));
                    };
                    (self.fixed).append(of_kind(kind), held, FixedBlock::padding(), set)
                }
                Vector::Rods => {
                    let set = |block: &mut RodBlock, lane: usize, slot: usize| {
                        let desc = rods[slot].as_ref().expect("awake rods are laid out");
                        block.set(lane, &rod_lane(desc, bodies));
                    };
                    let rod_held = |s: usize| trees.has_rod(s);
                    (self.rods).append(rod_slots.clone(), rod_held, RodBlock::padding(), set)
                }
            };
            group.set(kind, range);
        }
        group
    }
}

/// The block kind a joint is laid out in: its type, its drive, and (for a
/// socket) the path its limits take.
fn block_kind(desc: &JointDesc) -> BlockKind {
    let driven = desc.drive.is_some();
    match desc.kind {
        JointKind::Socket(limits) => match (driven, limits.is_plain()) {
            (true, true) => BlockKind::DrivenSocket,
            (false, true) => BlockKind::Socket,
            (true, false) => BlockKind::DrivenShapedSocket,
            (false, false) => BlockKind::ShapedSocket,
        },
        JointKind::Hinge { .. } if driven => BlockKind::DrivenHinge,
        JointKind::Hinge { .. } => BlockKind::Hinge,
        JointKind::Fixed => BlockKind::Fixed,
    }
}

/// The lane header of a constraint between bodies `a` and `b`: their rows
/// (slots + 1, row 0 is the null row) and which are dynamic.
pub(crate) fn pair(a: BodyHandle, b: BodyHandle, bodies: &BodyStore) -> PairLane {
    let (ia, ib) = (a.index(), b.index());
    let dynamic = |i: usize| bodies.kind[i] == BodyKind::Dynamic;
    PairLane {
        body_a: ia as u32 + 1,
        body_b: ib as u32 + 1,
        dynamic_a: dynamic(ia),
        dynamic_b: dynamic(ib),
    }
}

/// Where a joint sits on its bodies, its frames normalised by the
/// project's own square root (the same bits on every platform).
fn frames(desc: &JointDesc) -> JointFrames {
    JointFrames {
        anchor_a: desc.anchor_a,
        anchor_b: desc.anchor_b,
        frame_a: desc.frame_a.normalize_portable(),
        frame_b: desc.frame_b.normalize_portable(),
    }
}

/// A socket's lane data: the plain path's cone, or the shaped path's
/// ellipse (its semi-axes the sines of half the half-angles, by the
/// project's own sine, so that every platform lays out the same bits) and
/// pyramid.
pub(crate) fn socket_lane(desc: &JointDesc, limits: &SwingTwist, bodies: &BodyStore) -> SocketLane {
    let plain_cone = match limits.swing {
        Swing::Cone(half) if limits.is_plain() => half,
        _ => PI,
    };
    SocketLane {
        pair: pair(desc.body_a, desc.body_b, bodies),
        frames: frames(desc),
        swing_max: plain_cone,
        twist: limits.twist.unwrap_or([-PI, PI]),
        drive: desc.drive.map(|d| d.lane()),
        shaped: if limits.is_plain() {
            ShapedLimits::FREE
        } else {
            shaped_limits(limits)
        },
    }
}

/// The shaped path's settings for a socket's limits.
fn shaped_limits(limits: &SwingTwist) -> ShapedLimits {
    let semi = crate::joint::ellipse_semi_axis;
    let mut shaped = ShapedLimits::FREE;
    match limits.swing {
        Swing::Free => {}
        Swing::Cone(half) => shaped.ellipse = [semi(half), semi(half)],
        Swing::Ellipse { y, z } => shaped.ellipse = [semi(y), semi(z)],
        Swing::Pyramid { y, z } => shaped.pyramid = [y, z],
    }
    shaped.softness = limits.softness.lane();
    shaped
}

/// A hinge's lane data.
pub(crate) fn hinge_lane(
    desc: &JointDesc,
    range: Option<[f32; 2]>,
    softness: LimitSoftness,
    bodies: &BodyStore,
) -> HingeLane {
    HingeLane {
        pair: pair(desc.body_a, desc.body_b, bodies),
        frames: frames(desc),
        range: range.unwrap_or([-PI, PI]),
        softness: softness.lane(),
        drive: desc.drive.map(|d| d.lane()),
    }
}

/// A fixed joint's lane data.
pub(crate) fn fixed_lane(desc: &JointDesc, bodies: &BodyStore) -> FixedLane {
    FixedLane {
        pair: pair(desc.body_a, desc.body_b, bodies),
        frames: frames(desc),
    }
}

/// A rod's lane data.
pub(crate) fn rod_lane(desc: &RodDesc, bodies: &BodyStore) -> RodLane {
    RodLane {
        pair: pair(desc.body_a, desc.body_b, bodies),
        frame_a: desc.frame_a.normalize_portable(),
        frame_b: desc.frame_b.normalize_portable(),
        rest_length: desc.rest_length,
        bend_rest: desc.bend_rest.normalize(),
        twist_rest: desc.twist_rest,
        bend_rest_velocity: desc.bend_rest_velocity,
        twist_rest_velocity: desc.twist_rest_velocity,
        bend: desc.softness(desc.bending),
        twist: desc.softness(desc.twisting),
        bend_max: desc.bend_limit.unwrap_or(PI),
        twist_range: desc.twist_limit.unwrap_or([-PI, PI]),
        max_torque: desc.max_torque,
    }
}
