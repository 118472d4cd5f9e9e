//! One direct solve's phases on one slice of a [`TreeBlock`]: measure
//! every node, eliminate leaves first, substitute root first, settle the
//! limits' active set, move the bodies (the steps of `super`'s
//! documentation); and the bookkeeping between the phases, in plain code
//! over the lanes: the active set held, ports and parents copied between
//! the blocks of one pass, crossings joined per tree.
//!
//! **Pulled complements.** Each node leaves minus its Schur complement
//! and right-hand side in its own scratch (`minus`, `minus_b`), and a
//! parent takes its children's in a fixed order (`Topology::children`)
//! when it is eliminated. So a node whose inputs did not change keeps its
//! factors and its complement from the pass before: a re-pass (a limit
//! row taken or let go) factors only the nodes on the paths from the
//! changed joints to the root (`TreeBlock::dirty`), and a subtree laid
//! out in another block hands its complement over by a copy (a
//! [`super::Port`]) with the same bits.
//!
//! **Limit rows.** A joint's equality rows are always solved; its limit
//! rows only where held ([`ldl::Held`]): a row no lane of the slice holds
//! costs nothing, and in a lane that does not hold it the row leaves
//! `+0` everywhere (`ldl`'s documentation), so a lane's bits never depend
//! on its neighbours.
//!
//! Every block size is a constant of its function (a body's 6; a joint's
//! equality and limit rows, [`JointRows::first_limit`] and
//! [`JointRows::count`]), chosen per node by a `match` on the topology
//! (the same in every lane), so that the dense loops unroll and stay in
//! registers.

use vertebra_math::block::BLOCK_LANES;
use vertebra_math::{Lane, Mask, Vec3};

use super::MAX_LIMIT_RETURN_SPEED;
use super::drive::DRIVE_RECORD;
use super::ldl::{self, Held, MAX, PACKED, at};
use super::pin;
use super::rows::{
    FREE, JointRows, LIMIT_RECORD as RECORD, MAX_DRIVE_ROWS, MAX_OPTIONAL, Rows, SwingRows,
};
use super::{Child, JointNode, MEASURED, NONE, NodeKind, SubstepScale, Topology, TreeBlock};
use crate::body::{BodyLanes, BodyRows};
use crate::parts::limit::Softness;

/// Calls `$f::<$L, E, K>($args)` with a joint kind's `E` equality rows and
/// `K` optional rows (its limits', then its drive's) as constants.
macro_rules! by_rows {
    ($kind:expr, $f:ident::<$L:ty>($($arg:expr),* $(,)?)) => {
        match $kind {
            JointRows::Socket(SwingRows::Pyramid, true) => $f::<$L, 3, 6>($($arg),*),
            JointRows::Socket(SwingRows::Pyramid, false) => $f::<$L, 3, 3>($($arg),*),
            JointRows::Socket(_, true) => $f::<$L, 3, 5>($($arg),*),
            JointRows::Socket(_, false) | JointRows::Rod => $f::<$L, 3, 2>($($arg),*),
            JointRows::Hinge(true) => $f::<$L, 5, 2>($($arg),*),
            JointRows::Hinge(false) => $f::<$L, 5, 1>($($arg),*),
            JointRows::Fixed => $f::<$L, 6, 0>($($arg),*),
        }
    };
}

/// Loads lane values from scratch arrays.
#[inline(always)]
pub(super) fn load<L: Lane, const N: usize>(src: &[[f32; BLOCK_LANES]], start: usize) -> [L; N] {
    let mut out = [L::splat(0.0); N];
    for (o, s) in out.iter_mut().zip(src) {
        *o = L::load(&s[start..]);
    }
    out
}

/// Loads the first `count` (at most `N`) lane values from scratch arrays,
/// the rest zero: a block's entries where the scratch is sized for the
/// largest (a body's 6 x 6 in a scratch sized for a driven pyramid's
/// 9 x 9).
#[inline(always)]
fn load_first<L: Lane, const N: usize>(
    src: &[[f32; BLOCK_LANES]],
    start: usize,
    count: usize,
) -> [L; N] {
    let mut out = [L::splat(0.0); N];
    for (o, s) in out.iter_mut().zip(&src[..count]) {
        *o = L::load(&s[start..]);
    }
    out
}

/// A body's block: the packed entries of a 6 x 6 lower triangle.
const BODY_PACKED: usize = at(6, 0);

/// Stores lane values into scratch arrays.
#[inline(always)]
fn store<L: Lane>(values: &[L], dst: &mut [[f32; BLOCK_LANES]], start: usize) {
    for (v, d) in values.iter().zip(dst) {
        v.store(&mut d[start..]);
    }
}

/// The bits of the lanes of the slice from `start`.
#[inline(always)]
fn slice_bits<L: Lane>(start: usize) -> u8 {
    (((1u32 << L::WIDTH) - 1) << start) as u8
}

/// Joint node `n`'s limit rows: which lanes hold each (its active set),
/// and whether any lane of the slice does.
#[inline(always)]
fn held<L: Lane, const E: usize, const K: usize>(
    block: &TreeBlock,
    n: usize,
    start: usize,
) -> Held<L, K> {
    let zero = L::splat(0.0);
    let bits = slice_bits::<L>(start);
    let mut held = Held {
        lanes: [zero.gt(zero); K],
        any: [false; K],
    };
    for o in 0..K {
        held.lanes[o] = L::load(&block.scratch[n].active[o][start..]).gt(zero);
        held.any[o] = block.held[n][o] & bits != 0;
    }
    held
}

// ---------------------------------------------------------------------------
// Measure.
// ---------------------------------------------------------------------------

