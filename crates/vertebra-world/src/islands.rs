//! Islands and sleeping, as Box2D v3's persistent islands: dynamic bodies
//! linked by joints, rods and touching contacts form an island, the unit
//! that falls asleep and wakes up.
//!
//! **Kept incrementally.** A new body is an island of its own. A joint or
//! rod between two dynamic bodies merges their islands when it is added;
//! so does each step's contact between two awake dynamic bodies. Links
//! that go (a joint removed, two bodies no longer touching) do not split
//! an island at once: the island is marked, and split lazily, at most one
//! island per step, and only when part of it wants to sleep (Box2D's
//! `b2SplitIsland`): a pile that keeps moving never pays for splits. A
//! contact's end is seen as a change of the sum of a hash of the island's
//! touching body pairs from one step to the next.
//!
//! **Sleeping.** After each step, a dynamic body whose mass has moved less
//! than `speed * time` ([`SleepSettings`]) from its anchor adds the step's
//! time to its stillness; else its stillness restarts from zero, anchored
//! where it is. Each time its stillness completes another `time`, the
//! anchor moves on to where it is. So a body is still while its mass stays
//! within `speed * time` of where each window began (a mean speed below
//! `speed` over each window), however fast it moves inside that reach: a
//! limb jittering in place sleeps (a test of the speeds at each step, as
//! Box2D's, kept a jittering pile awake), and so
//! does one creeping slower than `speed`, as under Box2D's speed test; an
//! oscillation of amplitude below half the reach sleeps too (as Jolt's
//! test of a body's points against a fixed radius lets it). The move is
//! the root mean square over the body's mass of its points' moves (its
//! centre's move and its turn weighted by its inertia): a limb twisting
//! in place about its own axis barely moves, one swinging does.
//! An island whose every body has been still for [`SleepSettings::time`],
//! and that has no split pending, falls asleep: its velocities are zeroed,
//! and until it wakes its bodies are not integrated, its joints and rods
//! are out of the solver's layout, its contacts are not solved and a
//! collision layer finds no pairs between sleeping bodies. A body jointed
//! to a moving kinematic body, or held by a drive whose target moves or a
//! rod whose rest moves, is never still.
//!
//! **Waking.** The whole island wakes (stillness back to zero) when one of
//! its bodies is set a pose or velocity, pushed (force, torque, impulse),
//! changes kind, gains or loses a joint or rod, has its rod or drive
//! changed, is touched by a contact whose other body is awake (or a
//! kinematic body that moves), or on [`World::wake`](crate::World::wake).
//!
//! **Deterministic.** Islands, their ids and the sleep state depend only on
//! the world's history of calls and contact lists, never on threads: ids
//! are the lowest free, a merge keeps the larger island (the lower id on a
//! tie), a split numbers its parts in the order of their lowest bodies. The state here is
//! part of snapshots and of the state hash; each island's member list is
//! derived from the bodies' island ids and its order changes no result.

use glam::{DVec3, Quat, Vec3};
use serde::{Deserialize, Serialize};
use vertebra_math::PortableQuat;
use vertebra_store::{BodyHandle, BodyKind, BodyStore};

use crate::config::SleepSettings;
use crate::{Contact, JointDesc, RodDesc};

/// How far body `i`'s mass moved from `from` to `to`, squared: the mean
/// over its mass of its points' squared moves (m^2). A point at `r` from
/// the centre moves by `dx + (R - 1) r`; the mean of `r` is zero, and the
/// mean of `|(R - 1) r|^2` is `v^T E[|r|^2 - r r^T] v = v^T (I / m) v` with
/// `v = 2 sin(a / 2) axis`, twice the turn's vector part (in the body
/// frame, where `I` is given).
fn mass_moved_squared(bodies: &BodyStore, i: usize, from: (DVec3, Quat), to: (DVec3, Quat)) -> f64 {
    let turn = from.1.inverse().mul_portable(to.1);
    let v = (2.0 * Vec3::new(turn.x, turn.y, turn.z)).as_dvec3();
    let inertia = bodies.inertia[i].as_dmat3();
    let spread = v.dot(inertia * v) / f64::from(bodies.mass[i]);
    (to.0 - from.0).length_squared() + spread
}

