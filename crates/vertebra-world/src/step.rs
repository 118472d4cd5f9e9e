//! One step: for each substep, predict, iterate the coloured position
//! passes, derive velocities, run the velocity pass, damp (XPBD for rigid
//! bodies, Müller et al. 2020, algorithm 2).

use core::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};

use glam::{Quat, Vec3};
use vertebra_kernels::body::{BodyPairs, BodyRows};
use vertebra_kernels::contact::{self, ContactBlock};
use vertebra_kernels::direct::{self, Topology, TreeBlock};
use vertebra_kernels::driven::StartPass;
use vertebra_kernels::fixed::{self, FixedBlock};
use vertebra_kernels::hinge::{self, HingeBlock};
use vertebra_kernels::limited;
use vertebra_kernels::rod::{self, RodBlock};
use vertebra_kernels::socket::{PositionPass, SocketBlock};
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;
use vertebra_store::{BodyKind, BodyStore};

use crate::World;
use crate::bins::Bins;
use crate::contact::{ContactBin, ContactLayout};
use crate::islands::Islands;
use crate::joint::JointKind;
use crate::layout::{Bin, Group, Layout};
use crate::parallel::Shared;
use crate::stages::{BlockChunks, Chunks, Cursor, Part, SharedBlocks, SliceChunks};
use crate::start::start_blocks;

/// Direct solves after a substep's last iteration, with nothing between
/// (`SolverConfig::joints` = `Direct`): each is a Newton step on the
/// joints' rows, so the error the last iteration's solve left (second
/// order in its correction, whatever the limits and contacts did before
/// it) shrinks quadratically again, and the hard limits' active set
/// settles. In the 30-ragdoll drop at 1 x 4 the second took the sockets'
/// summed angular error from 0.39 to 0.12 rad (docs/direct.md).
const CLOSING_SOLVES: usize = 2;

/// Contacts from which the step's start ([`start_blocks_all`]) is a launch
/// of the workers of its own: below, one launch costs about what it
/// saves (about 60 ns a contact on this machine, docs/threads.md).
const START_LAUNCH_CONTACTS: usize = 1024;

/// The step's start, before its substeps: the contacts' blocks filled
/// from this step's contacts (`ContactLayout::plan` placed them) and every
/// joint block's start of step (`Layout::start_step`), each block alone
/// from the bodies as they stand (capped at `max_depth`, m, for the
/// contacts). With more than one worker and many contacts, one launch of
/// the workers: one stage of every kind's blocks in chunks (each chunk
/// writes only its own blocks, and reads only the bodies and the
/// contacts); else all of it on the calling thread. The same bits either
/// way.
pub(crate) fn start_blocks_all(world: &mut World, max_depth: f32, workers: usize) {
    let bodies = &world.bodies;
    let (fill, blocks) = world
        .contact_layout
        .fill(&world.contacts, bodies, max_depth);
    if workers <= 1 || world.contacts.len() < START_LAUNCH_CONTACTS {
        // On the calling thread, block after block: no chunks to lend (a
        // single ragdoll's step is a few tens of thousands of
        // instructions, and lending five slices in chunks cost thousands).
        fill.blocks(0, blocks);
        world.layout.start_step(bodies);
        return;
    }
    let pieces = workers.saturating_mul(CHUNKS_PER_WORKER);
    let contacts = SliceChunks::new(blocks, pieces, |first, b: &mut [ContactBlock]| {
        fill.blocks(first, b)
    });
    let layout = &mut world.layout;
    let sockets = SliceChunks::new(&mut layout.sockets.blocks, pieces, |_, b: &mut [_]| {
        start_blocks::<SocketBlock>(b, bodies)
    });
    let hinges = SliceChunks::new(&mut layout.hinges.blocks, pieces, |_, b: &mut [_]| {
        start_blocks::<HingeBlock>(b, bodies)
    });
    let fixed = SliceChunks::new(&mut layout.fixed.blocks, pieces, |_, b: &mut [_]| {
        start_blocks::<FixedBlock>(b, bodies)
    });
    let rods = SliceChunks::new(&mut layout.rods.blocks, pieces, |_, b: &mut [_]| {
        start_blocks::<RodBlock>(b, bodies)
    });
    let trees = SliceChunks::new(&mut layout.trees.blocks, pieces, |_, b: &mut [_]| {
        start_blocks::<TreeBlock>(b, bodies)
    });
    world
        .stages
        .run(&*world.tasks, workers, &|cursor: &mut Cursor| {
            cursor.stage(&[&contacts, &sockets, &hinges, &fixed, &rods, &trees])
        });
}

pub(crate) fn step(world: &mut World, dt: f32, workers: usize) {
    let h = dt / world.config.substeps as f32;
    upload(&world.bodies, world.rows.get());
    world
        .previous
        .resize(world.bodies.capacity(), (Vec3::ZERO, Quat::IDENTITY));
    mark_moving(&world.bodies, &world.islands, &mut world.moving);
    let substeps = world.config.substeps;
    for substep in 0..substeps {
        start_drives(world, h);
        world
            .layout
            .sockets
            .blocks
            .iter_mut()
            .for_each(SocketBlock::reset_lambdas);
        world
            .layout
            .hinges
            .blocks
            .iter_mut()
            .for_each(HingeBlock::reset_lambdas);
        world
            .layout
            .rods
            .blocks
            .iter_mut()
            .for_each(RodBlock::reset_lambdas);
        // An overlap found at detection comes out evenly over the step
        // (docs/contacts.md, "The jammed pile").
        let remaining = (substeps - 1 - substep) as f32 / substeps as f32;
        world
            .contact_layout
            .blocks
            .iter_mut()
            .for_each(|b| b.start_substep(remaining));
        world.repaired += solve_substep(world, h, workers);
    }
    commit(world);
    keep_drive_targets(world);
    keep_rod_rests(world);
    let bodies = &mut world.bodies;
    bodies.force.iter_mut().for_each(|f| *f = Vec3::ZERO);
    bodies.torque.iter_mut().for_each(|t| *t = Vec3::ZERO);
}