/// Measures every node where the tree stands (bodies do not move between
/// a solve's passes, so only its first measures): a body's mass matrix
/// (world) and a joint's errors into `measured`, each joint's Jacobians
/// where the tree couples it to each body (its parent side at the joint,
/// its child side at the child body; the root joint's parent side is its
/// static, kinematic or other block's body), and each limit row's record.
#[inline(always)]
pub(super) fn measure<L: Lane>(
    block: &mut TreeBlock,
    topology: &Topology,
    rows: &BodyRows,
    start: usize,
    scale: SubstepScale,
) {
    let zero = L::splat(0.0);
    for (n, node) in topology.nodes.iter().enumerate() {
        let mut measured = [zero; MEASURED];
        match node.kind {
            NodeKind::Body { index } => {
                let body = &block.bodies[index as usize];
                let q = BodyLanes::<L>::gather(rows, &body.row[start..]).q;
                let mass = L::load(&body.mass[start..]);
                let inertia = body.inertia_lanes::<L>(start).rotated(q);
                measured = [
                    mass, inertia.xx, inertia.xy, inertia.xz, inertia.yy, inertia.yz, inertia.zz,
                ];
            }
            NodeKind::Joint {
                index,
                rows: kind,
                a,
                b,
            } => {
                let joint = &block.joints[index as usize];
                let (body_a, body_b) = joint.bodies.gather::<L>(rows, start);
                let geometry = joint.geometry(start, scale);
                let mut measured_rows = Rows::measure(kind, &body_a, &body_b, &geometry);
                let count = if block.driven {
                    let drive = Rows::measure_drive(kind, &body_a, &body_b, &geometry);
                    record_drive(
                        &mut block.scratch[n],
                        kind,
                        &drive,
                        (&body_a, &body_b),
                        start,
                    );
                    for k in kind.first_drive()..kind.count() {
                        measured_rows.c[k] = drive.c[k];
                        (measured_rows.ja[k], measured_rows.jb[k]) = (drive.ja[k], drive.jb[k]);
                    }
                    kind.count()
                } else {
                    kind.first_drive()
                };
                let first = kind.first_limit();
                measured[..first].copy_from_slice(&measured_rows.c[..first]);
                let back = Return {
                    hard: !joint.soft_lanes::<L>(start),
                    step: L::splat(MAX_LIMIT_RETURN_SPEED / scale.inv_h),
                };
                record_limits(
                    &mut block.scratch[n],
                    (kind, joint, back),
                    &measured_rows,
                    (&body_a, &body_b),
                    start,
                );
                // The parent side: the parent body, or the root joint's
                // side with no node.
                let b_is_parent = b == node.parent || (node.parent == NONE && b == NONE);
                let (parent, child, child_node) = if b_is_parent {
                    (&measured_rows.jb, &measured_rows.ja, a)
                } else {
                    (&measured_rows.ja, &measured_rows.jb, b)
                };
                store(
                    parent[..count].as_flattened(),
                    &mut block.scratch[n].coupling,
                    start,
                );
                if child_node != NONE {
                    store(
                        child[..count].as_flattened(),
                        &mut block.scratch[child_node as usize].coupling,
                        start,
                    );
                }
            }
        }
        store(&measured, &mut block.scratch[n].measured, start);
    }
    for pins in block.pins.iter_mut() {
        pin::measure::<L>(pins, rows, start);
    }
}

/// How a joint's hard limit rows come back from far past their bounds
/// ([`MAX_LIMIT_RETURN_SPEED`]).
struct Return<L: Lane> {
    /// The lanes whose limits are hard (a soft limit's own spring and
    /// damping bound its return).
    hard: L::Mask,
    /// What a substep takes back (`MAX_LIMIT_RETURN_SPEED h`).
    step: L,
}

/// Records a joint's limit rows as measured (for the active set and
/// [`settle`]: each row's signed distance, its angular Jacobians and its
/// generalised inverse mass `w = j_a^T I_a^-1 j_a + j_b^T I_b^-1 j_b`).
/// A hard row's distance is taken from where the substep lets it end:
/// its violation at the substep's start (`JointNode::limit_start`) less
/// a substep's return, none for a row that started less than that past
/// its bound (whose distance is then its own, bit for bit).
#[inline(always)]
fn record_limits<L: Lane>(
    scratch: &mut super::NodeScratch,
    (kind, joint, back): (JointRows, &JointNode, Return<L>),
    measured: &Rows<L>,
    (a, b): (&BodyLanes<L>, &BodyLanes<L>),
    start: usize,
) {
    let zero = L::splat(0.0);
    for (l, k) in (kind.first_limit()..kind.first_drive()).enumerate() {
        let mut record = [zero; RECORD];
        record[1..4].copy_from_slice(&measured.ja[k][3..6]);
        record[4..7].copy_from_slice(&measured.jb[k][3..6]);
        let ja = Vec3::new(record[1], record[2], record[3]);
        let jb = Vec3::new(record[4], record[5], record[6]);
        let excess = (L::load(&joint.limit_start[l][start..]) - back.step).max(zero);
        record[0] = measured.c[k] - L::select(back.hard, excess, zero);
        record[7] = inverse_mass(a, ja) + inverse_mass(b, jb);
        store(
            &record,
            &mut scratch.limits[l * RECORD..(l + 1) * RECORD],
            start,
        );
    }
}

/// Records a joint's drive rows as measured (for their right-hand sides
/// and [`accumulate`]: each row's error and its generalised inverse mass
/// `w = j^T I_a^-1 j + j^T I_b^-1 j`, its `J_b`'s angular part `j`).
#[inline(always)]
fn record_drive<L: Lane>(
    scratch: &mut super::NodeScratch,
    kind: JointRows,
    measured: &Rows<L>,
    (a, b): (&BodyLanes<L>, &BodyLanes<L>),
    start: usize,
) {
    for (r, k) in (kind.first_drive()..kind.count()).enumerate() {
        let jb = &measured.jb[k];
        let j = Vec3::new(jb[3], jb[4], jb[5]);
        let w = inverse_mass(a, j) + inverse_mass(b, j);
        let at = r * DRIVE_RECORD;
        store(&[measured.c[k], w], &mut scratch.drive[at..at + 2], start);
    }
}

/// `j^T I^-1 j` for a world axis `j` (the body's inverse inertia is in its
/// own frame).
#[inline(always)]
fn inverse_mass<L: Lane>(body: &BodyLanes<L>, j: Vec3<L>) -> L {
    let local = body.q.inverse_rotate(j);
    local.dot(body.inv_inertia.mul_vec(local))
}

// ---------------------------------------------------------------------------
// The active set between the phases (plain code over the lanes).
// ---------------------------------------------------------------------------

/// Chooses which limit rows each lane holds in this pass: in a fresh
/// solve's first pass those violated now (`c > 0`), else the set the last
/// settle left; and records, per joint node, the lanes holding each row.
pub(super) fn hold(block: &mut TreeBlock, topology: &Topology, first_pass: bool) {
    let fresh = block.fresh && first_pass;
    for (n, node) in topology.nodes.iter().enumerate() {
        let NodeKind::Joint {
            index, rows: kind, ..
        } = node.kind
        else {
            continue;
        };
        let limits = kind.limit_count();
        let drive = &block.joints[index as usize].drive;
        let scratch = &mut block.scratch[n];
        let mut bits = [0u8; MAX_OPTIONAL];
        for (o, lane_bits) in bits
            .iter_mut()
            .enumerate()
            .take(kind.count() - kind.first_limit())
        {
            for lane in 0..BLOCK_LANES {
                if o >= limits {
                    // A drive's rows: held where the lane has a drive.
                    scratch.active[o][lane] = if block.driven {
                        drive.settings.enabled[lane]
                    } else {
                        0.0
                    };
                } else if fresh {
                    let c = scratch.limits[o * RECORD][lane];
                    scratch.active[o][lane] = if c > 0.0 { 1.0 } else { 0.0 };
                }
                if first_pass {
                    scratch.first[o][lane] = scratch.active[o][lane];
                }
                *lane_bits |= u8::from(scratch.active[o][lane] > 0.0) << lane;
            }
        }
        block.held[n] = bits;
    }
}

