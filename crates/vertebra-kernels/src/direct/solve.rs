//! One direct solve of one slice of a [`TreeBlock`]: assemble every
//! node's block, eliminate leaves first, substitute root first, move the
//! bodies (the steps of `super`'s documentation).
//!
//! Every block size is a constant of its function (a body's 6, a joint's
//! 5 or 6 rows: [`JointRows::count`]), chosen per node by a `match` on the
//! topology (the same in every lane), so that the dense loops unroll and
//! stay in registers.

use vertebra_math::block::BLOCK_LANES;
use vertebra_math::{Lane, Mask, Sym3, Vec3};

use super::ldl::{self, MAX, PACKED, at};
use super::rows::{FREE, JointRows, LIMIT_RECORD as RECORD, MAX_LIMITS, Rows};
use super::{JointNode, MEASURED, NONE, NodeKind, SubstepScale, Topology, TreeBlock};
use crate::body::{BodyLanes, BodyRows};
use crate::parts::limit::Softness;

/// Loads lane values from scratch arrays.
#[inline(always)]
fn load<L: Lane, const N: usize>(src: &[[f32; BLOCK_LANES]], start: usize) -> [L; N] {
    let mut out = [L::splat(0.0); N];
    for (o, s) in out.iter_mut().zip(src) {
        *o = L::load(&s[start..]);
    }
    out
}

/// Stores lane values into scratch arrays.
#[inline(always)]
fn store<L: Lane>(values: &[L], dst: &mut [[f32; BLOCK_LANES]], start: usize) {
    for (v, d) in values.iter().zip(dst) {
        v.store(&mut d[start..]);
    }
}

/// Measures every node's block where the tree stands (bodies do not move
/// between a solve's passes, so only its first measures): a body's mass
/// matrix (world) and a joint's errors into `measured`, each joint's
/// Jacobians where the tree couples it to each body (its limit rows' are
/// [`hold`]'s), and each limit row's record.
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
                let [xx, yy, zz, xy, xz, yz] = load::<L, 6>(&body.inertia, start);
                let inertia = Sym3 {
                    xx,
                    yy,
                    zz,
                    xy,
                    xz,
                    yz,
                }
                .rotated(q);
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
                let rows = Rows::measure(kind, &body_a, &body_b, &geometry);
                let first = kind.first_limit();
                measured[..first].copy_from_slice(&rows.c[..first]);
                record_limits(
                    &mut block.scratch[n],
                    kind,
                    &rows,
                    (&body_a, &body_b),
                    start,
                );
                for (side, jacobian) in [(a, &rows.ja), (b, &rows.jb)] {
                    if side == NONE {
                        continue;
                    }
                    let mut flat = [zero; MAX * 6];
                    for (r, row) in jacobian.iter().take(first).enumerate() {
                        flat[r * 6..r * 6 + 6].copy_from_slice(row);
                    }
                    let holder = holder(n, node.parent, side);
                    store(
                        &flat[..first * 6],
                        &mut block.scratch[holder].coupling,
                        start,
                    );
                }
            }
        }
        store(&measured, &mut block.scratch[n].measured, start);
    }
}

/// Which node holds the coupling of joint node `n` (parent `parent`) to
/// its body node `side`: whichever of the two is the other's child.
#[inline(always)]
fn holder(n: usize, parent: u32, side: u32) -> usize {
    if parent == side { n } else { side as usize }
}

/// Records a joint's limit rows as measured (for [`hold`] and [`settle`]:
/// each row's signed distance, its angular Jacobians and its generalised
/// inverse mass `w = j_a^T I_a^-1 j_a + j_b^T I_b^-1 j_b`).
#[inline(always)]
fn record_limits<L: Lane>(
    scratch: &mut super::NodeScratch,
    kind: JointRows,
    measured: &Rows<L>,
    (a, b): (&BodyLanes<L>, &BodyLanes<L>),
    start: usize,
) {
    let zero = L::splat(0.0);
    for (l, k) in (kind.first_limit()..kind.count()).enumerate() {
        let mut record = [zero; RECORD];
        record[0] = measured.c[k];
        record[1..4].copy_from_slice(&measured.ja[k][3..6]);
        record[4..7].copy_from_slice(&measured.jb[k][3..6]);
        let ja = Vec3::new(record[1], record[2], record[3]);
        let jb = Vec3::new(record[4], record[5], record[6]);
        record[7] = inverse_mass(a, ja) + inverse_mass(b, jb);
        store(
            &record,
            &mut scratch.limits[l * RECORD..(l + 1) * RECORD],
            start,
        );
    }
}

