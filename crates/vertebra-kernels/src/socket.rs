//! The ball-and-socket joint: a point part, a swing cone, a twist range and
//! an angular drive, solved together in one lane-generic kernel.
//!
//! Constraint data lives in [`SocketBlock`]s of eight lanes (AoSoA), laid
//! out by the scheduler in colour order. A pass walks its blocks `L::WIDTH`
//! lanes at a time: gather both bodies' rows, apply the parts, scatter.
//! Padding lanes name the null row and write nothing.

use bytemuck::{Pod, Zeroable};
use glam::{Quat as GQuat, Vec3 as GVec3};
use vertebra_math::block::{BLOCK_LANES, QuatBlock, Vec3Block};
use vertebra_math::{Lane, LaneKernel};

use crate::body::{BodyPairs, BodyRows, VelocityLanes};
use crate::parts::{drive, point, swing, twist};
use crate::residual::Residual;

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
    /// Drive target: b's joint frame relative to a's.
    pub drive_target: QuatBlock,
    /// Drive compliance (rad / (N m)); 0 is infinitely stiff.
    pub drive_compliance: [f32; BLOCK_LANES],
    /// 1 where the drive is on, 0 where off.
    pub drive_enabled: [f32; BLOCK_LANES],
    /// Drive damping rate (1/s).
    pub drive_damping: [f32; BLOCK_LANES],
    /// The drive's accumulated XPBD multiplier (world vector), reset every
    /// substep.
    pub drive_lambda: Vec3Block,
}

/// One socket's solver data (one lane of a block).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SocketLane {
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
    /// Swing cone half-angle (rad), pi when unlimited.
    pub swing_max: f32,
    /// Twist range (rad), `[-pi, pi]` when unlimited.
    pub twist: [f32; 2],
    /// Drive target, compliance (rad/(N m)) and damping (1/s), if driven.
    pub drive: Option<(GQuat, f32, f32)>,
}

impl SocketBlock {
    /// A block of padding lanes.
    pub fn padding() -> Self {
        let mut block = Self::zeroed();
        for lane in 0..BLOCK_LANES {
            block.clear(lane);
        }
        block
    }

    /// Makes `lane` a padding lane: null rows, no writes, nothing enabled.
    pub fn clear(&mut self, lane: usize) {
        self.set(
            lane,
            &SocketLane {
                body_a: 0,
                body_b: 0,
                dynamic_a: false,
                dynamic_b: false,
                anchor_a: GVec3::ZERO,
                anchor_b: GVec3::ZERO,
                frame_a: GQuat::IDENTITY,
                frame_b: GQuat::IDENTITY,
                swing_max: core::f32::consts::PI,
                twist: [-core::f32::consts::PI, core::f32::consts::PI],
                drive: None,
            },
        );
    }

    /// Writes one socket into `lane`.
    pub fn set(&mut self, lane: usize, s: &SocketLane) {
        self.bodies
            .set(lane, s.body_a, s.body_b, s.dynamic_a, s.dynamic_b);
        self.anchor_a.set(lane, s.anchor_a);
        self.anchor_b.set(lane, s.anchor_b);
        self.frame_a.set(lane, s.frame_a);
        self.frame_b.set(lane, s.frame_b);
        self.swing_max[lane] = s.swing_max;
        (self.twist_min[lane], self.twist_max[lane]) = (s.twist[0], s.twist[1]);
        let (target, compliance, damping) = s.drive.unwrap_or((GQuat::IDENTITY, 0.0, 0.0));
        self.drive_target.set(lane, target);
        self.drive_compliance[lane] = compliance;
        self.drive_damping[lane] = damping;
        self.drive_enabled[lane] = if s.drive.is_some() { 1.0 } else { 0.0 };
        self.drive_lambda.set(lane, GVec3::ZERO);
    }
}

