//! Pins: contacts between a body of a tree and a static or kinematic body,
//! solved as rows of the tree's direct solve.
//!
//! **Why.** Iterated beside the direct solve, a contact pushes its body
//! out and the tree's exact solve that follows pulls it back by its share
//! of the tree's mass: a 1 kg foot under a 69 kg ragdoll keeps 1/70 of
//! each push, for the normal and for friction, and a standing ragdoll
//! sinks and slides away on its feet. A pin puts the contact into the
//! solve that moves the whole tree.
//!
//! **The rows.** A pin has three rows on its tree body, all through the
//! step's first lever arm `r` (as the contact part's): along the outward
//! normal `u` (from the other body toward the tree's), with error the
//! points' separation `c_n = d . u` (plus the overlap the substep may keep),
//! and along two tangents `t_1`, `t_2`, with error the points' tangential
//! offset since the contact was made, `c_t = d . t` (the static friction
//! of the contact part). Each row is `j = (e, r x e)` for its direction
//! `e`. A held row is a stiff spring, `kappa = PIN_STIFFNESS x` the whole
//! tree's mass, eliminated into the body's 6 x 6 block:
//!
//! ```text
//! (M + kappa sum j j^T) dx - J^T dlambda = -kappa sum j c + sum j f
//! ```
//!
//! (the second sum: a sliding pin's prescribed friction `f`), so a pin
//! adds no unknowns and no loops, however many a body has. Its
//! multiplier is `lambda = -kappa (c + j . dx)` (kg m, a positional
//! impulse): stiff against the tree's mass, the pin holds to about
//! `1 / PIN_STIFFNESS` of what the tree pushes into it.
//!
//! **The active set.** A normal row is held where the solve starts with
//! the points overlapping (`c_n < 0`); after each pass a held row that
//! pulls (`c_n + j . dx > PIN_CROSSING`) is let go and one carried into
//! the other body (`< -PIN_CROSSING`) taken, for another pass, as the
//! limits' rows are.
//!
//! **Friction: one Coulomb bound per body.** A body's held pins share one
//! bound, as a wrench about their centre of pressure `o` (the normal
//! multipliers' mean of the arms): with `F` the summed tangential
//! multipliers, `tau` their moment about `o` along the normal and `s` the
//! patch's size (the loaded pins' mean distance from their own centre),
//! the patch holds while `|F|^2 + (tau / s)^2 <= (sum mu lambda_n)^2` (an
//! elliptic limit surface), each over the substep's solves so far and
//! this one. A cone per pin lets a pushed box feel twice its `mu`: its
//! load moves to the front corners, and the back ones' excess is clamped
//! from their multipliers, not from the body. The size is the patch's,
//! not the load's spread about `o`: a capsule whose load sat on one end
//! had a size near zero, so any twist its joints held slid it, and a limp
//! ragdoll's limbs kept turning (6.48 rad/s in its fourth second, 0.35
//! with the patch's size).
//!
//! A body's pins either **stick** (the tangent rows held with the
//! normal's) or **slide**: no tangent rows, each held pin pushing
//! `mu lambda_n` of the pass before against its way (a prescribed `f` on
//! the right-hand side). The way is against the point's velocity as the
//! solve starts, when that is above [`SLIDING_SPEED`], else along the
//! friction the held pass asked. A solve starts sliding where a pin's
//! point moves faster than [`SLIDING_SPEED`] along the ground, else
//! sticking. A sticking patch beyond its bound slides from the next pass;
//! a sliding one whose friction turned its slip over the substep around
//! (the points' tangential motion since the substep began, along their
//! ways) has stopped, and sticks from the next pass. A sliding pass whose
//! normals changed takes another with their new `mu lambda_n`. Each such
//! change is a pin crossing: the lane takes another pass, up to
//! [`PIN_PASSES`], whatever its limits' bound.
//!
//! **Bits.** Everything is lane by lane with masks and selects, read from
//! the tree's own lanes; a lane's passes depend on its own tree alone, so
//! every backend and every grouping of the trees gives the same bits.