/// Every node's starting block from what [`measure`] left: a body's mass
/// matrix, a joint's zero (hard rows; a soft limit's compliance) with its
/// errors on the right. A limit row is held where the active set says
/// (`first`: the limits violated now), its Jacobians written where the
/// tree couples it; else it is zeroed (dropped by the factorisation).
#[inline(always)]
pub(super) fn hold<L: Lane>(
    block: &mut TreeBlock,
    topology: &Topology,
    start: usize,
    scale: SubstepScale,
    first: bool,
) {
    let zero = L::splat(0.0);
    for (n, node) in topology.nodes.iter().enumerate() {
        let measured = load::<L, MEASURED>(&block.scratch[n].measured, start);
        let mut diagonal = [zero; PACKED];
        let mut rhs = [zero; MAX];
        match node.kind {
            NodeKind::Body { .. } => {
                let [mass, xx, xy, xz, yy, yz, zz] = measured;
                for k in 0..3 {
                    diagonal[at(k, k)] = mass;
                }
                diagonal[at(3, 3)] = xx;
                diagonal[at(4, 3)] = xy;
                diagonal[at(5, 3)] = xz;
                diagonal[at(4, 4)] = yy;
                diagonal[at(5, 4)] = yz;
                diagonal[at(5, 5)] = zz;
            }
            NodeKind::Joint {
                index,
                rows: kind,
                a,
                b,
            } => {
                let limits = kind.first_limit();
                rhs[..limits].copy_from_slice(&measured[..limits]);
                let held = hold_limits::<L>(block, n, (kind, node.parent), (a, b), start, first);
                for (l, k) in (limits..kind.count()).enumerate() {
                    rhs[k] = L::select(held.active[l], held.c[l], zero);
                }
                if block.soft {
                    let joint = &block.joints[index as usize];
                    let softness =
                        joint
                            .softness
                            .lanes(start, L::splat(scale.inv_h), L::splat(scale.inv_h2));
                    soften(
                        joint,
                        kind,
                        &softness,
                        &held,
                        start,
                        (&mut diagonal, &mut rhs),
                    );
                }
            }
        }
        let scratch = &mut block.scratch[n];
        store(&diagonal, &mut scratch.diagonal, start);
        store(&rhs, &mut scratch.rhs, start);
    }
}

/// A joint's limit rows in one solve's pass: which are held, and each
/// row's measured distance and `w`.
struct Held<L: Lane> {
    active: [L::Mask; MAX_LIMITS],
    c: [L; MAX_LIMITS],
    weights: [L; MAX_LIMITS],
}

/// Chooses which of joint node `n`'s limit rows are held (`first`: those
/// violated now, else the active set [`settle`] left), records the set,
/// and writes each row's Jacobians where the tree couples it to each body
/// (zero for a row not held).
#[inline(always)]
fn hold_limits<L: Lane>(
    block: &mut TreeBlock,
    n: usize,
    (kind, parent): (JointRows, u32),
    (a, b): (u32, u32),
    start: usize,
    first: bool,
) -> Held<L> {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let mut held = Held {
        active: [zero.gt(zero); MAX_LIMITS],
        c: [zero; MAX_LIMITS],
        weights: [zero; MAX_LIMITS],
    };
    for (l, k) in (kind.first_limit()..kind.count()).enumerate() {
        let scratch = &mut block.scratch[n];
        let record = load::<L, RECORD>(&scratch.limits[l * RECORD..(l + 1) * RECORD], start);
        let c = record[0];
        let active = if first {
            c.gt(zero)
        } else {
            L::load(&scratch.active[l][start..]).gt(zero)
        };
        L::select(active, one, zero).store(&mut scratch.active[l][start..]);
        (held.active[l], held.c[l], held.weights[l]) = (active, c, record[7]);
        // A limit's row has no linear part: `J_a`'s is `-0`, `J_b`'s `0`
        // (`rows::Rows::limit`).
        let minus = L::splat(-0.0);
        let ja = [minus, minus, minus, record[1], record[2], record[3]];
        let jb = [zero, zero, zero, record[4], record[5], record[6]];
        for (side, jacobian) in [(a, ja), (b, jb)] {
            if side == NONE {
                continue;
            }
            let mut row = [zero; 6];
            for (r, j) in row.iter_mut().zip(jacobian) {
                *r = L::select(active, j, zero);
            }
            let coupling = &mut block.scratch[holder(n, parent, side)].coupling;
            store(&row, &mut coupling[k * 6..k * 6 + 6], start);
        }
    }
    held
}

