//! The solver's constraint layout: every socket in a lane of a block, the
//! blocks ordered by colour, then the overflow set. Rebuilt only when the
//! colouring changes (a joint added or removed), never per step.

use core::f32::consts::PI;
use core::ops::Range;

use vertebra_kernels::socket::{SocketBlock, SocketLane};
use vertebra_math::block::BLOCK_LANES;
use vertebra_scheduler::{Colouring, MAX_COLOURS};
use vertebra_store::{BodyKind, BodyStore};

use crate::socket::SocketDesc;

/// No socket in this lane.
pub(crate) const EMPTY: u32 = u32::MAX;

/// One colour's (or the overflow set's) blocks: driven sockets first, then
/// plain ones, each group in blocks of its own.
#[derive(Clone, Debug, Default)]
pub(crate) struct Group {
    /// Blocks of sockets with a drive.
    pub driven: Range<usize>,
    /// Blocks of sockets without.
    pub plain: Range<usize>,
}

#[derive(Clone, Debug, Default)]
pub(crate) struct Layout {
    /// All socket blocks: colour 0's, colour 1's, ..., then overflow.
    pub blocks: Vec<SocketBlock>,
    /// The non-empty colours, in colour order.
    pub colours: Vec<Group>,
    /// The overflow set (solved by the scalar kernel).
    pub overflow: Group,
    /// For each block lane, the socket slot it holds, or `EMPTY`.
    pub lane_socket: Vec<u32>,
    /// For each socket slot, its (block, lane).
    pub place: Vec<(usize, usize)>,
}

impl Layout {
    /// Lays out every coloured socket; `sockets[slot]` is `Some` when live.
    pub fn build(
        colouring: &Colouring,
        sockets: &[Option<SocketDesc>],
        bodies: &BodyStore,
    ) -> Self {
        let mut layout = Self {
            place: vec![(0, 0); sockets.len()],
            ..Self::default()
        };
        for c in 0..MAX_COLOURS {
            let group = layout.append_group(colouring.colour(c), sockets, bodies);
            if !(group.driven.is_empty() && group.plain.is_empty()) {
                layout.colours.push(group);
            }
        }
        layout.overflow = layout.append_group(colouring.overflow(), sockets, bodies);
        layout
    }

    fn append_group(
        &mut self,
        keys: &std::collections::BTreeSet<u64>,
        sockets: &[Option<SocketDesc>],
        bodies: &BodyStore,
    ) -> Group {
        let driven = |key: &&u64| {
            sockets[**key as usize]
                .as_ref()
                .is_some_and(|s| s.drive.is_some())
        };
        Group {
            driven: self.append(keys.iter().filter(driven), sockets, bodies),
            plain: self.append(keys.iter().filter(|k| !driven(k)), sockets, bodies),
        }
    }

    fn append<'k>(
        &mut self,
        keys: impl Iterator<Item = &'k u64>,
        sockets: &[Option<SocketDesc>],
        bodies: &BodyStore,
    ) -> Range<usize> {
        let start = self.blocks.len();
        for (k, &key) in keys.enumerate() {
            let slot = key as usize;
            let lane = k % BLOCK_LANES;
            if lane == 0 {
                self.blocks.push(SocketBlock::padding());
                self.lane_socket.extend([EMPTY; BLOCK_LANES]);
            }
            let block = self.blocks.len() - 1;
            let desc = sockets[slot].as_ref().expect("coloured sockets are live");
            self.blocks[block].set(lane, &solver_lane(desc, bodies));
            self.lane_socket[block * BLOCK_LANES + lane] = slot as u32;
            self.place[slot] = (block, lane);
        }
        start..self.blocks.len()
    }
}

/// A socket's lane data: rows are body slots + 1 (row 0 is the null row).
pub(crate) fn solver_lane(desc: &SocketDesc, bodies: &BodyStore) -> SocketLane {
    let ia = desc.body_a.index();
    let ib = desc.body_b.index();
    SocketLane {
        body_a: ia as u32 + 1,
        body_b: ib as u32 + 1,
        dynamic_a: bodies.kind[ia] == BodyKind::Dynamic,
        dynamic_b: bodies.kind[ib] == BodyKind::Dynamic,
        anchor_a: desc.anchor_a,
        anchor_b: desc.anchor_b,
        frame_a: desc.frame_a.normalize(),
        frame_b: desc.frame_b.normalize(),
        swing_max: desc.swing_limit.unwrap_or(PI),
        twist: desc.twist_limit.unwrap_or([-PI, PI]),
        drive: desc
            .drive
            .map(|d| (d.target.normalize(), d.compliance, d.damping)),
    }
}