/// The drives' substep start, before the bodies move: each drive's error
/// against the last substep's target, then the target advanced by `h`;
/// each rod's bend and twist error (its soft parts damp against them)
/// against the last substep's rest shape, then the rest advanced by `h`;
/// each shaped socket's and hinge's limit violations (`limited.rs`: a
/// damped limit's `C_0`).
/// Every driven block, one after another, on the world's backend (each
/// lane reads and writes only its own block).
fn start_drives(world: &mut World, h: f32) {
    let rows = &*world.rows.get();
    let layout = &mut world.layout;
    let bins = core::mem::take(&mut layout.bins);
    let groups = bins
        .iter()
        .flat_map(|b| b.colours.iter().chain(core::iter::once(&b.overflow)));
    // An empty range is not dispatched: a small world's groups hold few
    // kinds, and entering a backend is not free.
    let some = |range: &Range<usize>| !range.is_empty();
    for group in groups {
        for range in [&group.driven, &group.shaped_driven]
            .into_iter()
            .filter(|r| some(r))
        {
            world.backend.dispatch(StartPass {
                blocks: &mut layout.sockets.blocks[range.clone()],
                rows,
                h,
            });
        }
        if some(&group.hinges_driven) {
            world.backend.dispatch(StartPass {
                blocks: &mut layout.hinges.blocks[group.hinges_driven.clone()],
                rows,
                h,
            });
        }
        for range in [&group.shaped_driven, &group.shaped_plain]
            .into_iter()
            .filter(|r| some(r))
        {
            world.backend.dispatch(limited::StartPass {
                blocks: &mut layout.sockets.blocks[range.clone()],
                rows,
            });
        }
        for range in [&group.hinges_driven, &group.hinges_plain]
            .into_iter()
            .filter(|r| some(r))
        {
            world.backend.dispatch(limited::StartPass {
                blocks: &mut layout.hinges.blocks[range.clone()],
                rows,
            });
        }
        if some(&group.rods) {
            world.backend.dispatch(rod::StartPass {
                blocks: &mut layout.rods.blocks[group.rods.clone()],
                rows,
                h,
            });
        }
    }
    for bin in &bins {
        if some(&bin.trees) {
            world.backend.dispatch(direct::StartPass {
                blocks: &mut layout.trees.blocks[bin.trees.clone()],
                topologies: &layout.trees.topologies,
                rows,
            });
        }
    }
    layout.bins = bins;
}

/// Writes each moving drive's advanced target (a nonzero
/// `target_velocity`) back to its joint's description, and lays the joint
/// out again from the description: the next step then starts from the
/// description, bit for bit as a rebuilt layout (a restored snapshot, a
/// joint added or removed) starts from it. The lane holds the target
/// normalised (`AngularDrive::lane`), and normalising an advanced target
/// again moves it by an ulp in some steps, so the lane kept as it was
/// would differ from what the description lays out. A still target is
/// left alone: its description is as given and its lane is the layout's
/// (the kernel's advance returns it bit for bit). The same rule as
/// [`keep_rod_rests`].
fn keep_drive_targets(world: &mut World) {
    let layout = &mut world.layout;
    for (slot, desc) in world.joints.iter_mut().enumerate() {
        let Some(desc) = desc.as_mut() else { continue };
        if world.islands.holds_asleep(desc.body_a, desc.body_b) {
            continue; // not laid out
        }
        let Some(drive) = desc.drive.as_mut() else {
            continue;
        };
        if drive.target_velocity == Vec3::ZERO {
            continue;
        }
        drive.target = match desc.kind {
            JointKind::Socket(_) => {
                let (block, lane) = layout.sockets.place[slot];
                layout.sockets.blocks[block].drive.target.get(lane)
            }
            JointKind::Hinge { .. } => {
                let (block, lane) = layout.hinges.place[slot];
                layout.hinges.blocks[block].drive.target.get(lane)
            }
            JointKind::Fixed => continue,
        };
        layout.update_joint(slot, desc, &world.bodies);
    }
}

/// Writes each moving rod's advanced rest shape back to its description
/// and lays the rod out again from it, as [`keep_drive_targets`] does for
/// drives (and for the same reason: the lane holds the rest normalised).
/// A still rest is left alone (its description and lane are as they
/// were).
fn keep_rod_rests(world: &mut World) {
    let layout = &mut world.layout;
    for (slot, desc) in world.rods.iter_mut().enumerate() {
        let Some(desc) = desc.as_mut() else { continue };
        if world.islands.holds_asleep(desc.body_a, desc.body_b) {
            continue; // not laid out
        }
        let (bend, twist) = (
            desc.bend_rest_velocity != Vec3::ZERO,
            desc.twist_rest_velocity != 0.0,
        );
        if !(bend || twist) {
            continue;
        }
        let (block, lane) = layout.rods.place[slot];
        let block = &layout.rods.blocks[block];
        if bend {
            desc.bend_rest = block.bend_rest.get(lane);
        }
        if twist {
            desc.twist_rest = block.twist_rest[lane];
        }
        layout.update_rod(slot, desc, &world.bodies);
    }
}

/// Rows for every slot (stale slots hold harmless old data: no joint
/// references them), every body at zero displacement: the rows hold each
/// body's motion since the step began (see `vertebra_kernels::body`).
pub(crate) fn upload(bodies: &BodyStore, rows: &mut BodyRows) {
    if rows.pose.len() != bodies.capacity() + 1 {
        *rows = BodyRows::with_bodies(bodies.capacity());
    }
    for i in 0..bodies.capacity() {
        rows.inertia[i + 1].set(BodyRows::inertia_row(bodies.inverse_inertia[i]));
        rows.velocity[i + 1].set(BodyRows::velocity_row(
            bodies.linear_velocity[i],
            bodies.angular_velocity[i],
        ));
        rows.pose[i + 1].set(BodyRows::pose_row(
            Vec3::ZERO,
            bodies.inverse_mass[i],
            bodies.orientation[i],
        ));
    }
}

/// A body's displacement since the step began and its orientation, as the
/// rows hold them.
fn pose(rows: &BodyRows, i: usize) -> (Vec3, Quat) {
    let [px, py, pz, _, qx, qy, qz, qw] = rows.pose[i + 1].get();
    (Vec3::new(px, py, pz), Quat::from_xyzw(qx, qy, qz, qw))
}

