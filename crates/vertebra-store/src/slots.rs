//! A table's slots: which indices are live, the generation each was
//! issued with, and the lineage of the world that issued them (what
//! [`Handle`]s are checked against).

use serde::ser::{Serialize, SerializeStruct, Serializer};

use crate::error::Error;
use crate::handle::{Handle, physical_only};

/// The most generations a table issues: 2^48 insertions, a million a
/// second for nine years. A decoded table whose counter is beyond it is
/// refused, so the counter can never overflow.
pub const MAX_GENERATION: u64 = 1 << 48;

/// Slot bookkeeping: which indices are live, the generation each live one
/// was issued with, and a free list that reuses the lowest freed index
/// first (deterministic).
#[derive(Clone, Debug, Default, serde::Deserialize)]
pub struct Slots {
    lineage: u32,
    /// The generation the next insertion gets; above every one issued.
    next_generation: u64,
    generation: Vec<u64>,
    live: Vec<bool>,
    free: std::collections::BTreeSet<u32>,
}

impl Serialize for Slots {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if physical_only() {
            return (&self.live, &self.free).serialize(s);
        }
        let mut out = s.serialize_struct("Slots", 5)?;
        out.serialize_field("lineage", &self.lineage)?;
        out.serialize_field("next_generation", &self.next_generation)?;
        out.serialize_field("generation", &self.generation)?;
        out.serialize_field("live", &self.live)?;
        out.serialize_field("free", &self.free)?;
        out.end()
    }
}

impl Slots {
    /// An empty table whose handles carry `lineage`.
    pub fn new(lineage: u32) -> Self {
        Self {
            lineage,
            ..Self::default()
        }
    }

    /// Takes a slot; returns its handle. The caller stores the item's data
    /// at `handle.index()`, growing its arrays when the index is new.
    pub fn insert<T>(&mut self) -> Handle<T> {
        let index = match self.free.pop_first() {
            Some(i) => i,
            None => {
                self.generation.push(0);
                self.live.push(false);
                (self.live.len() - 1) as u32
            }
        };
        let generation = self.next_generation;
        self.next_generation += 1;
        self.live[index as usize] = true;
        self.generation[index as usize] = generation;
        Handle::from_raw(index, self.lineage, generation)
    }

    /// `Ok(slot index)` for a live handle; `ForeignHandle(what)` for a
    /// handle of another lineage, `StaleHandle(what)` for a removed item.
    pub fn check<T>(&self, handle: Handle<T>, what: &'static str) -> Result<usize, Error> {
        let (index, lineage, generation) = handle.to_raw();
        let i = index as usize;
        if lineage != self.lineage {
            Err(Error::ForeignHandle(what))
        } else if self.is_live(i) && self.generation[i] == generation {
            Ok(i)
        } else {
            Err(Error::StaleHandle(what))
        }
    }

    /// Whether `handle` names a live item.
    pub fn contains<T>(&self, handle: Handle<T>) -> bool {
        self.check(handle, "").is_ok()
    }

    /// Frees the slot of a live handle; `false` if it was stale or foreign.
    pub fn remove<T>(&mut self, handle: Handle<T>) -> bool {
        if !self.contains(handle) {
            return false;
        }
        self.live[handle.index()] = false;
        self.free.insert(handle.to_raw().0);
        true
    }

    /// Makes the handles this table issues from now on newer than every
    /// handle `other` ever issued: a world restoring a snapshot keeps its
    /// own counter when it is ahead, so nothing it handed out before the
    /// restore is handed out again.
    pub fn issue_after(&mut self, other: &Slots) {
        self.next_generation = self.next_generation.max(other.next_generation);
    }

    /// The number of slots ever allocated (live or free).
    pub fn capacity(&self) -> usize {
        self.live.len()
    }

    /// Checks the table's own consistency (a decoded snapshot's tables are
    /// untrusted): one generation per slot, every generation below the
    /// counter, the counter at most [`MAX_GENERATION`], and the free list
    /// naming exactly the dead slots. The error
    /// names the table (`what`) and the slot.
    pub fn validate(&self, what: &str) -> Result<(), Error> {
        let corrupt = |why: String| Err(Error::CorruptSnapshot(format!("{what} slots: {why}")));
        if self.generation.len() != self.live.len() {
            return corrupt(format!(
                "{} generations for {} slots",
                self.generation.len(),
                self.live.len()
            ));
        }
        if self.next_generation > MAX_GENERATION {
            return corrupt(format!("{} generations issued", self.next_generation));
        }
        if let Some(i) = (0..self.live.len()).find(|&i| self.generation[i] >= self.next_generation)
        {
            return corrupt(format!("slot {i}'s generation was never issued"));
        }
        if let Some(&i) = self.free.iter().find(|&&i| self.is_live(i as usize)) {
            return corrupt(format!("slot {i} is both live and free"));
        }
        let dead = self.live.iter().filter(|&&l| !l).count();
        if self.free.len() != dead {
            return corrupt(format!(
                "{} dead slots but {} on the free list",
                dead,
                self.free.len()
            ));
        }
        Ok(())
    }

    /// Whether slot `index` is live.
    pub fn is_live(&self, index: usize) -> bool {
        self.live.get(index).copied().unwrap_or(false)
    }

    /// The live handle at `index`, if any.
    pub fn handle_at<T>(&self, index: usize) -> Option<Handle<T>> {
        self.is_live(index)
            .then(|| Handle::from_raw(index as u32, self.lineage, self.generation[index]))
    }

    /// Live items.
    pub fn len(&self) -> usize {
        self.live.len() - self.free.len()
    }

    /// No live items.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reused_slot_gets_a_new_generation() {
        let mut slots = Slots::new(1);
        let first: Handle<()> = slots.insert();
        assert!(slots.remove(first));
        let second: Handle<()> = slots.insert();
        assert_eq!(first.index(), second.index());
        assert_eq!(slots.check(first, "x"), Err(Error::StaleHandle("x")));
        assert_eq!(slots.check(second, "x"), Ok(0));
    }

    #[test]
    fn a_counter_that_could_overflow_is_refused() {
        let mut slots = Slots::new(1);
        let _: Handle<()> = slots.insert();
        assert_eq!(slots.validate("body"), Ok(()));
        slots.next_generation = u64::MAX;
        assert!(slots.validate("body").is_err());
        slots.next_generation = 0;
        assert!(
            slots.validate("body").is_err(),
            "slot 0's generation was never issued"
        );
    }

    #[test]
    fn another_lineage_is_foreign() {
        let mut ours = Slots::new(1);
        let mut theirs = Slots::new(2);
        let _: Handle<()> = ours.insert();
        let foreign: Handle<()> = theirs.insert();
        assert_eq!(ours.check(foreign, "x"), Err(Error::ForeignHandle("x")));
    }

    #[test]
    fn issuing_after_an_earlier_table_never_repeats_a_handle() {
        let mut slots = Slots::new(1);
        let earlier = slots.clone();
        let later: Handle<()> = slots.insert();
        let mut restored = earlier.clone();
        restored.issue_after(&slots);
        let again: Handle<()> = restored.insert();
        assert_ne!(again, later);
        assert_eq!(restored.check(later, "x"), Err(Error::StaleHandle("x")));
    }
}
