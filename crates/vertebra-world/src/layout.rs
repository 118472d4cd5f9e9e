//! The solver's constraint layout: every joint in a lane of a block of its
//! type, the blocks ordered by colour, then the overflow set. Rebuilt only
//! when the colouring changes (a joint added or removed), never per step.
//!
//! Colouring keys: a socket is its slot, a rod its slot plus [`ROD_KEY`].

use core::f32::consts::PI;
use core::ops::Range;
use std::collections::BTreeSet;

use vertebra_kernels::body::{BodyPairs, StartLane};
use vertebra_kernels::rod::{RodBlock, RodLane};
use vertebra_kernels::socket::{SocketBlock, SocketLane};
use vertebra_math::block::BLOCK_LANES;
use vertebra_scheduler::{Colouring, MAX_COLOURS};
use vertebra_store::{BodyHandle, BodyKind, BodyStore};

use crate::rod::RodDesc;
use crate::socket::SocketDesc;

/// No joint in this lane.
pub(crate) const EMPTY: u32 = u32::MAX;

/// Added to a rod's slot to make its colouring key.
pub(crate) const ROD_KEY: u64 = 1 << 32;

/// One colour's (or the overflow set's) blocks, by kind.
#[derive(Clone, Debug, Default)]
pub(crate) struct Group {
    /// Socket blocks with drives.
    pub driven: Range<usize>,
    /// Socket blocks without.
    pub plain: Range<usize>,
    /// Rod blocks.
    pub rods: Range<usize>,
}

impl Group {
    fn is_empty(&self) -> bool {
        self.driven.is_empty() && self.plain.is_empty() && self.rods.is_empty()
    }
}

/// Blocks of one joint type, with the slot in each lane and each slot's
/// place.
#[derive(Clone, Debug)]
pub(crate) struct Blocks<B> {
    pub blocks: Vec<B>,
    /// For each block lane, the joint slot it holds, or `EMPTY`.
    pub lane_slot: Vec<u32>,
    /// For each joint slot, its (block, lane).
    pub place: Vec<(usize, usize)>,
}

impl<B> Default for Blocks<B> {
    fn default() -> Self {
        Self {
            blocks: Vec::new(),
            lane_slot: Vec::new(),
            place: Vec::new(),
        }
    }
}

impl<B: Copy> Blocks<B> {
    fn append(
        &mut self,
        slots: impl Iterator<Item = usize>,
        padding: B,
        mut set: impl FnMut(&mut B, usize, usize),
    ) -> Range<usize> {
        let start = self.blocks.len();
        for (k, slot) in slots.enumerate() {
            let lane = k % BLOCK_LANES;
            if lane == 0 {
                self.blocks.push(padding);
                self.lane_slot.extend([EMPTY; BLOCK_LANES]);
            }
            let block = self.blocks.len() - 1;
            set(&mut self.blocks[block], lane, slot);
            self.lane_slot[block * BLOCK_LANES + lane] = slot as u32;
            if self.place.len() <= slot {
                self.place.resize(slot + 1, (0, 0));
            }
            self.place[slot] = (block, lane);
        }
        start..self.blocks.len()
    }
}

#[derive(Clone, Debug, Default)]
pub(crate) struct Layout {
    pub sockets: Blocks<SocketBlock>,
    pub rods: Blocks<RodBlock>,
    /// The non-empty colours, in colour order.
    pub colours: Vec<Group>,
    /// The overflow set (solved by the scalar kernel).
    pub overflow: Group,
    /// Every colour passed [`crate::parallel::colour_is_disjoint`]: its
    /// blocks may run on several threads.
    pub disjoint: bool,
}

impl Layout {
    /// Lays out every coloured joint; `sockets[slot]`, `rods[slot]` are
    /// `Some` when live.
    pub fn build(
        colouring: &Colouring,
        sockets: &[Option<SocketDesc>],
        rods: &[Option<RodDesc>],
        bodies: &BodyStore,
    ) -> Self {
        let mut layout = Self::default();
        for c in 0..MAX_COLOURS {
            let group = layout.append(colouring.colour(c), sockets, rods, bodies);
            if !group.is_empty() {
                layout.colours.push(group);
            }
        }
        layout.overflow = layout.append(colouring.overflow(), sockets, rods, bodies);
        layout.disjoint = layout.colours.iter().all(|g| {
            let sockets = layout.sockets.blocks[g.driven.clone()]
                .iter()
                .chain(&layout.sockets.blocks[g.plain.clone()]);
            let rods = layout.rods.blocks[g.rods.clone()].iter();
            crate::parallel::colour_is_disjoint(
                sockets.map(|b| &b.bodies).chain(rods.map(|b| &b.bodies)),
            )
        });
        layout
    }