/// Moves every body by its displacement over the step, in double
/// precision (`BodyStore::displace`: the coordinate keeps what an `f32`
/// cannot hold, and the world's edge holds bodies in).
fn commit(world: &mut World) {
    let (b, islands) = (&mut world.bodies, &world.islands);
    for i in 0..b.capacity() {
        if b.is_live(i) && b.kind[i] != BodyKind::Static && !islands.is_asleep(i) {
            let (displacement, orientation) = pose(world.rows.get(), i);
            b.displace(i, displacement);
            b.orientation[i] = orientation;
        }
    }
}

/// Integration of velocities (gravity, forces, the implicit gyroscopic
/// term in the body frame) and of the rows' displacements and
/// orientations, for one chunk of bodies; the previous ones are kept for
/// deriving velocities afterwards.
fn predict(c: &mut BodyChunk, b: &BodyRead, rows: &BodyRows, h: f32) {
    let (max_linear, max_angular) = (b.max_linear_speed, b.max_angular_speed);
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        if !b.moving[i] {
            continue;
        }
        // The speed limits, before and after the forces: huge but finite
        // velocities or forces would overflow `|w|^2` in the exponential map
        // (or `w x I w`) and poison the world.
        let w = limit(c.angular_velocity[j], max_angular);
        if b.kind[i] == BodyKind::Dynamic {
            let v = c.linear_velocity[j] + (b.gravity + b.force[i] * b.inverse_mass[i]) * h;
            c.linear_velocity[j] = limit(v, max_linear);
            let q = c.orientation[j];
            let w_body = gyroscopic(q.inverse() * w, b.inertia[i], h);
            let torque_body = q.inverse() * b.torque[i];
            let w_body = limit(w_body + b.inverse_inertia[i] * torque_body * h, max_angular);
            c.angular_velocity[j] = q * w_body;
        } else {
            c.linear_velocity[j] = limit(c.linear_velocity[j], max_linear);
            c.angular_velocity[j] = w;
        }
        let (displacement, orientation) = pose(rows, i);
        c.previous[j] = (displacement, orientation);
        rows.pose[i + 1].set(BodyRows::pose_row(
            displacement + c.linear_velocity[j] * h,
            b.inverse_mass[i],
            integrate(orientation, c.angular_velocity[j], h),
        ));
    }
}

/// Holds every moving body's velocities to the speed limits, as the step
/// begins: the contacts measure their approach speed from them before any
/// substep has held them (an accepted spin of 1e38 rad/s overflowed
/// `w x r` there and turned both bodies NaN).
pub(crate) fn hold_speeds(b: &mut BodyStore, islands: &Islands, max_linear: f32, max_angular: f32) {
    for i in 0..b.capacity() {
        if b.is_live(i) && b.kind[i] != BodyKind::Static && !islands.is_asleep(i) {
            b.linear_velocity[i] = limit(b.linear_velocity[i], max_linear);
            b.angular_velocity[i] = limit(b.angular_velocity[i], max_angular);
        }
    }
}

