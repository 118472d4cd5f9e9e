//! Generational handles: a slot index, the generation the slot had when
//! the item was made, and the lineage of the tables that issued it.
//!
//! - **Generations are never reissued.** A table keeps one counter, raised
//!   by every insertion and never lowered (a restored snapshot's counter
//!   only raises it, see [`Slots::issue_after`](crate::Slots::issue_after)), so a handle to a removed
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

pub(crate) fn physical_only() -> bool {
    PHYSICAL_ONLY.with(Cell::get)
}

/// A stable reference to an item of kind `T` in a [`Slots`](crate::Slots) table.
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

/// Marker for body handles.
#[derive(Debug)]
pub enum BodyTag {}

/// A stable reference to a body.
pub type BodyHandle = Handle<BodyTag>;