/// After a settle in which some tree crossed: every lane of such a tree
/// takes the set the settle chose, and marks for factoring again each
/// joint whose set changed or whose drive the settle capped, and the body
/// below it (their ancestors follow in the elimination).
pub(super) fn take_crossings(block: &mut TreeBlock, topology: &Topology) {
    let crossing = block.crossing;
    for (n, node) in topology.nodes.iter().enumerate() {
        let NodeKind::Joint {
            index,
            rows: kind,
            a,
            b,
        } = node.kind
        else {
            continue;
        };
        let limits = kind.limit_count();
        let drive = &mut block.joints[index as usize].drive;
        let scratch = &mut block.scratch[n];
        let mut changed = 0u8;
        for (lane, &crossed) in crossing.iter().enumerate() {
            if crossed == 0.0 {
                continue;
            }
            // A drive's cap is taken once the tree's pins have settled (or
            // their passes are spent: `join_crossings` clears their flag).
            if block.driven && flags(crossed) & PIN_CROSSED == 0 && drive.take(lane) {
                changed |= 1 << lane;
            }
            for o in 0..limits {
                if scratch.next[o][lane] != scratch.active[o][lane] {
                    changed |= 1 << lane;
                    scratch.active[o][lane] = scratch.next[o][lane];
                }
            }
        }
        block.dirty[n] |= changed;
        for side in [a, b] {
            if side != NONE && side != node.parent {
                block.dirty[side as usize] |= changed;
            }
        }
    }
    if block.pinned() {
        for (n, node) in topology.nodes.iter().enumerate() {
            if let NodeKind::Body { index } = node.kind {
                block.dirty[n] |= pin::take(&mut block.pins[index as usize], &crossing);
            }
        }
    }
}

/// The set the last settle chose, releases included, as the next
/// solve's start.
pub(super) fn adopt(block: &mut TreeBlock) {
    for scratch in block.scratch.iter_mut() {
        scratch.active = scratch.next;
    }
}

/// A lane's crossings, flags summed into one value per lane: a limit
/// row's (another pass while the solve's bound allows), a drive's cap
/// reached (taken once the tree's pins settle, or in one pass more when
/// their passes are spent), a pin's (another pass up to
/// [`pin::PIN_PASSES`]).
const LIMIT_CROSSED: u8 = 1;
/// See [`LIMIT_CROSSED`].
const DRIVE_CAPPED: u8 = 2;
/// See [`LIMIT_CROSSED`].
const PIN_CROSSED: u8 = 4;

/// A lane's crossing flags.
fn flags(crossing: f32) -> u8 {
    crossing as u8
}

/// Adds `theirs`'s crossing flags to `mine`.
fn join(mine: &mut f32, theirs: f32) {
    *mine = f32::from(flags(*mine) | flags(theirs));
}

/// `flag` in the lanes of `mask`, else 0.
#[inline(always)]
fn flag<L: Lane>(mask: L::Mask, flag: u8) -> L {
    L::select(mask, L::splat(f32::from(flag)), L::splat(0.0))
}

/// Where a solve's passes stand: this pass, the passes its limits may
/// take, and the pins' (and the drives' caps').
#[derive(Clone, Copy)]
pub(super) struct Bounds {
    /// This pass (from 1).
    pub pass: usize,
    /// The limits' passes.
    pub passes: usize,
    /// The pins' passes ([`restart`]ed lanes take as many again).
    pub most: usize,
}

/// Joins each tree's crossings across the blocks its pieces take: a trunk
/// crosses where a piece hanging from it does, and every piece where its
/// trunk does. Then, lane by lane: once the limits' passes are spent,
/// their crossings no longer count; once the pins' are (`most`, or twice
/// that and a pass in a restarted lane), only drives' caps do, for one
/// pass more, and a lane whose pins still cross as their passes run out is
/// marked [`TreeBlock::unsettled`]. Returns whether any tree crossed.
pub(super) fn join_crossings(blocks: &mut [TreeBlock], bounds: Bounds) -> bool {
    join_pieces(blocks);
    let Bounds { pass, passes, most } = bounds;
    let mut any = false;
    for block in blocks.iter_mut() {
        for (lane, c) in block.crossing.iter_mut().enumerate() {
            let restarted = block.restarted & (1 << lane) != 0;
            let pins = if restarted {
                most + pin::PIN_PASSES
            } else {
                most
            };
            let mut kept = !0u8;
            if pass >= passes {
                kept &= !LIMIT_CROSSED;
            }
            if pass == pins && flags(*c) & PIN_CROSSED != 0 {
                block.unsettled |= 1 << lane;
            }
            if pass >= pins {
                kept &= !PIN_CROSSED;
            }
            if pass > pins {
                kept = 0;
            }
            *c = f32::from(flags(*c) & kept);
            any |= *c != 0.0;
        }
    }
    any
}

/// Joins each tree's [`TreeBlock::crossing`] flags across the blocks its
/// pieces take: a trunk gets those of every piece hanging from it, then
/// every piece its trunk's.
pub(super) fn join_pieces(blocks: &mut [TreeBlock]) {
    join_across_pieces(blocks, crossing_of, join);
}

/// A block's [`TreeBlock::crossing`].
pub(super) fn crossing_of(block: &mut TreeBlock) -> &mut [f32; BLOCK_LANES] {
    &mut block.crossing
}