/// `v` shortened to at most `max` (`v` itself when it is no longer), and
/// finite even when a component overflowed to infinity.
pub(crate) fn limit(v: Vec3, max: f32) -> Vec3 {
    if v.length_squared() <= max * max {
        return v;
    }
    let v = v.clamp(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
    let scaled = v / v.abs().max_element();
    scaled.normalize() * max
}

/// The gyroscopic term, implicitly: `I (w' - w) + h w' x I w' = 0` in the
/// body frame, solved by one Newton step from `w` (as Bullet's implicit
/// gyroscopic body solver). The explicit term `-h I^-1 (w x I w)` gains
/// energy and lets the angular momentum drift; this does not blow up.
fn gyroscopic(w: Vec3, inertia: glam::Mat3, h: f32) -> Vec3 {
    let skew = |v: Vec3| {
        glam::Mat3::from_cols(
            Vec3::new(0.0, v.z, -v.y),
            Vec3::new(-v.z, 0.0, v.x),
            Vec3::new(v.y, -v.x, 0.0),
        )
    };
    let residual = w.cross(inertia * w) * h;
    let jacobian = inertia + (skew(w) * inertia - skew(inertia * w)) * h;
    let turned = w - jacobian.inverse() * residual;
    // A singular Jacobian, or an inertia so large the product overflowed:
    // no gyroscopic correction this substep.
    if jacobian.determinant().abs() > f32::MIN_POSITIVE && turned.is_finite() {
        turned
    } else {
        w
    }
}

/// Turns `q` at angular velocity `w` for `h` seconds exactly:
/// `exp(w h / 2) q`. The first-order `q + h/2 (w, 0) q` turns by
/// `2 atan(|w| h / 2)` instead, and together with deriving `w` from the
/// quaternion difference it bleeds spin at `(|w| h)^2 / 8` per substep.
/// Through the math layer's polynomials, so every platform agrees.
fn integrate(q: Quat, w: Vec3, h: f32) -> Quat {
    let (axis, speed) = vertebra_math::Vec3::<f32>::from(w).normalize_or_zero();
    let turn = vertebra_math::Quat::<f32>::from_axis_angle(axis, speed * h);
    vertebra_math::PortableQuat::normalize_portable(glam::Quat::from(turn * q.into()))
}

/// The angular velocity that turns `q0` into `q` in `h` seconds, exactly
/// (the inverse of [`integrate`]): `log(q q0*) / h`, shortest arc.
pub(crate) fn angular_velocity(q: Quat, q0: Quat, h: f32) -> Vec3 {
    let turn = vertebra_math::Quat::<f32>::from(vertebra_math::PortableQuat::mul_portable(
        q,
        q0.conjugate(),
    ));
    Vec3::from(turn.to_rotation_vector()) / h
}

/// Which socket blocks: with drives or not, plain or shaped path.
#[derive(Clone, Copy)]
struct SocketBlocks {
    driven: bool,
    shaped: bool,
}

/// One kind of pass over one group's blocks of one type.
trait Pass: Sync {
    /// Whether the pass has work for joints (else their stages are left
    /// out).
    fn joints(&self) -> bool {
        true
    }
    /// Sockets (`driven` and `shaped` say which blocks).
    fn sockets(
        &self,
        blocks: &mut [SocketBlock],
        kind: SocketBlocks,
        rows: &BodyRows,
        backend: Backend,
    );
    /// Hinges (`driven` says which blocks).
    fn hinges(&self, blocks: &mut [HingeBlock], driven: bool, rows: &BodyRows, backend: Backend);
    /// Fixed joints.
    fn fixed(&self, blocks: &mut [FixedBlock], rows: &BodyRows, backend: Backend);
    /// Rods.
    fn rods(&self, blocks: &mut [RodBlock], rows: &BodyRows, backend: Backend);
    /// Contacts.
    fn contacts(&self, blocks: &mut [ContactBlock], rows: &BodyRows, backend: Backend);
    /// The direct solve's trees (nothing but in the position pass):
    /// `joined`, all of `blocks` are one solve (trees cut into pieces),
    /// else each block is.
    fn trees(&self, _: &mut [TreeBlock], _: &[Topology], _: &BodyRows, _: Backend, _: bool) {}
}

/// The position iteration.
#[derive(Clone, Copy)]
struct Positions {
    inv_h: f32,
    inv_h2: f32,
    /// How many times a tree solve may factor its tree
    /// (`direct::PositionPass::passes`).
    passes: usize,
}

impl Pass for Positions {
    fn sockets(
        &self,
        blocks: &mut [SocketBlock],
        kind: SocketBlocks,
        rows: &BodyRows,
        backend: Backend,
    ) {
        let (inv_h, inv_h2) = (self.inv_h, self.inv_h2);
        match (kind.driven, kind.shaped) {
            (true, false) => backend.dispatch(PositionPass::<true, false> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            }),
            (false, false) => backend.dispatch(PositionPass::<false, false> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            }),
            (true, true) => backend.dispatch(PositionPass::<true, true> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            }),
            (false, true) => backend.dispatch(PositionPass::<false, true> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            }),
        }
    }
    fn hinges(&self, blocks: &mut [HingeBlock], driven: bool, rows: &BodyRows, backend: Backend) {
        let (inv_h, inv_h2) = (self.inv_h, self.inv_h2);
        if driven {
            backend.dispatch(hinge::PositionPass::<true> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            });
        } else {
            backend.dispatch(hinge::PositionPass::<false> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            });
        }
    }
    fn fixed(&self, blocks: &mut [FixedBlock], rows: &BodyRows, backend: Backend) {
        backend.dispatch(fixed::PositionPass { blocks, rows });
    }
    fn rods(&self, blocks: &mut [RodBlock], rows: &BodyRows, backend: Backend) {
        backend.dispatch(rod::PositionPass {
            blocks,
            rows,
            inv_h: self.inv_h,
            inv_h2: self.inv_h2,
        });
    }
    fn contacts(&self, blocks: &mut [ContactBlock], rows: &BodyRows, backend: Backend) {
        backend.dispatch(contact::PositionPass { blocks, rows });
    }
    fn trees(
        &self,
        blocks: &mut [TreeBlock],
        topologies: &[Topology],
        rows: &BodyRows,
        backend: Backend,
        joined: bool,
    ) {
        let scale = direct::SubstepScale {
            inv_h: self.inv_h,
            inv_h2: self.inv_h2,
        };
        let solve = |blocks: &mut [TreeBlock], backend: Backend| {
            direct::PositionPass {
                blocks,
                topologies,
                rows,
                scale,
                passes: self.passes,
            }
            .run(backend);
        };
        if joined {
            solve(blocks, backend);
        } else {
            for block in blocks.chunks_mut(1) {
                solve(block, backend_for_tree(backend, &block[0]));
            }
        }
    }
}

/// The backend a tree block is solved on: the world's, except that a
/// block of one live tree (a shape seen once) runs on the scalar path
/// where the world's is 4-lane SSE4.1: there the scalar path measured
/// cheaper for it (the single ragdoll's direct step: 498k
/// instructions against 532k on sse4), where on AVX2 the 4-lane half is
/// (457k). Every backend gives the same bits.
fn backend_for_tree(backend: Backend, block: &TreeBlock) -> Backend {
    let live = (!block.padding & ((1 << BLOCK_LANES) - 1)).count_ones();
    match backend {
        Backend::Sse41 if live == 1 => Backend::Scalar,
        _ => backend,
    }
}

/// The velocity pass (contact friction and restitution; joints have none:
/// drives damp at the position level), or with `relax` a relax pass
/// (`contact::VelocityPass`: the contacts take back their push-out's speed).
struct Velocities {
    h: f32,
    resting_speed: f32,
    relax: bool,
}

impl Pass for Velocities {
    fn joints(&self) -> bool {
        false
    }
    fn sockets(&self, _: &mut [SocketBlock], _: SocketBlocks, _: &BodyRows, _: Backend) {}
    fn hinges(&self, _: &mut [HingeBlock], _: bool, _: &BodyRows, _: Backend) {}
    fn fixed(&self, _: &mut [FixedBlock], _: &BodyRows, _: Backend) {}
    fn rods(&self, _: &mut [RodBlock], _: &BodyRows, _: Backend) {}
    fn contacts(&self, blocks: &mut [ContactBlock], rows: &BodyRows, backend: Backend) {
        let (h, resting_speed, relax) = (self.h, self.resting_speed, self.relax);
        backend.dispatch(contact::VelocityPass {
            blocks,
            rows,
            h,
            resting_speed,
            relax,
        });
    }
}

/// How many relax passes follow the velocity pass when
/// `SolverConfig::relax_contacts` is on: enough for the contacts of one
/// body to share the taking back (a box pushed out of the ground on four
/// corners leaves at under 1 cm/s and 0.01 rad/s, where one pass left it
/// spinning at 1.2 rad/s).
pub(crate) const RELAX_PASSES: u32 = 4;

/// The most chunks a body pass is split into.
const MAX_BODY_CHUNKS: usize = 64;

