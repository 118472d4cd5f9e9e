//! A detection's working memory ([`Detection`]): each collider's pose,
//! reach and bounds, the sweep order, the candidate pairs, parry's
//! manifolds, and which colliders move or sleep in which island, with the
//! marks a round of detection gives the sleeping islands.
//!
//! Its own file because the set keeps one between calls (a steady scene's
//! detection allocates nothing) while the phases that fill it (`detect.rs`,
//! `broad_phase.rs`, `narrow_phase.rs`, `islands.rs`) work on the set: the
//! set holds this, they read both. It reads nothing of the crate.

use parry3d::bounding_volume::Aabb;
use parry3d::math::Pose;
use parry3d::query::ContactManifold;

/// A detection's working memory, kept between calls so that a steady
/// scene's detection allocates nothing.
#[derive(Clone, Default)]
pub(crate) struct Detection {
    /// Each collider's body pose.
    pub(crate) poses: Vec<Pose>,
    /// How far each collider's body can move in the step (m).
    pub(crate) reach: Vec<f32>,
    /// Each collider's bounds, loosened by the prediction and its reach.
    pub(crate) aabbs: Vec<Aabb>,
    /// The solid colliders in sweep order.
    pub(crate) solids: Vec<usize>,
    /// The candidate pairs of collider indices, ascending.
    pub(crate) pairs: Vec<(usize, usize)>,
    /// Parry's output for one pair.
    pub(crate) manifolds: Vec<ContactManifold<(), ()>>,
    /// Each collider's body moves on its own (awake and dynamic, or
    /// kinematic with a velocity).
    pub(crate) acts: Vec<bool>,
    /// Each collider's body's island while it sleeps, else `NO_ISLAND`.
    pub(crate) asleep_in: Vec<u32>,
    /// Per island id: [`UNTOUCHED`], [`WAKING`] (touched by the last
    /// round's contacts: its pairs are found in this round) or [`DONE`].
    pub(crate) islands: Vec<u8>,
}

/// A collider whose body does not sleep.
pub(crate) const NO_ISLAND: u32 = u32::MAX;
pub(crate) const UNTOUCHED: u8 = 0;
pub(crate) const WAKING: u8 = 1;
pub(crate) const DONE: u8 = 2;
