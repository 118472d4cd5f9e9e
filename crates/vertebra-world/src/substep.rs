//! One substep as named stages over the workers: predict, the position
//! iterations (each colour's contacts, then its joints kind by kind from
//! the joint kinds' table, then the direct solve's trees), the closing
//! tree solves, derive velocities, the velocity and relax passes, and the
//! bodies' finish; with the solve bins `1..` each on one worker. The one
//! place the substep lends its blocks to the workers is [`Substep::lend`].

use core::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};

use vertebra_kernels::body::{BodyPairs, BodyRows};
use vertebra_kernels::contact::{ContactBlock, VelocitySettings};
use vertebra_kernels::direct::{self, Topology, TreeBlock};
use vertebra_kernels::fixed::FixedBlock;
use vertebra_kernels::hinge::HingeBlock;
use vertebra_kernels::pass::SubstepScale;
use vertebra_kernels::rod::RodBlock;
use vertebra_kernels::socket::SocketBlock;
use vertebra_math::Backend;

use crate::World;
use crate::bins::Bins;
use crate::body_drive::Clock;
use crate::contact_layout::{ContactBin, ContactLayout, Pinned, pins_to_contacts};
use crate::integrate::{
    BodyChunk, BodyRead, damp, derive_velocities, predict, read_velocities, repair,
};
use crate::kinds::{BlockKind, Group, JointBlock, Vector};
use crate::layout::{Bin, Layout};
use crate::parallel::Shared;
use crate::passes::{Pass, Positions, Velocities};
use crate::stages::{Chunks, Cursor, Part, SharedBlocks};

/// Direct solves after a substep's last iteration, with nothing between
/// (`SolverConfig::joints` = `Direct`): each is a Newton step on the
/// joints' rows, so the error the last iteration's solve left (second
/// order in its correction, whatever the limits and contacts did before
/// it) shrinks quadratically again, and the hard limits' active set
/// settles. In the 30-ragdoll drop at 1 x 4 the second took the sockets'
/// summed angular error from 0.39 to 0.12 rad (docs/direct.md).
const CLOSING_SOLVES: usize = 2;

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
pub(crate) const CHUNKS_PER_WORKER: usize = 4;

/// What the workers of one substep share: the stages' work.
struct Substep<'a> {
    rows: Shared<'a>,
    backend: Backend,
    workers: usize,
    min_blocks: usize,
    iterations: u32,
    h: f32,
    /// Which substep of the step this is (from 0).
    k: u32,
    /// Relax passes after the velocity pass ([`RELAX_PASSES`] or none).
    relax_passes: u32,
    bodies: BodyRead<'a>,
    body_chunks: [Mutex<Option<BodyChunk<'a>>>; MAX_BODY_CHUNKS],
    body_chunk_count: usize,
    /// Every block the stages solve, lent to the workers ([`Self::lend`]).
    blocks: SubstepBlocks<'a>,
    topologies: &'a [Topology],
    trees_disjoint: bool,
    joint_bins: &'a [Bin],
    joints_disjoint: bool,
    contact_colours: &'a [Range<usize>],
    contact_bins: &'a [ContactBin],
    contacts_disjoint: bool,
    /// The bins `1..` keep to their own rows (`bins_apart`): each may be
    /// solved by one worker while others solve the rest.
    bins_apart: bool,
    /// The step's pins (`ContactLayout::pin`).
    pins: &'a [Pinned],
    /// Bodies put back by [`repair`] this substep.
    repaired: AtomicU64,
}

/// One substep after its drives have started: predict, the position
/// iterations, derive velocities, the velocity pass, damp and repair, as
/// one launch of the task system's workers walking the stages
/// ([`Substep::walk`]). Returns how many bodies were repaired.
pub(crate) fn solve_substep(world: &mut World, clock: Clock, workers: usize) -> u64 {
    let Clock { k, h } = clock;
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
        k,
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
            drives: &world.body_drives,
            gravity: config.gravity,
            max_linear_speed: config.max_linear_speed,
            max_angular_speed: config.max_angular_speed,
        },
        body_chunks,
        body_chunk_count,
        blocks: SubstepBlocks {
            sockets: SharedBlocks::new(&mut layout.sockets.blocks),
            hinges: SharedBlocks::new(&mut layout.hinges.blocks),
            fixed: SharedBlocks::new(&mut layout.fixed.blocks),
            rods: SharedBlocks::new(&mut layout.rods.blocks),
            trees: SharedBlocks::new(&mut layout.trees.blocks),
            contacts: SharedBlocks::new(&mut contacts.blocks),
        },
        topologies: &layout.trees.topologies,
        trees_disjoint: layout.trees.disjoint,
        joint_bins: &layout.bins,
        joints_disjoint: layout.disjoint,
        contact_colours: &contacts.colours,
        contact_bins: &contacts.bins,
        contacts_disjoint: contacts.disjoint,
        bins_apart,
        pins: &contacts.pins,
        repaired: AtomicU64::new(0),
    };
    world
        .stages
        .run(&*world.tasks, workers, &|cursor: &mut Cursor| {
            substep.walk(cursor)
        });
    substep.repaired.into_inner()
}

