//! The collision set ([`Collisions`]): what it holds, each field with what
//! it is for and which file keeps it, and its prediction margin.
//!
//! Its own file because every other file that works on the set reads its
//! fields, while the set holds only the types of the files below it (the
//! colliders, the ragdoll parts, the detection's working memory, the
//! record of what was found, the events, the query tree): the set is the
//! layer between those types and the files that act on it.

use std::collections::{HashMap, HashSet};

use glam::{Quat, Vec3};
use parry3d::bounding_volume::Aabb;
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use vertebra_world::{BodyHandle, Contact, Error, Timeline};

use crate::collider::Collider;
use crate::contact_events::ContactEvents;
use crate::detection::Detection;
use crate::found::Found;
use crate::part::Parts;
use crate::query_tree::QueryTree;

/// Checks a prediction margin (m): finite, not negative.
pub(crate) fn check_prediction(prediction: f32) -> Result<(), Error> {
    if !prediction.is_finite() {
        return Err(Error::NonFinite("collision prediction"));
    }
    if prediction < 0.0 {
        return Err(Error::NonPositive("collision prediction"));
    }
    Ok(())
}

/// All colliders and the rules for which pairs are tested.
#[derive(Clone, Default)]
pub struct Collisions {
    pub(crate) colliders: Vec<(Collider, SharedShape)>,
    pub(crate) excluded: HashSet<(BodyHandle, BodyHandle)>,
    pub(crate) prediction: f32,
    /// Bodies of ragdolls whose self-collision is off, each with its
    /// ragdoll's group: two bodies of one group are never tested.
    pub(crate) apart: HashMap<BodyHandle, u64>,
    /// The group the next ragdoll whose self-collision goes off gets.
    pub(crate) next_apart: u64,
    /// The ragdoll and bone of every ragdoll body the set added
    /// (`build_ragdoll`, `add_ragdoll`).
    pub(crate) parts: Parts,
    /// The pairs of bodies touching after the last step the events saw,
    /// in ascending order (`events.rs`).
    pub(crate) touching: Vec<(BodyHandle, BodyHandle)>,
    /// Counts every change to the colliders (added, removed, moved to
    /// other bodies, restored): with the world's, when the query tree and
    /// a detection's record still hold. Not part of the set's state.
    pub(crate) version: u64,
    /// What the last `find_contacts_into` found, for `after_step`
    /// (`found.rs`, `frame.rs`). Not part of the set's state.
    pub(crate) found: Found,
    /// The last step's events (`contact_events.rs`, filled by
    /// `events.rs`). Output, not state.
    pub(crate) events: ContactEvents,
    /// The scene queries' tree (`query_tree.rs`, built and read by
    /// `query.rs`). Not part of the set's state.
    pub(crate) tree: QueryTree,
    /// The list [`Collisions::step`] finds contacts into (working memory).
    pub(crate) frame_contacts: Vec<Contact>,
    /// Scratch of continuous collision: the bodies it puts back.
    pub(crate) moves: Vec<(BodyHandle, Vec3, Quat)>,
    /// Scratch of continuous collision: the static solids, their bounds
    /// and poses.
    pub(crate) statics: Vec<(usize, Aabb, Pose)>,
    /// The world's run of states the set serves, once it has served one
    /// (`pairing.rs`). Not part of the set's state: never saved; a clone
    /// serves the same world.
    pub(crate) serves: Option<Timeline>,
    /// Working memory of [`Collisions::find_contacts_into`] (not part of
    /// the set's state: never saved, and a clone's starts empty in effect,
    /// as every call rewrites it).
    pub(crate) scratch: Detection,
}

impl Collisions {
    /// No colliders yet; a 1 cm prediction margin.
    pub fn new() -> Self {
        Self {
            prediction: 0.01,
            ..Self::default()
        }
    }

    /// The prediction margin (m): contacts are made for gaps up to this
    /// size too, on top of how far each body can move in the step (see
    /// [`Collisions::find_contacts`]).
    pub fn prediction(&self) -> f32 {
        self.prediction
    }

    /// Sets the prediction margin (m, finite, not negative); `Err` (and no
    /// change) otherwise.
    pub fn set_prediction(&mut self, margin: f32) -> Result<(), Error> {
        check_prediction(margin)?;
        self.prediction = margin;
        Ok(())
    }
}
