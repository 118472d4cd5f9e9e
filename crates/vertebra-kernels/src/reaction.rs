//! What a joint did to its bodies over a step: the sum of its positional
//! impulses and the sum of its turns of one body, from which the world
//! reads the joint's force and torque (and breaks a joint past its
//! thresholds). The solve never reads them: recording changes no bit.
//!
//! Every part of a joint moves its bodies by positional impulses: a
//! push `P` at the lever arm `r` moves a body by `P / m` and turns it by
//! `I^-1 (r x P)`, an angular correction `L` turns it by `I^-1 L`. So
//! between a lane's gather and its scatter, the change of the body the
//! joint moves (`b`, or `a` when `b` does not move: a joint to a static or
//! kinematic body) is the joint's whole impulse on it: `P = m dp` exactly,
//! and the angular impulse about its centre of mass `I dtheta` with
//! `dtheta = 2 vec(q' q*)` (to first order in the turn, as the parts turn
//! it). Measuring the motion, not each part, covers every part (points,
//! limits, axes, locks, drives) in one place per kernel. The inertia is
//! applied by the world, once per step (`I` is not in the rows).

use bytemuck::{Pod, Zeroable};
use glam::Vec3 as GVec3;
use vertebra_math::block::Vec3Block;
use vertebra_math::{Lane, Quat, Vec3};

use crate::body::{BodyLanes, safe_ratio};

/// Eight joints' records over the current step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct ReactionBlock {
    /// The positional impulses on `b` (kg m, world), summed over the
    /// step's substeps and iterations; for a `b` that does not move, the
    /// opposite of those on `a`.
    pub impulse: Vec3Block,
    /// The turns of the measured body (`b`, or `a` when `b` does not move;
    /// rad, world), summed likewise.
    pub turn: Vec3Block,
}

impl ReactionBlock {
    /// Zeroes the record, as a step begins.
    pub fn reset(&mut self) {
        *self = Self::zeroed();
    }

    /// `lane`'s record: the impulse on `b` (kg m) and the measured body's
    /// turn (rad), both world.
    pub fn get(&self, lane: usize) -> (GVec3, GVec3) {
        (self.impulse.get(lane), self.turn.get(lane))
    }

    /// Adds what the lanes' parts did between `before` and `after` (each
    /// `(a, b)`), lanes `start..`.
    #[inline(always)]
    pub fn record<L: Lane>(
        &mut self,
        start: usize,
        before: (&BodyLanes<L>, &BodyLanes<L>),
        after: (&BodyLanes<L>, &BodyLanes<L>),
    ) {
        let moves_b = after.1.inv_mass.gt(L::splat(0.0));
        let (from, to) = (Pose::of(moves_b, before), Pose::of(moves_b, after));
        let (p, turn) = moved(&from, &to);
        let impulse = Vec3::select(moves_b, p, -p);
        let sum = self.impulse.load::<L>(start) + impulse;
        self.impulse.store(start, sum);
        let sum = self.turn.load::<L>(start) + turn;
        self.turn.store(start, sum);
    }
}

/// The measured body's pose, per lane: `b`'s where it moves, else `a`'s.
struct Pose<L: Lane> {
    p: Vec3<L>,
    q: Quat<L>,
    inv_mass: L,
}

impl<L: Lane> Pose<L> {
    /// `b`'s pose in the lanes of `moves_b`, `a`'s in the others.
    #[inline(always)]
    fn of(moves_b: L::Mask, (a, b): (&BodyLanes<L>, &BodyLanes<L>)) -> Self {
        Self {
            p: Vec3::select(moves_b, b.p, a.p),
            q: Quat::select(moves_b, b.q, a.q),
            inv_mass: L::select(moves_b, b.inv_mass, a.inv_mass),
        }
    }
}

/// A body's change between two poses as a positional impulse (`m dp`, kg
/// m; 0 for a body that does not move) and a world turn (`2 vec(q'
/// q*)`, rad, the shorter way).
#[inline(always)]
fn moved<L: Lane>(from: &Pose<L>, to: &Pose<L>) -> (Vec3<L>, Vec3<L>) {
    let dp = to.p - from.p;
    let impulse = Vec3::new(
        safe_ratio(dp.x, to.inv_mass),
        safe_ratio(dp.y, to.inv_mass),
        safe_ratio(dp.z, to.inv_mass),
    );
    let dq = to.q * from.q.conjugate();
    (impulse, dq.vector().scale(L::splat(2.0).copysign(dq.w)))
}

/// The mean force (N) and torque (N m) over a step of `dt` seconds in
/// substeps of `h`, on `b`, about the joint's anchor, from a lane's
/// positional impulse `P` and the measured body's angular impulse
/// `I dtheta` (`angular`: its turn through its world inertia), its
/// anchor's lever arm `arm`: `F = P / (h dt)`, and the part of `I dtheta`
/// that is not the force's moment, `tau = I dtheta - r x P` on `b`, or
/// its opposite for `a` (`measured_b` false: `P` is then the opposite of
/// `a`'s).
pub fn force_and_torque(
    (impulse, angular): (GVec3, GVec3),
    arm: GVec3,
    measured_b: bool,
    (h, dt): (f32, f32),
) -> (GVec3, GVec3) {
    let scale = 1.0 / (h * dt);
    let torque = if measured_b {
        angular - arm.cross(impulse)
    } else {
        // a took -P at its arm: I_a dtheta_a = -tau + r_a x (-P).
        -(angular + arm.cross(impulse))
    };
    (impulse * scale, torque * scale)
}