use bytemuck::{Pod, Zeroable};
use vertebra_math::block::{BLOCK_LANES, Vec3Block};
use vertebra_math::{Lane, Vec3};

use crate::body::{BodyPairs, BodyRows, PairLane, StartLane, VelocityLanes};
use crate::parts::point;

/// The most pins a body takes (a foot's four corners); a body's further
/// contacts stay iterated.
pub const MAX_PINS: usize = 4;

/// A pin's stiffness per kilogram of its tree (`kappa = PIN_STIFFNESS x`
/// the tree's mass): a pin holds to about a hundredth of what the tree
/// pushes into it, and the body's block stays well conditioned in `f32`.
pub const PIN_STIFFNESS: f32 = 100.0;

/// How many passes a solve may take where pins cross (their normals held
/// or let go, their friction's mode changed) or drives reach their caps.
/// A solve whose pins have not settled by then ends on its last pass, or
/// (where that pass moved the tree further than its first) on its first
/// pass's set, solved once more (`PositionPass::run`).
pub const PIN_PASSES: usize = 8;

/// A pin's point moving along the ground faster than this (m/s) as a
/// solve starts slides: slower, the solve starts it held.
pub const SLIDING_SPEED: f32 = 0.01;

/// The active set's hysteresis for pins (m): how far a held normal must
/// pull, or one not held be carried in, before it crosses.
pub const PIN_CROSSING: f32 = 1.0e-6;

/// How far past the Coulomb bound (relative) a sticking patch may ask
/// before it slides, and how far a sliding pin's friction may differ from
/// `mu lambda_n` of its pass before it takes another.
const FRICTION_TOLERANCE: f32 = 1.0e-3;

/// A body's pins stick (tangent rows held).
pub const STICK: f32 = 0.0;
/// A body's pins slide (prescribed friction against their ways).
pub const SLIDE: f32 = 1.0;
/// A body's pins stick again, after a slide its friction turned around:
/// the last mode with friction.
pub const STUCK: f32 = 2.0;
/// A body's pins take no friction for the rest of the solve: it stuck
/// again and asked beyond its bound once more.
pub const FREE: f32 = 3.0;

/// How many times a solve may hold or let go one pin's normal before it
/// may no longer be taken (an active set over the contacts of a whole
/// tree can cycle); a pulling normal is let go whatever its count.
const MAX_FLIPS: f32 = 2.0;

/// Where a pin's record ([`PinSlot::record`]) keeps its three errors.
const C: usize = 0;
/// Its three rows on the tree body (6 each).
const J: usize = 3;
/// Its point's tangential velocity along the two tangents (m/s).
const V: usize = J + 18;
/// Its lever arm (m, world, the step's first).
const ARM: usize = V + 2;
/// How many values a pin's record holds: what it measures where the solve
/// stands (its errors, its rows on the tree body, its point's tangential
/// velocity, its lever arm).
pub const RECORD: usize = ARM + 3;

