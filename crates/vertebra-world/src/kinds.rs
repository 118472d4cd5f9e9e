//! The joint kinds' table: every kind of joint block the layout holds, in
//! the order a colour solves them ([`BlockKind::ALL`]), and a colour's
//! blocks as one range per kind ([`Group`]).
//!
//! A kind is a block type (the vector of `Layout` (`layout.rs`) it
//! lives in, [`Vector`]) with the kernel variant that solves it: sockets
//! with and without drives, on the plain and on the shaped path; hinges
//! with and without drives; fixed joints; rods. Kinds are kept apart so
//! that no lane pays for a part it does not use. Everything that walks a
//! colour's joints (the substep's stages, the drives' substep start, the
//! layout's body pairs) walks this table, and each block type's kernels
//! are reached through one trait ([`JointBlock`]). Adding a joint kind is
//! a row here and the steps `docs/adding-a-joint-kind.md` lists.

use core::ops::Range;

use vertebra_kernels::body::{BodyPairs, BodyRows};
use vertebra_kernels::fixed::{self, FixedBlock};
use vertebra_kernels::hinge::{self, HingeBlock};
use vertebra_kernels::pass::{SubstepScale, run};
use vertebra_kernels::rod::{self, RodBlock};
use vertebra_kernels::socket::{self, SocketBlock};
use vertebra_kernels::{driven, limited};
use vertebra_math::Backend;

use crate::start::StartBlock;

/// A kind of joint block: a block type and the variant of its kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BlockKind {
    /// Sockets with a drive, plain path (a cone and a twist range).
    DrivenSocket,
    /// Sockets without a drive, plain path.
    Socket,
    /// Sockets with a drive, shaped path (an elliptic or shaped swing).
    DrivenShapedSocket,
    /// Sockets without a drive, shaped path.
    ShapedSocket,
    /// Hinges with a drive.
    DrivenHinge,
    /// Hinges without a drive.
    Hinge,
    /// Fixed joints.
    Fixed,
    /// Rods (the paper's rod constraint).
    Rod,
}

/// The block vectors of the layout, one per block type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Vector {
    /// `SocketBlock`s.
    Sockets,
    /// `HingeBlock`s.
    Hinges,
    /// `FixedBlock`s.
    Fixed,
    /// `RodBlock`s.
    Rods,
}

impl BlockKind {
    /// Every kind, in the order a colour (and the overflow set) solves
    /// them. Inside a colour the order changes no result (its blocks share
    /// no dynamic body); the overflow set's kinds are solved one after
    /// another in this order.
    pub const ALL: [Self; 8] = [
        Self::DrivenSocket,
        Self::Socket,
        Self::DrivenShapedSocket,
        Self::ShapedSocket,
        Self::DrivenHinge,
        Self::Hinge,
        Self::Fixed,
        Self::Rod,
    ];

    /// How many kinds.
    pub const COUNT: usize = Self::ALL.len();

    /// The kind's place in [`Self::ALL`].
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The vector its blocks live in.
    pub const fn vector(self) -> Vector {
        match self {
            Self::DrivenSocket | Self::Socket | Self::DrivenShapedSocket | Self::ShapedSocket => {
                Vector::Sockets
            }
            Self::DrivenHinge | Self::Hinge => Vector::Hinges,
            Self::Fixed => Vector::Fixed,
            Self::Rod => Vector::Rods,
        }
    }

    /// Its lanes hold a drive.
    pub const fn driven(self) -> bool {
        matches!(
            self,
            Self::DrivenSocket | Self::DrivenShapedSocket | Self::DrivenHinge
        )
    }

    /// Its sockets take the shaped path (an elliptic or shaped swing).
    pub const fn shaped(self) -> bool {
        matches!(self, Self::DrivenShapedSocket | Self::ShapedSocket)
    }

    /// Its limits may be damped: the substep's start measures their
    /// violation (`vertebra_kernels::limited`). Shaped sockets and hinges.
    pub const fn damped_limits(self) -> bool {
        self.shaped() || matches!(self.vector(), Vector::Hinges)
    }
}

/// One colour's (or the overflow set's) blocks: a range of its kind's
/// vector per kind, indexed by [`BlockKind::index`].
#[derive(Clone, Debug, Default)]
pub(crate) struct Group {
    ranges: [Range<usize>; BlockKind::COUNT],
}

impl Group {
    /// Sets the blocks of `kind`.
    pub fn set(&mut self, kind: BlockKind, range: Range<usize>) {
        self.ranges[kind.index()] = range;
    }

    /// Every kind with its blocks, in solve order.
    pub fn kinds(&self) -> impl Iterator<Item = (BlockKind, &Range<usize>)> + Clone + '_ {
        BlockKind::ALL.into_iter().zip(&self.ranges)
    }

    /// No blocks of any kind.
    pub fn is_empty(&self) -> bool {
        self.ranges.iter().all(Range::is_empty)
    }

    /// How many blocks of every kind.
    pub fn len(&self) -> usize {
        self.ranges.iter().map(Range::len).sum()
    }
}

/// A joint block type: its kernels, by stage, for the kind of its blocks
/// (one dispatch: the stages call these, never a kernel by name).
pub(crate) trait JointBlock: Copy + Send + Sync + StartBlock {
    /// The block's bodies and lanes.
    fn pairs(&self) -> &BodyPairs;