    /// Measures where every joint's bodies stand as the step begins (the
    /// rows then hold displacements from there): each socket's anchors,
    /// each rod's chord between centres of mass.
    pub fn start_step(&mut self, bodies: &BodyStore) {
        for block in &mut self.sockets.blocks {
            for lane in 0..BLOCK_LANES {
                let anchors = (block.anchor_a.get(lane), block.anchor_b.get(lane));
                start_lane(&mut block.bodies, lane, anchors, bodies);
            }
        }
        for block in &mut self.rods.blocks {
            for lane in 0..BLOCK_LANES {
                let centres = (glam::Vec3::ZERO, glam::Vec3::ZERO);
                start_lane(&mut block.bodies, lane, centres, bodies);
            }
        }
    }

    fn append(
        &mut self,
        keys: &BTreeSet<u64>,
        sockets: &[Option<SocketDesc>],
        rods: &[Option<RodDesc>],
        bodies: &BodyStore,
    ) -> Group {
        let socket = |slot: usize| sockets[slot].as_ref().expect("coloured sockets are live");
        let socket_slots = || keys.iter().filter(|&&k| k < ROD_KEY).map(|&k| k as usize);
        let driven = socket_slots().filter(|&s| socket(s).drive.is_some());
        let plain = socket_slots().filter(|&s| socket(s).drive.is_none());
        let set_socket = |block: &mut SocketBlock, lane: usize, slot: usize| {
            block.set(lane, &socket_lane(socket(slot), bodies))
        };
        let driven = self
            .sockets
            .append(driven, SocketBlock::padding(), set_socket);
        let plain = self
            .sockets
            .append(plain, SocketBlock::padding(), set_socket);
        let rod_slots = keys
            .iter()
            .filter(|&&k| k >= ROD_KEY)
            .map(|&k| (k - ROD_KEY) as usize);
        let rods = self
            .rods
            .append(rod_slots, RodBlock::padding(), |block, lane, slot| {
                block.set(
                    lane,
                    &rod_lane(rods[slot].as_ref().expect("coloured rods are live"), bodies),
                );
            });
        Group {
            driven,
            plain,
            rods,
        }
    }
}

/// Sets `lane`'s start of step for points `local` (m, body frames) on its
/// bodies; padding lanes (the null row) start at the origin.
fn start_lane(
    pairs: &mut BodyPairs,
    lane: usize,
    (local_a, local_b): (glam::Vec3, glam::Vec3),
    bodies: &BodyStore,
) {
    let pose = |row: u32| match row.checked_sub(1) {
        Some(i) => (
            bodies.precise_position(i as usize),
            bodies.orientation[i as usize],
        ),
        None => (glam::DVec3::ZERO, glam::Quat::IDENTITY),
    };
    let ((pa, qa), (pb, qb)) = (pose(pairs.body_a[lane]), pose(pairs.body_b[lane]));
    pairs.set_start(lane, &StartLane::new(pa, qa, local_a, pb, qb, local_b));
}

/// Body rows are slots + 1 (row 0 is the null row).
fn rows(a: BodyHandle, b: BodyHandle, bodies: &BodyStore) -> (u32, u32, bool, bool) {
    let (ia, ib) = (a.index(), b.index());
    let dynamic = |i: usize| bodies.kind[i] == BodyKind::Dynamic;
    (ia as u32 + 1, ib as u32 + 1, dynamic(ia), dynamic(ib))
}

/// A socket's lane data.
pub(crate) fn socket_lane(desc: &SocketDesc, bodies: &BodyStore) -> SocketLane {
    let (body_a, body_b, dynamic_a, dynamic_b) = rows(desc.body_a, desc.body_b, bodies);
    SocketLane {
        body_a,
        body_b,
        dynamic_a,
        dynamic_b,
        anchor_a: desc.anchor_a,
        anchor_b: desc.anchor_b,
        frame_a: desc.frame_a.normalize(),
        frame_b: desc.frame_b.normalize(),
        swing_max: desc.swing_limit.unwrap_or(PI),
        twist: desc.twist_limit.unwrap_or([-PI, PI]),
        drive: desc.drive.map(|d| d.lane()),
    }
}

/// A rod's lane data.
pub(crate) fn rod_lane(desc: &RodDesc, bodies: &BodyStore) -> RodLane {
    let (body_a, body_b, dynamic_a, dynamic_b) = rows(desc.body_a, desc.body_b, bodies);
    RodLane {
        body_a,
        body_b,
        dynamic_a,
        dynamic_b,
        frame_a: desc.frame_a.normalize(),
        frame_b: desc.frame_b.normalize(),
        rest_length: desc.rest_length,
        bend_rest: desc.bend_rest.normalize(),
        twist_rest: desc.twist_rest,
        bend: desc.softness(desc.bending),
        twist: desc.softness(desc.twisting),
        bend_max: desc.bend_limit.unwrap_or(PI),
        twist_range: desc.twist_limit.unwrap_or([-PI, PI]),
        max_torque: desc.max_torque,
    }
}