/// A soft limit's row (`parts::limit`, whose header derives the step):
/// with `alpha = alpha~ + spring w` (`w` the row's own generalised inverse
/// mass) and `gamma` the damping, XPBD's damped step
/// `((1 + gamma) J dx + alpha dlambda = -(C + alpha lambda + gamma (C -
/// C_0))` divided by `1 + gamma`: `-alpha / (1 + gamma)` on the row's
/// diagonal, the right-hand side over `1 + gamma`. Zero compliance and
/// damping leave the hard row as it was, bit for bit.
#[inline(always)]
fn soften<L: Lane>(
    joint: &JointNode,
    kind: JointRows,
    soft: &Softness<L>,
    held: &Held<L>,
    start: usize,
    (diagonal, rhs): (&mut [L; PACKED], &mut [L; MAX]),
) {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    for (l, k) in (kind.first_limit()..kind.count()).enumerate() {
        let active = held.active[l];
        let (c, w) = (held.c[l], held.weights[l]);
        let quarter = if kind.is_sine_row(k) {
            L::splat(0.25)
        } else {
            one
        };
        let alpha = soft.alpha_tilde * quarter + soft.spring * w;
        let lambda = L::select(active, L::load(&joint.limit_lambda[l][start..]), zero);
        let c0 = L::load(&joint.limit_start[l][start..]);
        let damping = L::select(active, soft.gamma * (c - c0), zero);
        let inv = one / (one + soft.gamma);
        let damped = (soft.alpha_tilde + soft.spring + soft.gamma).gt(zero) & active;
        rhs[k] = L::select(damped, (c + alpha * lambda + damping) * inv, rhs[k]);
        diagonal[at(k, k)] = L::select(damped, -(alpha * inv), diagonal[at(k, k)]);
    }
}

