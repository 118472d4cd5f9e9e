//! Contacts (Müller et al. 2020, sec. 3.5): non-penetration and static
//! friction at the position level, dynamic friction and restitution at the
//! velocity level, one lane-generic kernel each, bit for bit like the
//! joints.
//!
//! A contact holds a point on each body (body frames) and a world normal
//! `n` from a to b, fixed for the step. With `r_a = q_a c_a`, `r_b = q_b c_b`
//! and the world points `p_a + r_a`, `p_b + r_b`:
//!
//! - **Non-penetration** (hard, one-sided): the separation along the normal
//!   `s = ((p_b + r_b) - (p_a + r_a)) . n` must not be negative:
//!   `C = min(s, 0)`, gradient `n` at `r_b` and `-n` at `r_a`, generalised
//!   masses `1/m + (r x n)^T I^-1 (r x n)`. `lambda_n` accumulates over a
//!   substep's iterations (the normal force is `lambda_n / h^2`). An
//!   overlap `o` the contact was made with is removed evenly over the
//!   step's `S` substeps: substep `k` solves `C = min(s + o (S - 1 - k) / S,
//!   0)`, so the bodies come out at `o / dt` whatever `S` (removed in the
//!   first substep they came out at `o / h`, and a substepped pile of
//!   ragdolls never came to rest).
//! - **Static friction** (inside the cone): the points were one point when
//!   the contact was made, so their tangential offset `d_t = d - (d . n) n`
//!   (`d` their difference) is how far the bodies slid. It is removed along
//!   `t = d_t / |d_t|`, with the accumulated tangential multiplier (a
//!   vector in the tangent plane) clamped to `|lambda_t| <= mu lambda_n`. Müller et al. apply the whole
//!   correction or none; solved point by point, a box corner's normal and
//!   tangential generalised masses differ (`w_n > w_t`), so all-or-nothing
//!   lets a box creep down a slope well below `atan(mu)`. Beyond the cone
//!   the contact slides, and dynamic friction acts at the velocity level.
//! - **Dynamic friction**: an impulse against the tangential relative
//!   velocity `v_t` of `min((mu lambda_n - |lambda_t|) / h, |v_t| / w_t)`:
//!   what is left of Coulomb's bound after the position level's friction
//!   (`lambda / h` is an impulse), or what stops the sliding.
//!   (Müller eq. 31 writes `min(h mu |f_n|, |v_t|)`, comparing an impulse
//!   with a speed; the generalised mass `w_t` puts them in one unit.)
//! - **Restitution**: the normal relative velocity is raised to
//!   `max(-e v_approach, 0)` (never lowered: a contact pushes, it does not
//!   pull), where `v_approach` is its value when the contact was made; below
//!   `2 |g| h` of approach the target is 0, so resting contacts do not
//!   jitter (Müller eq. 34).
//! - **Relax** (a setting: [`Velocities`] with `relax`, run a few times after the
//!   velocity pass): the normal relative velocity is brought to the same
//!   target from either side, with an accumulated impulse
//!   `lambda_v >= -lambda_n / h`: it may take back at most the impulse
//!   the contact's own push-out gave this substep. The position level's
//!   push-out, `depth / h` as speed, is then not kept: a body pressed into
//!   the ground by a joint, a limit or a drive and pushed back out does not
//!   fly up from it, and a pile comes to rest. It is Box2D v3's relax stage
//!   (solve with the push-out, then relax without it), and Müller et al.'s
//!   eq. 34 where it sets the normal velocity rather than raising it;
//!   iterated with the accumulated bound (as an impulse solver clamps its
//!   total impulse), the contacts of one body share the taking back, where
//!   one pass of each in turn leaves a box pushed out on four corners
//!   spinning.

use bytemuck::{Pod, Zeroable};
use glam::Vec3 as GVec3;
use vertebra_math::block::{BLOCK_LANES, Vec3Block};
use vertebra_math::{Lane, Vec3};

use crate::body::{
    BodyLanes, BodyPairs, BodyRows, LaneBlock, PairLane, StartLane, VelocityLanes, safe_ratio,
};
use crate::parts::point;
use crate::pass::BlockKernel;

