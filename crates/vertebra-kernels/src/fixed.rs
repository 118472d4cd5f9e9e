//! The fixed joint: a point part and the lock part (no relative rotation),
//! solved together in one lane-generic kernel: two bodies welded.

use bytemuck::{Pod, Zeroable};
use glam::{Quat as GQuat, Vec3 as GVec3};
use vertebra_math::block::{BLOCK_LANES, LaneSlices, QuatBlock, Vec3Block, for_live_slices};
use vertebra_math::{Lane, LaneKernel};

use crate::body::{BodyPairs, BodyRows};
use crate::parts::{lock, point};
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
    /// Row of body a.
    pub body_a: u32,
    /// Row of body b.
    pub body_b: u32,
    /// Whether body a is dynamic (written).
    pub dynamic_a: bool,
    /// Whether body b is dynamic (written).
    pub dynamic_b: bool,
    /// Anchor on a (m, a's body frame).
    pub anchor_a: GVec3,
    /// Anchor on b (m, b's body frame).
    pub anchor_b: GVec3,
    /// Joint frame in a's body frame.
    pub frame_a: GQuat,
    /// Joint frame in b's body frame.
    pub frame_b: GQuat,
}

impl FixedBlock {
    /// A block of padding lanes.
    pub fn padding() -> Self {
        let mut block = Self::zeroed();
        for lane in 0..BLOCK_LANES {
            block.clear(lane);
        }
        block
    }

    /// Makes `lane` a padding lane: null rows, no writes.
    pub fn clear(&mut self, lane: usize) {
        self.set(
            lane,
            &FixedLane {
                body_a: 0,
                body_b: 0,
                dynamic_a: false,
                dynamic_b: false,
                anchor_a: GVec3::ZERO,
                anchor_b: GVec3::ZERO,
                frame_a: GQuat::IDENTITY,
                frame_b: GQuat::IDENTITY,
            },
        );
    }

    /// Writes one fixed joint into `lane`.
    pub fn set(&mut self, lane: usize, f: &FixedLane) {
        self.bodies
            .set(lane, f.body_a, f.body_b, f.dynamic_a, f.dynamic_b);
        self.anchor_a.set(lane, f.anchor_a);
        self.anchor_b.set(lane, f.anchor_b);
        self.frame_a.set(lane, f.frame_a);
        self.frame_b.set(lane, f.frame_b);
    }
}

/// One XPBD iteration over `blocks`: the lock, then the point (last, as
/// for every joint).
pub struct PositionPass<'a> {
    /// The blocks to solve (one colour's, or the overflow set).
    pub blocks: &'a mut [FixedBlock],
    /// Body rows, read and written.
    pub rows: &'a BodyRows,
}

impl LaneKernel for PositionPass<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        // A fixed joint is all equality: a block the direct solve holds
        // has nothing left to iterate.
        for block in self.blocks.iter_mut() {
            if block.bodies.direct != 0 {
                continue;
            }
            let padding = block.bodies.padding;
            let mut positions = Positions {
                block,
                rows: self.rows,
            };
            for_live_slices::<L, _>(padding, &mut positions);
        }
    }
}

/// One block of a [`PositionPass`].
struct Positions<'a> {
    block: &'a mut FixedBlock,
    rows: &'a BodyRows,
}

impl LaneSlices for Positions<'_> {
    #[inline(always)]
    fn slice<L: Lane>(&mut self, start: usize) {
        solve_positions::<L>(self.block, start, self.rows);
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
