//! A joint's drive as rows of the direct solve, so that its frequency and
//! damping ratio hold for the limb it moves, children included.
//!
//! **Why rows of the tree.** Iterated as a part (`parts::drive`), a drive
//! given by frequency is a spring scaled by its own pair's effective
//! inertia `W^-1`: it moves its child body at the stated frequency, but
//! the bodies hanging below pull it back through their joints, so a limb
//! with children answers slower, and a damping ratio of 1 rings. Solved
//! with the tree's other rows, the drive's rows see the whole tree.
//!
//! **Frequency and ratio: each joint its own oscillator.** The drive
//! part's spring form leaves the error `C` of its row, after one
//! iteration from `C~`, at `C_1 (1 + g + s) = C~ + g C_0` with `s = (omega
//! h)^2` and `g = 2 zeta omega h`: the implicit Euler step of `C'' =
//! -omega^2 C - 2 zeta omega C'`, with no mass in it. The tree solve
//! reaches any target error exactly (to the linearisation), whatever the
//! masses that move with the joint: so each drive row is held as a hard
//! row at the target `T = (C~ + g C_0) / (1 + g + s)`, and every driven
//! joint's error follows its own oscillator at the stated frequency and
//! ratio, whatever it carries (as a computed-torque drive does in joint
//! space: its stiffness is the tree's joint-space mass times `omega^2`).
//! `C~` is the error without what the drive did this substep: the error
//! measured now less `delta`, the drive's own requested moves summed over
//! the substep's solves (`delta += T - C`, kept in `moved`). So a contact
//! or another part that moves the joint between solves moves it as a
//! spring lets it: the target follows by `1 / (1 + g + s)` of the push,
//! as the part's `alpha lambda` term makes it. In the stored numbers
//! (`period2 = 1 / omega^2`, `damping_time = 2 zeta / omega`):
//!
//! `T = (period2 (C - delta) + damping_time h C_0) / (period2 + damping_time h + h^2)`
//!
//! which is 0 for a rigid drive (both zero), with no division by zero.
//!
//! **Compliance and damping** (N m per radian: a spring of its own, not
//! scaled by any mass) make the row soft as a soft limit's
//! (`docs/direct.md`): `alpha~ = c / h^2`, `gamma = damping_time / h`,
//! `-alpha~ / (1 + gamma)` on the diagonal and `(C + alpha~ lambda +
//! gamma (C - C_0)) / (1 + gamma)` on the right.
//!
//! **Torque cap.** The rows' multipliers, summed over the substep's
//! solves (`lambda`, along a's axes), are the drive's angular impulse
//! times `h`: the torque is `lambda / h^2`. A cap bounds the multiplier,
//! and the bound is held as the limits' active set is: when a pass whose
//! pins have settled would take `|lambda + dlambda|` past `max_torque
//! h^2` (`DriveNode::settle`), its step is not taken; the drive is
//! capped for the rest of the substep at `cap = (lambda + dlambda)
//! max_torque h^2 / |lambda + dlambda|` and the tree is solved again (a
//! pass of its own, as a pin's crossing takes). In that pass and each
//! later solve the rows prescribe their step `cap - lambda` (a row of
//! compliance [`CAPPED_COMPLIANCE`] times its own inverse mass `w`, its
//! right-hand side `-CAPPED_COMPLIANCE w (cap - lambda)`: the row's
//! motion changes its step by a millionth), and the drive exerts its
//! capped torque. So an uncapped step, which may turn a limb into the
//! ground the contacts then push it out of (the push kept as speed),
//! never moves a body. A pass whose pins are still changing is no
//! measure of the drive (a pin about to let go holds a foot the drive
//! pushes against): it caps nothing, and the cap waits for the pins to
//! settle. Where their passes run out first, the cap is taken and the
//! tree's pins and limits start the solve again (`solve::restart`), with
//! as many passes again: the states the uncapped passes chose held what
//! the uncapped drive pushed. A cap found in a solve's very last pass is
//! taken after it: its step moves the bodies, the drive is capped after
//! it (`DriveNode::accumulate`), and the later solves take the excess
//! back. A hit beyond the cap turns the joint away, and the drive brings
//! it back afterwards.
//!
//! **Against a limit.** A drive pulling past a hard limit would ask of
//! its hard rows what the limit's row refuses (rows that repeat each
//! other, with other targets). So in a lane where a limit of the joint is
//! held, the drive's rows are soft instead: the part's own spring on its
//! pair's inverse mass `w`, `alpha~ = w period2 / h^2` (at least `w`: a
//! rigid drive as stiff as one step makes it) with its damping, as a soft
//! limit's rows are. The limit holds, and the drive pulls against it or
//! away from it with a spring's force; the limit lets go when the drive
//! pulls it inside. A soft limit is a spring the hard target rows
//! overrule.
//!
//! **Against pins.** A pin's normal is a stiff spring too, which a hard
//! row overrules: an uncapped drive turning a limb into the ground would
//! wind the pins up against it without bound. So in a lane whose tree
//! takes pins an uncapped drive's rows are soft in the same way. A capped
//! drive stays hard: its cap is the bound the pins settle against.