/// The root of `i` in the union-find forest `parent` (each slot its
/// parent, a root its own), halving the path on the way; islands and the
/// step's solve bins both use it.
pub(crate) fn root(parent: &mut [u32], mut i: usize) -> u32 {
    while parent[i] as usize != i {
        let up = parent[parent[i] as usize];
        parent[i] = up;
        i = up as usize;
    }
    i as u32
}

/// A body in no island: free slot, static or kinematic.
pub(crate) const NO_ISLAND: u32 = u32::MAX;

/// The longest stillness (s) a step can accumulate: it adds the step's
/// time, at most [`MAX_TIME_STEP`](vertebra_store::MAX_TIME_STEP) = 1 s, to
/// a double, and from 2^53 s on (285 million years) adding a second or less
/// no longer changes it. A snapshot's stillness above this is refused.
pub(crate) const MAX_STILLNESS: f64 = 9_007_199_254_740_992.0;

/// One island's flags.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Island {
    /// In use (some body's island).
    pub live: bool,
    pub asleep: bool,
    /// A link may have gone since the island was last split.
    pub split: bool,
    /// The sum of the hashes of the touching body pairs at the last step.
    pub touching: u64,
}

/// Every body's island and stillness, and every island's flags.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub(crate) struct Islands {
    /// Per body slot: its island, or [`NO_ISLAND`].
    pub(crate) of: Vec<u32>,
    /// Per body slot: how long (s) it has been still; double precision, so
    /// that a step still adds to it after a million seconds (in single
    /// precision a 1 ms step stops adding after about 17,000 s, so a long
    /// `SleepSettings::time` could never be reached).
    pub(crate) still: Vec<f64>,
    /// Per body slot: where it was when its stillness began (centre of
    /// mass, m, world; orientation).
    pub(crate) anchor: Vec<(DVec3, Quat)>,
    /// Per body slot: whether it may sleep.
    pub(crate) allowed: Vec<bool>,
    /// Per island id.
    pub(crate) islands: Vec<Island>,
    /// Derived (not saved): per island id, its bodies.
    #[serde(skip)]
    members: Vec<Vec<u32>>,
    /// Derived: per body slot, whether it sleeps.
    #[serde(skip)]
    asleep: Vec<bool>,
    /// Scratch of a step: per island id, this step's touching sum.
    #[serde(skip)]
    touching: Vec<u64>,
    /// Scratch of a split: per body slot, its union-find parent.
    #[serde(skip)]
    parent: Vec<u32>,
}

/// Whether a body moves on its own: awake and dynamic, or kinematic with a
/// velocity.
fn moves(bodies: &BodyStore, asleep: &[bool], i: usize) -> bool {
    match bodies.kind[i] {
        BodyKind::Dynamic => !asleep[i],
        BodyKind::Kinematic => {
            bodies.linear_velocity[i] != Vec3::ZERO || bodies.angular_velocity[i] != Vec3::ZERO
        }
        BodyKind::Static => false,
    }
}

/// The hash of a touching pair (order-free).
fn pair_hash(a: usize, b: usize) -> u64 {
    let (lo, hi) = (a.min(b) as u64, a.max(b) as u64);
    xxhash_rust::xxh3::xxh3_64(&((hi << 32) | lo).to_le_bytes())
}

impl Islands {
    /// Room for `capacity` body slots.
    fn grow(&mut self, capacity: usize) {
        if self.of.len() < capacity {
            self.of.resize(capacity, NO_ISLAND);
            self.still.resize(capacity, 0.0);
            self.anchor.resize(capacity, (DVec3::ZERO, Quat::IDENTITY));
            self.allowed.resize(capacity, true);
            self.asleep.resize(capacity, false);
        }
    }

    /// Whether body `i` sleeps.
    pub fn is_asleep(&self, i: usize) -> bool {
        self.asleep.get(i).copied().unwrap_or(false)
    }

    /// Whether a joint or rod between `a` and `b` sleeps (is out of the
    /// layout).
    pub fn holds_asleep(&self, a: BodyHandle, b: BodyHandle) -> bool {
        self.is_asleep(a.index()) || self.is_asleep(b.index())
    }

    /// Per body slot, whether it sleeps.
    pub fn asleep(&self) -> &[bool] {
        &self.asleep
    }

