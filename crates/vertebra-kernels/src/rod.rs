//! The rod constraint (Lewin et al., sections 5-7): an inextensible
//! Kirchhoff rod between the centres of mass of two bodies, held to a
//! circular arc, with soft bending and twisting and hard limits, solved in
//! one lane-generic kernel that shares the frames' measurement between its
//! parts (paper section 7).
//!
//! The soft bend and twist are drives (`parts::rod::drive`): damped
//! against their error as the substep began ([`Starts`]), optionally
//! given by frequency, and capped at a torque. Their rest shape may move:
//! [`Starts`] advances it every substep at its rates, as the drives'
//! start pass advances their targets (`driven.rs`).
//!
//! Part order per iteration: soft bend, soft twist, bend limit, twist
//! limit, curve, length. The hard geometric parts come last so that the arc
//! is closest to admissible at the end of an iteration; the length last of
//! all, because the curve changes `psi` and so the chord the length aims at.

use bytemuck::{Pod, Zeroable};
use glam::{Quat as GQuat, Vec3 as GVec3};
use vertebra_math::Lane;
use vertebra_math::block::{BLOCK_LANES, QuatBlock, Vec3Block};

use crate::body::{BodyPairs, BodyRows, LaneBlock, PairLane};
use crate::parts::angle::Softness;
use crate::parts::axis_x;
use crate::parts::rod::drive::{self, Drive};
use crate::parts::rod::{LocalFrames, bend, curve, frames, length, twist, world_tangents};
use crate::pass::{BlockKernel, SubstepScale};
use crate::residual::{Measured, Residual};

/// Eight rods, field by field.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct RodBlock {
    /// The two bodies of each lane.
    pub bodies: BodyPairs,
    /// `F_a`: the material frame at a, in a's body frame (+X: tangent).
    pub frame_a: QuatBlock,
    /// `F_b`: the material frame at b, in b's body frame.
    pub frame_b: QuatBlock,
    /// Rest bend direction of `t_b`, in a's material frame (unit): the
    /// current substep's ([`Starts`] advances it).
    pub bend_rest: Vec3Block,
    /// Rest length `l0` (m).
    pub rest_length: [f32; BLOCK_LANES],
    /// Rest twist (rad): the current substep's ([`Starts`] advances
    /// it).
    pub twist_rest: [f32; BLOCK_LANES],
    /// The rest direction's angular velocity (rad/s, a's material frame):
    /// [`Starts`] turns `bend_rest` by it every substep.
    pub bend_rest_velocity: Vec3Block,
    /// The rest twist's rate (rad/s): [`Starts`] advances `twist_rest`
    /// by it every substep.
    pub twist_rest_velocity: [f32; BLOCK_LANES],
    /// Bending compliance `l0 / k_b` (rad / (N m)).
    pub bend_compliance: [f32; BLOCK_LANES],
    /// Twisting compliance `l0 / k_t` (rad / (N m)).
    pub twist_compliance: [f32; BLOCK_LANES],
    /// Bending compliance per unit effective inverse inertia, `1 / omega^2`
    /// (s^2), for bending given by frequency.
    pub bend_period2: [f32; BLOCK_LANES],
    /// Twisting's `1 / omega^2` (s^2).
    pub twist_period2: [f32; BLOCK_LANES],
    /// Bending damping `gamma h` (s).
    pub bend_damping_time: [f32; BLOCK_LANES],
    /// Twisting damping `gamma h` (s).
    pub twist_damping_time: [f32; BLOCK_LANES],
    /// The largest torque of bending and of twisting (N m), infinity for
    /// none.
    pub max_torque: [f32; BLOCK_LANES],
    /// Bending relaxation factor (1 for XPBD, 0 for none).
    pub bend_relaxation: [f32; BLOCK_LANES],
    /// Twisting relaxation factor (1 for XPBD, 0 for none).
    pub twist_relaxation: [f32; BLOCK_LANES],
    /// Largest bend angle (rad); pi disables the limit.
    pub bend_max: [f32; BLOCK_LANES],
    /// Lowest twist (rad).
    pub twist_min: [f32; BLOCK_LANES],
    /// Highest twist (rad).
    pub twist_max: [f32; BLOCK_LANES],
    /// Bending's accumulated multiplier, reset every substep.
    pub bend_lambda: [f32; BLOCK_LANES],
    /// Twisting's accumulated multiplier, reset every substep.
    pub twist_lambda: [f32; BLOCK_LANES],
    /// The bend error `C n` as the substep began (rad, a's body frame, as
    /// the position pass measures it), measured by [`Starts`].
    pub bend_start: Vec3Block,
    /// The twist error as the substep began (rad), measured by
    /// [`Starts`].
    pub twist_start: [f32; BLOCK_LANES],
}

