//! Saving a collision set and restoring it, alongside `World::snapshot`:
//! rollback and save games need both, since contacts come from the set.
//!
//! Bytes: `"VTBCOLLS"`, the format version (u32 LE), the xxh3 hash of the
//! payload (u64 LE), then the payload (postcard): the world's bodies it was
//! taken with (a u64 hash of every live body's handle, `pairing.rs`), the
//! prediction margin,
//! every collider as it was added (body, shape, friction, restitution,
//! groups) in the set's order, the excluded pairs in a canonical order
//! (so equal sets give equal bytes), the ragdolls' parts (each ragdoll
//! body with its ragdoll and bone, in a canonical order), the pairs of
//! bodies touching (ascending, as the contact events keep them), then the
//! ragdolls' self-collision
//! settings: every body whose self-collision is off with its ragdoll's
//! group (u64), in a canonical order, and the next group to be given (at
//! most [`MAX_SELF_COLLISION_GROUPS`]). The
//! parry geometry is rebuilt from the shapes, exactly as
//! [`Collisions::add`] builds it.
//!
//! The format version changes with every change to the payload's layout,
//! so bytes of another layout are refused by their version rather than
//! misread.
//!
//! The bytes are untrusted input: the checksum only catches accidents (it
//! is not keyed), so [`Collisions::restore`] checks every value as
//! strictly as the API does, every collider's body against the world, and
//! that the world's bodies are those the snapshot was taken with.

use serde::{Deserialize, Serialize};
use vertebra_world::{BodyHandle, Error, World};

use crate::collider::Collider;
use crate::filter::ordered;
use crate::groups::MAX_SELF_COLLISION_GROUPS;
use crate::pairing::{OTHER_BODIES, census};
use crate::part::RagdollPart;
use crate::set::{Collisions, check_prediction};
use vertebra_math::DefaultFloatMode;

const MAGIC: &[u8; 8] = b"VTBCOLLS";
const VERSION: u32 = 4;
const HEADER: usize = 20;

/// A collision set's full state at one instant, with the identity of the
/// world's bodies it served: [`Collisions::snapshot`] takes it,
/// [`Collisions::restore`] puts it back.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CollisionSnapshot {
    bytes: Vec<u8>,
}

impl CollisionSnapshot {
    /// The encoded snapshot (to store or send).
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// A snapshot from bytes (any bytes: they are checked when restored).
    pub fn from_bytes(bytes: Vec<u8>) -> Self {
        Self { bytes }
    }
}

#[derive(Serialize, Deserialize)]
struct State {
    census: u64,
    prediction: f32,
    colliders: Vec<Collider>,
    excluded: Vec<(BodyHandle, BodyHandle)>,
    parts: Vec<(BodyHandle, RagdollPart)>,
    touching: Vec<(BodyHandle, BodyHandle)>,
    apart: Vec<(BodyHandle, u64)>,
    next_apart: u64,
}