    /// Body `i`'s island.
    pub fn island_of(&self, i: usize) -> Option<u32> {
        self.of.get(i).copied().filter(|&id| id != NO_ISLAND)
    }

    /// Whether body `i` may sleep.
    pub fn allowed(&self, i: usize) -> bool {
        self.allowed.get(i).copied().unwrap_or(true)
    }

    /// How many islands there are, and how many of them sleep.
    pub fn count(&self) -> (usize, usize) {
        let live = self.islands.iter().filter(|x| x.live);
        (live.clone().count(), live.filter(|x| x.asleep).count())
    }

    /// A new, awake island holding only `i`.
    fn open(&mut self, i: usize) {
        let id = match self.islands.iter().position(|x| !x.live) {
            Some(id) => id,
            None => {
                self.islands.push(Island::default());
                self.members.push(Vec::new());
                self.islands.len() - 1
            }
        };
        self.islands[id] = Island {
            live: true,
            ..Island::default()
        };
        self.members[id].clear();
        self.members[id].push(i as u32);
        self.of[i] = id as u32;
    }

    /// A body added at slot `i` (capacity: the store's now).
    pub fn add_body(&mut self, i: usize, kind: BodyKind, capacity: usize) {
        self.grow(capacity);
        self.of[i] = NO_ISLAND;
        self.still[i] = 0.0;
        self.allowed[i] = true;
        self.asleep[i] = false;
        if kind == BodyKind::Dynamic {
            self.open(i);
        }
    }

    /// Body `i` leaves its island (removed, or no longer dynamic): the
    /// island wakes (what rested on the body must fall) and may split.
    /// True when a sleeping island woke.
    pub fn take_out(&mut self, i: usize) -> bool {
        let Some(id) = self.island_of(i) else {
            return false;
        };
        let woke = self.wake_island(id);
        let id = id as usize;
        self.members[id].retain(|&b| b as usize != i);
        if self.members[id].is_empty() {
            self.islands[id] = Island::default();
        } else {
            self.islands[id].split = true;
        }
        self.of[i] = NO_ISLAND;
        self.still[i] = 0.0;
        woke
    }

    /// Body `i` became dynamic: an island of its own (its joints are
    /// linked again by the caller).
    pub fn make_dynamic(&mut self, i: usize) {
        if self.of[i] == NO_ISLAND {
            self.still[i] = 0.0;
            self.open(i);
        }
    }

    /// Wakes island `id`; true when it slept.
    fn wake_island(&mut self, id: u32) -> bool {
        let id = id as usize;
        if !self.islands[id].asleep {
            return false;
        }
        self.islands[id].asleep = false;
        for &b in &self.members[id] {
            self.asleep[b as usize] = false;
            self.still[b as usize] = 0.0;
        }
        true
    }

    /// Wakes body `i`'s island (it was set or pushed; an awake body's
    /// stillness is left to its motion, so that setting a value back
    /// leaves the state as it was); true when the island slept.
    pub fn wake(&mut self, i: usize) -> bool {
        self.island_of(i).is_some_and(|id| self.wake_island(id))
    }

    /// Allows or forbids body `i` to sleep (forbidding wakes it); true
    /// when its island slept.
    pub fn set_allowed(&mut self, i: usize, allowed: bool) -> bool {
        self.allowed[i] = allowed;
        if allowed { false } else { self.wake(i) }
    }

    /// A joint or rod between bodies `a` and `b` was added: both islands
    /// wake, and two dynamic bodies' islands merge. True when one slept.
    pub fn link(&mut self, a: usize, b: usize) -> bool {
        let woke = self.wake(a) | self.wake(b);
        if let (Some(x), Some(y)) = (self.island_of(a), self.island_of(b)) {
            self.merge(x, y);
        }
        woke
    }

    /// A joint or rod between `a` and `b` was removed: both islands wake,
    /// and theirs (one island, when both are dynamic) may split.
    pub fn unlink(&mut self, a: usize, b: usize) -> bool {
        let woke = self.wake(a) | self.wake(b);
        if let (Some(x), Some(_)) = (self.island_of(a), self.island_of(b)) {
            self.islands[x as usize].split = true;
        }
        woke
    }