/// `j^T I^-1 j` for a world axis `j` (the body's inverse inertia is in its
/// own frame).
#[inline(always)]
fn inverse_mass<L: Lane>(body: &BodyLanes<L>, j: Vec3<L>) -> L {
    let local = body.q.inverse_rotate(j);
    local.dot(body.inv_inertia.mul_vec(local))
}

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
/// CROSSING`, linearised) is held. The set is kept as the next solve's
/// start ([`adopt`]). Only a crossing makes the tree worth factoring
/// again: a held row that pulls violates nothing, it only holds its joint
/// on the boundary until the next solve releases it. So a lane where some
/// row crosses takes its new set for another pass, and every other lane
/// keeps the set it had, which gives it the same bits again; returns
/// whether any lane crossed. A lane's result is then its own, whatever
/// its slice's other lanes do (every backend, bit for bit).
#[inline(always)]
pub(super) fn settle<L: Lane>(block: &mut TreeBlock, topology: &Topology, start: usize) -> bool {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let mut crossed = zero.gt(zero);
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
        let limits = kind.first_limit();
        if limits == kind.count() {
            continue;
        }
        let dlambda = load::<L, MAX>(&block.scratch[n].rhs, start);
        let turn_a = turn_of(block, a, start);
        let turn_b = turn_of(block, b, start);
        let joint = &block.joints[index as usize];
        let soft = joint.soft_lanes::<L>(start);
        for (l, k) in (limits..kind.count()).enumerate() {
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
    for scratch in block.scratch.iter_mut() {
        for (active, next) in scratch.active.iter_mut().zip(&scratch.next) {
            let held = L::load(&active[start..]);
            L::select(crossed, L::load(&next[start..]), held).store(&mut active[start..]);
        }
    }
    let mut lanes = [0.0f32; BLOCK_LANES];
    L::select(crossed, one, zero).store(&mut lanes);
    let mut any = false;
    for lane in &lanes[..L::WIDTH] {
        any |= *lane != 0.0;
    }
    any
}

/// The set the last [`settle`] chose, releases included, as the next
/// solve's start.
#[inline(always)]
pub(super) fn adopt<L: Lane>(block: &mut TreeBlock, start: usize) {
    for scratch in block.scratch.iter_mut() {
        for (active, next) in scratch.active.iter_mut().zip(&scratch.next) {
            L::load(&next[start..]).store(&mut active[start..]);
        }
    }
}

/// Body node `n`'s turn from the solve (zero for none: static or
/// kinematic).
#[inline(always)]
fn turn_of<L: Lane>(block: &TreeBlock, n: u32, start: usize) -> Vec3<L> {
    if n == NONE {
        return Vec3::zero();
    }
    let x = load::<L, MAX>(&block.scratch[n as usize].rhs, start);
    Vec3::new(x[3], x[4], x[5])
}

/// Adds each held limit row's multiplier to its joint's substep total
/// (a soft limit's spring force; zero for a row not held).
#[inline(always)]
pub(super) fn accumulate<L: Lane>(block: &mut TreeBlock, topology: &Topology, start: usize) {
    if !block.soft {
        return;
    }
    for (n, node) in topology.nodes.iter().enumerate() {
        let NodeKind::Joint {
            index, rows: kind, ..
        } = node.kind
        else {
            continue;
        };
        let dlambda = load::<L, MAX>(&block.scratch[n].rhs, start);
        let joint = &mut block.joints[index as usize];
        for (l, k) in (kind.first_limit()..kind.count()).enumerate() {
            let total = L::load(&joint.limit_lambda[l][start..]) + dlambda[k];
            total.store(&mut joint.limit_lambda[l][start..]);
        }
    }
}

/// Each limit row's violation as the substep starts (`C_0`, 0 within the
/// limit), for a soft limit's damping.
#[inline(always)]
pub(super) fn start_limits<L: Lane>(
    block: &mut TreeBlock,
    topology: &Topology,
    rows: &BodyRows,
    start: usize,
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
        let measured = Rows::measure(kind, &a, &b, &joint.geometry(start, scale));
        for (l, k) in (kind.first_limit()..kind.count()).enumerate() {
            let violation = measured.c[k].max(L::splat(0.0));
            violation.store(&mut joint.limit_start[l][start..]);
        }
    }
}

/// Leaves first: each node's block factored, its Schur complement and its
/// right-hand side passed to its parent. For a joint child with rows `J`
/// against its parent body, `D_p -= J^T D^-1 J` and `b_p += J^T D^-1 b`;
/// for a body child against its parent joint's rows `J`,
/// `D_p -= J D^-1 J^T` and `b_p += J D^-1 b` (the coupling block is `-J`).
#[inline(always)]
pub(super) fn eliminate<L: Lane>(block: &mut TreeBlock, topology: &Topology, start: usize) {
    for (n, node) in topology.nodes.iter().enumerate() {
        let parent = (node.parent != NONE).then_some(node.parent as usize);
        match (node.kind, parent_size(topology, parent)) {
            (NodeKind::Body { .. }, Some(5)) => body_child::<L, 5>(block, n, parent, start),
            (NodeKind::Body { .. }, Some(6)) => body_child::<L, 6>(block, n, parent, start),
            (NodeKind::Body { .. }, _) => body_child::<L, 6>(block, n, None, start),
            (NodeKind::Joint { rows, .. }, _) if rows.count() == 5 => {
                joint_child::<L, 5>(block, n, parent, start)
            }
            (NodeKind::Joint { .. }, _) => joint_child::<L, 6>(block, n, parent, start),
        }
    }
}

