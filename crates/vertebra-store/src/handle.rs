//! Generational handles: a slot index and the slot's generation, so a
//! handle to a removed item is recognised as stale even after its slot is
//! reused.

use core::marker::PhantomData;

/// A stable reference to an item of kind `T` in a [`Slots`] table.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(bound = "")]
pub struct Handle<T> {
    index: u32,
    generation: u32,
    _kind: PhantomData<fn() -> T>,
}

impl<T> Handle<T> {
    /// The slot index (stable while the item lives).
    pub fn index(self) -> usize {
        self.index as usize
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
        (self.index, self.generation) == (o.index, o.generation)
    }
}
impl<T> Eq for Handle<T> {}
impl<T> core::hash::Hash for Handle<T> {
    fn hash<H: core::hash::Hasher>(&self, h: &mut H) {
        (self.index, self.generation).hash(h);
    }
}
impl<T> core::fmt::Debug for Handle<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "Handle({}v{})", self.index, self.generation)
    }
}

/// Slot bookkeeping: which indices are live, their generations, and a free
/// list that reuses the lowest freed index first (deterministic).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Slots {
    generation: Vec<u32>,
    live: Vec<bool>,
    free: std::collections::BTreeSet<u32>,
}

impl Slots {
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
        self.live[index as usize] = true;
        Handle {
            index,
            generation: self.generation[index as usize],
            _kind: PhantomData,
        }
    }

    /// Whether `handle` names a live item.
    pub fn contains<T>(&self, handle: Handle<T>) -> bool {
        let i = handle.index as usize;
        i < self.live.len() && self.live[i] && self.generation[i] == handle.generation
    }

    /// Frees the slot of a live handle; `false` if it was stale.
    pub fn remove<T>(&mut self, handle: Handle<T>) -> bool {
        if !self.contains(handle) {
            return false;
        }
        let i = handle.index as usize;
        self.live[i] = false;
        self.generation[i] = self.generation[i].wrapping_add(1);
        self.free.insert(handle.index);
        true
    }

    /// The number of slots ever allocated (live or free).
    pub fn capacity(&self) -> usize {
        self.live.len()
    }

    /// Whether the generation and liveness tables agree in length and the
    /// free list names only dead slots.
    pub fn is_consistent(&self) -> bool {
        self.generation.len() == self.live.len()
            && self
                .free
                .iter()
                .all(|&i| self.live.get(i as usize) == Some(&false))
    }

    /// Whether slot `index` is live.
    pub fn is_live(&self, index: usize) -> bool {
        self.live.get(index).copied().unwrap_or(false)
    }

    /// The live handle at `index`, if any.
    pub fn handle_at<T>(&self, index: usize) -> Option<Handle<T>> {
        self.is_live(index).then(|| Handle {
            index: index as u32,
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