/// How a soft part is set: XPBD compliance, or the paper's relaxation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RodSoftness {
    /// XPBD compliance (rad / (N m)); independent of step and iterations.
    Compliance(f32),
    /// The fraction of the error removed per iteration, in [0, 1] (the
    /// paper's relaxation factor); 0 turns the part off.
    Relaxation(f32),
    /// XPBD compliance (rad / (N m)) with damping, `gamma h` (s): compliance
    /// times the damping coefficient.
    Damped {
        /// Compliance (rad / (N m)).
        compliance: f32,
        /// `gamma h` (s).
        damping_time: f32,
    },
    /// A damped spring on the part's effective inertia
    /// (`parts::rod::drive`).
    Spring {
        /// `1 / omega^2` (s^2).
        period2: f32,
        /// `gamma h = 2 zeta / omega` (s).
        damping_time: f32,
    },
}

impl RodSoftness {
    /// (compliance, relaxation, period2, damping time) as the kernel reads
    /// them.
    pub fn lanes(self) -> [f32; 4] {
        match self {
            RodSoftness::Compliance(c) => [c, 1.0, 0.0, 0.0],
            RodSoftness::Relaxation(r) => [0.0, r, 0.0, 0.0],
            RodSoftness::Damped {
                compliance,
                damping_time,
            } => [compliance, 1.0, 0.0, damping_time],
            RodSoftness::Spring {
                period2,
                damping_time,
            } => [0.0, 1.0, period2, damping_time],
        }
    }
}

/// One rod's solver data (one lane of a block).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RodLane {
    /// The two bodies.
    pub pair: PairLane,
    /// Material frame at a (a's body frame).
    pub frame_a: GQuat,
    /// Material frame at b (b's body frame).
    pub frame_b: GQuat,
    /// Rest length (m).
    pub rest_length: f32,
    /// Rest bend direction of `t_b` in a's material frame (unit).
    pub bend_rest: GVec3,
    /// Rest twist (rad).
    pub twist_rest: f32,
    /// The rest direction's angular velocity (rad/s, a's material frame);
    /// only its part perpendicular to `bend_rest` moves it.
    pub bend_rest_velocity: GVec3,
    /// The rest twist's rate (rad/s).
    pub twist_rest_velocity: f32,
    /// Bending softness.
    pub bend: RodSoftness,
    /// Twisting softness.
    pub twist: RodSoftness,
    /// Largest bend (rad), pi when unlimited.
    pub bend_max: f32,
    /// Twist range (rad), `[-pi, pi]` when unlimited.
    pub twist_range: [f32; 2],
    /// The largest torque of bending and of twisting (N m), infinity for
    /// none.
    pub max_torque: f32,
}

impl LaneBlock for RodBlock {
    type Lane = RodLane;
    const PADDING: RodLane = RodLane {
        pair: PairLane::NULL,
        frame_a: GQuat::IDENTITY,
        frame_b: GQuat::IDENTITY,
        rest_length: 0.0,
        bend_rest: GVec3::X,
        twist_rest: 0.0,
        bend_rest_velocity: GVec3::ZERO,
        twist_rest_velocity: 0.0,
        bend: RodSoftness::Relaxation(0.0),
        twist: RodSoftness::Relaxation(0.0),
        bend_max: core::f32::consts::PI,
        twist_range: [-core::f32::consts::PI, core::f32::consts::PI],
        max_torque: f32::INFINITY,
    };

