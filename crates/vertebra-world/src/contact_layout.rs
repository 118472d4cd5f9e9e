//! This step's contacts coloured and laid out in blocks, into buffers the
//! world keeps (they change every step): greedy colours per solve bin, an
//! overflow set, and each lane filled from its contact and the bodies.

use core::ops::Range;

use glam::Vec3;
use vertebra_kernels::body::{BodyPairs, LaneBlock, StartLane};
use vertebra_kernels::contact::{ContactBlock, ContactImpulse, ContactLane};
use vertebra_kernels::direct::TreeBlock;
use vertebra_kernels::direct::pin::{MAX_PINS, PIN_STIFFNESS, PinLane};
use vertebra_math::block::BLOCK_LANES;
use vertebra_scheduler::MAX_COLOURS;
use vertebra_store::{BodyHandle, BodyKind, BodyStore};

use crate::bins::Bins;
use crate::contact::Contact;
use crate::layout::pair;
use crate::trees::Trees;

/// This step's contacts, coloured and in blocks. Kept by the world and
/// laid out again every step into the same buffers: once they have grown
/// to the world's contact count, a step's layout allocates nothing.
#[derive(Clone, Debug, Default)]
pub(crate) struct ContactLayout {
    pub blocks: Vec<ContactBlock>,
    /// Block ranges of the non-empty colours, bin by bin (`bins.rs`), in
    /// colour order inside each bin.
    pub colours: Vec<Range<usize>>,
    /// Per solve bin (bin 0 first): its colours and its overflow set.
    pub bins: Vec<ContactBin>,
    /// Every colour passed [`crate::parallel::colour_is_disjoint`].
    pub disjoint: bool,
    /// Scratch: each contact's bucket: its bin's colour (or overflow set),
    /// or [`ASLEEP`].
    colour_of: Vec<u32>,
    /// Scratch: per dynamic body, the bitset of colours its contacts use.
    body_colours: Vec<u32>,
    /// Scratch: the contacts' indices in solve order (bin by bin, colour
    /// by colour, the order given inside each).
    order: Vec<u32>,
    /// Scratch: where each bucket starts in `order`.
    starts: Vec<usize>,
    /// Scratch: where the next contact of each bucket goes in `order`.
    next: Vec<usize>,
    /// Scratch of the disjointness check.
    reads: Vec<u32>,
    /// Scratch: per block, its contacts' range of `order`.
    block_keys: Vec<Range<u32>>,
    /// This step's pins: the contacts its trees' solves take
    /// ([`Self::pin`]).
    pub pins: Vec<Pinned>,
    /// Scratch: per contact, whether a tree's solve takes it.
    pinned: Vec<bool>,
    /// Scratch: per tree, its mass (kg; NaN until a pin asks).
    tree_mass: Vec<f32>,
    /// Scratch: per contact, its block and lane.
    lane_of: Vec<(u32, u8)>,
}

/// A contact a tree's solve takes: where its lane is here, and where its
/// pin is.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pinned {
    /// The contact's block here and its lane.
    pub contact_block: u32,
    pub contact_lane: u8,
    /// The tree block, the body's index in it, the lane and the slot.
    pub block: u32,
    pub body: u32,
    pub lane: u8,
    pub slot: u8,
}

/// Writes each pin's multipliers over the substep's solves into its
/// contact's lane (`lambda_n`, `lambda_t`), where the velocity pass, the
/// relax passes and the step's impulses read them as any contact's.
pub(crate) fn pins_to_contacts(
    pins: &[Pinned],
    trees: &[TreeBlock],
    contacts: &mut [ContactBlock],
) {
    for p in pins {
        let pin = &trees[p.block as usize].pins[p.body as usize];
        let Some((normal, friction)) = pin.substep(p.lane as usize, p.slot as usize) else {
            continue;
        };
        let block = &mut contacts[p.contact_block as usize];
        let lane = p.contact_lane as usize;
        block.lambda_n[lane] = normal;
        block.lambda_t.set(lane, friction);
    }
}

/// One solve bin's contacts.
#[derive(Clone, Debug, Default)]
pub(crate) struct ContactBin {
    /// Its range of [`ContactLayout::colours`].
    pub colours: Range<usize>,
    /// Block range of its overflow set.
    pub overflow: Range<usize>,
}

/// The colour index of the overflow set.
const OVERFLOW: usize = MAX_COLOURS;

/// Buckets per bin: its colours and its overflow set.
const BUCKETS: usize = OVERFLOW + 1;