/// The size of a node's parent's block (none for the root). A `match`,
/// not `Option::map`: lane code has no closures (`tests/tidy.rs`).
#[inline(always)]
#[allow(clippy::manual_map)]
fn parent_size(topology: &Topology, parent: Option<usize>) -> Option<usize> {
    match parent {
        Some(p) => Some(topology.size(p)),
        None => None,
    }
}

/// Factors node `n`'s `N x N` block in place; returns the factors.
#[inline(always)]
fn factor<L: Lane, const N: usize>(block: &mut TreeBlock, n: usize, start: usize) -> [L; PACKED] {
    let mut factors = load::<L, PACKED>(&block.scratch[n].diagonal, start);
    ldl::factor::<L, N>(&mut factors);
    store(&factors, &mut block.scratch[n].diagonal, start);
    factors
}

/// Passes node `n`'s Schur complement to its parent `p`: with `A = L D
/// L^T` its factors and `u_r` the `R` columns of its coupling (`N`
/// entries each), `D_p -= U^T A^-1 U` and `b_p += U^T A^-1 b`, each as
/// `w^T D^-1 v` of forward solves `w = L^-1 u` ([`ldl::forward`]).
#[inline(always)]
fn complement<L: Lane, const N: usize, const R: usize>(
    block: &mut TreeBlock,
    (n, p): (usize, usize),
    factors: &[L; PACKED],
    columns: &mut [[L; MAX]; R],
    start: usize,
) {
    let mut z = load::<L, MAX>(&block.scratch[n].rhs, start);
    ldl::forward::<L, N>(factors, &mut z);
    let mut scaled = [[L::splat(0.0); MAX]; R];
    for (column, scaled) in columns.iter_mut().zip(scaled.iter_mut()) {
        ldl::forward::<L, N>(factors, column);
        for i in 0..N {
            scaled[i] = column[i] * factors[ldl::at(i, i)];
        }
    }
    let mut d = load::<L, PACKED>(&block.scratch[p].diagonal, start);
    let mut b = load::<L, MAX>(&block.scratch[p].rhs, start);
    for r in 0..R {
        for s in 0..=r {
            let mut sum = scaled[r][0] * columns[s][0];
            for i in 1..N {
                sum += scaled[r][i] * columns[s][i];
            }
            d[at(r, s)] -= sum;
        }
        let mut sum = scaled[r][0] * z[0];
        for i in 1..N {
            sum += scaled[r][i] * z[i];
        }
        b[r] += sum;
    }
    store(&d, &mut block.scratch[p].diagonal, start);
    store(&b, &mut block.scratch[p].rhs, start);
}

/// A joint node of `N` rows: factored, and its complement passed to its
/// parent body (`J^T D^-1 J`: the coupling's six columns).
#[inline(always)]
fn joint_child<L: Lane, const N: usize>(
    block: &mut TreeBlock,
    n: usize,
    parent: Option<usize>,
    start: usize,
) {
    let factors = factor::<L, N>(block, n, start);
    let Some(p) = parent else {
        return;
    };
    let j = load::<L, { MAX * 6 }>(&block.scratch[n].coupling, start);
    let mut columns = [[L::splat(0.0); MAX]; 6];
    for (c, column) in columns.iter_mut().enumerate() {
        for r in 0..N {
            column[r] = j[r * 6 + c];
        }
    }
    complement::<L, N, 6>(block, (n, p), &factors, &mut columns, start);
}

/// A body node: factored, and its complement passed to its parent joint
/// of `N` rows (`J D^-1 J^T`: the joint's `N` rows; none: the root).
#[inline(always)]
fn body_child<L: Lane, const N: usize>(
    block: &mut TreeBlock,
    n: usize,
    parent: Option<usize>,
    start: usize,
) {
    let factors = factor::<L, 6>(block, n, start);
    let Some(p) = parent else {
        return;
    };
    let j = load::<L, { MAX * 6 }>(&block.scratch[n].coupling, start);
    let mut columns = [[L::splat(0.0); MAX]; N];
    for (r, column) in columns.iter_mut().enumerate() {
        column.copy_from_slice(&j[r * 6..r * 6 + 6]);
    }
    complement::<L, 6, N>(block, (n, p), &factors, &mut columns, start);
}