/// Chunks per worker in a split stage: enough that a worker held up (its
/// core taken by another thread) leaves most of its share to the others.
const CHUNKS_PER_WORKER: usize = 4;

/// One chunk of bodies (slots `start..`): what the body passes write.
struct BodyChunk<'a> {
    start: usize,
    linear_velocity: &'a mut [Vec3],
    angular_velocity: &'a mut [Vec3],
    orientation: &'a mut [Quat],
    previous: &'a mut [(Vec3, Quat)],
}

/// What the body passes read: the bodies' other arrays, by slot, and the
/// world's settings.
struct BodyRead<'a> {
    moving: &'a [bool],
    kind: &'a [BodyKind],
    position: &'a [Vec3],
    inverse_mass: &'a [f32],
    inertia: &'a [glam::Mat3],
    inverse_inertia: &'a [glam::Mat3],
    force: &'a [Vec3],
    torque: &'a [Vec3],
    linear_damping: &'a [f32],
    angular_damping: &'a [f32],
    gravity: Vec3,
    max_linear_speed: f32,
    max_angular_speed: f32,
}

/// Which slots the body passes move: live, not static, not asleep.
fn mark_moving(b: &BodyStore, islands: &Islands, moving: &mut Vec<bool>) {
    moving.clear();
    moving.extend(
        (0..b.capacity())
            .map(|i| b.is_live(i) && b.kind[i] != BodyKind::Static && !islands.is_asleep(i)),
    );
}

/// What the workers of one substep share: the stages' work.
struct Substep<'a> {
    rows: Shared<'a>,
    backend: Backend,
    workers: usize,
    min_blocks: usize,
    iterations: u32,
    h: f32,
    /// Relax passes after the velocity pass ([`RELAX_PASSES`] or none).
    relax_passes: u32,
    bodies: BodyRead<'a>,
    body_chunks: [Mutex<Option<BodyChunk<'a>>>; MAX_BODY_CHUNKS],
    body_chunk_count: usize,
    sockets: SharedBlocks<'a, SocketBlock>,
    hinges: SharedBlocks<'a, HingeBlock>,
    fixed: SharedBlocks<'a, FixedBlock>,
    rods: SharedBlocks<'a, RodBlock>,
    trees: SharedBlocks<'a, TreeBlock>,
    topologies: &'a [Topology],
    trees_disjoint: bool,
    joint_bins: &'a [Bin],
    joints_disjoint: bool,
    contacts: SharedBlocks<'a, ContactBlock>,
    contact_colours: &'a [Range<usize>],
    contact_bins: &'a [ContactBin],
    contacts_disjoint: bool,
    /// The bins `1..` keep to their own rows (`bins_apart`): each may be
    /// solved by one worker while others solve the rest.
    bins_apart: bool,
    /// Bodies put back by [`repair`] this substep.
    repaired: AtomicU64,
}

/// One substep after its drives have started: predict, the position
/// iterations, derive velocities, the velocity pass, damp and repair, as
/// one launch of the task system's workers walking the stages
/// ([`Substep::walk`]). Returns how many bodies were repaired.
fn solve_substep(world: &mut World, h: f32, workers: usize) -> u64 {
    let config = &world.config;
    let b = &mut world.bodies;
    let n = b.capacity();
    let size = if workers > 1 {
        n.div_ceil(MAX_BODY_CHUNKS)
            .max(n.div_ceil(workers.saturating_mul(CHUNKS_PER_WORKER)))
    } else {
        n
    }
    .max(1);
    let mut body_chunks: [Mutex<Option<BodyChunk>>; MAX_BODY_CHUNKS] =
        core::array::from_fn(|_| Mutex::new(None));
    let chunks = (b.linear_velocity.chunks_mut(size))
        .zip(b.angular_velocity.chunks_mut(size))
        .zip(b.orientation.chunks_mut(size))
        .zip(world.previous[..n].chunks_mut(size));
    let mut body_chunk_count = 0;
    for (slot, (((linear_velocity, angular_velocity), orientation), previous)) in
        body_chunks.iter_mut().zip(chunks)
    {
        *slot.get_mut().unwrap_or_else(PoisonError::into_inner) = Some(BodyChunk {
            start: body_chunk_count * size,
            linear_velocity,
            angular_velocity,
            orientation,
            previous,
        });
        body_chunk_count += 1;
    }
    let bins_apart = bins_apart(&world.bins, &world.layout, &world.contact_layout);
    let layout = &mut world.layout;
    let contacts = &mut world.contact_layout;
    let substep = Substep {
        rows: Shared::new(world.rows.get()),
        backend: world.backend,
        workers,
        min_blocks: config.parallel_min_blocks,
        iterations: config.iterations,
        h,
        relax_passes: if config.relax_contacts {
            RELAX_PASSES
        } else {
            0
        },
        bodies: BodyRead {
            moving: &world.moving,
            kind: &b.kind,
            position: &b.position,
            inverse_mass: &b.inverse_mass,
            inertia: &b.inertia,
            inverse_inertia: &b.inverse_inertia,
            force: &b.force,
            torque: &b.torque,
            linear_damping: &b.linear_damping,
            angular_damping: &b.angular_damping,
            gravity: config.gravity,
            max_linear_speed: config.max_linear_speed,
            max_angular_speed: config.max_angular_speed,
        },
        body_chunks,
        body_chunk_count,
        sockets: SharedBlocks::new(&mut layout.sockets.blocks),
        hinges: SharedBlocks::new(&mut layout.hinges.blocks),
        fixed: SharedBlocks::new(&mut layout.fixed.blocks),
        rods: SharedBlocks::new(&mut layout.rods.blocks),
        trees: SharedBlocks::new(&mut layout.trees.blocks),
        topologies: &layout.trees.topologies,
        trees_disjoint: layout.trees.disjoint,
        joint_bins: &layout.bins,
        joints_disjoint: layout.disjoint,
        contacts: SharedBlocks::new(&mut contacts.blocks),
        contact_colours: &contacts.colours,
        contact_bins: &contacts.bins,
        contacts_disjoint: contacts.disjoint,
        bins_apart,
        repaired: AtomicU64::new(0),
    };
    world
        .stages
        .run(&*world.tasks, workers, &|cursor: &mut Cursor| {
            substep.walk(cursor)
        });
    substep.repaired.into_inner()
}

