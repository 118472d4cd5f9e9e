//! The world's sleeping calls (the rules are in `islands.rs`).

use vertebra_store::{BodyHandle, BodyKind, Error};

use crate::World;
use crate::islands::links;

impl World {
    /// Wakes `body`'s island: its bodies move again from rest, with their
    /// stillness restarted. A static or kinematic body belongs to no
    /// island: waking one wakes the islands jointed to it.
    pub fn wake(&mut self, body: BodyHandle) -> Result<(), Error> {
        self.bodies.index(body)?;
        self.wake_islands_of(body);
        Ok(())
    }

    /// Whether `body` sleeps (only a dynamic body does).
    pub fn is_asleep(&self, body: BodyHandle) -> Result<bool, Error> {
        Ok(self.islands.is_asleep(self.bodies.index(body)?))
    }

    /// `body`'s island: an id shared by every dynamic body linked to it by
    /// joints, rods and touching contacts (`None` for a static or
    /// kinematic body). Ids are reused once an island is gone; they are
    /// the same in every world with the same history.
    pub fn island(&self, body: BodyHandle) -> Result<Option<u32>, Error> {
        Ok(self.islands.island_of(self.bodies.index(body)?))
    }

    /// How many islands there are, and how many of them sleep.
    pub fn island_count(&self) -> (usize, usize) {
        self.islands.count()
    }

    /// Lets `body` sleep or keeps it awake (and its island with it): a
    /// body the game watches, or one it moves by hand every frame.
    /// Forbidding wakes its island. Every body may sleep when added; a
    /// world sleeps only with [`SolverConfig::sleep`](crate::SolverConfig::sleep) set.
    pub fn set_sleep_allowed(&mut self, body: BodyHandle, allowed: bool) -> Result<(), Error> {
        let i = self.bodies.index(body)?;
        self.layout_dirty |= self.islands.set_allowed(i, allowed);
        Ok(())
    }

    /// Whether `body` may sleep.
    pub fn sleep_allowed(&self, body: BodyHandle) -> Result<bool, Error> {
        Ok(self.islands.allowed(self.bodies.index(body)?))
    }

    /// Wakes the islands `body` reaches, as every call that sets or pushes
    /// a body must: a dynamic body's own island; for a static or kinematic
    /// body (in no island), the islands jointed to it, as [`World::wake`]
    /// promises (a fixed anchor moved by hand drags its sleeping chain
    /// along). `body` is live.
    pub(crate) fn wake_islands_of(&mut self, body: BodyHandle) {
        let i = body.index();
        let mut woke = self.islands.wake(i);
        if self.bodies.kind[i] != BodyKind::Dynamic && self.joints_at[i] > 0 {
            for link in links(&self.joints, &self.rods) {
                let (a, b) = (link.a as usize, link.b as usize);
                if a == i || b == i {
                    woke |= self.islands.wake(a) | self.islands.wake(b);
                }
            }
        }
        self.layout_dirty |= woke;
    }

    /// `body` changed kind from `before`: it leaves its island or gains
    /// one, and its links are made again (waking every island they reach).
    pub(crate) fn rejoin(&mut self, body: BodyHandle, before: BodyKind) {
        let i = body.index();
        if before == BodyKind::Dynamic {
            self.islands.take_out(i);
        }
        if self.bodies.kind[i] == BodyKind::Dynamic {
            self.islands.make_dynamic(i);
        }
        for link in links(&self.joints, &self.rods) {
            let (a, b) = (link.a as usize, link.b as usize);
            if a == i || b == i {
                self.islands.link(a, b);
            }
        }
        self.layout_dirty = true;
    }
}