    /// Writes one rod into `lane`.
    fn set(&mut self, lane: usize, r: &RodLane) {
        self.bodies.set(lane, &r.pair);
        self.frame_a.set(lane, r.frame_a);
        self.frame_b.set(lane, r.frame_b);
        self.bend_rest.set(lane, r.bend_rest);
        self.rest_length[lane] = r.rest_length;
        self.twist_rest[lane] = r.twist_rest;
        self.bend_rest_velocity.set(lane, r.bend_rest_velocity);
        self.twist_rest_velocity[lane] = r.twist_rest_velocity;
        [
            self.bend_compliance[lane],
            self.bend_relaxation[lane],
            self.bend_period2[lane],
            self.bend_damping_time[lane],
        ] = r.bend.lanes();
        [
            self.twist_compliance[lane],
            self.twist_relaxation[lane],
            self.twist_period2[lane],
            self.twist_damping_time[lane],
        ] = r.twist.lanes();
        self.max_torque[lane] = r.max_torque;
        self.bend_max[lane] = r.bend_max;
        (self.twist_min[lane], self.twist_max[lane]) = (r.twist_range[0], r.twist_range[1]);
        self.bend_lambda[lane] = 0.0;
        self.twist_lambda[lane] = 0.0;
        self.bend_start.set(lane, GVec3::ZERO);
        self.twist_start[lane] = 0.0;
    }
}

impl RodBlock {
    /// Resets the soft parts' multipliers (every substep).
    pub fn reset_lambdas(&mut self) {
        self.bend_lambda = [0.0; BLOCK_LANES];
        self.twist_lambda = [0.0; BLOCK_LANES];
    }
}

/// One XPBD iteration of rods (a [`BlockPass`](crate::pass::BlockPass)
/// over [`RodBlock`]s).
pub struct Positions;

impl BlockKernel for Positions {
    type Block = RodBlock;
    type Params = SubstepScale;
    #[inline(always)]
    fn padding(block: &RodBlock) -> u32 {
        block.bodies.padding
    }
    #[inline(always)]
    fn solve<L: Lane>(block: &mut RodBlock, start: usize, rows: &BodyRows, s: SubstepScale) {
        let (inv_h, inv_h2) = (L::splat(s.inv_h), L::splat(s.inv_h2));
        solve_positions(block, start, rows, inv_h, inv_h2);
    }
}

/// The rods' substep start (a [`BlockPass`](crate::pass::BlockPass) over
/// [`RodBlock`]s, its parameter the substep `h`, s): the soft parts'
/// errors as the substep begins, before the bodies move, against the last
/// substep's rest shape; then the rest shape advanced by `h` at its rates
/// (every substep, for the damping's rate relative to the rest's:
/// `parts::rod::drive`, "Moving rest").
pub struct Starts;

impl BlockKernel for Starts {
    type Block = RodBlock;
    type Params = f32;
    #[inline(always)]
    fn padding(block: &RodBlock) -> u32 {
        block.bodies.padding
    }
    #[inline(always)]
    fn solve<L: Lane>(block: &mut RodBlock, start: usize, rows: &BodyRows, h: f32) {
        let h = L::splat(h);
        let (a, b) = block.bodies.gather::<L>(rows, start);
        let frame_a = block.frame_a.load(start);
        let m = LocalFrames::new(&a, &b, frame_a, block.frame_b.load(start), axis_x(frame_a));
        let bend_rest = block.bend_rest.load(start);
        block.bend_start.store(start, bend::start(&m.f, bend_rest));
        let twist_rest = L::load(&block.twist_rest[start..]);
        twist::signed_rest_violation(&m.f, twist_rest).store(&mut block.twist_start[start..]);
        let velocity = block.bend_rest_velocity.load(start);
        block
            .bend_rest
            .store(start, drive::advance_direction(bend_rest, velocity, h));
        let rate = L::load(&block.twist_rest_velocity[start..]);
        drive::advance_twist(twist_rest, rate, h).store(&mut block.twist_rest[start..]);
    }
}

/// One soft part's drive, per lane, for the substep `h`.
#[inline(always)]
fn soft<L: Lane>(lanes: [&[f32]; 5], inv_h: L, inv_h2: L) -> Drive<L> {
    let [compliance, relaxation, period2, damping_time, max_torque] = lanes;
    Drive {
        soft: Softness {
            alpha_tilde: L::load(compliance) * inv_h2,
            relaxation: L::load(relaxation),
        },
        spring: L::load(period2) * inv_h2,
        gamma: L::load(damping_time) * inv_h,
        limit: L::load(max_torque) / inv_h2,
    }
}