impl Substep<'_> {
    /// The substep's stages, in order.
    fn walk(&self, cursor: &mut Cursor) {
        let h = self.h;
        let bodies = &self.bodies;
        self.body_pass(cursor, |c, rows| predict(c, bodies, rows, h));
        // An iteration's tree solve factors each tree once; the closing
        // solves settle the limits' active set (docs/direct.md, "The
        // limits").
        let positions = Positions {
            inv_h: 1.0 / h,
            inv_h2: 1.0 / (h * h),
            passes: 1,
        };
        let closing = Positions {
            passes: direct::MAX_PASSES,
            ..positions
        };
        for _ in 0..self.iterations {
            self.for_each_colour(cursor, 0, &positions);
        }
        if let Some(joints) = self.joint_bins.first() {
            for _ in 0..CLOSING_SOLVES {
                self.trees_stage(cursor, joints, &closing);
            }
        }
        self.bins_stage(cursor, |bin| {
            for _ in 0..self.iterations {
                self.solve_bin(bin, &positions);
            }
            for _ in 0..CLOSING_SOLVES {
                self.solve_bin_trees(bin, &closing);
            }
        });
        self.body_pass(cursor, |c, rows| derive_velocities(c, bodies, rows, h));
        let resting_speed = 2.0 * bodies.gravity.length() * h;
        let velocities = Velocities {
            h,
            resting_speed,
            relax: false,
        };
        let relax = Velocities {
            relax: true,
            ..velocities
        };
        for pass in core::iter::once(&velocities).chain((0..self.relax_passes).map(|_| &relax)) {
            self.for_each_colour(cursor, 0, pass);
            self.bins_stage(cursor, |bin| self.solve_bin(bin, pass));
        }
        self.body_pass(cursor, |c, rows| {
            read_velocities(c, bodies, rows);
            damp(c, bodies, h);
            let repaired = repair(c, bodies, rows);
            self.repaired.fetch_add(repaired, Ordering::Relaxed);
        });
    }

    /// One stage of `pass` over every chunk of bodies.
    fn body_pass(&self, cursor: &mut Cursor, pass: impl Fn(&mut BodyChunk, &BodyRows) + Sync) {
        cursor.stage(&[&Chunks(self.body_chunk_count, |chunk: usize| {
            let mut slot = self.body_chunks[chunk]
                .lock()
                .unwrap_or_else(PoisonError::into_inner);
            if let Some(c) = slot.as_mut() {
                pass(c, self.rows.rows());
            }
        })]);
    }

    /// Blocks per chunk for a stage of `blocks` blocks that may be split
    /// (all of them, one chunk, when it may not or is too small to be).
    fn chunk_size(&self, split: bool, blocks: usize) -> usize {
        if split && self.workers > 1 && blocks >= self.min_blocks {
            blocks.div_ceil(self.workers.saturating_mul(CHUNKS_PER_WORKER))
        } else {
            blocks
        }
    }

    /// Runs `pass` over this substep's contacts, then the joints: each
    /// colour in order, then its overflow set with the scalar kernel.
    /// Inside a colour, constraints share no dynamic body, so a colour is
    /// one stage whose chunks any worker may run (contacts are coloured on
    /// their own, so their colours are stages of their own).
    ///
    /// Joints come last so that what an iteration leaves behind is contact
    /// error, not joint error: joint error is what the animation skeleton
    /// shows, and what the paper's figure 8 measures. In the 30-ragdoll drop
    /// this order cut the mean joint error 2.4x (sockets) and 3.4x (rods),
    /// while ragdolls met the floor less deeply (10 mm against 25 mm at
    /// impact, 1.4 mm against 0.5 mm at rest); see docs/contacts.md.
    fn for_each_colour(&self, cursor: &mut Cursor, bin: usize, pass: &impl Pass) {
        for (range, backend) in self.contact_groups(bin) {
            let split = backend != Backend::Scalar && self.contacts_disjoint;
            let size = self.chunk_size(split, range.len());
            let run = |c: &mut [ContactBlock]| pass.contacts(c, self.rows.rows(), backend);
            // SAFETY: the only part of its stage.
            let part = unsafe { BlockChunks::new(&self.contacts, range.clone(), size, run) };
            cursor.stage(&[&part]);
        }
        if !pass.joints() {
            return;
        }
        let Some(joints) = self.joint_bins.get(bin) else {
            return;
        };
        for group in &joints.colours {
            self.joint_colour(cursor, group, self.backend, self.joints_disjoint, pass);
        }
        self.joint_colour(cursor, &joints.overflow, Backend::Scalar, false, pass);
        self.trees_stage(cursor, joints, pass);
    }

    /// One stage of `pass` over a bin's trees (none: no stage).
    fn trees_stage(&self, cursor: &mut Cursor, joints: &Bin, pass: &impl Pass) {
        let range = &joints.trees;
        if !range.is_empty() {
            let joined = joints.trees_joined;
            let size = self.chunk_size(self.trees_disjoint && !joined, range.len());
            let run = |c: &mut [TreeBlock]| {
                pass.trees(c, self.topologies, self.rows.rows(), self.backend, joined)
            };
            // SAFETY: the only part of its stage.
            let part = unsafe { BlockChunks::new(&self.trees, range.clone(), size, run) };
            cursor.stage(&[&part]);
        }
    }

    /// Bin `bin`'s contact groups in solve order: each colour on the
    /// world's backend, then the overflow set on the scalar one.
    fn contact_groups(&self, bin: usize) -> impl Iterator<Item = (Range<usize>, Backend)> + '_ {
        let contact_bin = self.contact_bins.get(bin).cloned().unwrap_or_default();
        let colours = self.contact_colours[contact_bin.colours.clone()]
            .iter()
            .map(|r| (r.clone(), self.backend));
        colours.chain(core::iter::once((contact_bin.overflow, Backend::Scalar)))
    }

    /// One stage whose chunks are the bins `1..`, each running `solve` on
    /// one worker (all of them in one chunk, one after another, unless
    /// the bins keep apart).
    fn bins_stage(&self, cursor: &mut Cursor, solve: impl Fn(usize) + Sync) {
        // Every bin of either layout (a world that never laid out a joint
        // has no joints' bin at all).
        let bins = self.joint_bins.len().max(self.contact_bins.len());
        let rest = 1..bins.max(1);
        if self.bins_apart {
            cursor.stage(&[&Chunks(rest.len(), |k| solve(1 + k))]);
        } else {
            cursor.stage(&[&Chunks(usize::from(!rest.is_empty()), |_| {
                rest.clone().for_each(&solve)
            })]);
        }
    }

    /// `pass` over bin `bin` (not 0), whole, on this worker: as
    /// [`Self::for_each_colour`] in order, with no stage between.
    fn solve_bin(&self, bin: usize, pass: &impl Pass) {
        let rows = &self.rows;
        for (range, backend) in self.contact_groups(bin) {
            let run = |c: &mut [ContactBlock]| pass.contacts(c, rows.rows(), backend);
            // SAFETY: a bin's blocks are its own (bins_stage hands each bin
            // to one worker).
            run_whole(unsafe { BlockChunks::new(&self.contacts, range.clone(), range.len(), run) });
        }
        if !pass.joints() {
            return;
        }
        let Some(joints) = self.joint_bins.get(bin) else {
            return;
        };
        let groups = (joints.colours.iter().map(|g| (g, self.backend)))
            .chain(core::iter::once((&joints.overflow, Backend::Scalar)));
        for (group, backend) in groups {
            for (range, driven, shaped) in group.socket_ranges() {
                let kind = SocketBlocks { driven, shaped };
                let run = |c: &mut [SocketBlock]| pass.sockets(c, kind, rows.rows(), backend);
                // SAFETY: as above.
                run_whole(unsafe {
                    BlockChunks::new(&self.sockets, range.clone(), range.len(), run)
                });
            }
            for (range, driven) in group.hinge_ranges() {
                let run = |c: &mut [HingeBlock]| pass.hinges(c, driven, rows.rows(), backend);
                // SAFETY: as above.
                run_whole(unsafe {
                    BlockChunks::new(&self.hinges, range.clone(), range.len(), run)
                });
            }
            let run = |c: &mut [FixedBlock]| pass.fixed(c, rows.rows(), backend);
            // SAFETY: as above.
            run_whole(unsafe {
                BlockChunks::new(&self.fixed, group.fixed.clone(), group.fixed.len(), run)
            });
            let run = |c: &mut [RodBlock]| pass.rods(c, rows.rows(), backend);
            // SAFETY: as above.
            run_whole(unsafe {
                BlockChunks::new(&self.rods, group.rods.clone(), group.rods.len(), run)
            });
        }
        self.solve_bin_trees(bin, pass);
    }

    /// `pass` over bin `bin`'s trees (not bin 0), whole, on this worker.
    fn solve_bin_trees(&self, bin: usize, pass: &impl Pass) {
        let Some(joints) = self.joint_bins.get(bin) else {
            return;
        };
        let (range, joined) = (joints.trees.clone(), joints.trees_joined);
        let run = |c: &mut [TreeBlock]| {
            pass.trees(c, self.topologies, self.rows.rows(), self.backend, joined)
        };
        // SAFETY: a bin's blocks are its own (bins_stage hands each bin to
        // one worker).
        run_whole(unsafe { BlockChunks::new(&self.trees, range.clone(), range.len(), run) });
    }

    /// One colour's joints (or the overflow set's): one stage of every
    /// kind's chunks when the colour may be split (`disjoint`, a SIMD
    /// backend), else one stage of one chunk per kind, one after another.
    fn joint_colour(
        &self,
        cursor: &mut Cursor,
        group: &Group,
        backend: Backend,
        disjoint: bool,
        pass: &impl Pass,
    ) {
        let split = backend != Backend::Scalar && disjoint;
        let socket_ranges = group.socket_ranges();
        let hinge_ranges = group.hinge_ranges();
        let blocks = socket_ranges.iter().map(|(r, ..)| r.len()).sum::<usize>()
            + hinge_ranges.iter().map(|(r, _)| r.len()).sum::<usize>()
            + group.fixed.len()
            + group.rods.len();
        if blocks == 0 {
            return; // an empty overflow set: no stage
        }
        let size = if split {
            self.chunk_size(true, blocks)
        } else {
            blocks
        };
        let rows = &self.rows;
        // The parts of one stage lend blocks of four different vectors,
        // and a group's ranges of one vector do not overlap (the layout
        // lays each kind's blocks out one range after another). Only the
        // kinds this colour holds become parts, in order (a small world's
        // colours hold one or two).
        let socket = |(range, driven, shaped): (&Range<usize>, bool, bool)| {
            let kind = SocketBlocks { driven, shaped };
            let run = move |c: &mut [SocketBlock]| pass.sockets(c, kind, rows.rows(), backend);
            // SAFETY: no other part lends these blocks (above).
            (!range.is_empty())
                .then(|| unsafe { BlockChunks::new(&self.sockets, range.clone(), size, run) })
        };
        let hinge = |(range, driven): (&Range<usize>, bool)| {
            let run = move |c: &mut [HingeBlock]| pass.hinges(c, driven, rows.rows(), backend);
            // SAFETY: no other part lends these blocks (above).
            (!range.is_empty())
                .then(|| unsafe { BlockChunks::new(&self.hinges, range.clone(), size, run) })
        };
        let [r0, r1, r2, r3] = socket_ranges;
        let (s0, s1, s2, s3) = (socket(r0), socket(r1), socket(r2), socket(r3));
        let [r4, r5] = hinge_ranges;
        let (h0, h1) = (hinge(r4), hinge(r5));
        let run = |c: &mut [FixedBlock]| pass.fixed(c, rows.rows(), backend);
        // SAFETY: no other part lends these blocks (above).
        let fixed = (!group.fixed.is_empty())
            .then(|| unsafe { BlockChunks::new(&self.fixed, group.fixed.clone(), size, run) });
        let run = |c: &mut [RodBlock]| pass.rods(c, rows.rows(), backend);
        // SAFETY: no other part lends these blocks (above).
        let rods = (!group.rods.is_empty())
            .then(|| unsafe { BlockChunks::new(&self.rods, group.rods.clone(), size, run) });
        fn part<P: Part>(p: &Option<P>) -> Option<&dyn Part> {
            p.as_ref().map(|p| p as &dyn Part)
        }
        let mut held = [
            part(&s0),
            part(&s1),
            part(&s2),
            part(&s3),
            part(&h0),
            part(&h1),
            part(&fixed),
            part(&rods),
        ]
        .into_iter()
        .flatten();
        let Some(first) = held.next() else {
            return;
        };
        let mut parts = [first; 8];
        let mut kinds = 1;
        for p in held {
            parts[kinds] = p;
            kinds += 1;
        }
        let parts = &parts[..kinds];
        if split {
            cursor.stage(parts);
        } else {
            // One stage each: the overflow set's constraints (or a crafted
            // colouring's) may share bodies across kinds.
            for &part in parts {
                cursor.stage(&[part]);
            }
        }
    }
}

