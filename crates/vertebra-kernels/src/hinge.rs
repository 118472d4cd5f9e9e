//! The hinge joint: a point part, the hinge axis part (the two frames' +X
//! axes held together), a range about that axis (the twist of the frames,
//! hard or soft) and an angular drive, solved together in one lane-generic
//! kernel.
//!
//! The range is the `twist` part's angle: the relative rotation's twist
//! about +X, in [-pi, pi], which for a hinge (no swing) is the hinge angle
//! itself; `[-pi, pi]` disables it. Both the axis part and the range
//! measure in the bodies' own frames, from b's orientation relative to a
//! (`hinge_axis`, `twist::violation_local`, `limit::solve_local`): fewer
//! rotations than the socket's world-frame parts. The drive is the
//! socket's drive part (`driven.rs`), with the same settings and the same
//! substep start.

use bytemuck::{Pod, Zeroable};
use vertebra_math::block::{BLOCK_LANES, QuatBlock, Vec3Block};
use vertebra_math::{Lane, Quat};

use crate::body::{BodyLanes, BodyPairs, BodyRows, JointFrames, LaneBlock, PairLane};
use crate::driven::{DriveBlock, DriveLane, Driven};
use crate::limited::{LimitLane, Limited, SoftnessBlock};
use crate::parts::{hinge_axis, limit, point, swing, twist};
use crate::pass::{BlockKernel, SubstepScale};
use crate::reaction::ReactionBlock;
use crate::residual::{Measured, Residual};

/// Eight hinges, field by field.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct HingeBlock {
    /// The two bodies of each lane.
    pub bodies: BodyPairs,
    /// Anchor on a, a's body frame (m).
    pub anchor_a: Vec3Block,
    /// Anchor on b, b's body frame (m).
    pub anchor_b: Vec3Block,
    /// Joint frame in a's body frame (its +X is the hinge axis).
    pub frame_a: QuatBlock,
    /// Joint frame in b's body frame.
    pub frame_b: QuatBlock,
    /// Lowest hinge angle (rad); -pi with `range_max = pi` disables it.
    pub range_min: [f32; BLOCK_LANES],
    /// Highest hinge angle (rad).
    pub range_max: [f32; BLOCK_LANES],
    /// The range's softness (hard, compliance or spring, and damping;
    /// `parts::limit`).
    pub limit_softness: SoftnessBlock,
    /// The range's accumulated multiplier (N m s^2), reset every substep.
    pub limit_lambda: [f32; BLOCK_LANES],
    /// The range's violation at the substep's start (rad; the damping's
    /// `C_0`), measured by [`crate::limited::Starts`].
    pub limit_start: [f32; BLOCK_LANES],
    /// The angular drives.
    pub drive: DriveBlock,
    /// What each hinge did to its bodies this step (its force and torque;
    /// never read by the solve).
    pub reaction: ReactionBlock,
}

/// One hinge's solver data (one lane of a block).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HingeLane {
    /// The two bodies.
    pub pair: PairLane,
    /// Where the hinge sits on each body (its frames' +X the hinge axis).
    pub frames: JointFrames,
    /// Hinge range (rad), `[-pi, pi]` when unlimited.
    pub range: [f32; 2],
    /// The range's softness ([`LimitLane::HARD`] is hard).
    pub softness: LimitLane,
    /// The drive, if driven.
    pub drive: Option<DriveLane>,
}

impl LaneBlock for HingeBlock {
    type Lane = HingeLane;
    const PADDING: HingeLane = HingeLane {
        pair: PairLane::NULL,
        frames: JointFrames::NONE,
        range: [-core::f32::consts::PI, core::f32::consts::PI],
        softness: LimitLane::HARD,
        drive: None,
    };

    /// Writes one hinge into `lane`.
    fn set(&mut self, lane: usize, h: &HingeLane) {
        self.bodies.set(lane, &h.pair);
        self.anchor_a.set(lane, h.frames.anchor_a);
        self.anchor_b.set(lane, h.frames.anchor_b);
        self.frame_a.set(lane, h.frames.frame_a);
        self.frame_b.set(lane, h.frames.frame_b);
        (self.range_min[lane], self.range_max[lane]) = (h.range[0], h.range[1]);
        self.limit_softness.set(lane, &h.softness);
        self.limit_lambda[lane] = 0.0;
        self.limit_start[lane] = 0.0;
        self.drive.set(lane, h.drive.as_ref());
    }
}

