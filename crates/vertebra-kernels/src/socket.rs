//! The ball-and-socket joint: a point part, a swing limit, a twist range and
//! an angular drive, solved together in one lane-generic kernel.
//!
//! Two swing paths, chosen per block at compile time (`SHAPED`): the plain
//! one, a hard circular cone (`swing`) and a hard twist range (`twist`);
//! and the shaped one, an elliptical cone (`ellipse`) and a pyramid
//! (`pyramid`), each inactive at its widest, and the twist range, every
//! limit hard or soft (`limit`). The layout keeps the two in separate
//! blocks, so a plain socket computes exactly what it always did.
//!
//! Constraint data lives in [`SocketBlock`]s of eight lanes (AoSoA), laid
//! out by the scheduler in colour order. A pass walks its blocks `L::WIDTH`
//! lanes at a time: gather both bodies' rows, apply the parts, scatter.
//! Padding lanes name the null row and write nothing.

use bytemuck::{Pod, Zeroable};
use vertebra_math::block::{BLOCK_LANES, QuatBlock, Vec3Block};
use vertebra_math::{Lane, Quat, Vec3};

use crate::body::{BodyLanes, BodyPairs, BodyRows, JointFrames, LaneBlock, PairLane};
use crate::driven::{DriveBlock, DriveLane, Driven};
use crate::limited::{LimitLane, Limited, SoftnessBlock};
use crate::parts::{ellipse, limit, point, pyramid, swing, swing_direction, twist};
use crate::pass::{BlockKernel, SubstepScale};
use crate::reaction::ReactionBlock;
use crate::residual::{Measured, Residual};

/// Eight sockets, field by field.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct SocketBlock {
    /// The two bodies of each lane.
    pub bodies: BodyPairs,
    /// Anchor on a, a's body frame (m).
    pub anchor_a: Vec3Block,
    /// Anchor on b, b's body frame (m).
    pub anchor_b: Vec3Block,
    /// Joint frame in a's body frame (its +X is the twist axis).
    pub frame_a: QuatBlock,
    /// Joint frame in b's body frame.
    pub frame_b: QuatBlock,
    /// Swing cone half-angle (rad); pi disables it.
    pub swing_max: [f32; BLOCK_LANES],
    /// Lowest twist angle (rad); -pi with `twist_max = pi` disables it.
    pub twist_min: [f32; BLOCK_LANES],
    /// Highest twist angle (rad).
    pub twist_max: [f32; BLOCK_LANES],
    /// The angular drives.
    pub drive: DriveBlock,
    /// Shaped path: the elliptical cone's semi-axis about Y,
    /// `sin(theta_y / 2)` (1 disables).
    pub ellipse_y: [f32; BLOCK_LANES],
    /// Shaped path: the elliptical cone's semi-axis about Z.
    pub ellipse_z: [f32; BLOCK_LANES],
    /// Shaped path: the pyramid's range of the swing angle about Y,
    /// `[min, max]` (rad; -pi, pi disable).
    pub pyramid_y: [[f32; BLOCK_LANES]; 2],
    /// Shaped path: the pyramid's range about Z (rad).
    pub pyramid_z: [[f32; BLOCK_LANES]; 2],
    /// Shaped path: the limits' softness (hard, compliance or spring, and
    /// damping; `parts::limit`).
    pub limit_softness: SoftnessBlock,
    /// Shaped path: the violations of the ellipse, the pyramid's two angles
    /// and the twist range at the substep's start (the damping's `C_0`),
    /// measured by [`crate::limited::Starts`].
    pub limit_start: [[f32; BLOCK_LANES]; 4],
    /// Shaped path: accumulated multipliers of the ellipse, the pyramid's
    /// two angles and the twist range, reset every substep.
    pub limit_lambda: [[f32; BLOCK_LANES]; 4],
    /// What each socket did to its bodies this step (its force and
    /// torque; never read by the solve).
    pub reaction: ReactionBlock,
}

