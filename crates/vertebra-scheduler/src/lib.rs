//! The constraint graph's colouring (after Box2D v3's `b2ConstraintGraph`).
//!
//! Constraints of one colour share no dynamic body, so a colour can be
//! solved many at a time (lanes, threads) with the same result as one at a
//! time: that is what makes whole-world steps bit-identical across backends
//! and thread counts. Colours are solved one after another (Gauss-Seidel
//! across colours, Jacobi inside one).
//!
//! - Each dynamic body keeps a bitset of the colours its constraints use.
//! - A new constraint takes the lowest colour free in both bodies' sets;
//!   static and kinematic bodies are never coloured (they are not written).
//! - At most [`MAX_COLOURS`] colours; a constraint that finds none free goes
//!   to the overflow set, solved one at a time by the scalar kernel.
//! - Adding and removing update the sets in place; nothing is rebuilt per
//!   step. The result depends only on the sequence of calls: deterministic.

use std::collections::{BTreeMap, BTreeSet};

/// The most colours; further constraints overflow.
pub const MAX_COLOURS: usize = 24;

/// Where a constraint is solved.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
pub enum Slot {
    /// In this colour (`< MAX_COLOURS`).
    Colour(u8),
    /// In the overflow set.
    Overflow,
}

/// The colouring of a set of constraints, each named by a `u64` key and
/// touching up to two dynamic bodies (by index).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Colouring {
    body_colours: Vec<u32>,
    members: Vec<BTreeSet<u64>>,
    overflow: BTreeSet<u64>,
    placed: BTreeMap<u64, (Slot, [Option<u32>; 2])>,
}

impl Colouring {
    /// An empty colouring.
    pub fn new() -> Self {
        Self {
            members: vec![BTreeSet::new(); MAX_COLOURS],
            ..Self::default()
        }
    }

    /// Colours constraint `key` over its dynamic bodies (`None` for a
    /// static or kinematic end). Returns where it went.
    ///
    /// # Panics
    /// If `key` is already coloured.
    pub fn add(&mut self, key: u64, bodies: [Option<u32>; 2]) -> Slot {
        assert!(
            !self.placed.contains_key(&key),
            "constraint {key} coloured twice"
        );
        let highest = bodies.iter().flatten().max().map_or(0, |&b| b as usize + 1);
        self.reserve_bodies(highest);
        let used = bodies
            .iter()
            .flatten()
            .fold(0u32, |acc, &b| acc | self.colours_of(b));
        let slot = match (0..MAX_COLOURS).find(|&c| used & (1 << c) == 0) {
            Some(c) => {
                for &b in bodies.iter().flatten() {
                    self.body_colours[b as usize] |= 1 << c;
                }
                self.members[c].insert(key);
                Slot::Colour(c as u8)
            }
            None => {
                self.overflow.insert(key);
                Slot::Overflow
            }
        };
        self.placed.insert(key, (slot, bodies));
        slot
    }

    /// Removes constraint `key`; returns where it was, or `None` if unknown.
    pub fn remove(&mut self, key: u64) -> Option<Slot> {
        let (slot, bodies) = self.placed.remove(&key)?;
        match slot {
            Slot::Colour(c) => {
                self.members[c as usize].remove(&key);
                for &b in bodies.iter().flatten() {
                    self.body_colours[b as usize] &= !(1 << c);
                }
            }
            Slot::Overflow => {
                self.overflow.remove(&key);
            }
        }
        Some(slot)
    }

    /// Where `key` is solved.
    pub fn slot(&self, key: u64) -> Option<Slot> {
        self.placed.get(&key).map(|p| p.0)
    }

    /// The keys of colour `c`, ascending.
    pub fn colour(&self, c: usize) -> &BTreeSet<u64> {
        &self.members[c]
    }

    /// The overflow keys, ascending.
    pub fn overflow(&self) -> &BTreeSet<u64> {
        &self.overflow
    }

