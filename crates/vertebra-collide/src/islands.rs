//! Sleeping islands in detection: which colliders move on their own and
//! which sleep in which island ([`Collisions::sleep_state`]), and, after a
//! round of contacts, which sleeping islands those contacts touch (the
//! step will wake them, so the next round finds their pairs too:
//! [`wake_touched`]).
//!
//! Its own file because it is the one part of detection that asks the
//! world about sleep; the rounds themselves are `detect.rs`'s, the pairs
//! of a round `broad_phase.rs`'s.

use glam::Vec3;
use vertebra_world::{BodyHandle, BodyKind, Contact, Error, World};

use crate::detection::{DONE, Detection, NO_ISLAND, UNTOUCHED, WAKING};
use crate::set::Collisions;

impl Collisions {
    /// Each collider's body's sleep state into `scratch`.
    pub(crate) fn sleep_state(&self, world: &World, scratch: &mut Detection) -> Result<(), Error> {
        scratch.acts.clear();
        scratch.asleep_in.clear();
        scratch.islands.clear();
        for (index, (c, _)) in self.colliders.iter().enumerate() {
            let refused = |e| c.refused(index, e);
            let s = world.body(c.body).map_err(refused)?;
            let asleep = world.is_asleep(c.body).map_err(refused)?;
            let moving = s.linear_velocity != Vec3::ZERO || s.angular_velocity != Vec3::ZERO;
            scratch
                .acts
                .push(match world.bodies().kind[c.body.index()] {
                    BodyKind::Dynamic => !asleep,
                    BodyKind::Kinematic => moving,
                    BodyKind::Static => false,
                });
            let island = world.island(c.body).map_err(refused)?.filter(|_| asleep);
            let island = island.unwrap_or(NO_ISLAND);
            if island != NO_ISLAND && scratch.islands.len() <= island as usize {
                scratch.islands.resize(island as usize + 1, UNTOUCHED);
            }
            scratch.asleep_in.push(island);
        }
        Ok(())
    }
}

/// Marks the sleeping islands `found` touches (the step will wake them) as
/// waking, and those that were waking as done; true when any island is
/// newly waking.
pub(crate) fn wake_touched(scratch: &mut Detection, world: &World, found: &[Contact]) -> bool {
    for mark in &mut scratch.islands {
        if *mark == WAKING {
            *mark = DONE;
        }
    }
    // The contacts' bodies are live: they were just read.
    let marks = scratch.islands.len();
    let island_of = |body: BodyHandle| {
        let asleep = world.is_asleep(body).unwrap_or(false);
        let island = world.island(body).ok().flatten().filter(|_| asleep)?;
        Some(island as usize).filter(|&k| k < marks)
    };
    let mut woke = false;
    for c in found {
        for island in [island_of(c.body_a), island_of(c.body_b)]
            .into_iter()
            .flatten()
        {
            if scratch.islands[island] == UNTOUCHED {
                scratch.islands[island] = WAKING;
                woke = true;
            }
        }
    }
    woke
}
