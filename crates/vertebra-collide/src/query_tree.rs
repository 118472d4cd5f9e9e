//! The set's tree of its solid colliders' bounds for the scene queries
//! ([`QueryTree`]: parry's `Bvh`), with what it was built from and the
//! planes that are in no tree.
//!
//! Its own file because the set keeps the tree while the queries that
//! build and read it work on the set (`query.rs`, whose header says when
//! the tree holds and what a query does when it does not).

use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh, BvhWorkspace};
use vertebra_world::Timeline;

/// The set's tree of its solid colliders' bounds, and what it was built
/// from.
#[derive(Clone, Default)]
pub(crate) struct QueryTree {
    pub(crate) bvh: Bvh,
    /// The world's timeline, pose version and the set's collider version
    /// the tree holds; `None`: never built.
    pub(crate) stamp: Option<(Timeline, u64, u64)>,
    /// Scratch: the solid colliders' bounds, leaf by leaf.
    pub(crate) bounds: Vec<Aabb>,
    /// Each leaf's collider index (leaves are numbered densely: parry's
    /// tree of one or two leaves assumes so).
    pub(crate) leaves: Vec<usize>,
    /// The collider version the tree's leaves are of (refit while it
    /// holds, built anew when it changes).
    pub(crate) built_for: Option<u64>,
    /// parry's working memory for a refit.
    pub(crate) workspace: BvhWorkspace,
    /// The planes (half spaces, in no tree), by collider index: every
    /// query tests them.
    pub(crate) planes: Vec<usize>,
}