/// Eight contacts, field by field.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct ContactBlock {
    /// The two bodies of each lane.
    pub bodies: BodyPairs,
    /// Contact point on a (m, a's body frame).
    pub point_a: Vec3Block,
    /// Contact point on b (m, b's body frame).
    pub point_b: Vec3Block,
    /// Normal from a to b (world, unit).
    pub normal: Vec3Block,
    /// Friction coefficient (static and dynamic).
    pub friction: [f32; BLOCK_LANES],
    /// Coefficient of restitution in [0, 1].
    pub restitution: [f32; BLOCK_LANES],
    /// Normal relative velocity of b to a when the contact was made (m/s;
    /// negative when approaching).
    pub approach: [f32; BLOCK_LANES],
    /// The overlap when the contact was made (m, >= 0; 0 for a gap).
    pub overlap: [f32; BLOCK_LANES],
    /// How much of `overlap` may remain at the end of this substep (m):
    /// the overlap is removed evenly over the step's substeps.
    pub allowance: [f32; BLOCK_LANES],
    /// Accumulated normal multiplier, reset every substep.
    pub lambda_n: [f32; BLOCK_LANES],
    /// Accumulated tangential multiplier (a world vector in the tangent
    /// plane), reset every substep.
    pub lambda_t: Vec3Block,
    /// The relax passes' accumulated normal impulse (N s, at least
    /// `-lambda_n / h`), reset every substep.
    pub lambda_v: [f32; BLOCK_LANES],
    /// `lambda_n` of the step's substeps before this one, summed (kg m):
    /// what the position level pushed (read by [`ContactBlock::impulse`];
    /// never read by the solve).
    pub pushed_n: [f32; BLOCK_LANES],
    /// `lambda_t` of the step's substeps before this one, summed (kg m,
    /// world).
    pub pushed_t: Vec3Block,
    /// The velocity pass's normal impulses (restitution) and the relax
    /// passes' (negative where they take back a push-out) of the step,
    /// summed (N s, along the normal; never read by the solve).
    pub kicked_n: [f32; BLOCK_LANES],
    /// The velocity pass's friction impulses on b of the step, summed (N s,
    /// world).
    pub kicked_t: Vec3Block,
    /// Nonzero: a tree's direct solve takes the contact (a pin,
    /// `direct::pin`): the position iterations and the velocity pass's
    /// dynamic friction leave it out, and its multipliers are the pin's,
    /// written in after the substep's solves (restitution and relax read
    /// them as any contact's).
    pub pinned: [f32; BLOCK_LANES],
}

/// One contact's solver data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLane {
    /// The two bodies.
    pub pair: PairLane,
    /// Contact point on a (a's body frame).
    pub point_a: GVec3,
    /// Contact point on b (b's body frame).
    pub point_b: GVec3,
    /// Normal from a to b (world, unit).
    pub normal: GVec3,
    /// Friction coefficient.
    pub friction: f32,
    /// Restitution.
    pub restitution: f32,
    /// Approach velocity along the normal (m/s).
    pub approach: f32,
    /// The overlap when the contact was made (m, >= 0).
    pub overlap: f32,
    /// The two points when the step began.
    pub start: StartLane,
    /// Whether a tree's direct solve takes it ([`ContactBlock::pinned`]).
    pub pinned: bool,
}

/// A padding lane: null rows, zero normal, so nothing acts, and no writes
/// (as every kernel's padding: were its lanes to write the null row, a
/// colour's padding lanes would share a written row and no colour of
/// contacts could be split over threads).
impl LaneBlock for ContactBlock {
    type Lane = ContactLane;
    const PADDING: ContactLane = ContactLane {
        pair: PairLane::NULL,
        point_a: GVec3::ZERO,
        point_b: GVec3::ZERO,
        normal: GVec3::ZERO,
        friction: 0.0,
        restitution: 0.0,
        approach: 0.0,
        overlap: 0.0,
        start: StartLane::ZERO,
        pinned: false,
    };

    /// Writes one contact into `lane`.
    fn set(&mut self, lane: usize, c: &ContactLane) {
        self.bodies.set(lane, &c.pair);
        self.bodies.set_start(lane, &c.start);
        self.point_a.set(lane, c.point_a);
        self.point_b.set(lane, c.point_b);
        self.normal.set(lane, c.normal);
        self.friction[lane] = c.friction;
        self.restitution[lane] = c.restitution;
        self.approach[lane] = c.approach;
        self.overlap[lane] = c.overlap;
        self.allowance[lane] = c.overlap;
        self.lambda_n[lane] = 0.0;
        self.lambda_t.set(lane, GVec3::ZERO);
        self.pushed_n[lane] = 0.0;
        self.pushed_t.set(lane, GVec3::ZERO);
        self.kicked_n[lane] = 0.0;
        self.kicked_t.set(lane, GVec3::ZERO);
        self.pinned[lane] = if c.pinned { 1.0 } else { 0.0 };
    }
}