/// One pin slot of one body of a tree, in each lane: the contact (as the
/// contact part holds it), and the solve's state.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct PinSlot {
    /// The contact's two bodies (rows read) and its start of step.
    pub pair: BodyPairs,
    /// Contact point on a (m, a's body frame).
    pub point_a: Vec3Block,
    /// Contact point on b (m, b's body frame).
    pub point_b: Vec3Block,
    /// The contact's normal, from a to b (world, unit).
    pub normal: Vec3Block,
    /// Friction coefficient.
    pub friction: [f32; BLOCK_LANES],
    /// The overlap when the contact was made (m).
    pub overlap: [f32; BLOCK_LANES],
    /// How much of the overlap may remain at the end of this substep (m).
    pub allowance: [f32; BLOCK_LANES],
    /// `1`: the tree's body is the contact's b; `-1`: its a; `0`: no pin.
    pub side: [f32; BLOCK_LANES],
    /// As measured by the solve ([`RECORD`] values).
    pub record: [[f32; BLOCK_LANES]; RECORD],
    /// The normal row held in this pass (1) or not (0).
    pub held: [f32; BLOCK_LANES],
    /// The normal row's next pass.
    pub next: [f32; BLOCK_LANES],
    /// How many times this solve held or let go the normal row.
    pub flips: [f32; BLOCK_LANES],
    /// This pass's normal multiplier (kg m).
    pub lambda_n: [f32; BLOCK_LANES],
    /// This pass's friction (kg m, world, in the tangent plane).
    pub lambda_t: Vec3Block,
    /// The friction a sliding pin pushes with in this pass (kg m, along
    /// `way`).
    pub force: [f32; BLOCK_LANES],
    /// The friction it pushes with in the next pass.
    pub next_force: [f32; BLOCK_LANES],
    /// A sliding pin's friction direction (world, unit).
    pub way: Vec3Block,
    /// The next pass's way.
    pub next_way: Vec3Block,
    /// The normal row's and the way's state as the solve began
    /// (`measure`), for `restart`.
    pub first: [f32; BLOCK_LANES],
    /// See [`Self::first`].
    pub first_way: Vec3Block,
    /// The substep's solves before this one, summed: the normal
    /// multipliers (kg m).
    pub substep_n: [f32; BLOCK_LANES],
    /// And the friction (kg m, world).
    pub substep_t: Vec3Block,
    /// The points' tangential offset as the substep started (m, world,
    /// from the other body's point to the tree's): what the substep's slip
    /// is measured from.
    pub origin: Vec3Block,
}

/// The pins of one body of a tree, in each lane.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct PinNode {
    /// The slots, filled from the first.
    pub slots: [PinSlot; MAX_PINS],
    /// `kappa` (kg): [`PIN_STIFFNESS`] times the whole tree's mass.
    pub stiffness: [f32; BLOCK_LANES],
    /// The friction's mode this pass ([`STICK`], [`SLIDE`], [`STUCK`],
    /// [`FREE`]: each solve starts sticking or sliding and only moves on).
    pub mode: [f32; BLOCK_LANES],
    /// Its next pass's.
    pub next_mode: [f32; BLOCK_LANES],
    /// Its mode as the solve began, for `restart`.
    pub first_mode: [f32; BLOCK_LANES],
    /// The step's pin impulses on the body, summed: linear (kg m) and
    /// angular about its centre (kg m^2), world (never read by the solve:
    /// the joints' loads, `LoadPass`, leave them out).
    pub impulse: [[f32; BLOCK_LANES]; 6],
}

/// One pin as the world lays it out: the contact's solver data, which of
/// its bodies is the tree's, and the tree's stiffness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinLane {
    /// The two bodies.
    pub pair: PairLane,
    /// Contact point on a (a's body frame).
    pub point_a: glam::Vec3,
    /// Contact point on b (b's body frame).
    pub point_b: glam::Vec3,
    /// Normal from a to b (world, unit).
    pub normal: glam::Vec3,
    /// Friction coefficient.
    pub friction: f32,
    /// The overlap when the contact was made (m, >= 0).
    pub overlap: f32,
    /// The two points when the step began.
    pub start: StartLane,
    /// Whether the tree's body is b (else a).
    pub tree_is_b: bool,
}

impl PinNode {
    /// No pins in any lane.
    pub fn empty() -> Self {
        Self::zeroed()
    }

    /// Empties `lane`'s slots (as a step's contacts are laid out again).
    pub fn clear_lane(&mut self, lane: usize) {
        for slot in &mut self.slots {
            slot.side[lane] = 0.0;
            slot.pair.set(lane, &PairLane::NULL);
            slot.friction[lane] = 0.0;
        }
    }