/// One XPBD iteration over `blocks`: every socket's parts, in the order
/// drive, swing, twist, point (the point last, so that anchors are closest
/// at the end of an iteration). `DRIVE` says whether the blocks' sockets
/// have drives: the layout keeps driven and plain sockets in separate
/// blocks, so a plain socket never pays for a drive multiplied by zero, and
/// the choice is made at compile time, not per lane.
pub struct PositionPass<'a, const DRIVE: bool> {
    /// The blocks to solve (one colour's, or the overflow set).
    pub blocks: &'a mut [SocketBlock],
    /// Body rows, read and written.
    pub rows: &'a BodyRows,
    /// `1 / h^2` for the substep `h` (s^-2): `alpha~ = compliance / h^2`.
    pub inv_h2: f32,
}

impl<const DRIVE: bool> LaneKernel for PositionPass<'_, DRIVE> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        let inv_h2 = L::splat(self.inv_h2);
        for block in self.blocks.iter_mut() {
            for start in (0..BLOCK_LANES).step_by(L::WIDTH) {
                solve_positions::<L, DRIVE>(block, start, self.rows, inv_h2);
            }
        }
    }
}

#[inline(always)]
fn solve_positions<L: Lane, const DRIVE: bool>(
    block: &mut SocketBlock,
    start: usize,
    rows: &BodyRows,
    inv_h2: L,
) {
    let (mut a, mut b) = block.bodies.gather::<L>(rows, start);
    let frame_a = block.frame_a.load::<L>(start);
    let frame_b = block.frame_b.load::<L>(start);

    if DRIVE {
        let lambda = block.drive_lambda.load::<L>(start);
        let alpha_tilde = L::load(&block.drive_compliance[start..]) * inv_h2;
        let enabled = L::load(&block.drive_enabled[start..]);
        let target = block.drive_target.load::<L>(start);
        let lambda = drive::solve(
            &mut a,
            &mut b,
            frame_a,
            frame_b,
            target,
            enabled,
            alpha_tilde,
            lambda,
        );
        block.drive_lambda.store(start, lambda);
    }

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
    point::solve(
        &mut a,
        &mut b,
        block.anchor_a.load(start),
        block.anchor_b.load(start),
        &block.bodies.start(start),
    );

    block.bodies.scatter(rows, start, &a, &b);
}

/// The velocity pass: drive damping, `min(damping h, 1)` of the relative
/// angular velocity removed per substep of `h` seconds. Only driven blocks
/// need it.
pub struct VelocityPass<'a> {
    /// The blocks (one colour's, or the overflow set).
    pub blocks: &'a [SocketBlock],
    /// Body rows: poses and inertia read, velocities read and written.
    pub rows: &'a BodyRows,
    /// The substep (s).
    pub h: f32,
}

impl LaneKernel for VelocityPass<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        let h = L::splat(self.h);
        for block in self.blocks {
            for start in (0..BLOCK_LANES).step_by(L::WIDTH) {
                let (a, b) = block.bodies.gather::<L>(self.rows, start);
                let mut va = VelocityLanes::<L>::gather(self.rows, &block.bodies.body_a[start..]);
                let mut vb = VelocityLanes::<L>::gather(self.rows, &block.bodies.body_b[start..]);
                let rate =
                    L::load(&block.drive_damping[start..]) * L::load(&block.drive_enabled[start..]);
                let fraction = (rate * h).min(L::splat(1.0));
                drive::damp(&a, &b, &mut va, &mut vb, fraction);
                va.scatter(self.rows, &block.bodies.write_a[start..]);
                vb.scatter(self.rows, &block.bodies.write_b[start..]);
            }
        }
    }
}

/// A socket's residual error: anchor separation (m) and angular limit
/// overshoot (swing + twist, rad), as the paper's figure 8 counts them.
impl Residual for SocketBlock {
    #[inline(always)]
    fn residual<L: Lane>(&self, rows: &BodyRows, start: usize) -> (L, L) {
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
        let overshoot = swing::overshoot(theta, L::load(&self.swing_max[start..]))
            + twist::excess(phi, lo, hi).abs();
        (d.length(), overshoot)
    }
}
