//! One step around its substeps: the joint and contact blocks' start of
//! step, then per substep the drives' and limits' start and the substep
//! itself (`substep.rs`), then the bodies moved by their motion in double
//! precision and the moving targets written back to the descriptions
//! (XPBD for rigid bodies, Müller et al. 2020, algorithm 2).

use glam::{Quat, Vec3};
use vertebra_kernels::body::BodyRows;
use vertebra_kernels::contact::ContactBlock;
use vertebra_kernels::direct::{self, TreeBlock};
use vertebra_kernels::fixed::FixedBlock;
use vertebra_kernels::hinge::HingeBlock;
use vertebra_kernels::rod::RodBlock;
use vertebra_kernels::socket::SocketBlock;
use vertebra_math::Backend;
use vertebra_store::{BodyKind, BodyStore};

use crate::World;
use crate::body_drive::Clock;
use crate::integrate::{mark_moving, pose};
use crate::joint::JointKind;
use crate::kinds::{BlockKind, JointBlock, Vector};
use crate::stages::{Cursor, SliceChunks};
use crate::start::start_blocks;
use crate::substep::{CHUNKS_PER_WORKER, solve_substep};

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

/// The step after its contacts and joint blocks have started
/// ([`start_blocks_all`]): `substeps` times the drives' start and a
/// substep ([`solve_substep`]), then the bodies moved by their motion,
/// the drives' and rods' moving targets kept, and the forces cleared.
pub(crate) fn solve(world: &mut World, dt: f32, workers: usize) {
    let h = dt / world.config.substeps as f32;
    upload(&world.bodies, world.rows.get());
    world
        .previous
        .resize(world.bodies.capacity(), (Vec3::ZERO, Quat::IDENTITY));
    mark_moving(&world.bodies, &world.islands, &mut world.moving);
    let substeps = world.config.substeps;
    for substep in 0..substeps {
        start_drives(world, h);
        world.layout.reset_lambdas();
        // An overlap found at detection comes out evenly over the step
        // (docs/contacts.md, "The jammed pile").
        let remaining = (substeps - 1 - substep) as f32 / substeps as f32;
        world
            .contact_layout
            .blocks
            .iter_mut()
            .for_each(|b| b.start_substep(remaining));
        for block in &mut world.layout.trees.blocks {
            block
                .pins
                .iter_mut()
                .for_each(|p| p.start_substep(remaining));
        }
        let clock = Clock { k: substep, h };
        world.repaired += solve_substep(world, clock, workers);
    }
    commit(world);
    keep_drive_targets(world);
    let elapsed = substeps as f32 * h;
    for d in &mut world.body_drives {
        d.advance(elapsed);
    }
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
    let backend = world.backend;
    for group in groups {
        // An empty range is not dispatched: a small world's groups hold
        // few kinds, and entering a backend is not free.
        for (kind, range) in group.kinds().filter(|(_, r)| !r.is_empty()) {
            let r = range.clone();
            match kind.vector() {
                Vector::Sockets => {
                    start_substep(&mut layout.sockets.blocks[r], kind, rows, h, backend)
                }
                Vector::Hinges => {
                    start_substep(&mut layout.hinges.blocks[r], kind, rows, h, backend)
                }
                Vector::Fixed => start_substep(&mut layout.fixed.blocks[r], kind, rows, h, backend),
                Vector::Rods => start_substep(&mut layout.rods.blocks[r], kind, rows, h, backend),
            }
        }
    }
    for bin in &bins {
        if !bin.trees.is_empty() {
            world.backend.dispatch(direct::StartPass {
                blocks: &mut layout.trees.blocks[bin.trees.clone()],
                topologies: &layout.trees.topologies,
                rows,
                h,
            });
        }
    }
    layout.bins = bins;
}

/// [`JointBlock::start_substep`] for `blocks`, all of `kind`.
fn start_substep<B: JointBlock>(
    blocks: &mut [B],
    kind: BlockKind,
    rows: &BodyRows,
    h: f32,
    backend: Backend,
) {
    B::start_substep(blocks, kind, rows, h, backend);
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
                layout.sockets.blocks[block].drive.settings.target.get(lane)
            }
            JointKind::Hinge { .. } => {
                let (block, lane) = layout.hinges.place[slot];
                layout.hinges.blocks[block].drive.settings.target.get(lane)
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