    /// Sets `lane`'s slot `k` to the pin `pin` of a tree of stiffness
    /// `kappa` (kg).
    pub fn set(&mut self, lane: usize, k: usize, pin: &PinLane, kappa: f32) {
        let slot = &mut self.slots[k];
        slot.pair.set(lane, &pin.pair);
        slot.pair.set_start(lane, &pin.start);
        slot.point_a.set(lane, pin.point_a);
        slot.point_b.set(lane, pin.point_b);
        slot.normal.set(lane, pin.normal);
        slot.friction[lane] = pin.friction;
        slot.overlap[lane] = pin.overlap;
        slot.allowance[lane] = pin.overlap;
        slot.side[lane] = if pin.tree_is_b { 1.0 } else { -1.0 };
        self.stiffness[lane] = kappa;
    }

    /// Starts a step: the step's impulse on the body zeroed.
    pub fn start_step(&mut self) {
        self.impulse = [[0.0; BLOCK_LANES]; 6];
    }

    /// Starts a substep: the substep's sums zeroed and the overlap allowed
    /// at its end set to `remaining` (in [0, 1]) of each contact's.
    pub fn start_substep(&mut self, remaining: f32) {
        for slot in &mut self.slots {
            slot.substep_n = [0.0; BLOCK_LANES];
            slot.substep_t = Vec3Block::ZERO;
            for (allowed, overlap) in slot.allowance.iter_mut().zip(slot.overlap) {
                *allowed = overlap * remaining;
            }
        }
    }

    /// `lane`'s slot `k`'s multipliers over the substep's solves so far, if
    /// it holds a pin: the normal's (kg m) and the friction on the
    /// contact's b (kg m, world): what the contact part would have
    /// accumulated in its `lambda_n` and `lambda_t`.
    pub fn substep(&self, lane: usize, k: usize) -> Option<(f32, glam::Vec3)> {
        let slot = &self.slots[k];
        let side = slot.side[lane];
        if side == 0.0 {
            return None;
        }
        Some((slot.substep_n[lane], slot.substep_t.get(lane) * side))
    }
}

/// Two unit tangents completing the unit `u` to a right-handed basis
/// (Duff et al. 2017, "Building an orthonormal basis, revisited"),
/// branch-free.
#[inline(always)]
fn tangents<L: Lane>(u: Vec3<L>) -> (Vec3<L>, Vec3<L>) {
    let one = L::splat(1.0);
    let sign = one.copysign(u.z);
    let a = -one / (sign + u.z);
    let b = u.x * u.y * a;
    (
        Vec3::new(one + sign * u.x * u.x * a, sign * b, -(sign * u.x)),
        Vec3::new(b, sign + u.y * u.y * a, -u.y),
    )
}

/// The row `(e, r x e)` of direction `e` through the arm `r`.
#[inline(always)]
fn row<L: Lane>(e: Vec3<L>, r: Vec3<L>) -> [L; 6] {
    let m = r.cross(e);
    [e.x, e.y, e.z, m.x, m.y, m.z]
}

/// `j . x` for a row and a body's six unknowns.
#[inline(always)]
fn dot6<L: Lane>(j: &[L], x: &[L]) -> L {
    let mut s = L::splat(0.0);
    for k in 0..6 {
        s += j[k] * x[k];
    }
    s
}

/// A slot's measured values of lanes `start ..`.
#[inline(always)]
fn record<L: Lane>(slot: &PinSlot, start: usize) -> [L; RECORD] {
    let mut values = [L::splat(0.0); RECORD];
    for (v, r) in values.iter_mut().zip(&slot.record) {
        *v = L::load(&r[start..]);
    }
    values
}

/// Row `r`'s error after the body's step `x`: `c + j . x`.
#[inline(always)]
fn after<L: Lane>(values: &[L; RECORD], r: usize, x: &[L; 6]) -> L {
    values[C + r] + dot6(&values[J + 6 * r..J + 6 * r + 6], x)
}

/// The lanes of a slot that hold a pin.
#[inline(always)]
fn live<L: Lane>(slot: &PinSlot, start: usize) -> L::Mask {
    L::load(&slot.side[start..]).ne(L::splat(0.0))
}

/// The outward normal `u` and tangents of lanes `start ..` of a slot.
#[inline(always)]
fn directions<L: Lane>(slot: &PinSlot, start: usize) -> [Vec3<L>; 3] {
    let side = L::load(&slot.side[start..]);
    let n = slot.normal.load::<L>(start);
    let u = Vec3::new(n.x * side, n.y * side, n.z * side);
    let (t1, t2) = tangents(u);
    [u, t1, t2]
}