impl ContactBlock {
    /// Starts a substep: the multipliers reset, and the overlap allowed at
    /// its end set to `remaining` (in [0, 1]) of the contact's overlap.
    pub fn start_substep(&mut self, remaining: f32) {
        // What the substep before pushed, kept for `impulse`.
        for lane in 0..BLOCK_LANES {
            self.pushed_n[lane] += self.lambda_n[lane];
            let pushed_t = self.pushed_t.get(lane) + self.lambda_t.get(lane);
            self.pushed_t.set(lane, pushed_t);
        }
        self.lambda_n = [0.0; BLOCK_LANES];
        self.lambda_t = Vec3Block::default();
        self.lambda_v = [0.0; BLOCK_LANES];
        for (allowed, overlap) in self.allowance.iter_mut().zip(self.overlap) {
            *allowed = overlap * remaining;
        }
    }
}

/// What one contact did in its step: the impulses it applied to body b
/// (body a took their opposite).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactImpulse {
    /// Along the normal (N s, at least 0: a contact pushes, never pulls):
    /// the position level's push over every substep, the velocity pass's
    /// restitution, less what the relax passes took back (never more than
    /// a substep's push).
    pub normal: f32,
    /// Friction, in the tangent plane (N s, world): the position level's
    /// static friction and the velocity pass's dynamic friction.
    pub friction: GVec3,
}

impl ContactBlock {
    /// The impulses `lane`'s contact applied over the step so far, for
    /// substeps of `h` seconds (a multiplier `lambda` in kg m is the
    /// impulse `lambda / h`).
    pub fn impulse(&self, lane: usize, h: f32) -> ContactImpulse {
        let pushed_n = self.pushed_n[lane] + self.lambda_n[lane];
        let pushed_t = self.pushed_t.get(lane) + self.lambda_t.get(lane);
        ContactImpulse {
            normal: pushed_n / h + self.kicked_n[lane],
            friction: pushed_t / h + self.kicked_t.get(lane),
        }
    }
}

/// The lever arms the corrections act through, and the world points'
/// difference `(p_b + r_b) - (p_a + r_a)` now (the point part's measure).
///
/// The arms are the step's first (`PairStart`), not the turned ones the
/// difference is measured with (Box2D v3's contact anchors do the same).
/// A contact's points are where the bodies touched at detection; on a
/// round body that turns, the point turns away from the bottom, and a
/// normal correction through the turned arm spins the body on, each
/// substep more: a capsule lying still on the ground spun up about its
/// axis by 11% a frame (`m g R h^2 / I` a substep) until it turned at
/// 188 rad/s. Through the first arms the normal acts through the axis, as
/// at detection.
#[inline(always)]
fn arms<L: Lane>(
    block: &ContactBlock,
    start: usize,
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
) -> (Vec3<L>, Vec3<L>, Vec3<L>) {
    let first = block.bodies.start(start);
    let (_, _, d) = point::separation(
        a,
        b,
        block.point_a.load(start),
        block.point_b.load(start),
        &first,
    );
    (first.arm_a, first.arm_b, d)
}

/// Moves both bodies by the positional impulse `impulse` (b) and its
/// opposite (a).
#[inline(always)]
fn push<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    ra: Vec3<L>,
    rb: Vec3<L>,
    impulse: Vec3<L>,
) {
    b.apply_impulse(rb, impulse);
    a.apply_impulse(ra, -impulse);
}

/// One XPBD iteration of contacts (a [`BlockPass`](crate::pass::BlockPass)
/// over [`ContactBlock`]s): non-penetration, then static friction.
pub struct Positions;

impl BlockKernel for Positions {
    type Block = ContactBlock;
    type Params = ();
    #[inline(always)]
    fn padding(block: &ContactBlock) -> u32 {
        block.bodies.padding
    }
    #[inline(always)]
    fn solve<L: Lane>(block: &mut ContactBlock, start: usize, rows: &BodyRows, (): ()) {
        solve_positions::<L>(block, start, rows);
    }
}

