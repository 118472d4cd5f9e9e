//! The angular drive as a block of eight lanes, embedded by every joint
//! block that can be driven (sockets and hinges), and the drives' substep
//! start ([`Starts`]) written once for all of them. The drive's physics
//! is `parts::drive`.

use core::marker::PhantomData;

use bytemuck::{Pod, Zeroable};
use glam::{Quat as GQuat, Vec3 as GVec3};
use vertebra_math::block::{BLOCK_LANES, QuatBlock, Vec3Block};
use vertebra_math::{Lane, Quat};

use crate::body::{BodyLanes, BodyPairs, BodyRows};
use crate::parts::drive;
use crate::pass::BlockKernel;

/// Eight drives' settings, field by field: what a drive asks, held alike
/// by the iterated drive ([`DriveBlock`]) and by a tree joint's drive
/// rows in the direct solve (`direct::drive`), each beside its own
/// substep state.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct DriveSettings {
    /// Target of the current substep: b's joint frame relative to a's
    /// (advanced every substep by the drive's start: [`Starts`], or the
    /// direct solve's start pass).
    pub target: QuatBlock,
    /// Target angular velocity (rad/s, a's joint frame).
    pub velocity: Vec3Block,
    /// Compliance (rad / (N m)); 0 with `period2 = 0` is infinitely stiff.
    pub compliance: [f32; BLOCK_LANES],
    /// Compliance per unit effective inverse inertia, `1 / omega^2` (s^2),
    /// for drives given by frequency.
    pub period2: [f32; BLOCK_LANES],
    /// Damping `gamma h` (s): compliance times damping, or `2 zeta / omega`.
    pub damping_time: [f32; BLOCK_LANES],
    /// Torque limit (N m), infinity for none.
    pub max_torque: [f32; BLOCK_LANES],
    /// 1 where the drive is on, 0 where off.
    pub enabled: [f32; BLOCK_LANES],
}

impl DriveSettings {
    /// Writes one joint's drive (or none) into `lane`.
    pub fn set(&mut self, lane: usize, drive: Option<&DriveLane>) {
        let d = drive.copied().unwrap_or(DriveLane::OFF);
        self.target.set(lane, d.target);
        self.velocity.set(lane, d.velocity);
        self.compliance[lane] = d.compliance;
        self.period2[lane] = d.period2;
        self.damping_time[lane] = d.damping_time;
        self.max_torque[lane] = d.max_torque;
        self.enabled[lane] = if drive.is_some() { 1.0 } else { 0.0 };
    }
}

/// Eight iterated drives: their settings and their XPBD state.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct DriveBlock {
    /// What the drives ask.
    pub settings: DriveSettings,
    /// The accumulated XPBD multiplier (world vector), reset every substep.
    pub lambda: Vec3Block,
    /// The error at the substep's start (rad, world), measured by
    /// [`Starts`].
    pub start: Vec3Block,
}

/// One joint's drive as the kernel holds it (see `parts::drive`).
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
    /// What an undriven lane holds: nothing that pulls.
    pub const OFF: Self = Self {
        target: GQuat::IDENTITY,
        velocity: GVec3::ZERO,
        compliance: 0.0,
        period2: 0.0,
        damping_time: 0.0,
        max_torque: f32::INFINITY,
    };
}

impl DriveBlock {
    /// Writes one joint's drive (or none) into `lane`.
    pub fn set(&mut self, lane: usize, drive: Option<&DriveLane>) {
        self.settings.set(lane, drive);
        self.lambda.set(lane, GVec3::ZERO);
        self.start.set(lane, GVec3::ZERO);
    }

    /// The lanes from `start` as the drive part reads them.
    #[inline(always)]
    fn lanes<L: Lane>(&self, start: usize) -> drive::Drive<L> {
        let s = &self.settings;
        drive::Drive {
            target: s.target.load(start),
            compliance: L::load(&s.compliance[start..]),
            period2: L::load(&s.period2[start..]),
            damping_time: L::load(&s.damping_time[start..]),
            max_torque: L::load(&s.max_torque[start..]),
            enabled: L::load(&s.enabled[start..]),
            start: self.start.load(start),
        }
    }

    /// One XPBD iteration of the lanes from `start` on bodies `a` and `b`
    /// with joint frames `frame_a`, `frame_b`; `1 / h` and `1 / h^2` of the
    /// substep `h`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn solve<L: Lane>(
        &mut self,
        start: usize,
        a: &mut BodyLanes<L>,
        b: &mut BodyLanes<L>,
        frame_a: Quat<L>,
        frame_b: Quat<L>,
        inv_h: L,
        inv_h2: L,
    ) {
        let lambda = self.lambda.load::<L>(start);
        let d = self.lanes(start);
        let lambda = drive::solve(a, b, frame_a, frame_b, &d, inv_h, inv_h2, lambda);
        self.lambda.store(start, lambda);
    }
}

/// A block of joints that embeds drives: what [`Starts`] needs of it.
pub trait Driven {
    /// The lanes' bodies.
    fn bodies(&self) -> &BodyPairs;
    /// The lanes' joint frames from `start`, in a's and b's body frames.
    fn frames<L: Lane>(&self, start: usize) -> (Quat<L>, Quat<L>);
    /// The lanes' drives.
    fn drive_mut(&mut self) -> &mut DriveBlock;
}

/// The drives' substep start (before the bodies are predicted; a
/// [`BlockPass`](crate::pass::BlockPass) over `B`s, its parameter the
/// substep `h`, s): each error measured against the last substep's
/// target, then the target advanced by `h` at its angular velocity
/// (`parts::drive`). Only driven blocks need it.
pub struct Starts<B>(PhantomData<fn() -> B>);

impl<B: Driven> BlockKernel for Starts<B> {
    type Block = B;
    type Params = f32;
    #[inline(always)]
    fn padding(block: &B) -> u32 {
        block.bodies().padding
    }
    #[inline(always)]
    fn solve<L: Lane>(block: &mut B, start: usize, rows: &BodyRows, h: f32) {
        let (a, b) = block.bodies().gather::<L>(rows, start);
        let (frame_a, frame_b) = block.frames::<L>(start);
        let d = block.drive_mut();
        let target = d.settings.target.load::<L>(start);
        let enabled = L::load(&d.settings.enabled[start..]);
        let error = drive::start(&a, &b, frame_a, frame_b, target, enabled);
        d.start.store(start, error);
        let velocity = d.settings.velocity.load(start);
        d.settings
            .target
            .store(start, drive::advance(target, velocity, L::splat(h)));
    }
}