/// The bucket of a contact left out (its dynamic bodies sleep): past every
/// bin's.
const ASLEEP: u32 = u32::MAX;

impl ContactLayout {
    /// Colours `contacts` greedily in the order given (each takes the
    /// lowest colour free at both its dynamic bodies, after
    /// [`MAX_COLOURS`] the overflow set: `vertebra_scheduler::Colouring`'s
    /// rule, with bitsets that live for one step) and lays them out bin by
    /// bin (`bins`: a contact's is its awake dynamic body's), each overlap
    /// capped at `max_depth` (m) for this step: [`Self::plan`], every
    /// block filled ([`ContactFill`]), [`Self::check`]. The step does the
    /// same with the blocks filled in chunks on its workers.
    #[cfg(test)]
    pub fn rebuild(
        &mut self,
        contacts: &[Contact],
        bodies: &BodyStore,
        asleep: &[bool],
        bins: &Bins,
        max_depth: f32,
    ) {
        self.plan(contacts, bodies, asleep, bins);
        let (fill, blocks) = self.fill(contacts, bodies, max_depth);
        fill.blocks(0, blocks);
        self.check();
    }

    /// Colours `contacts` and sorts them into bins and colours: the block
    /// ranges of every colour and bin, and as many padding blocks as they
    /// hold, each to be filled from its contacts ([`Self::fill`]).
    pub fn plan(&mut self, contacts: &[Contact], bodies: &BodyStore, asleep: &[bool], bins: &Bins) {
        self.pins.clear();
        self.pinned.clear();
        self.pinned.resize(contacts.len(), false);
        self.blocks.clear();
        self.colours.clear();
        self.bins.clear();
        self.block_keys.clear();
        if contacts.is_empty() {
            // Every bin empty, as the buckets below would leave them,
            // without walking them (a ragdoll alone has no contacts).
            let empty = ContactBin {
                colours: 0..0,
                overflow: 0..0,
            };
            self.bins.resize(bins.count.max(1), empty);
            return;
        }
        self.colour(contacts, bodies, asleep, bins);
        let buckets = bins.count.max(1) * BUCKETS;
        self.sort_by_bucket(buckets);
        for bucket in 0..buckets {
            let keys = self.starts[bucket]..self.starts[bucket + 1];
            let start = self.block_keys.len();
            let blocks = keys.clone().step_by(BLOCK_LANES);
            self.block_keys
                .extend(blocks.map(|k| k as u32..(k + BLOCK_LANES).min(keys.end) as u32));
            let range = start..self.block_keys.len();
            if bucket % BUCKETS == 0 {
                let at = self.colours.len();
                self.bins.push(ContactBin {
                    colours: at..at,
                    overflow: 0..0,
                });
            }
            let bin = self.bins.last_mut().expect("pushed above");
            if bucket % BUCKETS == OVERFLOW {
                bin.overflow = range;
            } else if !range.is_empty() {
                self.colours.push(range);
                bin.colours.end = self.colours.len();
            }
        }
        self.blocks
            .resize(self.block_keys.len(), ContactBlock::padding());
    }