#[inline(always)]
fn solve_positions<L: Lane>(block: &mut ContactBlock, start: usize, rows: &BodyRows) {
    let (mut a, mut b) = block.bodies.gather::<L>(rows, start);
    let n = block.normal.load::<L>(start);
    let zero = L::splat(0.0);

    let (ra, rb, d) = arms(block, start, &a, &b);
    let allowance = L::load(&block.allowance[start..]);
    // A pinned lane's rows are its tree's: nothing here.
    let free = L::load(&block.pinned[start..]).eq(zero);
    let c = L::select(free, (d.dot(n) + allowance).min(zero), zero);
    let (resp_a, resp_b) = (a.positional_response(ra, n), b.positional_response(rb, n));
    let dlambda_n = safe_ratio(-c, resp_a.weight + resp_b.weight);
    b.push(n, &resp_b, dlambda_n);
    a.push(n, &resp_a, -dlambda_n);
    let lambda_n = L::load(&block.lambda_n[start..]) + dlambda_n;
    lambda_n.store(&mut block.lambda_n[start..]);

    let (ra, rb, d) = arms(block, start, &a, &b);
    let (t, slide) = (d - n.scale(d.dot(n))).normalize_or_zero();
    let w = a.positional_weight(ra, t) + b.positional_weight(rb, t);
    // Coulomb: the accumulated tangential multiplier, a vector (the slide's
    // direction changes between iterations), is clamped to the cone
    // `|lambda_t| <= mu lambda_n`: a projection, as impulse solvers clamp.
    let lambda_t = block.lambda_t.load::<L>(start);
    let wanted = lambda_t + t.scale(safe_ratio(-slide, w));
    let (direction, size) = wanted.normalize_or_zero();
    let bound = L::load(&block.friction[start..]) * lambda_n;
    let clamped = Vec3::select(free, direction.scale(size.min(bound)), lambda_t);
    let impulse = clamped - lambda_t;
    push(&mut a, &mut b, ra, rb, impulse);
    block.lambda_t.store(start, clamped);

    block.bodies.scatter(rows, start, &a, &b);
}

/// A velocity pass over the contacts (a [`BlockPass`](crate::pass::BlockPass)
/// over [`ContactBlock`]s): dynamic friction and restitution, or with
/// [`VelocitySettings::relax`] a relax pass (module docs, "Relax"): each
/// touching contact's normal velocity brought to its target, taking back
/// at most its push-out. A relax pass accumulates `lambda_v` in the
/// blocks; both add their impulses to `kicked_n` and `kicked_t`. Body
/// rows: poses and inertia read, velocities read and written.
pub struct Velocities;

/// What every block of a velocity pass shares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VelocitySettings {
    /// The substep `h` (s).
    pub h: f32,
    /// Approach speeds below this bounce not at all (m/s): `2 |g| h`.
    pub resting_speed: f32,
    /// A relax pass, not the velocity pass.
    pub relax: bool,
}

impl BlockKernel for Velocities {
    type Block = ContactBlock;
    type Params = VelocitySettings;
    #[inline(always)]
    fn padding(block: &ContactBlock) -> u32 {
        block.bodies.padding
    }
    #[inline(always)]
    fn solve<L: Lane>(
        block: &mut ContactBlock,
        start: usize,
        rows: &BodyRows,
        v: VelocitySettings,
    ) {
        let (h, resting_speed) = (L::splat(v.h), L::splat(v.resting_speed));
        if v.relax {
            relax::<L>(block, start, rows, h, resting_speed);
        } else {
            solve_velocities::<L>(block, start, rows, h, resting_speed);
        }
    }
}

/// The normal relative velocity a contact aims for: `-e v_approach` when
/// it came in faster than `resting_speed`, else 0 (m/s).
#[inline(always)]
fn normal_target<L: Lane>(block: &ContactBlock, start: usize, resting_speed: L) -> L {
    let approach = L::load(&block.approach[start..]);
    let bounces = (-approach).gt(resting_speed);
    L::select(
        bounces,
        (-L::load(&block.restitution[start..]) * approach).max(L::splat(0.0)),
        L::splat(0.0),
    )
}

/// A slice of contacts at the velocity level: both bodies' poses and
/// velocities, the lever arms, the normal and the substep's normal
/// multiplier, as both velocity passes read them.
struct Touch<L: Lane> {
    a: BodyLanes<L>,
    b: BodyLanes<L>,
    va: VelocityLanes<L>,
    vb: VelocityLanes<L>,
    ra: Vec3<L>,
    rb: Vec3<L>,
    n: Vec3<L>,
    lambda_n: L,
}