/// Root first: each node's unknowns from its factored block, its
/// right-hand side and its parent's unknowns (`x = D^-1 (b + J x_p)` for
/// a joint, `D^-1 (b + J^T x_p)` for a body), kept in `rhs`.
#[inline(always)]
pub(super) fn substitute<L: Lane>(block: &mut TreeBlock, topology: &Topology, start: usize) {
    for (n, node) in topology.nodes.iter().enumerate().rev() {
        let parent = (node.parent != NONE).then_some(node.parent as usize);
        match (node.kind, parent_size(topology, parent)) {
            (NodeKind::Body { .. }, Some(5)) => unknowns::<L, 6, 5>(block, n, parent, false, start),
            (NodeKind::Body { .. }, _) => unknowns::<L, 6, 6>(block, n, parent, false, start),
            (NodeKind::Joint { rows, .. }, _) if rows.count() == 5 => {
                unknowns::<L, 5, 6>(block, n, parent, true, start)
            }
            (NodeKind::Joint { .. }, _) => unknowns::<L, 6, 6>(block, n, parent, true, start),
        }
    }
}

/// Node `n`'s `N` unknowns, from its parent's `P` (`joint`: `n` holds the
/// rows, else the parent does).
#[inline(always)]
fn unknowns<L: Lane, const N: usize, const P: usize>(
    block: &mut TreeBlock,
    n: usize,
    parent: Option<usize>,
    joint: bool,
    start: usize,
) {
    let factors = load::<L, PACKED>(&block.scratch[n].diagonal, start);
    let mut x = load::<L, MAX>(&block.scratch[n].rhs, start);
    if let Some(p) = parent {
        let xp = load::<L, MAX>(&block.scratch[p].rhs, start);
        let j = load::<L, { MAX * 6 }>(&block.scratch[n].coupling, start);
        if joint {
            // x += J x_p: N rows against the body's 6.
            for (r, xr) in x.iter_mut().enumerate().take(N) {
                for c in 0..6 {
                    *xr += j[r * 6 + c] * xp[c];
                }
            }
        } else {
            // x += J^T x_p: the parent's P rows against this body's 6.
            for r in 0..P {
                for c in 0..6 {
                    x[c] += j[r * 6 + c] * xp[r];
                }
            }
        }
    }
    ldl::solve::<L, N>(&factors, &mut x);
    store(&x[..N], &mut block.scratch[n].rhs, start);
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
        let x = load::<L, MAX>(&block.scratch[n].rhs, start);
        // A trust region: the rows are linear in the turn, so a turn of
        // more than a radian (a tree of near-dependent rows across a
        // million-to-one inertia ratio) is not a step the linearisation
        // vouches for. The body's whole step is scaled down to it; the
        // next solve re-linearises. Never reached in the scenes (their
        // golden hashes did not move).
        let turn = Vec3::new(x[3], x[4], x[5]);
        let (cap, angle) = (L::splat(MAX_TURN), turn.length());
        let scale = L::select(angle.gt(cap), cap / angle.max(cap), L::splat(1.0));
        lanes.p += Vec3::new(x[0], x[1], x[2]).scale(scale);
        let turn = lanes.q.inverse_rotate(turn.scale(scale));
        lanes.q = lanes.q.integrate_local(turn, L::splat(1.0));
        lanes.scatter_pose(rows, &body.write[start..]);
    }
}

/// Every joint's rows count is 5 or 6 (the sizes above).
const _: () = {
    use super::rows::SwingRows::{Cone, Ellipse, Pyramid};
    assert!(JointRows::Socket(Cone).count() == 5 && JointRows::Socket(Ellipse).count() == 5);
    assert!(JointRows::Rod.count() == 5 && JointRows::Socket(Pyramid).count() == 6);
    assert!(JointRows::Hinge.count() == 6 && JointRows::Fixed.count() == 6);
};
