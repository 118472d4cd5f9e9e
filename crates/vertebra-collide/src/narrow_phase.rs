//! The narrow phase: every candidate pair's contacts, from parry's
//! manifolds (the ground's written by `manifold.rs`), with the pair's
//! friction (geometric mean) and restitution (the larger).
//!
//! Its own file because it is the step from pairs to contacts and nothing
//! else: the pairs come from the broad phase (`broad_phase.rs`), the
//! bit-exact pieces of one pair from `manifold.rs`.

use parry3d::query::{DefaultQueryDispatcher, PersistentQueryDispatcher};
use vertebra_world::Contact;

use crate::detection::Detection;
use crate::manifold::{fresh, plane_manifold, push_manifold};
use crate::pose::relative_pose;
use crate::set::Collisions;

impl Collisions {
    /// Every pair's contacts into `contacts` (appended).
    pub(crate) fn narrow(&self, scratch: &mut Detection, contacts: &mut Vec<Contact>) {
        let (poses, reach) = (&scratch.poses, &scratch.reach);
        for &(i, j) in &scratch.pairs {
            let ((ci, si), (cj, sj)) = (&self.colliders[i], &self.colliders[j]);
            fresh(&mut scratch.manifolds);
            let relative = relative_pose(&poses[i], &poses[j]);
            let prediction = self.prediction + reach[i] + reach[j];
            let on_plane = plane_manifold(
                &relative,
                si.as_ref(),
                sj.as_ref(),
                prediction,
                &mut scratch.manifolds,
            );
            if !on_plane
                && DefaultQueryDispatcher
                    .contact_manifolds(
                        &relative,
                        si.as_ref(),
                        sj.as_ref(),
                        prediction,
                        &mut scratch.manifolds,
                        &mut None,
                    )
                    .is_err()
            {
                continue; // a pair parry has no algorithm for (none of ours)
            }
            let friction = (ci.friction * cj.friction).sqrt();
            let restitution = ci.restitution.max(cj.restitution);
            for m in &scratch.manifolds {
                push_manifold(
                    contacts,
                    m,
                    (ci.body, &poses[i]),
                    (cj.body, &poses[j]),
                    friction,
                    restitution,
                );
            }
        }
    }
}
