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

use crate::body::{BodyPairs, BodyRows};
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
    /// Drive target of the current substep: b's joint frame relative to
    /// a's (advanced by [`StartPass`] every substep).
    pub drive_target: QuatBlock,
    /// Drive target angular velocity (rad/s, a's joint frame).
    pub drive_velocity: Vec3Block,
    /// Drive compliance (rad / (N m)); 0 with `drive_period2 = 0` is
    /// infinitely stiff.
    pub drive_compliance: [f32; BLOCK_LANES],
    /// Drive compliance per unit effective inverse inertia, `1 / omega^2`
    /// (s^2), for drives given by frequency.
    pub drive_period2: [f32; BLOCK_LANES],
    /// Drive damping `gamma h` (s): compliance times damping, or
    /// `2 zeta / omega`.
    pub drive_damping_time: [f32; BLOCK_LANES],
    /// Drive torque limit (N m), infinity for none.
    pub drive_max_torque: [f32; BLOCK_LANES],
    /// 1 where the drive is on, 0 where off.
    pub drive_enabled: [f32; BLOCK_LANES],
    /// The drive's accumulated XPBD multiplier (world vector), reset every
    /// substep.
    pub drive_lambda: Vec3Block,
    /// The drive's error at the substep's start (rad, world), measured by
    /// [`StartPass`].
    pub drive_start: Vec3Block,
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
    /// The drive, if driven.
    pub drive: Option<DriveLane>,
}

/// One socket's drive as the kernel holds it (see `parts::drive`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveLane {
    /// The target at the step's start: b's joint frame relative to a's.
    pub target: GQuat,
    /// The target's angular velocity (rad/s, a's joint frame).
    pub velocity: GVec3,
    /// Compliance (rad / (N m)).
    pub compliance: f32,
    /// `1 / omega^2` (s^2).
    pub period2: f32,
    /// `gamma h` (s).
    pub damping_time: f32,
    /// Torque limit (N m), infinity for none.
    pub max_torque: f32,
}

impl DriveLane {
    /// What a plain socket's lane holds: nothing that pulls.
    pub const OFF: Self = Self {
        target: GQuat::IDENTITY,
        velocity: GVec3::ZERO,
        compliance: 0.0,
        period2: 0.0,
        damping_time: 0.0,
        max_torque: f32::INFINITY,
    };
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
        let d = s.drive.unwrap_or(DriveLane::OFF);
        self.drive_target.set(lane, d.target);
        self.drive_velocity.set(lane, d.velocity);
        self.drive_compliance[lane] = d.compliance;
        self.drive_period2[lane] = d.period2;
        self.drive_damping_time[lane] = d.damping_time;
        self.drive_max_torque[lane] = d.max_torque;
        self.drive_enabled[lane] = if s.drive.is_some() { 1.0 } else { 0.0 };
        self.drive_lambda.set(lane, GVec3::ZERO);
        self.drive_start.set(lane, GVec3::ZERO);
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
    /// `1 / h` for the substep `h` (s^-1): the drive's `gamma`.
    pub inv_h: f32,
    /// `1 / h^2` (s^-2): `alpha~ = compliance / h^2`.
    pub inv_h2: f32,
}

impl<const DRIVE: bool> LaneKernel for PositionPass<'_, DRIVE> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        let (inv_h, inv_h2) = (L::splat(self.inv_h), L::splat(self.inv_h2));
        for block in self.blocks.iter_mut() {
            for start in (0..BLOCK_LANES).step_by(L::WIDTH) {
                solve_positions::<L, DRIVE>(block, start, self.rows, inv_h, inv_h2);
            }
        }
    }
}

#[inline(always)]
fn solve_positions<L: Lane, const DRIVE: bool>(
    block: &mut SocketBlock,
    start: usize,
    rows: &BodyRows,
    inv_h: L,
    inv_h2: L,
) {
    let (mut a, mut b) = block.bodies.gather::<L>(rows, start);
    let frame_a = block.frame_a.load::<L>(start);
    let frame_b = block.frame_b.load::<L>(start);

    if DRIVE {
        let lambda = block.drive_lambda.load::<L>(start);
        let d = drive_lanes(block, start);
        let lambda = drive::solve(&mut a, &mut b, frame_a, frame_b, &d, inv_h, inv_h2, lambda);
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

/// A driven lane's settings as the drive part reads them.
#[inline(always)]
fn drive_lanes<L: Lane>(block: &SocketBlock, start: usize) -> drive::Drive<L> {
    drive::Drive {
        target: block.drive_target.load(start),
        compliance: L::load(&block.drive_compliance[start..]),
        period2: L::load(&block.drive_period2[start..]),
        damping_time: L::load(&block.drive_damping_time[start..]),
        max_torque: L::load(&block.drive_max_torque[start..]),
        enabled: L::load(&block.drive_enabled[start..]),
        start: block.drive_start.load(start),
    }
}

/// The drives' substep start (before the bodies are predicted): each
/// error measured against the last substep's target, then the target
/// advanced by `h` at its angular velocity (`parts::drive`). Only driven
/// blocks need it.
pub struct StartPass<'a> {
    /// The blocks (one colour's, or the overflow set).
    pub blocks: &'a mut [SocketBlock],
    /// Body rows, read.
    pub rows: &'a BodyRows,
    /// The substep (s).
    pub h: f32,
}

impl LaneKernel for StartPass<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        let h = L::splat(self.h);
        for block in self.blocks.iter_mut() {
            for start in (0..BLOCK_LANES).step_by(L::WIDTH) {
                let (a, b) = block.bodies.gather::<L>(self.rows, start);
                let target = block.drive_target.load::<L>(start);
                let error = drive::start(
                    &a,
                    &b,
                    block.frame_a.load(start),
                    block.frame_b.load(start),
                    target,
                    L::load(&block.drive_enabled[start..]),
                );
                block.drive_start.store(start, error);
                let velocity = block.drive_velocity.load(start);
                block
                    .drive_target
                    .store(start, drive::advance(target, velocity, h));
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