    /// The bitset of colours used at dynamic body `body`.
    pub fn colours_of(&self, body: u32) -> u32 {
        self.body_colours.get(body as usize).copied().unwrap_or(0)
    }

    /// Checks a colouring that did not come from [`Colouring::add`] (a
    /// decoded snapshot) against the constraints it should colour, `key ->
    /// dynamic bodies` (as passed to `add`), over `bodies` body slots:
    /// every constraint placed exactly once, in a colour below
    /// [`MAX_COLOURS`] or the overflow set, over the same bodies; no two
    /// constraints of one colour share a dynamic body; each body's bitset
    /// names exactly its constraints' colours. Nothing is rebuilt: the
    /// colours a valid history gave decide the solve order, and keeping
    /// them keeps it. The error names the constraint or body.
    pub fn validate(
        &self,
        constraints: &BTreeMap<u64, [Option<u32>; 2]>,
        bodies: usize,
    ) -> Result<(), String> {
        if self.members.len() != MAX_COLOURS {
            return Err(format!("{} colours, not {MAX_COLOURS}", self.members.len()));
        }
        if self.body_colours.len() > bodies {
            return Err(format!(
                "bitsets for {} bodies, but {bodies} body slots",
                self.body_colours.len()
            ));
        }
        for (&key, &edge) in constraints {
            let Some(&(slot, placed)) = self.placed.get(&key) else {
                return Err(format!("constraint {key} is not coloured"));
            };
            if placed != edge {
                return Err(format!("constraint {key} is coloured over other bodies"));
            }
            let member = match slot {
                Slot::Colour(c) => self
                    .members
                    .get(c as usize)
                    .is_some_and(|m| m.contains(&key)),
                Slot::Overflow => self.overflow.contains(&key),
            };
            if !member {
                return Err(format!("constraint {key} is missing from its {slot:?}"));
            }
        }
        let members = self.members.iter().map(BTreeSet::len).sum::<usize>() + self.overflow.len();
        if self.placed.len() != constraints.len() || members != constraints.len() {
            return Err(format!(
                "{} constraints placed and {members} in colours for {} constraints",
                self.placed.len(),
                constraints.len()
            ));
        }
        let mut expected = vec![0u32; self.body_colours.len()];
        for (colour, keys) in self.members.iter().enumerate() {
            let mut seen = BTreeSet::new();
            for &b in keys.iter().flat_map(|k| constraints[k].iter().flatten()) {
                let bits = expected
                    .get_mut(b as usize)
                    .ok_or_else(|| format!("body {b} has no colour bitset"))?;
                if !seen.insert(b) {
                    return Err(format!("body {b} is in colour {colour} twice"));
                }
                *bits |= 1 << colour;
            }
        }
        if let Some(b) = (0..expected.len()).find(|&b| expected[b] != self.body_colours[b]) {
            return Err(format!(
                "body {b}'s colour bitset disagrees with its constraints"
            ));
        }
        if let Some(b) = constraints
            .values()
            .flat_map(|e| e.iter().flatten())
            .find(|&&b| b as usize >= self.body_colours.len())
        {
            return Err(format!("body {b} has no colour bitset"));
        }
        Ok(())
    }