/// A socket's shaped limits (one lane), the shaped path's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapedLimits {
    /// The elliptical cone's semi-axes `[sin(theta_y / 2), sin(theta_z /
    /// 2)]`, each at least [`ellipse::MIN_SEMI_AXIS`]; `[1, 1]` is free.
    pub ellipse: [f32; 2],
    /// The pyramid's ranges of the swing angles about Y and Z (rad);
    /// `[-pi, pi]` is free.
    pub pyramid: [[f32; 2]; 2],
    /// The limits' softness ([`LimitLane::HARD`] is hard).
    pub softness: LimitLane,
}

impl ShapedLimits {
    /// No shaped limit: what the plain path's lanes hold.
    pub const FREE: Self = Self {
        ellipse: [1.0, 1.0],
        pyramid: [
            [-core::f32::consts::PI, core::f32::consts::PI],
            [-core::f32::consts::PI, core::f32::consts::PI],
        ],
        softness: LimitLane::HARD,
    };
}

/// One socket's solver data (one lane of a block).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SocketLane {
    /// The two bodies.
    pub pair: PairLane,
    /// Where the joint sits on each body.
    pub frames: JointFrames,
    /// Swing cone half-angle (rad), pi when unlimited.
    pub swing_max: f32,
    /// Twist range (rad), `[-pi, pi]` when unlimited.
    pub twist: [f32; 2],
    /// The drive, if driven.
    pub drive: Option<DriveLane>,
    /// The shaped path's limits ([`ShapedLimits::FREE`] on the plain path).
    pub shaped: ShapedLimits,
}

impl LaneBlock for SocketBlock {
    type Lane = SocketLane;
    const PADDING: SocketLane = SocketLane {
        pair: PairLane::NULL,
        frames: JointFrames::NONE,
        swing_max: core::f32::consts::PI,
        twist: [-core::f32::consts::PI, core::f32::consts::PI],
        drive: None,
        shaped: ShapedLimits::FREE,
    };

    /// Writes one socket into `lane`.
    fn set(&mut self, lane: usize, s: &SocketLane) {
        self.bodies.set(lane, &s.pair);
        self.anchor_a.set(lane, s.frames.anchor_a);
        self.anchor_b.set(lane, s.frames.anchor_b);
        self.frame_a.set(lane, s.frames.frame_a);
        self.frame_b.set(lane, s.frames.frame_b);
        self.swing_max[lane] = s.swing_max;
        (self.twist_min[lane], self.twist_max[lane]) = (s.twist[0], s.twist[1]);
        self.drive.set(lane, s.drive.as_ref());
        let shaped = &s.shaped;
        (self.ellipse_y[lane], self.ellipse_z[lane]) = (shaped.ellipse[0], shaped.ellipse[1]);
        for k in 0..2 {
            self.pyramid_y[k][lane] = shaped.pyramid[0][k];
            self.pyramid_z[k][lane] = shaped.pyramid[1][k];
        }
        self.limit_softness.set(lane, &shaped.softness);
        for lambda in &mut self.limit_lambda {
            lambda[lane] = 0.0;
        }
        for c0 in &mut self.limit_start {
            c0[lane] = 0.0;
        }
    }
}

impl SocketBlock {
    /// Zeroes every accumulated multiplier (the drive's and the shaped
    /// limits'), as each substep begins.
    pub fn reset_lambdas(&mut self) {
        self.drive.lambda = Vec3Block::default();
        self.limit_lambda = [[0.0; BLOCK_LANES]; 4];
    }
}

/// One XPBD iteration of sockets (a [`BlockPass`](crate::pass::BlockPass) over [`SocketBlock`]s):
/// every socket's parts, in the order drive, swing, twist, point (the
/// point last, so that anchors are closest at the end of an iteration).
/// `DRIVE` says whether the blocks' sockets have drives, `SHAPED` whether
/// they take the shaped path: the layout keeps each combination in its own
/// blocks, so a plain socket never pays for a drive multiplied by zero or
/// an ellipse that cannot bind, and the choice is made at compile time,
/// not per lane.
pub struct Positions<const DRIVE: bool, const SHAPED: bool>;

