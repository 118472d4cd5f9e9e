//! Generational handles: a slot index, the generation the slot had when
//! the item was made, and the lineage of the tables that issued it.
//!
//! - **Generations are never reissued.** A table keeps one counter, raised
//!   by every insertion and never lowered (a restored snapshot's counter
//!   only raises it, see [`Slots::issue_after`]), so a handle to a removed
//!   item is recognised as stale even after its slot is reused, and a
//!   handle issued after a snapshot stays stale after that snapshot is
//!   restored.
//! - **Lineages tell worlds apart.** Every world draws a random lineage;
//!   its handles carry it, and a handle of another lineage is refused as
//!   foreign instead of acting on whatever body has the same slot here. A
//!   restored snapshot brings its lineage with it: a world that restores
//!   another world's snapshot (a save game, a server's state) takes on that
//!   world's handles, and its own earlier handles become foreign.

use core::cell::Cell;
use core::marker::PhantomData;

use serde::ser::{Serialize, SerializeStruct, Serializer};

use crate::error::Error;

thread_local! {
    static PHYSICAL_ONLY: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f` with handles and slot tables serialising only what a step can
/// read of them (slot indices, which slots are live and which free), not
/// the lineage of the world that issued them or their generations: state
/// serialised inside `f` is equal for equal worlds, whichever world built
/// them and however often their handles were reissued. (`World::state_hash`
/// hashes the world so.) Nothing serialised inside `f` can be decoded.
pub fn serialize_physical_only<R>(f: impl FnOnce() -> R) -> R {
    /// Puts the caller's setting back, even if `f` unwinds.
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            PHYSICAL_ONLY.with(|p| p.set(self.0));
        }
    }
    let _restore = Restore(PHYSICAL_ONLY.with(|p| p.replace(true)));
    f()
}

fn physical_only() -> bool {
    PHYSICAL_ONLY.with(Cell::get)
}

/// The most generations a table issues: 2^48 insertions, a million a
/// second for nine years. A decoded table whose counter is beyond it is
/// refused, so the counter can never overflow.
pub const MAX_GENERATION: u64 = 1 << 48;

/// A stable reference to an item of kind `T` in a [`Slots`] table.
#[derive(serde::Deserialize)]
#[serde(bound = "")]
pub struct Handle<T> {
    index: u32,
    lineage: u32,
    generation: u64,
    #[serde(skip)]
    _kind: PhantomData<fn() -> T>,
}

impl<T> Serialize for Handle<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if physical_only() {
            return self.index.serialize(s);
        }
        let mut out = s.serialize_struct("Handle", 3)?;
        out.serialize_field("index", &self.index)?;
        out.serialize_field("lineage", &self.lineage)?;
        out.serialize_field("generation", &self.generation)?;
        out.end()
    }
}

impl<T> Handle<T> {
    /// The slot index (stable while the item lives).
    pub fn index(self) -> usize {
        self.index as usize
    }

    /// The handle as three plain numbers (slot index, the issuing
    /// world's lineage, generation), for a C ABI or a message;
    /// [`Handle::from_raw`] takes them back. Any three numbers make a
    /// handle: a world refuses one it did not issue, as stale or foreign.
    pub fn to_raw(self) -> (u32, u32, u64) {
        self.key()
    }

    /// The handle of [`Handle::to_raw`]'s numbers.
    pub fn from_raw(index: u32, lineage: u32, generation: u64) -> Self {
        Self {
            index,
            lineage,
            generation,
            _kind: PhantomData,
        }
    }

    fn key(self) -> (u32, u32, u64) {
        (self.index, self.lineage, self.generation)
    }
}

impl<T> Clone for Handle<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Handle<T> {}
impl<T> PartialEq for Handle<T> {
    fn eq(&self, o: &Self) -> bool {
        self.key() == o.key()
    }
}
impl<T> Eq for Handle<T> {}
impl<T> core::hash::Hash for Handle<T> {
    fn hash<H: core::hash::Hasher>(&self, h: &mut H) {
        self.key().hash(h);
    }
}
impl<T> core::fmt::Debug for Handle<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "Handle({}v{}@{:08x})",
            self.index, self.generation, self.lineage
        )
    }
}

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
        Handle {
            index,
            lineage: self.lineage,
            generation,
            _kind: PhantomData,
        }
    }

    /// `Ok(slot index)` for a live handle; `ForeignHandle(what)` for a
    /// handle of another lineage, `StaleHandle(what)` for a removed item.
    pub fn check<T>(&self, handle: Handle<T>, what: &'static str) -> Result<usize, Error> {
        let i = handle.index as usize;
        if handle.lineage != self.lineage {
            Err(Error::ForeignHandle(what))
        } else if self.is_live(i) && self.generation[i] == handle.generation {
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
        self.live[handle.index as usize] = false;
        self.free.insert(handle.index);
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
        self.is_live(index).then(|| Handle {
            index: index as u32,
            lineage: self.lineage,
            generation: self.generation[index],
            _kind: PhantomData,
        })
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