/// Joins a per-lane value of each tree (`value` of a block) across the
/// blocks its pieces take with `join(mine, theirs)`: a trunk takes in
/// every piece hanging from it, then every piece its trunk. So a tree cut
/// into pieces reaches the value it would have whole.
pub(super) fn join_across_pieces(
    blocks: &mut [TreeBlock],
    value: fn(&mut TreeBlock) -> &mut [f32; BLOCK_LANES],
    join: fn(&mut f32, f32),
) {
    for k in 0..blocks.len() {
        let (before, rest) = blocks.split_at_mut(k);
        let block = &mut rest[0];
        for p in 0..block.ports.len() {
            for lane in 0..BLOCK_LANES {
                if let Some(s) = block.ports[p].source[lane] {
                    let theirs = value(&mut before[s.block as usize])[s.lane as usize];
                    join(&mut value(block)[lane], theirs);
                }
            }
        }
    }
    for k in (0..blocks.len()).rev() {
        let (head, after) = blocks.split_at_mut(k + 1);
        let block = &mut head[k];
        for lane in 0..BLOCK_LANES {
            if let Some(s) = block.parent[lane] {
                let theirs = value(&mut after[s.block as usize - k - 1])[s.lane as usize];
                join(&mut value(block)[lane], theirs);
            }
        }
    }
}

/// After the pass that spent the pins' passes (`most`) in a solve with
/// pins, the lanes where a drive's cap was found (and taken): the drive was
/// uncapped in every pass so far, and the pins' states those passes chose
/// hold what an uncapped drive pushed (a heap a drive straightens chose
/// them so, and kept the push as speed). Their pins and limits go back to
/// the solve's start, and the lanes take the pins' passes again, with the
/// drive capped. Returns the lanes restarted.
pub(super) fn restart(block: &mut TreeBlock) -> u8 {
    let mut lanes = 0u8;
    for (lane, &c) in block.crossing.iter().enumerate() {
        if flags(c) & DRIVE_CAPPED != 0 && block.restarted & (1 << lane) == 0 {
            lanes |= 1 << lane;
        }
    }
    if lanes == 0 {
        return 0;
    }
    start_again(block, lanes);
    block.restarted |= lanes;
    block.unsettled &= !lanes;
    lanes
}

/// The pins and limits of `lanes` as the solve began (`pin::restart`, the
/// first pass's active set), every node of theirs marked for factoring.
pub(super) fn start_again(block: &mut TreeBlock, lanes: u8) {
    for lane in 0..BLOCK_LANES {
        if lanes & (1 << lane) == 0 {
            continue;
        }
        for pins in block.pins.iter_mut() {
            pin::restart(pins, lane);
        }
        for scratch in block.scratch.iter_mut() {
            for o in 0..MAX_OPTIONAL {
                scratch.active[o][lane] = scratch.first[o][lane];
            }
        }
    }
    for dirty in block.dirty.iter_mut() {
        *dirty |= lanes;
    }
}

/// Copies into block `k`'s ports their subtrees' complements (and which
/// lanes were eliminated again), from the earlier blocks they lie in.
pub(super) fn take_ports(blocks: &mut [TreeBlock], k: usize) {
    let (before, rest) = blocks.split_at_mut(k);
    let block = &mut rest[0];
    for port in block.ports.iter_mut() {
        port.dirty = 0;
        for (lane, source) in port.source.iter().enumerate() {
            let Some(s) = source else {
                continue;
            };
            let from = &before[s.block as usize];
            let scratch = &from.scratch[s.node as usize];
            let at = s.lane as usize;
            for (to, from) in port.minus.iter_mut().zip(&scratch.minus) {
                to[lane] = from[at];
            }
            for (to, from) in port.minus_b.iter_mut().zip(&scratch.minus_b) {
                to[lane] = from[at];
            }
            port.dirty |= ((from.dirty[s.node as usize] >> at) & 1) << lane;
        }
    }
}

/// Copies into block `k` each lane's parent body's unknowns, from the
/// later block its trunk lies in.
pub(super) fn take_parent(blocks: &mut [TreeBlock], k: usize) {
    let (head, after) = blocks.split_at_mut(k + 1);
    let block = &mut head[k];
    for (lane, source) in block.parent.iter().enumerate() {
        let Some(s) = source else {
            continue;
        };
        let from = &after[s.block as usize - k - 1].scratch[s.node as usize];
        for (to, x) in block.parent_x.iter_mut().zip(&from.x) {
            to[lane] = x[s.lane as usize];
        }
    }
}

// ---------------------------------------------------------------------------
// Eliminate.
// ---------------------------------------------------------------------------

/// Leaves first: every node with a lane of the slice to factor again (its
/// own set changed, or a child's block) takes its children's complements,
/// is factored, and leaves its own for its parent.
#[inline(always)]
pub(super) fn eliminate<L: Lane>(
    block: &mut TreeBlock,
    topology: &Topology,
    start: usize,
    scale: SubstepScale,
) {
    let bits = slice_bits::<L>(start);
    for (n, node) in topology.nodes.iter().enumerate() {
        let mut dirty = block.dirty[n];
        for &child in topology.children(n) {
            dirty |= match child {
                Child::Node(c) => block.dirty[c as usize],
                Child::Port(p) => block.ports[p as usize].dirty,
            };
        }
        block.dirty[n] = dirty;
        if dirty & bits == 0 {
            continue;
        }
        match node.kind {
            NodeKind::Body { .. } => {
                let factors = body_block::<L>(block, topology, n, start);
                if node.parent != NONE {
                    let p = node.parent as usize;
                    let NodeKind::Joint { rows, .. } = topology.nodes[p].kind else {
                        unreachable!("a body's parent is a joint");
                    };
                    by_rows!(rows, body_out::<L>(block, n, p, &factors, start));
                }
            }
            NodeKind::Joint { rows, .. } => {
                by_rows!(rows, joint_node::<L>(block, topology, n, start, scale));
            }
        }
    }
}

/// Body node `n`'s block: its mass matrix and its children's complements,
/// factored; returns the factors (also kept, with its right-hand side).
#[inline(always)]
fn body_block<L: Lane>(
    block: &mut TreeBlock,
    topology: &Topology,
    n: usize,
    start: usize,
) -> [L; PACKED] {
    let zero = L::splat(0.0);
    let [mass, xx, xy, xz, yy, yz, zz] = load::<L, MEASURED>(&block.scratch[n].measured, start);
    let mut d = [zero; PACKED];
    for k in 0..3 {
        d[at(k, k)] = mass;
    }
    (d[at(3, 3)], d[at(4, 3)], d[at(5, 3)]) = (xx, xy, xz);
    (d[at(4, 4)], d[at(5, 4)], d[at(5, 5)]) = (yy, yz, zz);
    let mut b = [zero; MAX];
    for &child in topology.children(n) {
        let (minus, minus_b) = match child {
            Child::Node(c) => {
                let s = &block.scratch[c as usize];
                (&s.minus, &s.minus_b)
            }
            Child::Port(p) => {
                let port = &block.ports[p as usize];
                (&port.minus, &port.minus_b)
            }
        };
        // A body's entries only, not the largest block's (the rest
        // stay zero).
        let minus = load::<L, BODY_PACKED>(minus, start);
        let minus_b = load::<L, 6>(minus_b, start);
        for (d, m) in d.iter_mut().zip(&minus) {
            *d += *m;
        }
        for (b, m) in b.iter_mut().zip(&minus_b) {
            *b -= *m;
        }
    }
    if let NodeKind::Body { index } = topology.nodes[n].kind
        && let Some(pins) = block.pins.get(index as usize)
    {
        pin::add_to_block::<L>(pins, &mut d, &mut b, start);
    }
    ldl::factor::<L, 6>(&mut d);
    let scratch = &mut block.scratch[n];
    store(&d[..BODY_PACKED], &mut scratch.factors, start);
    store(&b[..6], &mut scratch.b, start);
    d
}