impl<const DRIVE: bool, const SHAPED: bool> BlockKernel for Positions<DRIVE, SHAPED> {
    type Block = SocketBlock;
    type Params = SubstepScale;
    #[inline(always)]
    fn padding(block: &SocketBlock) -> u32 {
        block.bodies.padding
    }
    /// A block whose joints the direct solve holds, drives included,
    /// has nothing left to iterate.
    #[inline(always)]
    fn skips(block: &SocketBlock) -> bool {
        block.bodies.direct != 0
    }
    #[inline(always)]
    fn solve<L: Lane>(block: &mut SocketBlock, start: usize, rows: &BodyRows, s: SubstepScale) {
        let (inv_h, inv_h2) = (L::splat(s.inv_h), L::splat(s.inv_h2));
        solve_positions::<L, DRIVE, SHAPED>(block, start, rows, inv_h, inv_h2);
    }
}

#[inline(always)]
fn solve_positions<L: Lane, const DRIVE: bool, const SHAPED: bool>(
    block: &mut SocketBlock,
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

    if SHAPED {
        solve_shaped(block, start, &mut a, &mut b, inv_h, inv_h2);
    } else {
        swing::solve(
            &mut a,
            &mut b,
            frame_a,
            frame_b,
            L::load(&block.swing_max[start..]),
        );
        let (lo, hi) = (
            L::load(&block.twist_min[start..]),
            L::load(&block.twist_max[start..]),
        );
        twist::solve(&mut a, &mut b, frame_a, frame_b, lo, hi);
    }
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

/// The shaped path's limits: the elliptical cone, the pyramid's two
/// angles, the twist range, each hard or soft.
#[inline(always)]
fn solve_shaped<L: Lane>(
    block: &mut SocketBlock,
    start: usize,
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    inv_h: L,
    inv_h2: L,
) {
    let frame_a = block.frame_a.load::<L>(start);
    let frame_b = block.frame_b.load::<L>(start);
    let soft = block.limit_softness.lanes(start, inv_h, inv_h2);
    let (semi_y, semi_z) = (
        L::load(&block.ellipse_y[start..]),
        L::load(&block.ellipse_z[start..]),
    );
    // The ellipse's error is in swing sines, half a radian per radian for
    // small swings: a quarter of the compliance (see `ellipse`). A spring's
    // `period2` and every `damping_time` are ratios, the same in any units.
    let dir = swing_direction::measure(a, b, frame_a, frame_b);
    let (n, c) = ellipse::violation(&dir, semi_y, semi_z);
    let quarter = limit::Softness {
        alpha_tilde: soft.alpha_tilde * L::splat(0.25),
        ..soft
    };
    solve_limit(block, 0, start, a, b, ([n, dir.in_b(n)], c), quarter);

    let dir = swing_direction::measure(a, b, frame_a, frame_b);
    let [(y, cy), (z, cz)] = pyramid::violations(
        &dir,
        load_range(&block.pyramid_y, start),
        load_range(&block.pyramid_z, start),
    );
    solve_limit(block, 1, start, a, b, ([y, dir.in_b(y)], cy), soft);
    solve_limit(block, 2, start, a, b, ([z, dir.in_b(z)], cz), soft);

    let (lo, hi) = (
        L::load(&block.twist_min[start..]),
        L::load(&block.twist_max[start..]),
    );
    let (axes, c) = twist::violation_local(a, b, frame_a, frame_b, lo, hi);
    let lambda = L::load(&block.limit_lambda[3][start..]);
    let c0 = L::load(&block.limit_start[3][start..]);
    limit::solve_local(a, b, axes, (c, c0), soft, lambda)
        .store(&mut block.limit_lambda[3][start..]);
}

/// The shaped path's four violations (ellipse in swing sines, pyramid y
/// and z, twist; rad), each 0 where its limit holds.
#[inline(always)]
fn shaped_violations<L: Lane>(
    block: &SocketBlock,
    start: usize,
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
) -> [L; 4] {
    let frame_a = block.frame_a.load::<L>(start);
    let frame_b = block.frame_b.load::<L>(start);
    let dir = swing_direction::measure(a, b, frame_a, frame_b);
    let (_, ellipse) = ellipse::violation(
        &dir,
        L::load(&block.ellipse_y[start..]),
        L::load(&block.ellipse_z[start..]),
    );
    let [(_, y), (_, z)] = pyramid::violations(
        &dir,
        load_range(&block.pyramid_y, start),
        load_range(&block.pyramid_z, start),
    );
    let (lo, hi) = (
        L::load(&block.twist_min[start..]),
        L::load(&block.twist_max[start..]),
    );
    let (_, twist) = twist::violation_local(a, b, frame_a, frame_b, lo, hi);
    [ellipse, y, z, twist]
}

impl Limited for SocketBlock {
    fn bodies(&self) -> &BodyPairs {
        &self.bodies
    }
    #[inline(always)]
    fn start_limits<L: Lane>(&mut self, start: usize, a: &BodyLanes<L>, b: &BodyLanes<L>) {
        let c0 = shaped_violations(self, start, a, b);
        for (k, c0) in c0.into_iter().enumerate() {
            c0.store(&mut self.limit_start[k][start..]);
        }
    }
}

/// A `[min, max]` pair of arrays as lanes.
#[inline(always)]
fn load_range<L: Lane>(range: &[[f32; BLOCK_LANES]; 2], start: usize) -> [L; 2] {
    [L::load(&range[0][start..]), L::load(&range[1][start..])]
}

/// One shaped limit (`k` its multiplier and start) through the limit part,
/// its axis given in each body's own frame.
#[inline(always)]
fn solve_limit<L: Lane>(
    block: &mut SocketBlock,
    k: usize,
    start: usize,
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    (axes, c): ([Vec3<L>; 2], L),
    soft: limit::Softness<L>,
) {
    let lambda = L::load(&block.limit_lambda[k][start..]);
    let c0 = L::load(&block.limit_start[k][start..]);
    limit::solve_local(a, b, axes, (c, c0), soft, lambda)
        .store(&mut block.limit_lambda[k][start..]);
}

impl Driven for SocketBlock {
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

/// How far the swing lies outside the elliptical cone (the angle from b's
/// twist axis to the nearest allowed one, rad) and the pyramid (rad): 0 on
/// the plain path, whose shapes are free.
#[inline(always)]
fn shaped_violation<L: Lane>(
    block: &SocketBlock,
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    start: usize,
) -> L {
    let (fa, fb) = (
        block.frame_a.load::<L>(start),
        block.frame_b.load::<L>(start),
    );
    let dir = swing_direction::measure(a, b, fa, fb);
    let (semi_y, semi_z) = (
        L::load(&block.ellipse_y[start..]),
        L::load(&block.ellipse_z[start..]),
    );
    let beyond_ellipse = ellipse::violation_angle(&dir, semi_y, semi_z);
    let [(_, y), (_, z)] = pyramid::violations(
        &dir,
        load_range(&block.pyramid_y, start),
        load_range(&block.pyramid_z, start),
    );
    beyond_ellipse + y + z
}

/// A socket's residual error: anchor separation (m) and angular limit
/// overshoot (swing, whatever its shape, + twist, rad), as the paper's
/// figure 8 counts them.
impl Residual for SocketBlock {
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
        let (_, theta) = swing::measure(&a, &b, fa, fb);
        let (_, phi) = twist::measure(&a, &b, fa, fb);
        let (lo, hi) = (
            L::load(&self.twist_min[start..]),
            L::load(&self.twist_max[start..]),
        );
        let violation = swing::violation(theta, L::load(&self.swing_max[start..]))
            + twist::signed_violation(phi, lo, hi).abs()
            + shaped_violation(self, &a, &b, start);
        Measured {
            linear: d.length(),
            angular: violation,
            limit: violation,
        }
    }
}