    /// Makes room for body indices below `bodies`.
    pub fn reserve_bodies(&mut self, bodies: usize) {
        if self.body_colours.len() < bodies {
            self.body_colours.resize(bodies, 0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    /// No two constraints of one colour share a dynamic body, and the
    /// bitsets say exactly which colours each body's constraints use.
    fn check(c: &Colouring, edges: &BTreeMap<u64, [Option<u32>; 2]>) {
        let mut expected = vec![0u32; c.body_colours.len()];
        for (colour, keys) in c.members.iter().enumerate() {
            let mut seen = BTreeSet::new();
            for key in keys {
                for &b in edges[key].iter().flatten() {
                    assert!(seen.insert(b), "body {b} twice in colour {colour}");
                    expected[b as usize] |= 1 << colour;
                }
            }
        }
        assert_eq!(expected, c.body_colours);
        let placed: usize = c.members.iter().map(|m| m.len()).sum::<usize>() + c.overflow.len();
        assert_eq!(placed, edges.len());
    }

    #[test]
    fn random_adds_and_removes_keep_colours_disjoint() {
        let mut rng = StdRng::seed_from_u64(7);
        let mut c = Colouring::new();
        c.reserve_bodies(60);
        let mut edges = BTreeMap::new();
        for step in 0..5000u64 {
            if rng.random_bool(0.35) && !edges.is_empty() {
                let key = *edges
                    .keys()
                    .nth(rng.random_range(0..edges.len()))
                    .expect("a key");
                edges.remove(&key);
                assert!(c.remove(key).is_some());
            } else {
                let a = rng.random_range(0..60u32);
                let b = (a + rng.random_range(1..60)) % 60;
                let bodies = [Some(a), if rng.random_bool(0.2) { None } else { Some(b) }];
                c.add(step, bodies);
                edges.insert(step, bodies);
            }
            if step % 97 == 0 {
                check(&c, &edges);
            }
        }
        check(&c, &edges);
    }

    #[test]
    fn validate_accepts_what_add_made_and_names_what_was_tampered_with() {
        let mut c = Colouring::new();
        let mut edges = BTreeMap::new();
        for k in 0..10u64 {
            let bodies = [Some(k as u32), Some(k as u32 + 1)];
            c.add(k, bodies);
            edges.insert(k, bodies);
        }
        assert_eq!(c.validate(&edges, 11), Ok(()));
        assert!(c.validate(&edges, 5).is_err(), "bitsets beyond the bodies");
        let mut missing = edges.clone();
        missing.insert(99, [Some(0), None]);
        assert_eq!(
            c.validate(&missing, 11),
            Err("constraint 99 is not coloured".into())
        );
        // Joint 1 moved into joint 0's colour: they share body 1.
        let mut clash = c.clone();
        clash.members[1].remove(&1);
        clash.members[0].insert(1);
        clash.placed.insert(1, (Slot::Colour(0), edges[&1]));
        assert_eq!(
            clash.validate(&edges, 11),
            Err("body 1 is in colour 0 twice".into())
        );
        let mut bits = c.clone();
        bits.body_colours[3] = 0;
        assert!(bits.validate(&edges, 11).is_err());
        let mut out_of_range = c.clone();
        out_of_range
            .placed
            .insert(2, (Slot::Colour(200), edges[&2]));
        assert!(out_of_range.validate(&edges, 11).is_err());
    }

    #[test]
    fn a_hub_body_overflows_after_max_colours() {
        // 30 constraints on one body: 24 colours, then overflow.
        let mut c = Colouring::new();
        c.reserve_bodies(31);
        let slots: Vec<Slot> = (0..30)
            .map(|k| c.add(k, [Some(0), Some(k as u32 + 1)]))
            .collect();
        for (k, s) in slots.iter().enumerate() {
            let expected = if k < MAX_COLOURS {
                Slot::Colour(k as u8)
            } else {
                Slot::Overflow
            };
            assert_eq!(*s, expected);
        }
        assert_eq!(c.overflow().len(), 30 - MAX_COLOURS);
        // Freeing a colour lets the next constraint take it.
        c.remove(3);
        assert_eq!(c.add(100, [Some(0), Some(40)]), Slot::Colour(3));
    }

    #[test]
    fn a_chain_needs_two_colours() {
        let mut c = Colouring::new();
        c.reserve_bodies(11);
        let slots: Vec<Slot> = (0..10)
            .map(|k| c.add(k, [Some(k as u32), Some(k as u32 + 1)]))
            .collect();
        assert!(
            slots
                .iter()
                .all(|s| matches!(s, Slot::Colour(0) | Slot::Colour(1)))
        );
        // Static ends take no bit.
        assert_eq!(c.add(50, [None, Some(0)]), Slot::Colour(1));
        assert_eq!(c.colours_of(0), 0b11);
    }
}