    /// Merges islands `x` and `y` (both awake); the larger keeps its id.
    fn merge(&mut self, x: u32, y: u32) {
        if x == y {
            return;
        }
        let size = |id: u32| self.members[id as usize].len();
        let (keep, gone) = if (size(x), y) > (size(y), x) {
            (x, y)
        } else {
            (y, x)
        };
        let moved = core::mem::take(&mut self.members[gone as usize]);
        for &b in &moved {
            self.of[b as usize] = keep;
        }
        self.members[keep as usize].extend_from_slice(&moved);
        // Give the emptied vector back, so a later island reuses it.
        self.members[gone as usize] = moved;
        self.members[gone as usize].clear();
        let (k, g) = (keep as usize, gone as usize);
        self.islands[k].split |= self.islands[g].split;
        self.islands[k].touching = self.islands[k]
            .touching
            .wrapping_add(self.islands[g].touching);
        self.islands[g] = Island::default();
    }

    /// The step's contacts, as it begins: an island touched by a body that
    /// moves wakes (to a fixed point: a woken island's bodies move, so
    /// what they touch wakes too), two awake dynamic bodies' islands
    /// merge, and an island whose touching pairs changed may split. True
    /// when an island woke.
    pub fn touch(&mut self, contacts: &[Contact], bodies: &BodyStore) -> bool {
        let mut woke = false;
        loop {
            let mut changed = false;
            for c in contacts {
                let (a, b) = (c.body_a.index(), c.body_b.index());
                for (x, y) in [(a, b), (b, a)] {
                    if self.asleep[y] && moves(bodies, &self.asleep, x) {
                        changed |= self.wake_island(self.of[y]);
                    }
                }
            }
            woke |= changed;
            if !changed {
                break;
            }
        }
        for c in contacts {
            let (a, b) = (c.body_a.index(), c.body_b.index());
            if let (Some(x), Some(y)) = (self.island_of(a), self.island_of(b))
                && !self.asleep[a]
            {
                self.merge(x, y);
            }
        }
        self.sum_touching(contacts, |_| true);
        for (island, &now) in self.islands.iter_mut().zip(&self.touching) {
            if island.live && !island.asleep && island.touching != now {
                island.split = true;
                island.touching = now;
            }
        }
        woke
    }

    /// Into `touching`, per island, the sum of the hashes of the touching
    /// pairs of awake dynamic bodies in it for which `counted` holds (a
    /// pair's contact points in a row count once: a manifold's points
    /// come and go as bodies settle).
    fn sum_touching(&mut self, contacts: &[Contact], counted: impl Fn(u32) -> bool) {
        self.touching.clear();
        self.touching.resize(self.islands.len(), 0);
        let mut last = None;
        for c in contacts {
            let (a, b) = (c.body_a.index(), c.body_b.index());
            let (x, y) = (self.of[a], self.of[b]);
            let pair = Some((a.min(b), a.max(b)));
            if x == NO_ISLAND || x != y || self.asleep[a] || !counted(x) || pair == last {
                continue;
            }
            last = pair;
            let sum = &mut self.touching[x as usize];
            *sum = sum.wrapping_add(pair_hash(a, b));
        }
    }

    /// After a step of `dt` seconds: each awake body's stillness, then at
    /// most one split (of the island holding the stillest body among those
    /// with a split pending), then every island still long enough sleeps
    /// (velocities zeroed). True when an island fell asleep.
    pub fn settle(
        &mut self,
        settings: &SleepSettings,
        dt: f32,
        bodies: &mut BodyStore,
        links: impl Iterator<Item = Link> + Clone,
        contacts: &[Contact],
    ) -> bool {
        self.update_stillness(settings, dt, bodies, links.clone());
        if let Some(id) = self.split_candidate(settings) {
            self.split(id, links, contacts);
        }
        let mut slept = false;
        for id in 0..self.islands.len() {
            let island = self.islands[id];
            if !island.live || island.asleep || island.split {
                continue;
            }
            let members = &self.members[id];
            if members
                .iter()
                .all(|&b| self.still[b as usize] >= f64::from(settings.time))
            {
                self.islands[id].asleep = true;
                for &b in members {
                    let b = b as usize;
                    self.asleep[b] = true;
                    bodies.linear_velocity[b] = Vec3::ZERO;
                    bodies.angular_velocity[b] = Vec3::ZERO;
                }
                slept = true;
            }
        }
        slept
    }