impl HingeBlock {
    /// Zeroes the accumulated multipliers, as each substep begins.
    pub fn reset_lambdas(&mut self) {
        self.drive.lambda = Vec3Block::default();
        self.limit_lambda = [0.0; BLOCK_LANES];
    }
}

impl Driven for HingeBlock {
    fn bodies(&self) -> &BodyPairs {
        &self.bodies
    }
    #[inline(always)]
    fn frames<L: Lane>(&self, start: usize) -> (Quat<L>, Quat<L>) {
        (self.frame_a.load(start), self.frame_b.load(start))
    }
    fn drive_mut(&mut self) -> &mut DriveBlock {
        &mut self.drive
    }
}

impl Limited for HingeBlock {
    fn bodies(&self) -> &BodyPairs {
        &self.bodies
    }
    #[inline(always)]
    fn start_limits<L: Lane>(&mut self, start: usize, a: &BodyLanes<L>, b: &BodyLanes<L>) {
        let (fa, fb) = (self.frame_a.load::<L>(start), self.frame_b.load::<L>(start));
        let (lo, hi) = (
            L::load(&self.range_min[start..]),
            L::load(&self.range_max[start..]),
        );
        let (_, c0) = twist::violation_local(a, b, fa, fb, lo, hi);
        c0.store(&mut self.limit_start[start..]);
    }
}

/// One XPBD iteration of hinges (a [`BlockPass`](crate::pass::BlockPass) over [`HingeBlock`]s):
/// every hinge's parts, in the order drive, hinge axis, range, point (the
/// point last, as for the socket). `DRIVE` says whether the blocks' hinges
/// have drives (the layout keeps driven and plain hinges apart).
pub struct Positions<const DRIVE: bool>;

impl<const DRIVE: bool> BlockKernel for Positions<DRIVE> {
    type Block = HingeBlock;
    type Params = SubstepScale;
    #[inline(always)]
    fn padding(block: &HingeBlock) -> u32 {
        block.bodies.padding
    }
    /// A block whose joints the direct solve holds, drives included,
    /// has nothing left to iterate.
    #[inline(always)]
    fn skips(block: &HingeBlock) -> bool {
        block.bodies.direct != 0
    }
    #[inline(always)]
    fn solve<L: Lane>(block: &mut HingeBlock, start: usize, rows: &BodyRows, s: SubstepScale) {
        let (inv_h, inv_h2) = (L::splat(s.inv_h), L::splat(s.inv_h2));
        solve_positions::<L, DRIVE>(block, start, rows, inv_h, inv_h2);
    }
}

#[inline(always)]
fn solve_positions<L: Lane, const DRIVE: bool>(
    block: &mut HingeBlock,
    start: usize,
    rows: &BodyRows,
    inv_h: L,
    inv_h2: L,
) {
    let (mut a, mut b) = block.bodies.gather::<L>(rows, start);
    let before = (a, b);
    let frame_a = block.frame_a.load::<L>(start);
    let frame_b = block.frame_b.load::<L>(start);

    if DRIVE {
        let (a, b) = (&mut a, &mut b);
        block
            .drive
            .solve(start, a, b, frame_a, frame_b, inv_h, inv_h2);
    }

    hinge_axis::solve(&mut a, &mut b, frame_a, frame_b);
    let (lo, hi) = (
        L::load(&block.range_min[start..]),
        L::load(&block.range_max[start..]),
    );
    let (axes, c) = twist::violation_local(&a, &b, frame_a, frame_b, lo, hi);
    let soft = block.limit_softness.lanes(start, inv_h, inv_h2);
    let lambda = L::load(&block.limit_lambda[start..]);
    let c0 = L::load(&block.limit_start[start..]);
    limit::solve_local(&mut a, &mut b, axes, (c, c0), soft, lambda)
        .store(&mut block.limit_lambda[start..]);
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

/// A hinge's residual error: anchor separation (m), and the angle between
/// the hinge axes plus the range overshoot (rad).
impl Residual for HingeBlock {
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
        let (_, misalignment) = swing::measure(&a, &b, fa, fb);
        let (lo, hi) = (
            L::load(&self.range_min[start..]),
            L::load(&self.range_max[start..]),
        );
        let (_, violation) = twist::violation_local(&a, &b, fa, fb, lo, hi);
        Measured {
            linear: d.length(),
            angular: misalignment + violation,
            limit: violation,
        }
    }
}