use bytemuck::{Pod, Zeroable};
use vertebra_math::block::BLOCK_LANES;
use vertebra_math::{Lane, Mask};

use super::rows::{Geometry, JointRows, MAX_DRIVE_ROWS, drive_axes};
use crate::body::BodyLanes;
use crate::driven::{DriveLane, DriveSettings};
use crate::parts::drive;

/// The compliance of a capped drive's row, in units of its own inverse
/// mass: large enough that the row's own motion moves its prescribed
/// step by a millionth, small enough that its pivot stays a number.
pub const CAPPED_COMPLIANCE: f32 = 1.0e6;

/// The largest `alpha~` (per kg m^2) a soft drive row carries: a row
/// that soft pulls by less than 1e-30 of its error, and an infinite one
/// (a compliance near `f32::MAX`) would make `alpha~ lambda` a NaN.
pub const MAX_ALPHA: f32 = 1.0e30;

/// Values the solve records of each drive row (a node scratch's `drive`):
/// its error `c`, its generalised inverse mass `w` and its target `T`.
pub const DRIVE_RECORD: usize = 3;

/// A tree joint's drive in each lane: its settings, copied as the joint
/// is laid out (the same piece the iterated drive holds), and the
/// substep's state of its rows.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct DriveNode {
    /// What the drive asks. Its target is this substep's (advanced by
    /// [`super::StartPass`] every substep, as the joint block's own copy
    /// is, bit for bit).
    pub settings: DriveSettings,
    /// Each row's error at the substep's start, `C_0` (rad).
    pub start: [[f32; BLOCK_LANES]; MAX_DRIVE_ROWS],
    /// Each row's multiplier summed over the substep's solves.
    pub lambda: [[f32; BLOCK_LANES]; MAX_DRIVE_ROWS],
    /// Each row's requested moves summed over the substep's solves,
    /// `delta` (rad).
    pub moved: [[f32; BLOCK_LANES]; MAX_DRIVE_ROWS],
    /// The capped multiplier the rows hold once capped.
    pub cap: [[f32; BLOCK_LANES]; MAX_DRIVE_ROWS],
    /// 1 where the drive reached its cap this substep.
    pub capped: [f32; BLOCK_LANES],
    /// Where the last settle found the drive past its cap (1), the cap
    /// it would hold: taken if the tree is solved again
    /// (`DriveNode::take`).
    pub capping: [f32; BLOCK_LANES],
    /// See [`Self::capping`].
    pub next_cap: [[f32; BLOCK_LANES]; MAX_DRIVE_ROWS],
}

impl DriveNode {
    /// Writes one joint's drive (or none) into `lane`.
    pub fn set(&mut self, lane: usize, drive: Option<&DriveLane>) {
        self.settings.set(lane, drive);
        for row in 0..MAX_DRIVE_ROWS {
            self.start[row][lane] = 0.0;
            self.lambda[row][lane] = 0.0;
            self.moved[row][lane] = 0.0;
            self.cap[row][lane] = 0.0;
            self.next_cap[row][lane] = 0.0;
        }
        self.capped[lane] = 0.0;
        self.capping[lane] = 0.0;
    }

