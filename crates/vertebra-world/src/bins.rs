//! Solve bins: this step's islands, dealt out to the workers so that
//! islands that do not touch are solved with no synchronisation between
//! them (docs/threads.md, "Independent islands").
//!
//! Each step, the awake dynamic bodies linked by awake joints and rods and
//! by this step's contacts form islands (connected components, found
//! afresh: the persistent islands of `islands.rs` only merge while
//! sleeping is on, and split lazily). An island holding at least two
//! workers' share of the bodies is *large*: it goes to bin 0, whose
//! constraints the workers solve together, colour by colour (one stage
//! per colour). The
//! others are dealt to bins `1..`, the largest first, each to the bin with
//! the fewest bodies so far (Graham's longest-processing-time rule), and a
//! bin is solved whole (every iteration) by the one worker that claims it.
//!
//! **No result depends on the bins.** Constraints of two islands share no
//! dynamic body, and inside a bin each body meets its constraints in the
//! order the colouring gives (colour by colour, the overflow set last, as
//! in bin 0): which bin an island lands in, how its constraints share
//! blocks with other islands' and which worker runs them change the
//! packing, never the order of the corrections a body sees. So the bins
//! may depend on the worker count; results do not. With one worker every
//! body is in bin 0 and the step is the colour-by-colour one.
//!
//! Soundness does not rest on this file being right: the step checks that
//! every lane of a bin `1..` touches only rows of its own bin or rows
//! nobody writes ([`Bins::owns`], `step.rs`) before it solves bins at once.

use vertebra_math::row::NO_WRITE;
use vertebra_store::{BodyKind, BodyStore};

use crate::{Contact, JointDesc, RodDesc};

/// The bin of a body in none: static, kinematic, asleep or a free slot.
pub(crate) const NO_BIN: u32 = u32::MAX;

/// Bins per worker: more than one, so that a worker whose core is taken
/// leaves some of its share to the others.
const BINS_PER_WORKER: usize = 2;

/// Every body's bin for this step; scratch kept by the world (no
/// allocation once grown).
#[derive(Clone, Debug, Default)]
pub(crate) struct Bins {
    /// Per body slot: its bin, or [`NO_BIN`].
    pub of: Vec<u32>,
    /// How many bins (bin 0 included, even when empty).
    pub count: usize,
    /// Scratch: per body slot, its union-find parent.
    parent: Vec<u32>,
    /// Scratch: per body slot, the bodies of the island it is the root of.
    size: Vec<u32>,
    /// Scratch: the small islands' roots, largest first.
    small: Vec<u32>,
    /// Scratch: per bin, its bodies so far.
    load: Vec<u32>,
    /// Scratch: per root, its island's bin.
    root_bin: Vec<u32>,
}

impl Bins {
    /// This step's bins for `workers` workers: the islands of the awake
    /// dynamic bodies (`asleep` per slot) linked by `joints`, `rods` and
    /// `contacts`. True when a jointed body changed bin (`jointed` per
    /// slot: its joint count) or the bin count changed, that is when the
    /// joints' layout must be built again.
    #[allow(clippy::too_many_arguments)]
    pub fn assign(
        &mut self,
        bodies: &BodyStore,
        asleep: &[bool],
        joints: &[Option<JointDesc>],
        rods: &[Option<RodDesc>],
        contacts: &[Contact],
        jointed: &[u32],
        workers: usize,
    ) -> bool {
        let n = bodies.capacity();
        let solved = |i: usize| {
            bodies.is_live(i)
                && bodies.kind[i] == BodyKind::Dynamic
                && !asleep.get(i).copied().unwrap_or(false)
        };
        if workers <= 1 {
            return self.all_in_bin_0(n, solved, jointed);
        }
        self.parent.clear();
        self.parent.extend(0..n as u32);
        let links = (joints.iter().flatten().map(|d| (d.body_a, d.body_b)))
            .chain(rods.iter().flatten().map(|d| (d.body_a, d.body_b)))
            .chain(contacts.iter().map(|c| (c.body_a, c.body_b)));
        for (a, b) in links {
            let (a, b) = (a.index(), b.index());
            if solved(a) && solved(b) {
                self.union(a, b);
            }
        }
        self.size.clear();
        self.size.resize(n, 0);
        let mut total = 0;
        for i in (0..n).filter(|&i| solved(i)) {
            let root = self.root(i);
            self.size[root as usize] += 1;
            total += 1;
        }
        // Large: at least two workers' share of the bodies. A bin holding
        // a smaller island keeps its worker at most twice as long as the
        // step's share, which costs less than a wait per colour (docs/
        // threads.md); so is a lone island.
        let large = |size: u32| workers.saturating_mul(size as usize) >= 2 * total;
        self.small.clear();
        self.small.extend(
            (0..n as u32).filter(|&r| self.size[r as usize] > 0 && !large(self.size[r as usize])),
        );
        let size = &self.size;
        self.small
            .sort_unstable_by_key(|&r| (core::cmp::Reverse(size[r as usize]), r));
        let bins = self
            .small
            .len()
            .min(workers.saturating_mul(BINS_PER_WORKER));
        self.load.clear();
        self.load.resize(bins, 0);
        // Per root, its island's bin (0 for a large island).
        self.root_bin.clear();
        self.root_bin.resize(n, 0);
        for &root in &self.small {
            let lightest = (0..bins).min_by_key(|&b| (self.load[b], b)).unwrap_or(0);
            self.load[lightest] += self.size[root as usize];
            self.root_bin[root as usize] = lightest as u32 + 1;
        }
        // A new bin count rebuilds the joints' layout too, so that it
        // holds a (maybe empty) bin for every bin of the contacts'.
        let mut changed = self.of.len() != n || self.count != bins + 1;
        self.count = bins + 1;
        self.of.resize(n, NO_BIN);
        for i in 0..n {
            let bin = if solved(i) {
                let root = self.root(i) as usize;
                self.root_bin[root]
            } else {
                NO_BIN
            };
            changed |= self.of[i] != bin && jointed.get(i).is_some_and(|&j| j > 0);
            self.of[i] = bin;
        }
        changed
    }