    fn update_stillness(
        &mut self,
        settings: &SleepSettings,
        dt: f32,
        bodies: &BodyStore,
        links: impl Iterator<Item = Link>,
    ) {
        // The mean speed over each window of `time`, not the speed at each
        // step: a limb jittering in place in a jammed pile is still (a test
        // of the speeds at each step, as Box2D's, kept a jittering pile
        // awake), and so is one creeping slower than `speed` (the anchor
        // moves on to where the body is at the end of each window).
        let reach = f64::from(settings.speed) * f64::from(settings.time);
        for i in 0..self.of.len() {
            if self.of[i] == NO_ISLAND || self.asleep[i] {
                continue;
            }
            let now = (bodies.precise_position(i), bodies.orientation[i]);
            if self.still[i] == 0.0 {
                self.anchor[i] = now;
            }
            let drifted = mass_moved_squared(bodies, i, self.anchor[i], now) > reach * reach;
            if self.allowed[i] && !drifted {
                let (dt, time) = (f64::from(dt), f64::from(settings.time));
                let window = |still: f64| (still / time).floor();
                if window(self.still[i] + dt) > window(self.still[i]) {
                    self.anchor[i] = now;
                }
                self.still[i] += dt;
            } else {
                self.still[i] = 0.0;
                self.anchor[i] = now;
            }
        }
        // Held by something that moves: never still.
        for link in links {
            let kinematic_moves =
                |i: usize| bodies.kind[i] == BodyKind::Kinematic && moves(bodies, &self.asleep, i);
            let (a, b) = (link.a as usize, link.b as usize);
            if link.moving || kinematic_moves(a) || kinematic_moves(b) {
                for i in [a, b] {
                    if !self.asleep[i] {
                        self.still[i] = 0.0;
                    }
                }
            }
        }
    }

    /// The awake island with a split pending that holds the stillest body
    /// still long enough to sleep (Box2D's choice); the lower id on a tie.
    fn split_candidate(&self, settings: &SleepSettings) -> Option<u32> {
        let mut best: Option<(f64, u32)> = None;
        for (id, island) in self.islands.iter().enumerate() {
            if !(island.live && island.split && !island.asleep) {
                continue;
            }
            let stillest = self.members[id]
                .iter()
                .map(|&b| self.still[b as usize])
                .fold(0.0f64, f64::max);
            if stillest >= f64::from(settings.time) && best.is_none_or(|(s, _)| stillest > s) {
                best = Some((stillest, id as u32));
            }
        }
        best.map(|(_, id)| id)
    }

    /// Splits island `id` into its connected parts over `links` and
    /// `contacts` (union-find, each part's root its lowest body); the parts
    /// take the lowest free ids (the island's own among them) in the order
    /// of their lowest bodies.
    fn split(&mut self, id: u32, links: impl Iterator<Item = Link>, contacts: &[Contact]) {
        let mut members = core::mem::take(&mut self.members[id as usize]);
        members.sort_unstable();
        self.parent.resize(self.of.len(), 0);
        for &b in &members {
            self.parent[b as usize] = b;
        }
        let pairs = links.map(|l| (l.a as usize, l.b as usize)).chain(
            contacts
                .iter()
                .map(|c| (c.body_a.index(), c.body_b.index())),
        );
        for (a, b) in pairs {
            if self.of[a] == id && self.of[b] == id {
                let (ra, rb) = (self.root(a), self.root(b));
                let (lo, hi) = (ra.min(rb), ra.max(rb));
                self.parent[hi as usize] = lo;
            }
        }
        self.islands[id as usize] = Island::default();
        for &b in &members {
            self.of[b as usize] = NO_ISLAND;
        }
        // Members ascend, so each part is met first at its root.
        for &b in &members {
            let root = self.root(b as usize);
            if root == b {
                self.open(b as usize);
            } else {
                let part = self.of[root as usize];
                self.of[b as usize] = part;
                self.members[part as usize].push(b);
            }
        }
        // Each part's touching pairs as the next step will sum them (else
        // every part would count as changed, and split again).
        let parts = |x: u32| members.binary_search(&self.members[x as usize][0]).is_ok();
        let parts: Vec<bool> = (0..self.islands.len() as u32)
            .map(|x| self.islands[x as usize].live && parts(x))
            .collect();
        self.sum_touching(contacts, |x| parts[x as usize]);
        for (x, island) in self.islands.iter_mut().enumerate() {
            if parts[x] {
                island.touching = self.touching[x];
            }
        }
    }