impl<L: Lane> Touch<L> {
    #[inline(always)]
    fn gather(block: &ContactBlock, start: usize, rows: &BodyRows) -> Self {
        let pairs = &block.bodies;
        let (a, b) = pairs.gather::<L>(rows, start);
        let (ra, rb, _) = arms(block, start, &a, &b);
        Self {
            va: VelocityLanes::gather(rows, &pairs.body_a[start..]),
            vb: VelocityLanes::gather(rows, &pairs.body_b[start..]),
            n: block.normal.load(start),
            lambda_n: L::load(&block.lambda_n[start..]),
            a,
            b,
            ra,
            rb,
        }
    }

    /// Whether the contact pushed this substep (`lambda_n > 0`).
    #[inline(always)]
    fn touching(&self) -> L::Mask {
        self.lambda_n.gt(L::splat(0.0))
    }

    /// b's contact point's velocity relative to a's (m/s).
    #[inline(always)]
    fn relative(&self) -> Vec3<L> {
        (self.vb.v + self.vb.w.cross(self.rb)) - (self.va.v + self.va.w.cross(self.ra))
    }

    /// The generalised inverse mass along `d` at the contact point.
    #[inline(always)]
    fn weight(&self, d: Vec3<L>) -> L {
        self.a.positional_weight(self.ra, d) + self.b.positional_weight(self.rb, d)
    }

    /// Adds the velocity impulse `impulse` at `rb` to b and its opposite
    /// at `ra` to a.
    #[inline(always)]
    fn kick(&mut self, impulse: Vec3<L>) {
        self.vb.v += impulse.scale(self.b.inv_mass);
        self.vb.w += self.b.inv_inertia_mul(self.rb.cross(impulse));
        self.va.v -= impulse.scale(self.a.inv_mass);
        self.va.w -= self.a.inv_inertia_mul(self.ra.cross(impulse));
    }

    #[inline(always)]
    fn scatter(&self, block: &ContactBlock, start: usize, rows: &BodyRows) {
        self.va.scatter(rows, &block.bodies.write_a[start..]);
        self.vb.scatter(rows, &block.bodies.write_b[start..]);
    }
}

#[inline(always)]
fn relax<L: Lane>(block: &mut ContactBlock, start: usize, rows: &BodyRows, h: L, resting_speed: L) {
    let mut touch = Touch::<L>::gather(block, start, rows);
    let target = normal_target(block, start, resting_speed);
    let (n, lambda_n) = (touch.n, touch.lambda_n);
    let before = L::load(&block.lambda_v[start..]);
    let wanted = before + safe_ratio(target - touch.relative().dot(n), touch.weight(n));
    let after = L::select(touch.touching(), wanted.max(-(lambda_n / h)), before);
    touch.kick(n.scale(after - before));
    after.store(&mut block.lambda_v[start..]);
    (L::load(&block.kicked_n[start..]) + (after - before)).store(&mut block.kicked_n[start..]);
    touch.scatter(block, start, rows);
}

#[inline(always)]
fn solve_velocities<L: Lane>(
    block: &mut ContactBlock,
    start: usize,
    rows: &BodyRows,
    h: L,
    resting_speed: L,
) {
    let mut touch = Touch::<L>::gather(block, start, rows);
    let (n, zero, touching) = (touch.n, L::splat(0.0), touch.touching());

    let relative = touch.relative();
    let vn = relative.dot(n);
    let (t, speed_t) = (relative - n.scale(vn)).normalize_or_zero();
    // The impulse that stops the sliding, capped by what the position
    // level left of Coulomb's budget: (mu lambda_n - |lambda_t|) / h.
    let stop = safe_ratio(speed_t, touch.weight(t));
    let used = block.lambda_t.load::<L>(start).length();
    let budget = ((L::load(&block.friction[start..]) * touch.lambda_n - used) / h).max(zero);
    let impulse = stop.min(budget);
    // A pin's friction is all in its tree's solve.
    let free = L::load(&block.pinned[start..]).eq(zero);
    let friction = t.scale(L::select(touching & free, -impulse, zero));
    touch.kick(friction);
    let kicked_t = block.kicked_t.load::<L>(start) + friction;
    block.kicked_t.store(start, kicked_t);

    let target = normal_target(block, start, resting_speed);
    let change = L::select(touching, (target - touch.relative().dot(n)).max(zero), zero);
    let restitution = safe_ratio(change, touch.weight(n));
    touch.kick(n.scale(restitution));
    (L::load(&block.kicked_n[start..]) + restitution).store(&mut block.kicked_n[start..]);
    touch.scatter(block, start, rows);
}