    /// One worker: every solved body in bin 0, no island search (the
    /// bins `assign` would deal with every island large).
    fn all_in_bin_0(&mut self, n: usize, solved: impl Fn(usize) -> bool, jointed: &[u32]) -> bool {
        let mut changed = self.of.len() != n || self.count != 1;
        self.count = 1;
        self.of.resize(n, NO_BIN);
        for i in 0..n {
            let bin = if solved(i) { 0 } else { NO_BIN };
            changed |= self.of[i] != bin && jointed.get(i).is_some_and(|&j| j > 0);
            self.of[i] = bin;
        }
        changed
    }

    /// The root of `i`'s island.
    fn root(&mut self, i: usize) -> u32 {
        crate::islands::root(&mut self.parent, i)
    }

    /// Joins `a`'s and `b`'s islands (the lower root stays the root).
    fn union(&mut self, a: usize, b: usize) {
        let (x, y) = (self.root(a), self.root(b));
        let (low, high) = (x.min(y), x.max(y));
        self.parent[high as usize] = low;
    }

    /// The bin of a constraint between body rows `a` and `b` (slots + 1,
    /// row 0 the null row): its awake dynamic body's, or 0.
    pub fn of_rows(&self, a: u32, b: u32) -> u32 {
        let bin = |row: u32| {
            row.checked_sub(1)
                .and_then(|i| self.of.get(i as usize).copied())
                .filter(|&bin| bin != NO_BIN)
        };
        bin(a).or_else(|| bin(b)).unwrap_or(0)
    }

