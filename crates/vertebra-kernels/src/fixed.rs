//! The fixed joint: a point part and the lock part (no relative rotation),
//! solved together in one lane-generic kernel: two bodies welded.

use bytemuck::{Pod, Zeroable};
use vertebra_math::Lane;
use vertebra_math::block::{QuatBlock, Vec3Block};

use crate::body::{BodyPairs, BodyRows, JointFrames, LaneBlock, PairLane};
use crate::parts::{lock, point};
use crate::pass::BlockKernel;
use crate::reaction::ReactionBlock;
use crate::residual::{Measured, Residual};

/// Eight fixed joints, field by field.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct FixedBlock {
    /// The two bodies of each lane.
    pub bodies: BodyPairs,
    /// Anchor on a, a's body frame (m).
    pub anchor_a: Vec3Block,
    /// Anchor on b, b's body frame (m).
    pub anchor_b: Vec3Block,
    /// Joint frame in a's body frame.
    pub frame_a: QuatBlock,
    /// Joint frame in b's body frame (held equal to a's in the world).
    pub frame_b: QuatBlock,
    /// What each fixed joint did to its bodies this step (its force and
    /// torque; never read by the solve).
    pub reaction: ReactionBlock,
}

/// One fixed joint's solver data (one lane of a block).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedLane {
    /// The two bodies.
    pub pair: PairLane,
    /// Where the joint sits on each body.
    pub frames: JointFrames,
}

impl LaneBlock for FixedBlock {
    type Lane = FixedLane;
    const PADDING: FixedLane = FixedLane {
        pair: PairLane::NULL,
        frames: JointFrames::NONE,
    };

    /// Writes one fixed joint into `lane`.
    fn set(&mut self, lane: usize, f: &FixedLane) {
        self.bodies.set(lane, &f.pair);
        self.anchor_a.set(lane, f.frames.anchor_a);
        self.anchor_b.set(lane, f.frames.anchor_b);
        self.frame_a.set(lane, f.frames.frame_a);
        self.frame_b.set(lane, f.frames.frame_b);
    }
}

impl FixedBlock {}

/// One XPBD iteration of fixed joints (a [`BlockPass`](crate::pass::BlockPass)
/// over [`FixedBlock`]s): the lock, then the point (last, as for every
/// joint).
pub struct Positions;

impl BlockKernel for Positions {
    type Block = FixedBlock;
    type Params = ();
    #[inline(always)]
    fn padding(block: &FixedBlock) -> u32 {
        block.bodies.padding
    }
    /// A fixed joint is all equality: a block the direct solve holds has
    /// nothing left to iterate.
    #[inline(always)]
    fn skips(block: &FixedBlock) -> bool {
        block.bodies.direct != 0
    }
    #[inline(always)]
    fn solve<L: Lane>(block: &mut FixedBlock, start: usize, rows: &BodyRows, (): ()) {
        solve_positions::<L>(block, start, rows);
    }
}

#[inline(always)]
fn solve_positions<L: Lane>(block: &mut FixedBlock, start: usize, rows: &BodyRows) {
    let (mut a, mut b) = block.bodies.gather::<L>(rows, start);
    let before = (a, b);
    let frame_a = block.frame_a.load::<L>(start);
    let frame_b = block.frame_b.load::<L>(start);
    lock::solve(&mut a, &mut b, frame_a, frame_b);
    point::solve(
        &mut a,
        &mut b,
        block.anchor_a.load(start),
        block.anchor_b.load(start),
        &block.bodies.start(start),
    );
    block
        .reaction
        .record(start, (&before.0, &before.1), (&a, &b));
    block.bodies.scatter(rows, start, &a, &b);
}

/// A fixed joint's residual error: anchor separation (m) and the angle
/// between the two joint frames (rad).
impl Residual for FixedBlock {
    #[inline(always)]
    fn residual<L: Lane>(&self, rows: &BodyRows, start: usize) -> Measured<L> {
        let (a, b) = self.bodies.gather::<L>(rows, start);
        let (fa, fb) = (self.frame_a.load::<L>(start), self.frame_b.load::<L>(start));
        let (_, _, d) = point::separation(
            &a,
            &b,
            self.anchor_a.load(start),
            self.anchor_b.load(start),
            &self.bodies.start(start),
        );
        Measured {
            linear: d.length(),
            angular: lock::measure(&a, &b, fa, fb).length(),
            limit: L::splat(0.0),
        }
    }
}