/// As a substep starts, before the bodies are predicted: each pin's
/// points' tangential offset ([`PinSlot::origin`]).
#[inline(always)]
pub(super) fn start_substep<L: Lane>(pins: &mut PinNode, rows: &BodyRows, start: usize) {
    for slot in &mut pins.slots {
        let side = L::load(&slot.side[start..]);
        let d = separation(slot, rows, start).scale(side);
        let [u, ..] = directions(slot, start);
        let offset = d - u.scale(d.dot(u));
        slot.origin.store(
            start,
            Vec3::select(live::<L>(slot, start), offset, Vec3::zero()),
        );
    }
}

/// The points' separation now, from a's to b's (m, world).
#[inline(always)]
fn separation<L: Lane>(slot: &PinSlot, rows: &BodyRows, start: usize) -> Vec3<L> {
    let (a, b) = slot.pair.gather::<L>(rows, start);
    let first = slot.pair.start::<L>(start);
    let (_, _, d) = point::separation(
        &a,
        &b,
        slot.point_a.load(start),
        slot.point_b.load(start),
        &first,
    );
    d
}

/// Measures a body's pins where the solve stands (their errors and rows,
/// their points' tangential velocity) and starts the solve's active set:
/// every overlapping pin held, the friction sliding where a pin's point
/// moves faster than [`SLIDING_SPEED`] along the ground (its way against
/// that velocity), else sticking.
#[inline(always)]
pub(super) fn measure<L: Lane>(pins: &mut PinNode, rows: &BodyRows, start: usize) {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let mut sliding = zero.gt(zero);
    for slot in &mut pins.slots {
        let live = live::<L>(slot, start);
        let side = L::load(&slot.side[start..]);
        let first = slot.pair.start::<L>(start);
        let d = separation(slot, rows, start).scale(side);
        let [u, t1, t2] = directions(slot, start);
        let arm = Vec3::select(side.gt(zero), first.arm_b, first.arm_a);
        let allowance = L::load(&slot.allowance[start..]);
        let mut values = [zero; RECORD];
        values[C] = L::select(live, d.dot(u) + allowance, zero);
        values[C + 1] = L::select(live, d.dot(t1), zero);
        values[C + 2] = L::select(live, d.dot(t2), zero);
        for (k, e) in [u, t1, t2].into_iter().enumerate() {
            let j = row(e, arm);
            for c in 0..6 {
                values[J + 6 * k + c] = L::select(live, j[c], zero);
            }
        }
        let va = VelocityLanes::<L>::gather(rows, &slot.pair.body_a[start..]);
        let vb = VelocityLanes::<L>::gather(rows, &slot.pair.body_b[start..]);
        let relative = (vb.v + vb.w.cross(first.arm_b)) - (va.v + va.w.cross(first.arm_a));
        let v = relative.scale(side);
        let (vt1, vt2) = (v.dot(t1), v.dot(t2));
        values[V] = L::select(live, vt1, zero);
        values[V + 1] = L::select(live, vt2, zero);
        values[ARM] = L::select(live, arm.x, zero);
        values[ARM + 1] = L::select(live, arm.y, zero);
        values[ARM + 2] = L::select(live, arm.z, zero);
        for (v, r) in values.iter().zip(&mut slot.record) {
            v.store(&mut r[start..]);
        }
        let tangential = t1.scale(vt1) + t2.scale(vt2);
        let (direction, speed) = tangential.normalize_or_zero();
        let fast = live & speed.gt(L::splat(SLIDING_SPEED));
        sliding = sliding | fast;
        let way = Vec3::select(fast, -direction, Vec3::zero());
        slot.way.store(start, way);
        slot.next_way.store(start, way);
        slot.first_way.store(start, way);
        let held = L::select(live & values[C].lt(zero), one, zero);
        held.store(&mut slot.held[start..]);
        held.store(&mut slot.next[start..]);
        held.store(&mut slot.first[start..]);
        zero.store(&mut slot.flips[start..]);
        zero.store(&mut slot.force[start..]);
        zero.store(&mut slot.next_force[start..]);
        zero.store(&mut slot.lambda_n[start..]);
        slot.lambda_t.store(start, Vec3::<L>::zero());
    }
    let mode = L::select(sliding, L::splat(SLIDE), L::splat(STICK));
    mode.store(&mut pins.mode[start..]);
    mode.store(&mut pins.next_mode[start..]);
    mode.store(&mut pins.first_mode[start..]);
}