/// Body node `n`'s complement for its parent joint `p` of `E + K` rows:
/// with `A` the joint's rows on the body and `w = L^-1 A^T` (forward
/// solves), `A D^-1 A^T = w^T D^-1 w` and `A D^-1 b = w^T D^-1 L^-1 b`.
/// A limit row no lane of the slice holds is left out (the joint never
/// reads it there).
// Row indices address several arrays and the packed block (`at(i, j)`).
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn body_out<L: Lane, const E: usize, const K: usize>(
    block: &mut TreeBlock,
    n: usize,
    p: usize,
    factors: &[L; PACKED],
    start: usize,
) {
    let zero = L::splat(0.0);
    let held = held::<L, E, K>(block, p, start);
    let scratch = &block.scratch[n];
    let coupling = load_first::<L, { MAX * 6 }>(&scratch.coupling, start, (E + K) * 6);
    let mut z = load_first::<L, MAX>(&scratch.b, start, 6);
    ldl::forward::<L, 6>(factors, &mut z);
    // Each row's six entries on the body only: arrays sized for the
    // largest block (9 x 9) would be zeroed whole at every call.
    let mut w = [[zero; 6]; MAX];
    let mut scaled = [[zero; 6]; MAX];
    for i in 0..E + K {
        if !held.computed(E, i) {
            continue;
        }
        let mut row = [zero; MAX];
        row[..6].copy_from_slice(&coupling[i * 6..i * 6 + 6]);
        ldl::forward::<L, 6>(factors, &mut row);
        for k in 0..6 {
            w[i][k] = row[k];
            scaled[i][k] = row[k] * factors[at(k, k)];
        }
    }
    let scratch = &mut block.scratch[n];
    for i in 0..E + K {
        if !held.computed(E, i) {
            continue;
        }
        for j in 0..=i {
            if !held.computed(E, j) {
                continue;
            }
            let mut m = zero;
            for k in 0..6 {
                m -= scaled[i][k] * w[j][k];
            }
            m.store(&mut scratch.minus[at(i, j)][start..]);
        }
        let mut m = zero;
        for k in 0..6 {
            m -= scaled[i][k] * z[k];
        }
        m.store(&mut scratch.minus_b[i][start..]);
    }
}

/// Joint node `n` of `E` equality and `K` limit rows: its block (zero for
/// hard rows, a soft limit's compliance) and right-hand side (its errors)
/// with its child body's complement, factored with the rows each lane
/// holds; then its complement for its parent body (for the root joint,
/// the body its static, kinematic or other block's side stands for):
/// with `A` its rows on that body and `w = L^-1 A`, `A^T D^-1 A = w^T
/// D^-1 w`.
// Row indices address several arrays and the packed block (`at(i, j)`).
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn joint_node<L: Lane, const E: usize, const K: usize>(
    block: &mut TreeBlock,
    topology: &Topology,
    n: usize,
    start: usize,
    scale: SubstepScale,
) {
    let zero = L::splat(0.0);
    let held = held::<L, E, K>(block, n, start);
    let NodeKind::Joint {
        index, rows: kind, ..
    } = topology.nodes[n].kind
    else {
        unreachable!("a joint node");
    };
    let limits = kind.limit_count();
    let mut d = [zero; PACKED];
    let mut b = [zero; MAX];
    {
        let scratch = &block.scratch[n];
        let measured = load::<L, MEASURED>(&scratch.measured, start);
        b[..E].copy_from_slice(&measured[..E]);
        for o in 0..limits {
            if held.any[o] {
                b[E + o] = L::load(&scratch.limits[o * RECORD][start..]);
            }
        }
    }
    if block.soft && limits > 0 {
        let joint = &block.joints[index as usize];
        soften::<L, E, K>(
            block,
            (n, kind),
            joint,
            &held,
            (start, scale),
            (&mut d, &mut b),
        );
    }
    if block.driven && K > limits {
        let rows = drive_rows::<L, E, K>(block, (n, index as usize, limits), &held, (start, scale));
        for (k, (dk, bk)) in (E + limits..E + K).zip(rows) {
            (d[at(k, k)], b[k]) = (dk, bk);
        }
    }
    for &child in topology.children(n) {
        let Child::Node(c) = child else {
            unreachable!("a joint's child is a body of its block");
        };
        let s = &block.scratch[c as usize];
        for i in 0..E + K {
            if !held.computed(E, i) {
                continue;
            }
            for j in 0..=i {
                if held.computed(E, j) {
                    d[at(i, j)] += L::load(&s.minus[at(i, j)][start..]);
                }
            }
            b[i] -= L::load(&s.minus_b[i][start..]);
        }
    }
    ldl::factor_held::<L, E, K>(&mut d, &held);
    let scratch = &mut block.scratch[n];
    store(&d[..at(E + K, 0)], &mut scratch.factors, start);
    store(&b[..E + K], &mut scratch.b, start);
    ldl::forward_held::<L, E, K>(&d, &mut b, &held);
    let mut scaled = [[zero; MAX]; 6];
    let mut w = [[zero; MAX]; 6];
    for c in 0..6 {
        for i in 0..E + K {
            w[c][i] = L::load(&scratch.coupling[i * 6 + c][start..]);
        }
        ldl::forward_held::<L, E, K>(&d, &mut w[c], &held);
        for i in 0..E + K {
            if held.computed(E, i) {
                scaled[c][i] = w[c][i] * d[at(i, i)];
            }
        }
    }
    for r in 0..6 {
        for s in 0..=r {
            let mut m = zero;
            for i in 0..E + K {
                if held.computed(E, i) {
                    m -= scaled[r][i] * w[s][i];
                }
            }
            m.store(&mut scratch.minus[at(r, s)][start..]);
        }
        let mut m = zero;
        for i in 0..E + K {
            if held.computed(E, i) {
                m -= scaled[r][i] * b[i];
            }
        }
        m.store(&mut scratch.minus_b[r][start..]);
    }
}