/// Runs every chunk of `part` (a bin's blocks of one kind, one chunk) on
/// this worker.
fn run_whole(part: impl Part) {
    (0..part.chunks()).for_each(|chunk| part.run(chunk));
}

/// Whether every lane of every bin `1..` keeps to its bin's rows
/// ([`Bins::owns`]): then bins may be solved at once. Checked every step
/// from the lanes themselves, not taken on trust from `bins.rs`.
fn bins_apart(bins: &Bins, joints: &Layout, contacts: &ContactLayout) -> bool {
    let lanes_own = |bin: u32, pairs: &BodyPairs| {
        (0..pairs.body_a.len()).all(|l| {
            bins.owns(bin, pairs.body_a[l], pairs.write_a[l])
                && bins.owns(bin, pairs.body_b[l], pairs.write_b[l])
        })
    };
    let trees_own = |bin: u32, b: &TreeBlock| {
        (b.bodies.iter()).all(|n| (0..n.row.len()).all(|l| bins.owns(bin, n.row[l], n.write[l])))
            && b.joints.iter().all(|j| lanes_own(bin, &j.bodies))
    };
    let tree_bins = joints.bins.iter().enumerate().skip(1);
    if !tree_bins.clone().all(|(k, b)| {
        joints.trees.blocks[b.trees.clone()]
            .iter()
            .all(|t| trees_own(k as u32, t))
    }) {
        return false;
    }
    let joint_bins = joints.bins.iter().enumerate().skip(1);
    let contact_bins = contacts.bins.iter().enumerate().skip(1);
    joint_bins
        .clone()
        .all(|(k, b)| joints.bin_pairs(b).all(|p| lanes_own(k as u32, p)))
        && contact_bins
            .clone()
            .all(|(k, b)| contacts.bin_pairs(b).all(|p| lanes_own(k as u32, p)))
}