    /// The drive's substep start for the lanes from `start`, before the
    /// bodies are predicted: each row's error against the last substep's
    /// target (`+0` where off, whatever else shares the block), the target
    /// advanced by `h` at its velocity, the sums reset.
    #[inline(always)]
    pub(super) fn start<L: Lane>(
        &mut self,
        kind: JointRows,
        (a, b): (&BodyLanes<L>, &BodyLanes<L>),
        g: &Geometry<L>,
        start: usize,
        h: f32,
    ) {
        let zero = L::splat(0.0);
        let target = self.settings.target.load::<L>(start);
        let enabled = L::load(&self.settings.enabled[start..]).gt(zero);
        let (c, _) = drive::measure_in_a(a, b, g.frame_a, g.frame_b, target);
        for (row, e) in drive_axes(kind, g.frame_a).into_iter().enumerate() {
            L::select(enabled, c.dot(e), zero).store(&mut self.start[row][start..]);
            zero.store(&mut self.lambda[row][start..]);
            zero.store(&mut self.moved[row][start..]);
            zero.store(&mut self.cap[row][start..]);
        }
        zero.store(&mut self.capped[start..]);
        zero.store(&mut self.capping[start..]);
        let velocity = self.settings.velocity.load(start);
        self.settings
            .target
            .store(start, drive::advance(target, velocity, L::splat(h)));
    }

    /// The lanes from `start` whose drive has no torque cap.
    #[inline(always)]
    pub(super) fn uncapped<L: Lane>(&self, start: usize) -> L::Mask {
        let max_torque = L::load(&self.settings.max_torque[start..]);
        max_torque.eq(L::splat(f32::INFINITY))
    }

    /// Row `row`'s diagonal entry and right-hand side for the lanes from
    /// `start` (see the module documentation), from its record `[c, w]`
    /// and the lanes where a limit of the joint is held; returns them and
    /// the target `T` to record (`C` where the row is soft: no move).
    #[inline(always)]
    pub(super) fn row<L: Lane>(
        &self,
        row: usize,
        (c, w, limited): (L, L, L::Mask),
        start: usize,
        (inv_h, inv_h2): (L, L),
    ) -> (L, L, L) {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let h = one / inv_h;
        let h2 = one / inv_h2;
        let compliance = L::load(&self.settings.compliance[start..]);
        let period2 = L::load(&self.settings.period2[start..]);
        let damping_time = L::load(&self.settings.damping_time[start..]);
        let c0 = L::load(&self.start[row][start..]);
        let lambda = L::load(&self.lambda[row][start..]);
        let moved = L::load(&self.moved[row][start..]);
        // The oscillator's target, a hard row's right-hand side `C - T`.
        let spring = damping_time * h;
        let target = (period2 * (c - moved) + spring * c0) / (period2 + spring + h2);
        // A soft row: a compliant drive's, or a drive's against a held
        // limit, on its own pair's inverse mass (at most a substep's
        // period: a rigid drive's as stiff as one step can make it).
        let compliant = compliance.gt(zero);
        let paired = w * (period2 * inv_h2).max(one);
        let alpha = L::select(compliant, compliance * inv_h2, paired).min(L::splat(MAX_ALPHA));
        let gamma = damping_time * inv_h;
        let inv = one / (one + gamma);
        let soft_b = (c + alpha * lambda + gamma * (c - c0)) * inv;
        let soft = compliant | limited;
        let (mut d, mut b) = (
            L::select(soft, -(alpha * inv), zero),
            L::select(soft, soft_b, c - target),
        );
        let target = L::select(soft, c, target);
        // A capped drive's prescribed step.
        let capped = L::load(&self.capped[start..]).gt(zero);
        let big = L::splat(CAPPED_COMPLIANCE) * w;
        let cap = L::load(&self.cap[row][start..]);
        d = L::select(capped, -big, d);
        b = L::select(capped, -(big * (cap - lambda)), b);
        (d, b, target)
    }