/// A soft limit's row (`parts::limit`, whose header derives the step):
/// with `alpha = alpha~ + spring w` (`w` the row's own generalised inverse
/// mass) and `gamma` the damping, XPBD's damped step
/// `((1 + gamma) J dx + alpha dlambda = -(C + alpha lambda + gamma (C -
/// C_0))` divided by `1 + gamma`: `-alpha / (1 + gamma)` on the row's
/// diagonal, the right-hand side over `1 + gamma`. Zero compliance and
/// damping leave the hard row as it was, bit for bit.
#[inline(always)]
fn soften<L: Lane, const E: usize, const K: usize>(
    block: &TreeBlock,
    (n, kind): (usize, JointRows),
    joint: &JointNode,
    held: &Held<L, K>,
    (start, scale): (usize, SubstepScale),
    (d, b): (&mut [L; PACKED], &mut [L; MAX]),
) {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let soft = joint
        .softness
        .lanes(start, L::splat(scale.inv_h), L::splat(scale.inv_h2));
    let soft: &Softness<L> = &soft;
    for o in 0..kind.limit_count() {
        if !held.any[o] {
            continue;
        }
        let k = E + o;
        let active = held.lanes[o];
        let record = &block.scratch[n].limits[o * RECORD..(o + 1) * RECORD];
        let (c, w) = (L::load(&record[0][start..]), L::load(&record[7][start..]));
        let quarter = if kind.is_sine_row(k) {
            L::splat(0.25)
        } else {
            one
        };
        let alpha = soft.alpha_tilde * quarter + soft.spring * w;
        let lambda = L::select(active, L::load(&joint.limit_lambda[o][start..]), zero);
        let c0 = L::load(&joint.limit_start[o][start..]);
        let damping = L::select(active, soft.gamma * (c - c0), zero);
        let inv = one / (one + soft.gamma);
        let damped = (soft.alpha_tilde + soft.spring + soft.gamma).gt(zero) & active;
        b[k] = L::select(damped, (c + alpha * lambda + damping) * inv, b[k]);
        d[at(k, k)] = L::select(damped, -(alpha * inv), d[at(k, k)]);
    }
}

/// A joint's drive rows (`super::drive`): each held row's diagonal entry
/// and right-hand side (`+0` in a lane that does not hold it; soft in a
/// lane that holds one of the joint's limits, and for an uncapped drive in
/// a lane whose tree takes pins), its target recorded for [`accumulate`].
#[inline(always)]
fn drive_rows<L: Lane, const E: usize, const K: usize>(
    block: &mut TreeBlock,
    (n, index, limits): (usize, usize, usize),
    held: &Held<L, K>,
    (start, scale): (usize, SubstepScale),
) -> [(L, L); MAX_DRIVE_ROWS] {
    let zero = L::splat(0.0);
    let steps = (L::splat(scale.inv_h), L::splat(scale.inv_h2));
    let mut limited = zero.gt(zero);
    for &lanes in &held.lanes[..limits] {
        limited = limited | lanes;
    }
    if block.pinned() {
        let mut pinned = zero.gt(zero);
        for pins in &block.pins {
            pinned = pinned | L::load(&pins.stiffness[start..]).gt(zero);
        }
        limited = limited | (pinned & block.joints[index].drive.uncapped::<L>(start));
    }
    let mut out = [(zero, zero); MAX_DRIVE_ROWS];
    for (r, o) in (limits..K).enumerate() {
        if !held.any[o] {
            continue;
        }
        let at = r * DRIVE_RECORD;
        let record = &mut block.scratch[n].drive[at..at + DRIVE_RECORD];
        let [c, w, _] = load::<L, DRIVE_RECORD>(record, start);
        let drive = &block.joints[index].drive;
        let (d, b, target) = drive.row(r, (c, w, limited), start, steps);
        target.store(&mut record[2][start..]);
        out[r] = (held.keep(E, E + o, d), held.keep(E, E + o, b));
    }
    out
}

// ---------------------------------------------------------------------------
// Substitute.
// ---------------------------------------------------------------------------

/// Root first: each node's unknowns from its factors, its right-hand side
/// and its parent's unknowns (`x = D^-1 (b + J x_p)` for a joint, `D^-1
/// (b + J^T x_p)` for a body; a root joint's parent is
/// `TreeBlock::parent_x`, zero for a static or kinematic body).
#[inline(always)]
pub(super) fn substitute<L: Lane>(block: &mut TreeBlock, topology: &Topology, start: usize) {
    for (n, node) in topology.nodes.iter().enumerate().rev() {
        match node.kind {
            NodeKind::Body { .. } => {
                if node.parent == NONE {
                    body_unknowns::<L, 0, 0>(block, n, None, start);
                } else {
                    let p = node.parent as usize;
                    let NodeKind::Joint { rows, .. } = topology.nodes[p].kind else {
                        unreachable!("a body's parent is a joint");
                    };
                    by_rows!(rows, body_unknowns::<L>(block, n, Some(p), start));
                }
            }
            NodeKind::Joint { rows, .. } => {
                by_rows!(rows, joint_unknowns::<L>(block, n, node.parent, start));
            }
        }
    }
}

/// Body node `n`'s unknowns, from its parent joint `p`'s multipliers
/// (`E + K` rows; a limit row taken only where held).
#[inline(always)]
fn body_unknowns<L: Lane, const E: usize, const K: usize>(
    block: &mut TreeBlock,
    n: usize,
    parent: Option<usize>,
    start: usize,
) {
    let scratch = &block.scratch[n];
    let factors = load_first::<L, PACKED>(&scratch.factors, start, BODY_PACKED);
    let mut y = load_first::<L, MAX>(&scratch.b, start, 6);
    if let Some(p) = parent {
        let held = held::<L, E, K>(block, p, start);
        let xp = load_first::<L, MAX>(&block.scratch[p].x, start, E + K);
        let coupling = load_first::<L, { MAX * 6 }>(&scratch.coupling, start, (E + K) * 6);
        for i in 0..E {
            for c in 0..6 {
                y[c] += coupling[i * 6 + c] * xp[i];
            }
        }
        for o in 0..K {
            if !held.any[o] {
                continue;
            }
            let i = E + o;
            for c in 0..6 {
                y[c] = L::select(held.lanes[o], y[c] + coupling[i * 6 + c] * xp[i], y[c]);
            }
        }
    }
    ldl::solve::<L, 6>(&factors, &mut y);
    store(&y[..6], &mut block.scratch[n].x, start);
}