    /// Gives the solves of the trees `takes` marks (by index into
    /// `trees.members`) the contacts between one of their bodies and
    /// a static or kinematic body (`vertebra_kernels::direct::pin`), in
    /// the order given, up to [`MAX_PINS`] a body (its further contacts
    /// stay iterated), each from its lane here (overlap capped at
    /// `max_depth`, m), which is marked pinned ([`ContactBlock::pinned`]).
    /// Every pin of the step before is cleared first. After
    /// [`Self::plan`], before [`Self::fill`].
    pub fn pin(
        &mut self,
        contacts: &[Contact],
        bodies: &BodyStore,
        trees: &mut Trees,
        takes: &[bool],
        max_depth: f32,
    ) {
        for block in &mut trees.blocks {
            for pins in &mut block.pins {
                (0..BLOCK_LANES).for_each(|lane| pins.clear_lane(lane));
            }
        }
        self.tree_mass.clear();
        self.tree_mass.resize(trees.members.len(), f32::NAN);
        self.lane_of.clear();
        self.lane_of.resize(contacts.len(), (0, 0));
        for (block, keys) in self.block_keys.iter().enumerate() {
            let keys = &self.order[keys.start as usize..keys.end as usize];
            for (lane, &key) in keys.iter().enumerate() {
                self.lane_of[key as usize] = (block as u32, lane as u8);
            }
        }
        for (key, contact) in contacts.iter().enumerate() {
            if self.colour_of[key] == ASLEEP {
                continue;
            }
            let (a, b) = (contact.body_a.index(), contact.body_b.index());
            let fixed = |i: usize| bodies.kind[i] != BodyKind::Dynamic;
            let place = |i: usize| trees.bodies.get(i).copied().flatten();
            let (place, tree_is_b) = match (place(a), place(b)) {
                (Some(p), _) if fixed(b) => (p, false),
                (_, Some(p)) if fixed(a) => (p, true),
                _ => continue,
            };
            if !takes[place.tree] {
                continue;
            }
            let block = &mut trees.blocks[place.block];
            if !block.pinned() {
                block.take_pins();
            }
            let pins = &mut block.pins[place.body];
            let Some(slot) = (0..MAX_PINS).find(|&k| pins.slots[k].side[place.lane] == 0.0) else {
                continue;
            };
            let mass = &mut self.tree_mass[place.tree];
            if mass.is_nan() {
                *mass = trees.members[place.tree]
                    .iter()
                    .map(|&i| bodies.mass[i])
                    .sum();
            }
            let lane = contact_lane(contact, bodies, max_depth);
            let pin = PinLane {
                pair: lane.pair,
                point_a: lane.point_a,
                point_b: lane.point_b,
                normal: lane.normal,
                friction: lane.friction,
                overlap: lane.overlap,
                start: lane.start,
                tree_is_b,
            };
            pins.set(place.lane, slot, &pin, PIN_STIFFNESS * *mass);
            self.pinned[key] = true;
            let (contact_block, contact_lane) = self.lane_of[key];
            self.pins.push(Pinned {
                contact_block,
                contact_lane,
                block: place.block as u32,
                body: place.body as u32,
                lane: place.lane as u8,
                slot: slot as u8,
            });
        }
    }

    /// The planned blocks ([`Self::plan`]), to be filled by
    /// [`ContactFill::blocks`] in any chunks on any threads.
    pub fn fill<'a>(
        &'a mut self,
        contacts: &'a [Contact],
        bodies: &'a BodyStore,
        max_depth: f32,
    ) -> (ContactFill<'a>, &'a mut [ContactBlock]) {
        let fill = ContactFill {
            block_keys: &self.block_keys,
            order: &self.order,
            pinned: &self.pinned,
            contacts,
            bodies,
            max_depth,
        };
        (fill, &mut self.blocks)
    }

    /// Whether every colour may be split over threads, once the blocks are
    /// filled ([`crate::parallel::colour_is_disjoint`]).
    pub fn check(&mut self) {
        let (blocks, reads) = (&self.blocks, &mut self.reads);
        self.disjoint = self.colours.iter().all(|r| {
            crate::parallel::colour_is_disjoint(blocks[r.clone()].iter().map(|b| &b.bodies), reads)
        });
    }

    /// Each of the step's `count` contacts' impulses (in the order they
    /// were set; zero for one left out, between sleeping bodies) into
    /// `out` (its capacity kept), for substeps of `h` seconds: read from
    /// the blocks after the step's last substep.
    pub fn impulses(&self, count: usize, h: f32, out: &mut Vec<ContactImpulse>) {
        out.clear();
        out.resize(count, ContactImpulse::default());
        for (block, keys) in self.blocks.iter().zip(&self.block_keys) {
            let contacts = &self.order[keys.start as usize..keys.end as usize];
            for (lane, &key) in contacts.iter().enumerate() {
                out[key as usize] = block.impulse(lane, h);
            }
        }
    }

    /// The body pairs of every block of bin `bin`.
    pub fn bin_pairs<'a>(
        &'a self,
        bin: &'a ContactBin,
    ) -> impl Iterator<Item = &'a BodyPairs> + 'a {
        let colours = self.colours[bin.colours.clone()].iter();
        (colours.chain(core::iter::once(&bin.overflow)))
            .flat_map(|r| self.blocks[r.clone()].iter().map(|b| &b.bodies))
    }

    /// Each contact's bucket into `colour_of`: its bin's colour.
    fn colour(&mut self, contacts: &[Contact], bodies: &BodyStore, asleep: &[bool], bins: &Bins) {
        self.body_colours.clear();
        self.body_colours.resize(bodies.capacity(), 0);
        self.colour_of.clear();
        let dynamic =
            |h: BodyHandle| (bodies.kind[h.index()] == BodyKind::Dynamic).then_some(h.index());
        for c in contacts {
            let ends = [dynamic(c.body_a), dynamic(c.body_b)];
            // Between sleeping (or sleeping and still) bodies: not solved.
            if ends.iter().flatten().all(|&b| asleep[b]) {
                self.colour_of.push(ASLEEP);
                continue;
            }
            let used = ends
                .iter()
                .flatten()
                .fold(0u32, |acc, &b| acc | self.body_colours[b]);
            let colour = (!used).trailing_zeros() as usize;
            let bin = bins.of_rows(c.body_a.index() as u32 + 1, c.body_b.index() as u32 + 1);
            let bin = (bin as usize).min(bins.count.max(1) - 1);
            if colour < MAX_COLOURS {
                for &b in ends.iter().flatten() {
                    self.body_colours[b] |= 1 << colour;
                }
                self.colour_of.push((bin * BUCKETS + colour) as u32);
            } else {
                self.colour_of.push((bin * BUCKETS + OVERFLOW) as u32);
            }
        }
    }

    /// `order` as the contacts sorted by bucket, stably (a counting sort
    /// over `buckets` buckets, the left-out contacts last); `starts` where
    /// each bucket starts in it, and its end.
    fn sort_by_bucket(&mut self, buckets: usize) {
        let bucket = |c: u32| if c == ASLEEP { buckets } else { c as usize };
        self.starts.clear();
        self.starts.resize(buckets + 2, 0);
        for &c in &self.colour_of {
            self.starts[bucket(c) + 1] += 1;
        }
        for b in 0..=buckets {
            self.starts[b + 1] += self.starts[b];
        }
        self.order.clear();
        self.order.resize(self.colour_of.len(), 0);
        self.next.clear();
        self.next.extend_from_slice(&self.starts);
        for (k, &c) in self.colour_of.iter().enumerate() {
            let at = &mut self.next[bucket(c)];
            self.order[*at] = k as u32;
            *at += 1;
        }
    }
}

