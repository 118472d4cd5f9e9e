//! The broad phase: each collider's bounds loosened by the prediction
//! margin and how far its body can move in the step, then sort-and-sweep
//! along x for the solids (every solid against every plane), kept to the
//! pairs of the round that may collide.
//!
//! Its own file because it only proposes pairs: which of them touch is
//! the narrow phase's (`narrow_phase.rs`), which may touch at all the
//! filter's (`filter.rs`), and which round a pair belongs to the islands'
//! (`islands.rs`).

use parry3d::bounding_volume::BoundingVolume;
use vertebra_world::World;

use crate::collider::ColliderShape;
use crate::detection::{DONE, Detection, NO_ISLAND, WAKING};
use crate::set::Collisions;

impl Collisions {
    /// Each collider's bounds, and the solids in sweep order.
    pub(crate) fn bounds(&self, scratch: &mut Detection) {
        let (poses, reach) = (&scratch.poses, &scratch.reach);
        scratch.aabbs.clear();
        scratch.aabbs.extend((0..self.colliders.len()).map(|k| {
            self.colliders[k]
                .1
                .compute_aabb(&poses[k])
                .loosened(self.prediction + reach[k])
        }));
        let aabbs = &scratch.aabbs;
        let is_plane = |k: usize| matches!(self.colliders[k].0.shape, ColliderShape::Plane(_));
        let solids = &mut scratch.solids;
        solids.clear();
        solids.extend((0..self.colliders.len()).filter(|&k| !is_plane(k)));
        // Unstable but in place (no buffer): the index breaks ties, so the
        // order is the one a stable sort gives.
        solids
            .sort_unstable_by(|&a, &b| aabbs[a].mins.x.total_cmp(&aabbs[b].mins.x).then(a.cmp(&b)));
    }

    /// Into `scratch.pairs`, the pairs of collider indices whose bounds
    /// overlap and that may collide (sort-and-sweep along x for solids,
    /// every solid against every plane), of this round: in the `first`,
    /// those with a body that moves on its own; in each later one, those
    /// of the islands the last round woke (and of no island woken before).
    pub(crate) fn candidate_pairs(&self, world: &World, scratch: &mut Detection, first: bool) {
        let (aabbs, solids) = (&scratch.aabbs, &scratch.solids);
        let is_plane = |k: usize| matches!(self.colliders[k].0.shape, ColliderShape::Plane(_));
        let pairs = &mut scratch.pairs;
        pairs.clear();
        for (n, &a) in solids.iter().enumerate() {
            for &b in &solids[n + 1..] {
                if aabbs[b].mins.x > aabbs[a].maxs.x {
                    break;
                }
                if aabbs[a].intersects(&aabbs[b]) {
                    pairs.push((a.min(b), a.max(b)));
                }
            }
        }
        for plane in (0..self.colliders.len()).filter(|&k| is_plane(k)) {
            pairs.extend(solids.iter().map(|&s| (plane.min(s), plane.max(s))));
        }
        let (acts, asleep_in, islands) = (&scratch.acts, &scratch.asleep_in, &scratch.islands);
        let mark = |k: usize| {
            let island = asleep_in[k];
            (island != NO_ISLAND).then(|| islands[island as usize])
        };
        let in_round = |a: usize, b: usize| {
            if first {
                return acts[a] || acts[b];
            }
            let (ma, mb) = (mark(a), mark(b));
            !(acts[a] || acts[b])
                && (ma == Some(WAKING) || mb == Some(WAKING))
                && ma != Some(DONE)
                && mb != Some(DONE)
        };
        pairs.retain(|&(a, b)| in_round(a, b) && self.may_collide(world, a, b));
        pairs.sort_unstable();
    }
}