/// Derives velocities from the solved motion: `v = (d - d0) / h` from the
/// displacements since the step began (exact to the precision of the
/// motion, wherever the body is), `w = log(q q0*) / h` (shortest arc);
/// both held to the speed limits, which a hard correction can exceed.
fn derive_velocities(c: &mut BodyChunk, b: &BodyRead, rows: &BodyRows, h: f32) {
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        if !b.moving[i] || b.kind[i] != BodyKind::Dynamic {
            continue;
        }
        let (d, q) = pose(rows, i);
        let (d0, q0) = c.previous[j];
        c.orientation[j] = q;
        c.linear_velocity[j] = limit((d - d0) / h, b.max_linear_speed);
        c.angular_velocity[j] = limit(angular_velocity(q, q0, h), b.max_angular_speed);
        rows.velocity[i + 1].set(BodyRows::velocity_row(
            c.linear_velocity[j],
            c.angular_velocity[j],
        ));
    }
}

/// The velocity pass's results, held to the speed limits, back to the
/// bodies.
fn read_velocities(c: &mut BodyChunk, b: &BodyRead, rows: &BodyRows) {
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        if b.moving[i] && b.kind[i] == BodyKind::Dynamic {
            let [vx, vy, vz, _, wx, wy, wz, _] = rows.velocity[i + 1].get();
            c.linear_velocity[j] = limit(Vec3::new(vx, vy, vz), b.max_linear_speed);
            c.angular_velocity[j] = limit(Vec3::new(wx, wy, wz), b.max_angular_speed);
        }
    }
}

/// The last line of defence: a body whose motion is no longer finite goes
/// back to its pose before the substep, at rest, and is counted. Validated
/// input keeps every body finite: it never fired in any test, scene or in
/// 390,000 fuzzed call sequences run with it made to panic
/// (docs/robustness.md). It stays so that a case nobody found yet costs a
/// body a substep, not the world.
fn repair(c: &mut BodyChunk, b: &BodyRead, rows: &BodyRows) -> u64 {
    let mut repaired = 0;
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        let (displacement, orientation) = c.previous[j];
        let (d, q) = pose(rows, i);
        let finite = b.position[i].is_finite()
            && c.orientation[j].is_finite()
            && c.linear_velocity[j].is_finite()
            && c.angular_velocity[j].is_finite()
            && d.is_finite()
            && q.is_finite();
        if b.moving[i] && !finite {
            c.orientation[j] = orientation;
            c.linear_velocity[j] = Vec3::ZERO;
            c.angular_velocity[j] = Vec3::ZERO;
            rows.pose[i + 1].set(BodyRows::pose_row(
                displacement,
                b.inverse_mass[i],
                orientation,
            ));
            repaired += 1;
        }
    }
    repaired
}

/// Linear and angular damping: `v /= 1 + h c`.
fn damp(c: &mut BodyChunk, b: &BodyRead, h: f32) {
    for j in 0..c.linear_velocity.len() {
        let i = c.start + j;
        if b.moving[i] && b.kind[i] == BodyKind::Dynamic {
            c.linear_velocity[j] /= 1.0 + h * b.linear_damping[i];
            c.angular_velocity[j] /= 1.0 + h * b.angular_damping[i];
        }
    }
}