/// Adds a body's held pins to its block `d` (packed, 6 x 6) and right-hand
/// side `b`: `kappa j j^T` and `-kappa c j` for each held row, `f j` for a
/// sliding pin's friction along its way.
#[inline(always)]
pub(super) fn add_to_block<L: Lane>(
    pins: &PinNode,
    d: &mut [L; super::ldl::PACKED],
    b: &mut [L; super::ldl::MAX],
    start: usize,
) {
    use super::ldl::at;
    let zero = L::splat(0.0);
    let kappa = L::load(&pins.stiffness[start..]);
    let mode = L::load(&pins.mode[start..]);
    let (stick, slide) = sticks_slides(mode);
    for slot in &pins.slots {
        let values = record::<L>(slot, start);
        let held = L::load(&slot.held[start..]).gt(zero);
        for k in 0..3 {
            let on = if k == 0 { held } else { held & stick };
            let weight = L::select(on, kappa, zero);
            let j = &values[J + 6 * k..J + 6 * k + 6];
            for r in 0..6 {
                let wj = weight * j[r];
                for c in 0..=r {
                    d[at(r, c)] += wj * j[c];
                }
                b[r] -= wj * values[C + k];
            }
        }
        let force = L::select(held & slide, L::load(&slot.force[start..]), zero);
        let arm = arm_of::<L>(&values);
        let j = row(slot.way.load::<L>(start), arm);
        for r in 0..6 {
            b[r] += j[r] * force;
        }
    }
}

/// The lanes whose pins hold their tangent rows ([`STICK`], [`STUCK`]),
/// and those that slide.
#[inline(always)]
fn sticks_slides<L: Lane>(mode: L) -> (L::Mask, L::Mask) {
    let slide = mode.eq(L::splat(SLIDE));
    (mode.eq(L::splat(STICK)) | mode.eq(L::splat(STUCK)), slide)
}

/// A pin's lever arm (world, the step's first) as measured.
#[inline(always)]
fn arm_of<L: Lane>(values: &[L; RECORD]) -> Vec3<L> {
    Vec3::new(values[ARM], values[ARM + 1], values[ARM + 2])
}