    /// Body `i`'s union-find root.
    fn root(&mut self, i: usize) -> u32 {
        root(&mut self.parent, i)
    }

    /// Wakes every island (sleeping switched off).
    pub fn wake_all(&mut self) -> bool {
        let mut woke = false;
        for id in 0..self.islands.len() {
            if self.islands[id].live {
                woke |= self.wake_island(id as u32);
            }
        }
        woke
    }

    /// Copies the saved state (what a snapshot holds) into `copy`, reusing
    /// its buffers: kept before a step that may unwind (`rollback.rs`).
    pub fn keep_into(&self, copy: &mut Islands) {
        copy.of.clone_from(&self.of);
        copy.still.clone_from(&self.still);
        copy.anchor.clone_from(&self.anchor);
        copy.allowed.clone_from(&self.allowed);
        copy.islands.clone_from(&self.islands);
    }

    /// Puts back the saved state [`Islands::keep_into`] copied, and what is
    /// derived from it.
    pub fn put_back(&mut self, copy: &Islands) {
        copy.keep_into(self);
        self.derive();
    }

    /// Rebuilds what is derived (member lists, sleeping bodies) from the
    /// saved state, after a restore.
    pub fn derive(&mut self) {
        self.members = vec![Vec::new(); self.islands.len()];
        self.asleep = vec![false; self.of.len()];
        for (i, &id) in self.of.iter().enumerate() {
            if id != NO_ISLAND {
                self.members[id as usize].push(i as u32);
                self.asleep[i] = self.islands[id as usize].asleep;
            }
        }
    }

    /// Checks a saved state against its bodies and links (a snapshot's),
    /// as the API leaves it between calls:
    ///
    /// - the islands: every live dynamic body in a live island, nothing
    ///   else in one, every live island holding a body, the two dynamic
    ///   bodies of every link in one island, a free island with no flags;
    /// - stillness: finite, at least 0 and at most [`MAX_STILLNESS`], zero
    ///   for a body in no island; its anchor where a body can be (finite,
    ///   within [`MAX_COORDINATE`](vertebra_store::MAX_COORDINATE)) with a
    ///   unit orientation;
    /// - sleep: a sleeping island has no split pending, and each of its
    ///   bodies has been still (stillness above 0), may sleep, and is at
    ///   rest (velocities zeroed as it fell asleep, no pending force or
    ///   torque: setting or pushing a body wakes it); no link of a sleeping
    ///   body moves it (a drive's moving target, a rod's moving rest, a
    ///   kinematic body with a velocity: each keeps its island awake, and
    ///   setting one wakes the island).
    pub fn validate(
        &self,
        bodies: &BodyStore,
        links: impl Iterator<Item = Link>,
    ) -> Result<(), String> {
        let n = bodies.capacity();
        if [
            self.of.len(),
            self.still.len(),
            self.allowed.len(),
            self.anchor.len(),
        ] != [n; 4]
        {
            return Err(format!("islands: per-body arrays for {n} body slots"));
        }
        if let Some(id) = (0..self.islands.len())
            .find(|&k| !self.islands[k].live && self.islands[k] != Island::default())
        {
            return Err(format!("island {id}: free but flagged"));
        }
        let mut used = vec![false; self.islands.len()];
        for i in 0..n {
            let dynamic = bodies.is_live(i) && bodies.kind[i] == BodyKind::Dynamic;
            let id = self.of[i];
            let island = match (dynamic, id) {
                (false, NO_ISLAND) => None,
                (false, _) => return Err(format!("body {i}: in an island but not dynamic")),
                (true, NO_ISLAND) => return Err(format!("body {i}: dynamic in no island")),
                (true, id) => match self.islands.get(id as usize) {
                    Some(island) if island.live => {
                        used[id as usize] = true;
                        Some(island)
                    }
                    _ => return Err(format!("body {i}: in island {id}, which is not live")),
                },
            };
            let still = self.still[i];
            if !(still.is_finite() && (0.0..=MAX_STILLNESS).contains(&still)) {
                return Err(format!(
                    "body {i}: stillness {still:e} (0 to {MAX_STILLNESS:e} s)"
                ));
            }
            if island.is_none() && still != 0.0 {
                return Err(format!("body {i}: stillness {still} in no island"));
            }
            let (x, q) = self.anchor[i];
            if !(x.is_finite() && q.is_finite()) {
                return Err(format!("body {i}: stillness anchor not finite"));
            }
            vertebra_store::check_coordinate("stillness anchor", x.as_vec3())
                .and_then(|()| vertebra_store::check_unit_quat("stillness anchor orientation", q))
                .map_err(|e| format!("body {i}: {e}"))?;
            if island.is_some_and(|island| island.asleep) {
                asleep_at_rest(bodies, i, still, self.allowed[i])?;
            }
        }
        if let Some(id) = (0..self.islands.len()).find(|&k| self.islands[k].live != used[k]) {
            return Err(format!(
                "island {id}: live without bodies, or free with them"
            ));
        }
        if let Some(id) = (0..self.islands.len()).find(|&k| {
            let island = self.islands[k];
            island.asleep && island.split
        }) {
            return Err(format!("island {id}: asleep with a split pending"));
        }
        let asleep = |i: usize| {
            let id = self.of[i];
            id != NO_ISLAND && self.islands[id as usize].asleep
        };
        for link in links {
            let (a, b) = (link.a as usize, link.b as usize);
            let (x, y) = (self.of[a], self.of[b]);
            if x != NO_ISLAND && y != NO_ISLAND && x != y {
                return Err(format!(
                    "bodies {a} and {b}: linked but in islands {x} and {y}"
                ));
            }
            let kinematic_moves = |i: usize| {
                bodies.kind[i] == BodyKind::Kinematic
                    && (bodies.linear_velocity[i] != Vec3::ZERO
                        || bodies.angular_velocity[i] != Vec3::ZERO)
            };
            for (i, other) in [(a, b), (b, a)] {
                if !asleep(i) {
                    continue;
                }
                if link.moving {
                    return Err(format!(
                        "body {i}: asleep, held by a moving drive or rod rest (to body {other})"
                    ));
                }
                if kinematic_moves(other) {
                    return Err(format!(
                        "body {i}: asleep, linked to kinematic body {other}, which moves"
                    ));
                }
            }
        }
        Ok(())
    }
}