impl Collisions {
    /// The set's full state now, taken with `world`, the world it serves
    /// (see [`CollisionSnapshot`]): take it with `World::snapshot`, at the
    /// same moment, and restore the two together. `Err(WorldMismatch)`
    /// for a world the set does not serve (see [`Collisions::attach`]): a
    /// snapshot of it would tie the set to bodies it does not know.
    pub fn snapshot(&self, world: &World) -> Result<CollisionSnapshot, Error> {
        self.check_serves(world)?;
        let mut excluded: Vec<_> = self.excluded.iter().copied().collect();
        excluded.sort_by_cached_key(encode);
        let mut apart: Vec<_> = self.apart.iter().map(|(&b, &g)| (b, g)).collect();
        apart.sort_by_cached_key(encode);
        let mut parts: Vec<_> = self.parts.iter().collect();
        parts.sort_by_cached_key(|(b, _)| encode(b));
        let state = State {
            census: census(world),
            prediction: self.prediction,
            colliders: self.colliders().copied().collect(),
            excluded,
            parts,
            touching: self.touching.clone(),
            apart,
            next_apart: self.next_apart,
        };
        let payload = encode(&state);
        let mut bytes = Vec::with_capacity(HEADER + payload.len());
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&VERSION.to_le_bytes());
        bytes.extend_from_slice(&xxhash_rust::xxh3::xxh3_64(&payload).to_le_bytes());
        bytes.extend_from_slice(&payload);
        Ok(CollisionSnapshot { bytes })
    }

    /// Puts the set back to `snapshot`, for use with `world` (restore the
    /// world first, from its snapshot taken with this one: every collider's
    /// body must be live in it, and its bodies those the snapshot was taken
    /// with). From then on the set serves `world` as it is now.
    /// `Err(CorruptSnapshot)` for bytes that are not a collision-set
    /// snapshot of this version, damaged or undecodable; `Err(Collider)`
    /// naming the collider and its body for a collider [`Collisions::add`]
    /// would refuse or whose body is not in `world`; `NonFinite` or
    /// `NonPositive` for a margin [`Collisions::set_prediction`] would
    /// refuse; `CorruptSnapshot` naming the entry for a list the set could
    /// not have written (an excluded pair or self-collision entry out of
    /// the canonical order or repeated, a pair's bodies out of order), for
    /// a self-collision setting the API could not have made (a body twice,
    /// a body without a collider, a group not yet given) and for a group
    /// counter beyond [`MAX_SELF_COLLISION_GROUPS`]; `WorldMismatch` when the
    /// world's bodies are not those the snapshot was taken with (a world
    /// snapshot of another moment, with bodies added or removed between
    /// the two). A set's own snapshot always restores into its world, and
    /// a world restored from its snapshot taken at the same moment, in any
    /// process. The set is unchanged on error.
    pub fn restore(&mut self, snapshot: &CollisionSnapshot, world: &World) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        let state = decode(&snapshot.bytes)?;
        check_prediction(state.prediction)?;
        let mut restored = Collisions {
            prediction: state.prediction,
            ..Collisions::default()
        };
        for (index, collider) in state.colliders.into_iter().enumerate() {
            if let Err(e) = world.body(collider.body) {
                return Err(collider.refused(index, e));
            }
            restored.add(collider)?;
        }
        for (k, &(a, b)) in state.excluded.iter().enumerate() {
            if ordered(a, b) != (a, b) {
                return Err(Error::CorruptSnapshot(format!(
                    "excluded pair {k}: its bodies out of order"
                )));
            }
        }
        check_canonical("excluded pair", &state.excluded)?;
        restored.excluded = state.excluded.into_iter().collect();
        if state.next_apart > MAX_SELF_COLLISION_GROUPS {
            return Err(Error::CorruptSnapshot(format!(
                "self-collision groups: {} given, more than the 2^48 a set gives",
                state.next_apart
            )));
        }
        restored.next_apart = state.next_apart;
        check_canonical("self-collision entry", &state.apart)?;
        for (k, (body, group)) in state.apart.into_iter().enumerate() {
            restored.check_apart(body, group).map_err(|why| {
                Error::CorruptSnapshot(format!("self-collision entry {k}: {why}"))
            })?;
            restored.apart.insert(body, group);
        }
        check_canonical(
            "ragdoll part",
            &state.parts.iter().map(|(b, _)| *b).collect::<Vec<_>>(),
        )?;
        for (k, &(body, part)) in state.parts.iter().enumerate() {
            if !restored.colliders().any(|c| c.body == body) {
                return Err(Error::CorruptSnapshot(format!(
                    "ragdoll part {k}: a body without a collider"
                )));
            }
            restored.parts.insert(body, part);
        }
        for (k, &(a, b)) in state.touching.iter().enumerate() {
            if ordered(a, b) != (a, b) || a == b {
                return Err(Error::CorruptSnapshot(format!(
                    "touching pair {k}: its bodies out of order or the same"
                )));
            }
        }
        if let Some(k) = state
            .touching
            .windows(2)
            .position(|w| (w[0].0.to_raw(), w[0].1.to_raw()) >= (w[1].0.to_raw(), w[1].1.to_raw()))
        {
            return Err(Error::CorruptSnapshot(format!(
                "touching pair {}: out of order or repeated",
                k + 1
            )));
        }
        restored.touching = state.touching;
        if state.census != census(world) {
            return Err(Error::WorldMismatch(OTHER_BODIES));
        }
        restored.version = self.version + 1;
        restored.serve(world);
        *self = restored;
        Ok(())
    }
}

/// Refuses a list [`Collisions::snapshot`] could not have written: each
/// entry once, in the canonical order it writes (ascending by encoding).
fn check_canonical<T: Serialize>(what: &str, entries: &[T]) -> Result<(), Error> {
    let keys: Vec<Vec<u8>> = entries.iter().map(encode).collect();
    match keys.windows(2).position(|pair| pair[0] >= pair[1]) {
        Some(k) => Err(Error::CorruptSnapshot(format!(
            "{what} {}: out of order or repeated",
            k + 1
        ))),
        None => Ok(()),
    }
}

impl Collisions {
    /// Whether `body` may join `group` in a set being restored (its
    /// colliders already in, and so checked against the world); the reason
    /// if not.
    fn check_apart(&self, body: BodyHandle, group: u64) -> Result<(), &'static str> {
        if self.apart.contains_key(&body) {
            return Err("a body listed twice");
        }
        if !self.colliders().any(|c| c.body == body) {
            return Err("a body without a collider");
        }
        if group >= self.next_apart {
            return Err("a group not given yet");
        }
        Ok(())
    }
}

/// Postcard bytes of a value (our types always encode).
fn encode<T: Serialize>(value: &T) -> Vec<u8> {
    postcard::to_allocvec(value).expect("a collision set always encodes")
}

/// The state in `bytes`, if they are an intact snapshot of this version.
fn decode(bytes: &[u8]) -> Result<State, Error> {
    if bytes.len() < HEADER || &bytes[..8] != MAGIC {
        return Err(Error::CorruptSnapshot(
            "not a collision-set snapshot".into(),
        ));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != VERSION {
        return Err(Error::IncompatibleSnapshot(
            "a collision-set snapshot of another format version",
        ));
    }
    let checksum = u64::from_le_bytes(bytes[12..HEADER].try_into().expect("8 bytes"));
    let payload = &bytes[HEADER..];
    if xxhash_rust::xxh3::xxh3_64(payload) != checksum {
        return Err(Error::CorruptSnapshot("checksum mismatch".into()));
    }
    match postcard::take_from_bytes::<State>(payload) {
        Ok((state, [])) => Ok(state),
        Ok(_) => Err(Error::CorruptSnapshot(
            "bytes after the collision set".into(),
        )),
        Err(_) => Err(Error::CorruptSnapshot("undecodable collision set".into())),
    }
}