    /// Whether a lane of bin `bin` (not 0) reading rows `read` and writing
    /// `write` (`NO_WRITE` for none) keeps to its bin: what it writes is
    /// its bin's, and what it reads is its bin's or a row no bin writes.
    pub fn owns(&self, bin: u32, read: u32, write: u32) -> bool {
        let owner = |row: u32| match row.checked_sub(1) {
            Some(i) => self.of.get(i as usize).copied().unwrap_or(NO_BIN),
            None => NO_BIN,
        };
        let read_ok = owner(read) == bin || (owner(read) == NO_BIN && write == NO_WRITE);
        read_ok && (write == NO_WRITE || (write == read && owner(write) == bin))
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::{BodyDesc, BodyHandle, JointDesc, Shape, SolverConfig, World};

    /// Eight jointed pairs of spheres 10 m apart, with the bodies of each.
    fn pairs() -> (World, Vec<[BodyHandle; 2]>) {
        let mut world = World::new(SolverConfig::default()).unwrap();
        let mass = Shape::Sphere { radius: 0.1 }
            .mass_properties_with_mass(1.0)
            .unwrap();
        let pairs = (0..8)
            .map(|k| {
                let at = Vec3::new(10.0 * k as f32, 0.0, 0.0);
                let add = |world: &mut World, at| {
                    world
                        .add_body(BodyDesc::dynamic(mass).with_position(at))
                        .unwrap()
                };
                let (a, b) = (add(&mut world, at), add(&mut world, at + Vec3::X * 0.2));
                let joint = JointDesc::socket_at_world_anchor(
                    world.bodies(),
                    a,
                    b,
                    at + Vec3::X * 0.1,
                    Vec3::X,
                )
                .unwrap();
                world.add_joint(joint).unwrap();
                [a, b]
            })
            .collect();
        (world, pairs)
    }

    fn touching(a: BodyHandle, b: BodyHandle) -> Contact {
        Contact {
            body_a: a,
            body_b: b,
            point: Vec3::ZERO,
            normal: Vec3::X,
            depth: 0.0,
            friction: 0.5,
            restitution: 0.0,
        }
    }

    fn assign(world: &World, contacts: &[Contact], workers: usize, bins: &mut Bins) -> bool {
        bins.assign(
            &world.bodies,
            world.islands.asleep(),
            &world.joints,
            &world.rods,
            contacts,
            &world.joints_at,
            workers,
        )
    }

    #[test]
    fn islands_apart_are_dealt_to_bins_whole_and_a_large_island_stays_in_bin_zero() {
        let (world, pairs) = pairs();
        let bin = |bins: &Bins, h: BodyHandle| bins.of[h.index()];
        let mut bins = Bins::default();
        // One worker: everything in bin 0, solved colour by colour.
        assert!(assign(&world, &[], 1, &mut bins), "first assignment");
        assert_eq!(bins.count, 1);
        assert!(pairs.iter().flatten().all(|&h| bin(&bins, h) == 0));
        // Two workers: eight islands of two in four bins (two per worker),
        // two islands each, both bodies of a pair in the same bin.
        assert!(assign(&world, &[], 2, &mut bins), "the bins changed");
        assert_eq!(bins.count, 5);
        for [a, b] in &pairs {
            assert_eq!(bin(&bins, *a), bin(&bins, *b));
            assert!((1..5).contains(&bin(&bins, *a)));
        }
        for k in 1..5 {
            let held = pairs.iter().filter(|p| bin(&bins, p[0]) == k).count();
            assert_eq!(held, 2, "bin {k}");
        }
        assert!(!assign(&world, &[], 2, &mut bins), "the same again");
        // Contacts chaining the first four pairs and the last four: two
        // islands of half the bodies, below two workers' share: two bins.
        fn chain(pairs: &[[BodyHandle; 2]]) -> impl Iterator<Item = Contact> + '_ {
            pairs.windows(2).map(|w| touching(w[0][1], w[1][0]))
        }
        let contacts: Vec<Contact> = chain(&pairs[..4]).chain(chain(&pairs[4..])).collect();
        assert!(assign(&world, &contacts, 2, &mut bins));
        assert_eq!(bins.count, 3);
        let (first, last) = (bin(&bins, pairs[0][0]), bin(&bins, pairs[7][0]));
        assert!(first >= 1 && last >= 1 && first != last);
        assert!(pairs[..4].iter().flatten().all(|&h| bin(&bins, h) == first));
        assert!(pairs[4..].iter().flatten().all(|&h| bin(&bins, h) == last));
        // The static ground links nothing: a lane with it is its
        // dynamic body's.
        assert_eq!(
            bins.of_rows(0, pairs[7][0].index() as u32 + 1),
            bin(&bins, pairs[7][0])
        );
        // Chaining all eight: one island, solved colour by colour.
        let contacts: Vec<Contact> = chain(&pairs).collect();
        assert!(assign(&world, &contacts, 2, &mut bins));
        assert_eq!(bins.count, 1);
        assert!(pairs.iter().flatten().all(|&h| bin(&bins, h) == 0));
    }

    #[test]
    fn a_lane_keeps_to_its_bin_only_on_its_own_rows_and_rows_nobody_writes() {
        let (world, pairs) = pairs();
        let mut bins = Bins::default();
        assign(&world, &[], 2, &mut bins);
        let row = |h: BodyHandle| h.index() as u32 + 1;
        let (mine, other) = (pairs[0][0], pairs[1][0]);
        let k = bins.of[mine.index()];
        assert_ne!(k, bins.of[other.index()]);
        assert!(bins.owns(k, row(mine), row(mine)), "its own body");
        assert!(bins.owns(k, 0, NO_WRITE), "the null row, read");
        assert!(!bins.owns(k, row(other), row(other)), "another bin's body");
        assert!(
            !bins.owns(k, row(other), NO_WRITE),
            "another bin's body, read"
        );
        assert!(!bins.owns(k, row(mine), row(other)), "writing elsewhere");
    }
}