/// Checks that body `i` of a sleeping island (`still` its stillness,
/// `allowed` whether it may sleep) is as falling asleep left it.
fn asleep_at_rest(bodies: &BodyStore, i: usize, still: f64, allowed: bool) -> Result<(), String> {
    if still <= 0.0 {
        return Err(format!("body {i}: asleep but never still"));
    }
    if !allowed {
        return Err(format!("body {i}: asleep but not allowed to sleep"));
    }
    let moving = [
        ("linear velocity", bodies.linear_velocity[i]),
        ("angular velocity", bodies.angular_velocity[i]),
        ("force", bodies.force[i]),
        ("torque", bodies.torque[i]),
    ];
    if let Some((what, v)) = moving.iter().find(|(_, v)| *v != Vec3::ZERO) {
        return Err(format!("body {i}: asleep but its {what} is {v}"));
    }
    Ok(())
}

/// A joint or rod as islands see it: its two bodies, and whether it moves
/// them itself (a drive's moving target, a rod's moving rest).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Link {
    pub a: u32,
    pub b: u32,
    pub moving: bool,
}

/// Every live joint's and rod's link, in slot order.
pub(crate) fn links<'a>(
    joints: &'a [Option<JointDesc>],
    rods: &'a [Option<RodDesc>],
) -> impl Iterator<Item = Link> + Clone + 'a {
    let joints = joints.iter().flatten().map(|d| Link {
        a: d.body_a.index() as u32,
        b: d.body_b.index() as u32,
        moving: d
            .drive
            .is_some_and(|drive| drive.target_velocity != Vec3::ZERO),
    });
    let rods = rods.iter().flatten().map(|d| Link {
        a: d.body_a.index() as u32,
        b: d.body_b.index() as u32,
        moving: d.bend_rest_velocity != Vec3::ZERO || d.twist_rest_velocity != 0.0,
    });
    joints.chain(rods)
}