/// Joint node `n`'s multipliers, from its parent body's unknowns (the
/// block's `parent_x` for the root joint).
#[inline(always)]
fn joint_unknowns<L: Lane, const E: usize, const K: usize>(
    block: &mut TreeBlock,
    n: usize,
    parent: u32,
    start: usize,
) {
    let held = held::<L, E, K>(block, n, start);
    let xp = if parent == NONE {
        load::<L, 6>(&block.parent_x, start)
    } else {
        load::<L, 6>(&block.scratch[parent as usize].x, start)
    };
    let scratch = &block.scratch[n];
    let factors = load_first::<L, PACKED>(&scratch.factors, start, at(E + K, 0));
    let mut y = load_first::<L, MAX>(&scratch.b, start, E + K);
    let coupling = load_first::<L, { MAX * 6 }>(&scratch.coupling, start, (E + K) * 6);
    for i in 0..E + K {
        if held.computed(E, i) {
            for c in 0..6 {
                y[i] += coupling[i * 6 + c] * xp[c];
            }
        }
    }
    ldl::solve_held::<L, E, K>(&factors, &mut y, &held);
    store(&y[..E + K], &mut block.scratch[n].x, start);
}

// ---------------------------------------------------------------------------
// Settle.
// ---------------------------------------------------------------------------

/// The active set's hysteresis (rad, or swing sines for an ellipse): how
/// far past its limit a step must carry a row not held before [`settle`]
/// holds it, and how far inside a held row's release must let it move
/// (its multiplier times its `w`) before [`settle`] lets it go. A row on
/// its boundary to round-off is then neither held nor released pass after
/// pass (in the drop, without the margin, most solves took the bound on
/// passes).
const CROSSING: f32 = 1.0e-4;

/// The active set after a solve, for every joint's limit rows, from the
/// solve's multipliers and its step: a held row whose multiplier would
/// pull by more than the hysteresis (`w (lambda + dlambda) > CROSSING`
/// for a soft row's accumulated `lambda`, `w dlambda` for a hard row's:
/// the step moves it toward the limit) is released; a row not held that
/// the step would carry past its limit (`c + J_a dx_a + J_b dx_b >
/// CROSSING`, linearised) is held. The set is kept in `next`, the next
/// solve's start ([`adopt`]), and the lanes where a row crossed are
/// marked in `TreeBlock::crossing`. Only a crossing makes the tree worth
/// factoring again: a held row that pulls violates nothing, it only holds
/// its joint on the boundary until the next solve releases it. So a tree
/// where some row crosses takes its new set for another pass
/// ([`take_crossings`]), and every other keeps the set it had, which
/// gives it the same bits again. A drive whose step would pass its cap
/// crosses too (`super::drive`), and so do the pins ([`pin::settle`]).
#[inline(always)]
pub(super) fn settle<L: Lane>(
    block: &mut TreeBlock,
    topology: &Topology,
    start: usize,
    scale: SubstepScale,
) {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let mut pins_crossed = zero.gt(zero);
    for (n, node) in topology.nodes.iter().enumerate() {
        if let NodeKind::Body { index } = node.kind
            && let Some(pins) = block.pins.get_mut(index as usize)
        {
            let x = load::<L, 6>(&block.scratch[n].x, start);
            pins_crossed = pins_crossed | pin::settle::<L>(pins, &x, start);
        }
    }
    let mut crossed = zero.gt(zero);
    let mut capped = zero.gt(zero);
    for (n, node) in topology.nodes.iter().enumerate() {
        let NodeKind::Joint {
            index,
            rows: kind,
            a,
            b,
        } = node.kind
        else {
            continue;
        };
        let dlambda = load::<L, MAX>(&block.scratch[n].x, start);
        let (first, rows) = (kind.first_drive(), kind.count() - kind.first_drive());
        if block.driven && rows > 0 {
            let steps = &dlambda[first..first + rows];
            let drive = &mut block.joints[index as usize].drive;
            capped = capped | drive.settle(steps, start, scale.inv_h2);
        }
        let limits = kind.first_limit();
        if limits == first {
            continue;
        }
        let turn_a = turn_of(block, a, start);
        let turn_b = turn_of(block, b, start);
        let joint = &block.joints[index as usize];
        let soft = joint.soft_lanes::<L>(start);
        for (l, k) in (limits..kind.first_drive()).enumerate() {
            let scratch = &block.scratch[n];
            let record = load::<L, RECORD>(&scratch.limits[l * RECORD..(l + 1) * RECORD], start);
            let ja = Vec3::new(record[1], record[2], record[3]);
            let jb = Vec3::new(record[4], record[5], record[6]);
            let predicted = record[0] + ja.dot(turn_a) + jb.dot(turn_b);
            let held = L::load(&scratch.active[l][start..]).gt(zero);
            let lambda = L::select(soft, L::load(&joint.limit_lambda[l][start..]), zero);
            let pulls = ((lambda + dlambda[k]) * record[7]).gt(L::splat(CROSSING));
            let crosses = predicted.gt(L::splat(CROSSING)) & record[0].gt(L::splat(FREE));
            let now = held.and_not(pulls) | crosses.and_not(held);
            crossed = crossed | now.and_not(held);
            L::select(now, one, zero).store(&mut block.scratch[n].next[l][start..]);
        }
    }
    let crossing = flag::<L>(crossed, LIMIT_CROSSED)
        + flag::<L>(capped, DRIVE_CAPPED)
        + flag::<L>(pins_crossed, PIN_CROSSED);
    crossing.store(&mut block.crossing[start..]);
}

/// A joint node's first `rows` drive records.
#[inline(always)]
fn drive_records<L: Lane>(
    scratch: &super::NodeScratch,
    rows: usize,
    start: usize,
) -> [[L; DRIVE_RECORD]; MAX_DRIVE_ROWS] {
    let mut records = [[L::splat(0.0); DRIVE_RECORD]; MAX_DRIVE_ROWS];
    for (r, record) in records.iter_mut().enumerate().take(rows) {
        let at = r * DRIVE_RECORD;
        *record = load::<L, DRIVE_RECORD>(&scratch.drive[at..], start);
    }
    records
}

/// Body node `n`'s turn from the solve (for none, the side of the root
/// joint with no node: its parent's, zero for a static or kinematic
/// body).
#[inline(always)]
fn turn_of<L: Lane>(block: &TreeBlock, n: u32, start: usize) -> Vec3<L> {
    let x = if n == NONE {
        load::<L, 6>(&block.parent_x, start)
    } else {
        load::<L, 6>(&block.scratch[n as usize].x, start)
    };
    Vec3::new(x[3], x[4], x[5])
}