/// After a pass: each pin's multipliers from the body's step `x` (its
/// six unknowns), and the next pass's active set and friction; returns
/// the lanes where a pin crossed (their tree takes another pass).
#[inline(always)]
pub(super) fn settle<L: Lane>(pins: &mut PinNode, x: &[L; 6], start: usize) -> L::Mask {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let kappa = L::load(&pins.stiffness[start..]);
    let mode = L::load(&pins.mode[start..]);
    let (stick, slide) = sticks_slides(mode);
    let mut crossed = zero.gt(zero);
    // The patch: summed normal load, its moment of the arms (for the centre
    // of pressure), the friction and its moment about the origin, the
    // bound, and the slip along the ways.
    let (mut load, mut bound, mut slip) = (zero, zero, zero);
    let mut moment = Vec3::zero();
    let mut friction = Vec3::zero();
    let mut spin = zero;
    let mut arms = [Vec3::<L>::zero(); MAX_PINS];
    let mut normals = [Vec3::<L>::zero(); MAX_PINS];
    let mut loads = [zero; MAX_PINS];
    let mut frictions = [Vec3::<L>::zero(); MAX_PINS];
    for (k, slot) in pins.slots.iter_mut().enumerate() {
        let values = record::<L>(slot, start);
        let held = L::load(&slot.held[start..]).gt(zero);
        let [u, t1, t2] = directions(slot, start);
        let (sn, s1, s2) = (
            after(&values, 0, x),
            after(&values, 1, x),
            after(&values, 2, x),
        );
        let lambda_n = L::select(held, -(kappa * sn), zero);
        let held_t = t1.scale(-(kappa * s1)) + t2.scale(-(kappa * s2));
        let way = slot.way.load::<L>(start);
        let pushed = way.scale(L::load(&slot.force[start..]));
        let lambda_t = Vec3::select(
            held & stick,
            held_t,
            Vec3::select(held & slide, pushed, Vec3::zero()),
        );
        lambda_n.store(&mut slot.lambda_n[start..]);
        slot.lambda_t.store(start, lambda_t);
        // The normal's next pass.
        // A pulling normal is always let go; one is taken only while its
        // flips last, so the passes end.
        let live = live::<L>(slot, start);
        let takes = live & L::load(&slot.flips[start..]).lt(L::splat(MAX_FLIPS));
        let crossing = L::splat(PIN_CROSSING);
        let pulls = live & held & sn.gt(crossing);
        let carried = takes & !held & sn.lt(-crossing);
        let next = (held & !pulls) | carried;
        L::select(next, one, zero).store(&mut slot.next[start..]);
        crossed = crossed | pulls | carried;
        // The patch, over the substep so far and this pass.
        let total_n = L::load(&slot.substep_n[start..]) + lambda_n;
        let total_t = slot.substep_t.load::<L>(start) + lambda_t;
        let arm = arm_of::<L>(&values);
        load += total_n;
        moment += arm.scale(total_n);
        friction += total_t;
        bound += L::load(&slot.friction[start..]) * total_n;
        (arms[k], normals[k], loads[k], frictions[k]) = (arm, u, total_n, total_t);
        // A sliding pin's slip over the substep, along its way.
        let moved = t1.scale(s1) + t2.scale(s2) - slot.origin.load::<L>(start);
        slip += L::select(held, moved.dot(way), zero);
        // Its friction in the next pass: mu lambda_n of this one.
        let force = L::load(&slot.friction[start..]) * lambda_n.max(zero);
        let changed = (force - L::load(&slot.force[start..]))
            .abs()
            .gt(L::splat(FRICTION_TOLERANCE) * force + L::splat(1.0e-12));
        crossed = crossed | (slide & held & changed);
        force.store(&mut slot.next_force[start..]);
        slot.next_way.store(start, way);
    }
    // The moment of the friction about the centre of pressure.
    let has_load = load.gt(zero);
    let centre = Vec3::select(
        has_load,
        moment.scale(one / load.max(L::splat(f32::MIN_POSITIVE))),
        Vec3::zero(),
    );
    // The loaded pins' own centre and mean distance from it: the patch's
    // size, whatever its load's spread.
    let (mut count, mut middle) = (zero, Vec3::zero());
    for k in 0..MAX_PINS {
        let loaded = L::select(loads[k].gt(zero), one, zero);
        count += loaded;
        middle += arms[k].scale(loaded);
    }
    let middle = middle.scale(one / count.max(one));
    let mut spread = zero;
    for k in 0..MAX_PINS {
        let offset = arms[k] - centre;
        spin += offset.cross(frictions[k]).dot(normals[k]);
        let from_middle = arms[k] - middle;
        let across = from_middle - normals[k].scale(from_middle.dot(normals[k]));
        spread += L::select(loads[k].gt(zero), across.length(), zero);
    }
    let radius = L::select(has_load, spread / count.max(one), zero);
    let turning = L::select(
        radius.gt(L::splat(1.0e-4)),
        spin / radius.max(L::splat(1.0e-4)),
        zero,
    );
    let asked = friction.length_squared() + turning * turning;
    let limit = bound.max(zero) * L::splat(1.0 + FRICTION_TOLERANCE);
    // Without load (the normals pull), any friction is beyond.
    let beyond = stick & asked.gt(limit * limit);
    let stopped = slide & slip.gt(zero);
    // A patch beyond its bound slides, each pin against the friction its
    // held pass asked (or its point's velocity, kept from the start).
    for slot in pins.slots.iter_mut() {
        let lambda_t = slot.lambda_t.load::<L>(start);
        let kept = slot.way.load::<L>(start);
        let (asked, size) = lambda_t.normalize_or_zero();
        let fresh = kept.length_squared().gt(zero);
        let way = Vec3::select(fresh, kept, asked);
        let way = Vec3::select(beyond & size.gt(zero), way, kept);
        slot.next_way.store(start, way);
    }
    // Only on: stick, slide, stuck, free.
    let next = L::select(beyond | stopped, mode + L::splat(1.0), mode);
    next.store(&mut pins.next_mode[start..]);
    crossed | beyond | stopped
}