    /// Zeroes the multipliers a substep accumulates.
    fn reset_lambdas(&mut self);

    /// The substep's start, before the bodies move: a drive's error
    /// against its last target and the target advanced by `h` (s), a
    /// damped limit's violation, a rod's error against its rest shape and
    /// the rest advanced (`kind` says which of these its blocks have).
    fn start_substep(
        blocks: &mut [Self],
        kind: BlockKind,
        rows: &BodyRows,
        h: f32,
        backend: Backend,
    );

    /// One position iteration over `blocks`, all of `kind`.
    fn positions(
        blocks: &mut [Self],
        kind: BlockKind,
        scale: SubstepScale,
        rows: &BodyRows,
        backend: Backend,
    );
}

impl JointBlock for SocketBlock {
    fn pairs(&self) -> &BodyPairs {
        &self.bodies
    }
    fn reset_lambdas(&mut self) {
        SocketBlock::reset_lambdas(self);
    }
    fn start_substep(blocks: &mut [Self], kind: BlockKind, rows: &BodyRows, h: f32, b: Backend) {
        start_drives_and_limits(blocks, kind, rows, h, b);
    }
    fn positions(
        blocks: &mut [Self],
        kind: BlockKind,
        s: SubstepScale,
        rows: &BodyRows,
        b: Backend,
    ) {
        match (kind.driven(), kind.shaped()) {
            (true, false) => run::<socket::Positions<true, false>>(b, blocks, rows, s),
            (false, false) => run::<socket::Positions<false, false>>(b, blocks, rows, s),
            (true, true) => run::<socket::Positions<true, true>>(b, blocks, rows, s),
            (false, true) => run::<socket::Positions<false, true>>(b, blocks, rows, s),
        }
    }
}

impl JointBlock for HingeBlock {
    fn pairs(&self) -> &BodyPairs {
        &self.bodies
    }
    fn reset_lambdas(&mut self) {
        HingeBlock::reset_lambdas(self);
    }
    fn start_substep(blocks: &mut [Self], kind: BlockKind, rows: &BodyRows, h: f32, b: Backend) {
        start_drives_and_limits(blocks, kind, rows, h, b);
    }
    fn positions(
        blocks: &mut [Self],
        kind: BlockKind,
        s: SubstepScale,
        rows: &BodyRows,
        b: Backend,
    ) {
        match kind.driven() {
            true => run::<hinge::Positions<true>>(b, blocks, rows, s),
            false => run::<hinge::Positions<false>>(b, blocks, rows, s),
        }
    }
}

impl JointBlock for FixedBlock {
    fn pairs(&self) -> &BodyPairs {
        &self.bodies
    }
    fn reset_lambdas(&mut self) {}
    fn start_substep(_: &mut [Self], _: BlockKind, _: &BodyRows, _: f32, _: Backend) {}
    fn positions(blocks: &mut [Self], _: BlockKind, _: SubstepScale, rows: &BodyRows, b: Backend) {
        run::<fixed::Positions>(b, blocks, rows, ());
    }
}

impl JointBlock for RodBlock {
    fn pairs(&self) -> &BodyPairs {
        &self.bodies
    }
    fn reset_lambdas(&mut self) {
        RodBlock::reset_lambdas(self);
    }
    fn start_substep(blocks: &mut [Self], _: BlockKind, rows: &BodyRows, h: f32, b: Backend) {
        run::<rod::Starts>(b, blocks, rows, h);
    }
    fn positions(blocks: &mut [Self], _: BlockKind, s: SubstepScale, rows: &BodyRows, b: Backend) {
        run::<rod::Positions>(b, blocks, rows, s);
    }
}

/// A socket's or hinge's substep start: the drive's when `kind` has one,
/// then the damped limits' when it has them.
fn start_drives_and_limits<B>(
    blocks: &mut [B],
    kind: BlockKind,
    rows: &BodyRows,
    h: f32,
    backend: Backend,
) where
    B: driven::Driven + limited::Limited,
{
    if kind.driven() {
        run::<driven::Starts<B>>(backend, blocks, rows, h);
    }
    if kind.damped_limits() {
        run::<limited::Starts<B>>(backend, blocks, rows, ());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table in `docs/adding-a-joint-kind.md` lists every kind, in
    /// solve order, with its vector: the recipe and the code agree.
    #[test]
    fn the_recipe_lists_every_kind_in_solve_order() {
        let doc = include_str!("../../../docs/adding-a-joint-kind.md");
        let rows: Vec<(String, String)> = doc
            .lines()
            .filter_map(|l| {
                let cells: Vec<_> = l.split('|').map(str::trim).collect();
                // A table row: | `Kind` | `Vector` | ...
                let kind = cells.get(1)?.strip_prefix('`')?.strip_suffix('`')?;
                let vector = cells.get(2)?.strip_prefix('`')?.strip_suffix('`')?;
                Some((kind.to_string(), vector.to_string()))
            })
            .collect();
        let table: Vec<(String, String)> = BlockKind::ALL
            .iter()
            .map(|k| (format!("{k:?}"), format!("{:?}", k.vector())))
            .collect();
        assert_eq!(rows, table, "docs/adding-a-joint-kind.md's table");
    }

    #[test]
    fn indices_are_places_in_the_table() {
        for (i, kind) in BlockKind::ALL.into_iter().enumerate() {
            assert_eq!(kind.index(), i, "{kind:?}");
        }
    }
}