// ---------------------------------------------------------------------------
// Finish.
// ---------------------------------------------------------------------------

/// Adds each held limit row's multiplier to its joint's substep total
/// (a soft limit's spring force; zero for a row not held), in the lanes
/// whose limits are soft (a hard row's is never read: so what shares its
/// block changes nothing); and each drive's rows' multipliers and
/// requested moves to its sums, capping it (`super::drive`).
#[inline(always)]
pub(super) fn accumulate<L: Lane>(
    block: &mut TreeBlock,
    topology: &Topology,
    start: usize,
    scale: SubstepScale,
) {
    if !block.soft && !block.driven {
        return;
    }
    for (n, node) in topology.nodes.iter().enumerate() {
        let NodeKind::Joint {
            index, rows: kind, ..
        } = node.kind
        else {
            continue;
        };
        let dlambda = load::<L, MAX>(&block.scratch[n].x, start);
        let joint = &mut block.joints[index as usize];
        if block.soft {
            let soft = joint.soft_lanes::<L>(start);
            for (l, k) in (kind.first_limit()..kind.first_drive()).enumerate() {
                let lambda = L::load(&joint.limit_lambda[l][start..]);
                L::select(soft, lambda + dlambda[k], lambda)
                    .store(&mut joint.limit_lambda[l][start..]);
            }
        }
        let rows = kind.count() - kind.first_drive();
        if block.driven && rows > 0 {
            let records = drive_records::<L>(&block.scratch[n], rows, start);
            let first = kind.first_drive();
            let steps = &dlambda[first..first + rows];
            (joint.drive).accumulate(steps, &records[..rows], start, scale.inv_h2);
        }
    }
}

/// Each limit row's violation as the substep starts (`C_0`, 0 within the
/// limit): a soft limit's damping, a hard limit's bounded return.
#[inline(always)]
pub(super) fn start_limits<L: Lane>(
    block: &mut TreeBlock,
    topology: &Topology,
    rows: &BodyRows,
    start: usize,
    h: f32,
) {
    let scale = SubstepScale {
        inv_h: 0.0,
        inv_h2: 0.0,
    };
    for node in &topology.nodes {
        let NodeKind::Joint {
            index, rows: kind, ..
        } = node.kind
        else {
            continue;
        };
        let joint = &mut block.joints[index as usize];
        let (a, b) = joint.bodies.gather::<L>(rows, start);
        let geometry = joint.geometry(start, scale);
        let measured = Rows::measure_limits(kind, &a, &b, &geometry);
        for (l, k) in (kind.first_limit()..kind.first_drive()).enumerate() {
            let violation = measured.c[k].max(L::splat(0.0));
            violation.store(&mut joint.limit_start[l][start..]);
        }
        if block.driven && kind.first_drive() < kind.count() {
            joint.drive.start(kind, (&a, &b), &geometry, start, h);
        }
    }
    for pins in block.pins.iter_mut() {
        pin::start_substep::<L>(pins, rows, start);
    }
}

/// The largest turn one solve gives a body (rad).
const MAX_TURN: f32 = 1.0;

/// Moves every body by its unknowns: `p += dp`, turned by the world
/// rotation vector `dtheta` (`q += 1/2 (dtheta, 0) q`, renormalised, as
/// every part turns a body).
#[inline(always)]
pub(super) fn apply<L: Lane>(
    block: &mut TreeBlock,
    topology: &Topology,
    rows: &BodyRows,
    start: usize,
) {
    for (n, node) in topology.nodes.iter().enumerate() {
        let NodeKind::Body { index } = node.kind else {
            continue;
        };
        let body = &block.bodies[index as usize];
        let mut lanes = BodyLanes::<L>::gather(rows, &body.row[start..]);
        let x = load_first::<L, MAX>(&block.scratch[n].x, start, 6);
        // A trust region: the rows are linear in the turn, so a turn of
        // more than a radian (a tree of near-dependent rows across a
        // million-to-one inertia ratio) is not a step the linearisation
        // vouches for. The body's whole step is scaled down to it; the
        // next solve re-linearises. Never reached in the scenes (their
        // golden hashes did not move).
        let turn = Vec3::new(x[3], x[4], x[5]);
        let (cap, angle) = (L::splat(MAX_TURN), turn.length());
        let scale = L::select(angle.gt(cap), cap / angle.max(cap), L::splat(1.0));
        let (dp, world_turn) = (Vec3::new(x[0], x[1], x[2]).scale(scale), turn.scale(scale));
        lanes.p += dp;
        let turn = lanes.q.inverse_rotate(world_turn);
        lanes.q = lanes.q.integrate_local(turn, L::splat(1.0));
        lanes.scatter_pose(rows, &body.write[start..]);
        if let Some(pins) = block.pins.get_mut(index as usize) {
            pin::finish::<L>(pins, start);
        }
        // What moved it, for the joints' forces (never read by the solve).
        let moved = &mut block.bodies[index as usize].moved;
        for (k, v) in [dp.x, dp.y, dp.z, world_turn.x, world_turn.y, world_turn.z]
            .into_iter()
            .enumerate()
        {
            (L::load(&moved[k][start..]) + v).store(&mut moved[k][start..]);
        }
    }
}

/// Every joint's rows and equality rows are the sizes `by_rows!` names
/// (`E`, and `K` = `count - E`).
const _: () = {
    use super::rows::SwingRows::{Cone, Ellipse, Pyramid};
    let (cone, ellipse, pyramid) = (
        JointRows::Socket(Cone, false),
        JointRows::Socket(Ellipse, false),
        JointRows::Socket(Pyramid, false),
    );
    assert!(cone.count() == 5 && ellipse.count() == 5 && pyramid.count() == 6);
    assert!(
        JointRows::Socket(Cone, true).count() == 8 && JointRows::Socket(Pyramid, true).count() == 9
    );
    assert!(JointRows::Rod.count() == 5 && JointRows::Fixed.count() == 6);
    assert!(JointRows::Hinge(false).count() == 6 && JointRows::Hinge(true).count() == 7);
    assert!(cone.first_limit() == 3 && JointRows::Rod.first_limit() == 3);
    assert!(JointRows::Hinge(true).first_limit() == 5 && JointRows::Fixed.first_limit() == 6);
    assert!(pyramid.limit_count() <= super::rows::MAX_LIMITS);
    let driven = JointRows::Socket(Pyramid, true);
    assert!(driven.count() - driven.first_limit() <= MAX_OPTIONAL);
};
