//! Contact events per pair of bodies, from what each step solved (Box2D
//! v3's begin and end touch events, Jolt's `ContactListener`): which pairs
//! began touching, with how hard they met, which stopped, and every pair
//! touching with the impulse of the step. For sounds, damage, "which bone
//! hit the floor how hard".
//!
//! **Touching.** A pair begins touching in the first step its contacts
//! push (a positive normal impulse, `World::contact_impulses`), and stays
//! touching while it has contacts (within the detection's margin: a gap
//! opening for a step between a limb and the floor is no new hit), or
//! while all of its moving bodies sleep (a pile asleep keeps its pairs, as
//! Box2D's sleeping islands keep their contacts). It ends in the first
//! step after which it has no contact and a body of it is awake, or a
//! body of it is gone (removed, or a collider's body). So a resting pair
//! gives one `began` and, when it parts, one `ended`: not one a frame.
//!
//! **Deterministic, and saved.** Pairs are in ascending order of their
//! bodies' slots (each pair's bodies so ordered, its normal turned to
//! match); the touching pairs are part of the set's snapshot, so a run
//! restored from snapshots gives the events the original did.
//!
//! **No allocation in steady state**: the lists are the set's, cleared
//! and refilled each step.

use glam::Vec3;
use vertebra_world::{BodyHandle, BodyKind, World};

use crate::contact_events::{ContactEnded, ContactEvents, Touching};
use crate::filter::ordered;
use crate::set::Collisions;

/// A pair's order: its bodies' slots, lineages and generations (two
/// handles of one slot are of different generations).
type PairOrder = ((u32, u32, u64), (u32, u32, u64));

fn slots((a, b): (BodyHandle, BodyHandle)) -> PairOrder {
    (a.to_raw(), b.to_raw())
}

/// A live pair's place in [`slots`]' order: its bodies' slots (two live
/// bodies never share one, so among one step's pairs the slots alone
/// order them as [`slots`] does).
fn live_order((a, b): (BodyHandle, BodyHandle)) -> u64 {
    (u64::from(a.index() as u32) << 32) | u64::from(b.index() as u32)
}

impl Collisions {
    /// The contact events of the last step that [`Collisions::after_step`]
    /// (or [`Collisions::step`]) followed.
    pub fn events(&self) -> &ContactEvents {
        &self.events
    }

    /// The events of `world`'s last step (its contacts checked to be the
    /// ones this set found: `Found::check`). This step's pairs and the
    /// pairs touching before are both in pair order, so one merge of the
    /// two finds which began, which go on and which ended; the pairs
    /// touching after come out in order.
    pub(crate) fn update_events(&mut self, world: &World) {
        let mut events = core::mem::take(&mut self.events);
        events.began.clear();
        events.ended.clear();
        events.touching.clear();
        events.next.clear();
        let solved = world.solved_contacts();
        events.order.clear();
        events.order.extend(
            (solved.iter().enumerate())
                .map(|(k, c)| (live_order(ordered(c.body_a, c.body_b)), k as u32)),
        );
        events.order.sort_unstable();
        let mut before = 0;
        let mut run = 0;
        while run < events.order.len() {
            let first = &solved[events.order[run].1 as usize];
            let key = ordered(first.body_a, first.body_b);
            let end = run
                + (events.order[run..].iter())
                    .take_while(|(k, _)| *k == events.order[run].0)
                    .count();
            // The pairs touching before, ahead of this one: no contact.
            while let Some(&old) = self.touching.get(before)
                && slots(old) < slots(key)
            {
                self.without_contact(old, world, &mut events);
                before += 1;
            }
            let was = self
                .touching
                .get(before)
                .is_some_and(|&old| slots(old) == slots(key));
            before += usize::from(was);
            let pair = self.pair_of(key, &events.order[run..end], world);
            run = end;
            if pair.impulse > 0.0 || was {
                events.next.push(key);
                events.touching.push(pair);
                if !was {
                    events.began.push(pair);
                }
            }
        }
        for &old in &self.touching[before..] {
            self.without_contact(old, world, &mut events);
        }
        core::mem::swap(&mut self.touching, &mut events.next);
        self.events = events;
    }

    /// A pair touching before that had no contact this step: kept while
    /// every moving body of theirs sleeps, else ended.
    fn without_contact(
        &self,
        key: (BodyHandle, BodyHandle),
        world: &World,
        events: &mut ContactEvents,
    ) {
        let sleeping = |b: BodyHandle| match world.is_asleep(b) {
            Ok(asleep) => asleep || world.bodies().kind[b.index()] != BodyKind::Dynamic,
            Err(_) => false,
        };
        if sleeping(key.0) && sleeping(key.1) {
            events.next.push(key);
        } else {
            events.ended.push(ContactEnded {
                body_a: key.0,
                body_b: key.1,
                part_a: self.part(key.0),
                part_b: self.part(key.1),
            });
        }
    }

    /// One pair's step from its contacts (`entries`: each solved
    /// contact's index, all of this pair).
    fn pair_of(
        &self,
        key: (BodyHandle, BodyHandle),
        entries: &[(u64, u32)],
        world: &World,
    ) -> Touching {
        let (solved, impulses) = (world.solved_contacts(), world.contact_impulses());
        let mut pair = Touching {
            body_a: key.0,
            body_b: key.1,
            part_a: self.part(key.0),
            part_b: self.part(key.1),
            impulse: 0.0,
            friction: Vec3::ZERO,
            point: Vec3::ZERO,
            normal: Vec3::ZERO,
            closing_speed: 0.0,
        };
        let mut strongest = -1.0;
        for &(_, k) in entries {
            let (c, i) = (&solved[k as usize], &impulses[k as usize]);
            // Turned to the pair's order: out of body_a into body_b.
            let sign = if c.body_a == key.0 { 1.0 } else { -1.0 };
            pair.impulse += i.normal;
            pair.friction += i.friction * sign;
            pair.closing_speed = pair.closing_speed.max(self.found.closing[k as usize]);
            if i.normal > strongest {
                strongest = i.normal;
                pair.point = c.point;
                pair.normal = c.normal * sign;
            }
        }
        pair
    }
}