/// What filling the planned contact blocks reads: each block's contacts,
/// and the bodies as the step begins. Each block is filled alone.
pub(crate) struct ContactFill<'a> {
    block_keys: &'a [Range<u32>],
    order: &'a [u32],
    pinned: &'a [bool],
    contacts: &'a [Contact],
    bodies: &'a BodyStore,
    max_depth: f32,
}

impl ContactFill<'_> {
    /// Fills `blocks`, the planned blocks from block `first` on, each lane
    /// from its contact (the lanes past a block's contacts stay padding).
    pub fn blocks(&self, first: usize, blocks: &mut [ContactBlock]) {
        for (block, keys) in blocks.iter_mut().zip(&self.block_keys[first..]) {
            for (lane, &key) in self.order[keys.start as usize..keys.end as usize]
                .iter()
                .enumerate()
            {
                let contact = &self.contacts[key as usize];
                let data = ContactLane {
                    pinned: self.pinned[key as usize],
                    ..contact_lane(contact, self.bodies, self.max_depth)
                };
                block.set(lane, &data);
            }
        }
    }
}

/// Solver data at the bodies' current poses and velocities: the points
/// on each surface, `depth / 2` either side of `point` along the normal,
/// with the depth capped at `max_depth`. The cap is the push-out limit:
/// the solver removes at most `max_depth` of an overlap this step (the
/// rest is still there at the next detection), so a body teleported
/// deep into another comes out at the configured speed instead of
/// being fired out at `depth / dt`, tearing its joints on the way.
fn contact_lane(contact: &Contact, bodies: &BodyStore, max_depth: f32) -> ContactLane {
    let (ia, ib) = (contact.body_a.index(), contact.body_b.index());
    let n = contact.normal.normalize();
    let depth = contact.depth.min(max_depth);
    let on_a = contact.point + n * (0.5 * depth);
    let on_b = contact.point - n * (0.5 * depth);
    let local = |i: usize, p: Vec3| bodies.orientation[i].inverse() * (p - bodies.position[i]);
    let velocity = |i: usize, p: Vec3| {
        bodies.linear_velocity[i] + bodies.angular_velocity[i].cross(p - bodies.position[i])
    };
    let (point_a, point_b) = (local(ia, on_a), local(ib, on_b));
    // The points' separation is the contact's own `-depth n`, exactly:
    // rebuilt from the f32 surface points and the bodies' coordinates it
    // would lose a gap or overlap smaller than the coordinates' last
    // digit (a box 1.6 mm over the ground at 100 km hovered there).
    let start = StartLane {
        gap: n * -depth,
        ..StartLane::new(
            bodies.precise_position(ia),
            bodies.orientation[ia],
            point_a,
            bodies.precise_position(ib),
            bodies.orientation[ib],
            point_b,
        )
    };
    ContactLane {
        pair: pair(contact.body_a, contact.body_b, bodies),
        point_a,
        point_b,
        normal: n,
        friction: contact.friction,
        restitution: contact.restitution,
        approach: (velocity(ib, contact.point) - velocity(ia, contact.point)).dot(n),
        overlap: depth.max(0.0),
        start,
        pinned: false,
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};
    use vertebra_scheduler::Colouring;

    use super::*;
    use crate::{BodyDesc, Shape, SolverConfig, World};

    /// The solve order the scheduler's colouring gives `contacts` (a
    /// `Colouring` fed in order: what the layout was built from before it
    /// kept its buffers): colour by colour, keys ascending, overflow last.
    fn scheduler_order(contacts: &[Contact], bodies: &BodyStore) -> (Vec<u32>, Vec<usize>) {
        let mut colouring = Colouring::new();
        let dynamic = |h: BodyHandle| {
            (bodies.kind[h.index()] == BodyKind::Dynamic).then_some(h.index() as u32)
        };
        for (k, c) in contacts.iter().enumerate() {
            colouring.add(k as u64, [dynamic(c.body_a), dynamic(c.body_b)]);
        }
        let sets = (0..MAX_COLOURS)
            .map(|c| colouring.colour(c))
            .chain([colouring.overflow()]);
        let mut order = Vec::new();
        let mut sizes = Vec::new();
        for set in sets {
            order.extend(set.iter().map(|&k| k as u32));
            sizes.push(set.len());
        }
        (order, sizes)
    }

    #[test]
    fn contacts_are_solved_in_the_order_the_scheduler_colours_them() {
        let mut world = World::new(SolverConfig::default()).unwrap();
        let mass = Shape::Sphere { radius: 0.1 }
            .mass_properties_with_mass(1.0)
            .unwrap();
        let bodies: Vec<BodyHandle> = (0..40)
            .map(|k| {
                let desc = if k % 7 == 0 {
                    BodyDesc::fixed()
                } else {
                    BodyDesc::dynamic(mass)
                };
                world.add_body(desc).unwrap()
            })
            .collect();
        let mut layout = ContactLayout::default();
        for seed in 0..20 {
            let mut rng = StdRng::seed_from_u64(seed);
            // Body 1 is a hub: with 30 contacts it overflows 24 colours.
            let contacts: Vec<Contact> = (0..300)
                .map(|k| {
                    let a = if k < 30 { 1 } else { rng.random_range(0..40) };
                    let b = (a + rng.random_range(1..40)) % 40;
                    Contact {
                        body_a: bodies[a],
                        body_b: bodies[b],
                        point: Vec3::ZERO,
                        normal: Vec3::Y,
                        depth: 0.0,
                        friction: 0.5,
                        restitution: 0.0,
                    }
                })
                .filter(|c| {
                    let kind = |h: BodyHandle| world.bodies().kind[h.index()];
                    kind(c.body_a) == BodyKind::Dynamic || kind(c.body_b) == BodyKind::Dynamic
                })
                .collect();
            let asleep = vec![false; world.bodies().capacity()];
            layout.rebuild(
                &contacts,
                world.bodies(),
                &asleep,
                &Bins::default(),
                f32::INFINITY,
            );
            let (order, sizes) = scheduler_order(&contacts, world.bodies());
            assert_eq!(layout.order, order, "seed {seed}");
            assert!(sizes[OVERFLOW] > 0, "seed {seed}: the overflow set is used");
            let blocks = |n: usize| n.div_ceil(BLOCK_LANES);
            let colours: Vec<usize> = layout.colours.iter().map(|r| r.len()).collect();
            let expected: Vec<usize> = sizes[..OVERFLOW]
                .iter()
                .filter(|&&n| n > 0)
                .map(|&n| blocks(n))
                .collect();
            assert_eq!(colours, expected, "seed {seed}");
            assert_eq!(layout.bins.len(), 1, "seed {seed}: one bin");
            assert_eq!(layout.bins[0].overflow.len(), blocks(sizes[OVERFLOW]));
            assert!(layout.disjoint, "seed {seed}: every colour may be split");
        }
    }
}