#[inline(always)]
fn solve_positions<L: Lane>(
    block: &mut RodBlock,
    start: usize,
    rows: &BodyRows,
    inv_h: L,
    inv_h2: L,
) {
    let (mut a, mut b) = block.bodies.gather::<L>(rows, start);
    let (frame_a, frame_b) = (
        block.frame_a.load::<L>(start),
        block.frame_b.load::<L>(start),
    );

    let rest_length = L::load(&block.rest_length[start..]);
    let bend_drive = soft(
        [
            &block.bend_compliance[start..],
            &block.bend_relaxation[start..],
            &block.bend_period2[start..],
            &block.bend_damping_time[start..],
            &block.max_torque[start..],
        ],
        inv_h,
        inv_h2,
    );
    let (ta, tb) = (axis_x(frame_a), axis_x(frame_b));
    let frames = (frame_a, frame_b);
    let m = LocalFrames::tangents(&a, &b, frames, (ta, tb));
    let lambda = L::load(&block.bend_lambda[start..]);
    let lambda = bend::solve(
        &mut a,
        &mut b,
        &m,
        block.bend_rest.load(start),
        rest_length,
        &bend_drive,
        block.bend_start.load(start),
        lambda,
    );
    lambda.store(&mut block.bend_lambda[start..]);

    let twist_drive = soft(
        [
            &block.twist_compliance[start..],
            &block.twist_relaxation[start..],
            &block.twist_period2[start..],
            &block.twist_damping_time[start..],
            &block.max_torque[start..],
        ],
        inv_h,
        inv_h2,
    );
    let m = LocalFrames::new(&a, &b, frame_a, frame_b, ta);
    let lambda = L::load(&block.twist_lambda[start..]);
    let rest = L::load(&block.twist_rest[start..]);
    let start_twist = L::load(&block.twist_start[start..]);
    let lambda = twist::solve(&mut a, &mut b, &m, rest, &twist_drive, start_twist, lambda);
    lambda.store(&mut block.twist_lambda[start..]);

    // A block whose rods the direct solve holds leaves it their limits,
    // curve and length: only the soft bend and twist are iterated. The
    // curve moves the bodies along a world gradient: its frames are the
    // world's. The length needs only the bend angle.
    if block.bodies.direct == 0 {
        let m = LocalFrames::tangents(&a, &b, frames, (ta, tb));
        bend::limit(&mut a, &mut b, &m, L::load(&block.bend_max[start..]));
        let m = LocalFrames::new(&a, &b, frame_a, frame_b, ta);
        let (lo, hi) = (
            L::load(&block.twist_min[start..]),
            L::load(&block.twist_max[start..]),
        );
        twist::limit(&mut a, &mut b, &m, lo, hi);
        let chord = block.bodies.start(start);
        let f = world_tangents(&a, &b, frames, (ta, tb));
        curve::solve(&mut a, &mut b, &f, &chord);
        let m = LocalFrames::tangents(&a, &b, frames, (ta, tb));
        length::solve(&mut a, &mut b, &m.f, rest_length, &chord);
    }

    block.bodies.scatter(rows, start, &a, &b);
}

/// A rod's residual error, as the design brief defines it: linear
/// `|C_len|` (m), angular the curve error (the angle between `t_b` and the
/// reflection of `t_a`) plus limit overshoot (rad).
impl Residual for RodBlock {
    #[inline(always)]
    fn residual<L: Lane>(&self, rows: &BodyRows, start: usize) -> Measured<L> {
        let (a, b) = self.bodies.gather::<L>(rows, start);
        let f = frames(
            &a,
            &b,
            self.frame_a.load::<L>(start),
            self.frame_b.load::<L>(start),
        );
        let chord = self.bodies.start(start);
        let rest_length = L::load(&self.rest_length[start..]);
        let (_, c_len) = length::measure(&a, &b, &f, rest_length, &chord);
        let c_curve = curve::measure(&a, &b, &f, &chord).theta;
        let (_, bend_over) = bend::violation(&f, L::load(&self.bend_max[start..]));
        let (lo, hi) = (
            L::load(&self.twist_min[start..]),
            L::load(&self.twist_max[start..]),
        );
        let twist_over = crate::parts::twist::signed_violation(twist::measure(&f), lo, hi).abs();
        Measured {
            linear: c_len.abs(),
            angular: c_curve + bend_over + twist_over,
            limit: bend_over + twist_over,
        }
    }
}