    /// Where the summed multipliers `sum` (each row's) pass the cap
    /// (`|sum| > max_torque h^2`) in a lane not yet capped, and the capped
    /// multipliers there (`sum` scaled onto the cap).
    #[inline(always)]
    fn over_cap<L: Lane>(
        &self,
        sum: &[L],
        start: usize,
        inv_h2: f32,
    ) -> (L::Mask, [L; MAX_DRIVE_ROWS]) {
        let zero = L::splat(0.0);
        let mut squared = zero;
        for &x in sum {
            squared += x * x;
        }
        let limit = L::load(&self.settings.max_torque[start..]) / L::splat(inv_h2);
        let was = L::load(&self.capped[start..]).gt(zero);
        let caps = squared.gt(limit * limit).and_not(was);
        let scale = limit / L::select(caps, squared.sqrt(), L::splat(1.0));
        let mut capped = [zero; MAX_DRIVE_ROWS];
        for (out, &x) in capped.iter_mut().zip(sum) {
            // An overflowing sum (`squared` infinite) caps at zero, not at
            // `inf * 0`.
            let c = x * scale;
            *out = L::select(c.eq(c), c, zero);
        }
        (caps, capped)
    }

    /// After a pass, for the lanes from `start` not yet capped: whether
    /// the pass's multiplier steps `dlambda` take the drive past its cap;
    /// where they do, the cap it would hold is kept in `next_cap` and the
    /// lane marked in `capping`, for [`Self::take`]. Returns the marked
    /// lanes.
    #[inline(always)]
    pub(super) fn settle<L: Lane>(&mut self, dlambda: &[L], start: usize, inv_h2: f32) -> L::Mask {
        let zero = L::splat(0.0);
        let enabled = L::load(&self.settings.enabled[start..]).gt(zero);
        let mut sum = [zero; MAX_DRIVE_ROWS];
        for (row, &step) in dlambda.iter().enumerate() {
            sum[row] = L::select(enabled, L::load(&self.lambda[row][start..]) + step, zero);
        }
        let (caps, capped) = self.over_cap(&sum[..dlambda.len()], start, inv_h2);
        for (row, &c) in capped.iter().enumerate().take(dlambda.len()) {
            L::select(caps, c, zero).store(&mut self.next_cap[row][start..]);
        }
        L::select(caps, L::splat(1.0), zero).store(&mut self.capping[start..]);
        caps
    }

    /// Before the tree is solved again: the cap the last settle found in
    /// `lane`, held from now on. Returns whether there was one.
    pub(super) fn take(&mut self, lane: usize) -> bool {
        if self.capping[lane] == 0.0 {
            return false;
        }
        self.capped[lane] = 1.0;
        for row in 0..MAX_DRIVE_ROWS {
            self.cap[row][lane] = self.next_cap[row][lane];
        }
        true
    }

    /// After a solve, for the lanes from `start`: each row's multiplier
    /// step `dlambda` and, for the oscillator, its requested move `T - C`
    /// (`records`: each row's `[c, w, T]`) added to the substep's sums;
    /// and a drive whose summed torque passed `max_torque` (its solve's
    /// passes spent before its cap was taken) capped there for the rest of
    /// the substep.
    #[inline(always)]
    pub(super) fn accumulate<L: Lane>(
        &mut self,
        dlambda: &[L],
        records: &[[L; DRIVE_RECORD]],
        start: usize,
        inv_h2: f32,
    ) {
        let zero = L::splat(0.0);
        let enabled = L::load(&self.settings.enabled[start..]).gt(zero);
        let mut lambda = [zero; MAX_DRIVE_ROWS];
        for (row, &[c, _, target]) in records.iter().enumerate() {
            let sum = L::load(&self.lambda[row][start..]) + dlambda[row];
            let moved = L::load(&self.moved[row][start..]) + (target - c);
            lambda[row] = L::select(enabled, sum, zero);
            lambda[row].store(&mut self.lambda[row][start..]);
            L::select(enabled, moved, zero).store(&mut self.moved[row][start..]);
        }
        let rows = records.len();
        let (caps, capped) = self.over_cap(&lambda[..rows], start, inv_h2);
        for (row, &c) in capped.iter().enumerate().take(rows) {
            let cap = L::load(&self.cap[row][start..]);
            L::select(caps, c, cap).store(&mut self.cap[row][start..]);
        }
        let was = L::load(&self.capped[start..]).gt(zero);
        L::select(caps | was, L::splat(1.0), zero).store(&mut self.capped[start..]);
    }
}