/// After a solve: each pin's multipliers added to the substep's sums,
/// and their impulse on the body (linear, and angular about its centre)
/// to [`PinNode::impulse`].
#[inline(always)]
pub(super) fn finish<L: Lane>(pins: &mut PinNode, start: usize) {
    let mut linear = Vec3::<L>::zero();
    let mut angular = Vec3::<L>::zero();
    for slot in pins.slots.iter_mut() {
        let values = record::<L>(slot, start);
        let [u, ..] = directions(slot, start);
        let lambda_n = L::load(&slot.lambda_n[start..]);
        let lambda_t = slot.lambda_t.load::<L>(start);
        (L::load(&slot.substep_n[start..]) + lambda_n).store(&mut slot.substep_n[start..]);
        let substep_t = slot.substep_t.load::<L>(start) + lambda_t;
        slot.substep_t.store(start, substep_t);
        let impulse = u.scale(lambda_n) + lambda_t;
        linear += impulse;
        angular += arm_of::<L>(&values).cross(impulse);
    }
    let sums = [
        linear.x, linear.y, linear.z, angular.x, angular.y, angular.z,
    ];
    for (k, v) in sums.into_iter().enumerate() {
        (L::load(&pins.impulse[k][start..]) + v).store(&mut pins.impulse[k][start..]);
    }
}

/// Between passes (plain code over the lanes): each crossed lane takes
/// the next pass's active set, mode, ways and friction; returns the lanes
/// whose rows changed (their body is factored again).
pub(super) fn take(pins: &mut PinNode, crossing: &[f32; BLOCK_LANES]) -> u8 {
    let mut changed = 0u8;
    for (lane, &crossed) in crossing.iter().enumerate() {
        if crossed == 0.0 {
            continue;
        }
        if pins.mode[lane] != pins.next_mode[lane] {
            changed |= 1 << lane;
        }
        pins.mode[lane] = pins.next_mode[lane];
        for slot in pins.slots.iter_mut() {
            if slot.held[lane] != slot.next[lane] {
                slot.flips[lane] += 1.0;
                changed |= 1 << lane;
            }
            if slot.force[lane] != slot.next_force[lane] {
                changed |= 1 << lane;
            }
            slot.held[lane] = slot.next[lane];
            slot.force[lane] = slot.next_force[lane];
            slot.way.set(lane, slot.next_way.get(lane));
        }
    }
    changed
}

/// Between passes (plain code): `lane`'s pins as the solve began (its
/// [`measure`]): held, mode and ways as then, no flips, no sliding
/// friction.
pub(super) fn restart(pins: &mut PinNode, lane: usize) {
    pins.mode[lane] = pins.first_mode[lane];
    pins.next_mode[lane] = pins.first_mode[lane];
    for slot in pins.slots.iter_mut() {
        slot.held[lane] = slot.first[lane];
        slot.next[lane] = slot.first[lane];
        slot.flips[lane] = 0.0;
        slot.force[lane] = 0.0;
        slot.next_force[lane] = 0.0;
        let way = slot.first_way.get(lane);
        slot.way.set(lane, way);
        slot.next_way.set(lane, way);
    }
}