impl<'a> Substep<'a> {
    /// The substep's stages, in order.
    fn walk(&self, cursor: &mut Cursor) {
        let (h, k) = (self.h, self.k);
        let bodies = &self.bodies;
        self.body_pass(cursor, |c, rows| predict(c, bodies, rows, Clock { k, h }));
        // An iteration's tree solve factors each tree once; the closing
        // solves settle the limits' active set (docs/direct.md, "The
        // limits").
        let positions = Positions {
            scale: SubstepScale {
                inv_h: 1.0 / h,
                inv_h2: 1.0 / (h * h),
            },
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
                self.solve_bin(bin, &positions, true);
            }
            for _ in 0..CLOSING_SOLVES {
                self.solve_bin(bin, &closing, false);
            }
        });
        self.pins_stage(cursor);
        self.body_pass(cursor, |c, rows| derive_velocities(c, bodies, rows, h));
        let resting_speed = 2.0 * bodies.gravity.length() * h;
        let settings = VelocitySettings {
            h,
            resting_speed,
            relax: false,
        };
        let velocities = Velocities(settings);
        let relax = Velocities(VelocitySettings {
            relax: true,
            ..settings
        });
        for pass in core::iter::once(&velocities).chain((0..self.relax_passes).map(|_| &relax)) {
            self.for_each_colour(cursor, 0, pass);
            self.bins_stage(cursor, |bin| self.solve_bin(bin, pass, true));
        }
        self.body_pass(cursor, |c, rows| {
            read_velocities(c, bodies, rows);
            damp(c, bodies, h);
            let repaired = repair(c, bodies, rows);
            self.repaired.fetch_add(repaired, Ordering::Relaxed);
        });
    }

    /// Lends `blocks` (the contacts, a kind's joint blocks or the trees)
    /// in `range`, in chunks of `size`, to run `pass` on `backend`: the
    /// one place the substep's blocks reach its workers.
    ///
    /// # Safety
    /// While the result is run, nothing else may reach these blocks: it
    /// is the only part of its stage that lends them, or it is run whole
    /// by one worker holding its solve bin.
    // SAFETY: unsafe to call: `Lent::run` relies on this contract.
    unsafe fn lend<'s, P: Pass>(
        &'s self,
        blocks: Lend,
        range: Range<usize>,
        size: usize,
        pass: &'s P,
        backend: Backend,
    ) -> Lent<'s, 'a, P> {
        assert!(range.start <= range.end, "a range of blocks");
        Lent {
            substep: self,
            blocks,
            range,
            size: size.max(1),
            pass,
            backend,
        }
    }

    /// One stage of one chunk, after every tree's solves and before the
    /// velocity pass: each pin's multipliers into its contact's lane
    /// (`contact_layout::pins_to_contacts`). None without pins.
    fn pins_stage(&self, cursor: &mut Cursor) {
        if self.pins.is_empty() {
            return;
        }
        cursor.stage(&[&Chunks(1, |_| {
            let (trees, contacts) = (&self.blocks.trees, &self.blocks.contacts);
            // SAFETY: the only part of its stage, of one chunk: nothing
            // else reaches the trees or the contacts while it runs.
            let (trees, contacts) = unsafe {
                (
                    trees.range(0..trees.len()),
                    contacts.range(0..contacts.len()),
                )
            };
            pins_to_contacts(self.pins, trees, contacts);
        })]);
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
    fn for_each_colour<P: Pass>(&self, cursor: &mut Cursor, bin: usize, pass: &P) {
        for (range, backend) in self.contact_groups(bin) {
            let split = backend != Backend::Scalar && self.contacts_disjoint;
            let size = self.chunk_size(split, range.len());
            // SAFETY: the only part of its stage.
            let part = unsafe { self.lend(Lend::Contacts, range, size, pass, backend) };
            cursor.stage(&[&part]);
        }
        if !P::JOINTS {
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
    fn trees_stage<P: Pass>(&self, cursor: &mut Cursor, joints: &Bin, pass: &P) {
        let range = &joints.trees;
        if !range.is_empty() {
            let joined = joints.trees_joined;
            let size = self.chunk_size(self.trees_disjoint && !joined, range.len());
            let trees = Lend::Trees { joined };
            // SAFETY: the only part of its stage.
            let part = unsafe { self.lend(trees, range.clone(), size, pass, self.backend) };
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
    /// [`Self::for_each_colour`] in order, with no stage between; or with
    /// `!all` only its trees (the closing solves).
    fn solve_bin<P: Pass>(&self, bin: usize, pass: &P, all: bool) {
        let joints = self.joint_bins.get(bin);
        let contacts = (self.contact_groups(bin).filter(|_| all))
            .map(|(range, backend)| (Lend::Contacts, range, backend));
        let groups = joints
            .filter(|_| all && P::JOINTS)
            .into_iter()
            .flat_map(|j| {
                (j.colours.iter().map(|g| (g, self.backend)))
                    .chain(core::iter::once((&j.overflow, Backend::Scalar)))
            })
            .flat_map(|(group, backend)| {
                (group.kinds())
                    .map(move |(kind, range)| (Lend::Joints(kind), range.clone(), backend))
            });
        let trees = joints.filter(|_| P::JOINTS).map(|j| {
            let trees = Lend::Trees {
                joined: j.trees_joined,
            };
            (trees, j.trees.clone(), self.backend)
        });
        for (blocks, range, backend) in contacts.chain(groups).chain(trees) {
            let size = range.len();
            // SAFETY: a bin's blocks are its own (bins_stage hands each bin
            // to one worker), run whole here.
            run_whole(unsafe { self.lend(blocks, range, size, pass, backend) });
        }
    }

    /// One colour's joints (or the overflow set's): one stage of every
    /// kind's chunks when the colour may be split (`disjoint`, a SIMD
    /// backend), else one stage of one chunk per kind, one after another.
    fn joint_colour<P: Pass>(
        &self,
        cursor: &mut Cursor,
        group: &Group,
        backend: Backend,
        disjoint: bool,
        pass: &P,
    ) {
        let split = backend != Backend::Scalar && disjoint;
        let blocks = group.len();
        if blocks == 0 {
            return; // an empty overflow set: no stage
        }
        let size = if split {
            self.chunk_size(true, blocks)
        } else {
            blocks
        };
        // The parts of one stage lend blocks of different kinds, and a
        // group's ranges of one vector do not overlap (the layout lays each
        // kind's blocks out one range after another). Only the kinds this
        // colour holds become parts, in order (a small world's colours
        // hold one or two).
        let lent = group.kinds().map(|(kind, range)| {
            // SAFETY: no other part of the stage lends these blocks (above).
            (!range.is_empty()).then(|| unsafe {
                self.lend(Lend::Joints(kind), range.clone(), size, pass, backend)
            })
        });
        let lent: [Option<Lent<P>>; BlockKind::COUNT] = core::array::from_fn({
            let mut lent = lent;
            move |_| lent.next().flatten()
        });
        let mut held = lent.iter().flatten().map(|p| p as &dyn Part);
        let Some(first) = held.next() else {
            return;
        };
        let mut parts = [first; BlockKind::COUNT];
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

/// Which of the substep's blocks a [`Lent`] holds.
#[derive(Clone, Copy)]
enum Lend {
    /// A joint kind's blocks.
    Joints(BlockKind),
    /// Contact blocks.
    Contacts,
    /// Tree blocks (`joined`: all of them one solve).
    Trees { joined: bool },
}

/// The substep's blocks, lent to its workers for its launch.
struct SubstepBlocks<'a> {
    sockets: SharedBlocks<'a, SocketBlock>,
    hinges: SharedBlocks<'a, HingeBlock>,
    fixed: SharedBlocks<'a, FixedBlock>,
    rods: SharedBlocks<'a, RodBlock>,
    trees: SharedBlocks<'a, TreeBlock>,
    contacts: SharedBlocks<'a, ContactBlock>,
}

/// Blocks of the substep in chunks of `size`, each chunk run with `pass`
/// ([`Substep::lend`]).
struct Lent<'s, 'a, P> {
    substep: &'s Substep<'a>,
    blocks: Lend,
    range: Range<usize>,
    size: usize,
    pass: &'s P,
    backend: Backend,
}

impl<P: Pass> Lent<'_, '_, P> {
    /// A kind's joint blocks in `range` through its block type's kernels.
    fn joints<B: JointBlock>(
        &self,
        shared: &SharedBlocks<B>,
        kind: BlockKind,
        range: Range<usize>,
    ) {
        // SAFETY: `Substep::lend`'s contract: no one else reaches them.
        let blocks = unsafe { shared.range(range) };
        let rows = self.substep.rows.rows();
        self.pass.joints(blocks, kind, rows, self.backend);
    }
}

impl<P: Pass> Part for Lent<'_, '_, P> {
    fn chunks(&self) -> usize {
        self.range.len().div_ceil(self.size)
    }
    fn run(&self, chunk: usize) {
        let start = self.range.start + chunk * self.size;
        let range = start..(start + self.size).min(self.range.end);
        let (substep, rows) = (self.substep, self.substep.rows.rows());
        let shared = &substep.blocks;
        match self.blocks {
            Lend::Joints(kind) => match kind.vector() {
                Vector::Sockets => self.joints(&shared.sockets, kind, range),
                Vector::Hinges => self.joints(&shared.hinges, kind, range),
                Vector::Fixed => self.joints(&shared.fixed, kind, range),
                Vector::Rods => self.joints(&shared.rods, kind, range),
            },
            Lend::Contacts => {
                // SAFETY: `Substep::lend`'s contract: no one else reaches them.
                let blocks = unsafe { shared.contacts.range(range) };
                self.pass.contacts(blocks, rows, self.backend);
            }
            Lend::Trees { joined } => {
                // SAFETY: `Substep::lend`'s contract: no one else reaches them.
                let blocks = unsafe { shared.trees.range(range) };
                (self.pass).trees(blocks, substep.topologies, rows, self.backend, joined);
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
