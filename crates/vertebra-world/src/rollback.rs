//! What a step that unwinds puts back: the world as it was before the
//! call, bit for bit.
//!
//! A step runs foreign code only through its task system: `workers()`,
//! asked once as the step begins (before anything changes), and, with more
//! than one worker, `parallel_for` once per substep (and once for the
//! step's start with many contacts). Everything that a step changes before
//! its last `parallel_for` returns is kept here first, and put back if the
//! step unwinds: the bodies' velocities (held to the speed limits as the
//! step begins, then written by every substep) and orientations (written
//! by every substep), the islands' saved state (contacts wake and merge
//! islands as the step begins) and the NaN guard's count. Positions,
//! descriptions (moving drive targets and rod rests), forces, the sleep
//! update and the contact list change only after the last `parallel_for`
//! has returned. The solver's lanes (drive targets advanced substep by
//! substep, multipliers) are not kept: the layout is built again from the
//! descriptions at the next step, as a restored snapshot's is, to the same
//! bits.
//!
//! With one worker the task system is not called in the step at all, so
//! nothing is kept (the single-threaded step pays nothing for this).

use glam::{Quat, Vec3};

use crate::World;
use crate::islands::Islands;

/// The state a step changes before its last `parallel_for` returns, kept
/// in buffers the world holds (no allocation once they have grown).
#[derive(Debug, Default)]
pub(crate) struct Rollback {
    linear_velocity: Vec<Vec3>,
    angular_velocity: Vec<Vec3>,
    orientation: Vec<Quat>,
    islands: Islands,
    repaired: u64,
}

impl World {
    /// Keeps what the coming step may change before its task system's last
    /// call returns ([`World::roll_back`] puts it back).
    pub(crate) fn keep_for_rollback(&mut self) {
        let (kept, bodies) = (&mut self.rollback, &self.bodies);
        kept.linear_velocity.clone_from(&bodies.linear_velocity);
        kept.angular_velocity.clone_from(&bodies.angular_velocity);
        kept.orientation.clone_from(&bodies.orientation);
        self.islands.keep_into(&mut kept.islands);
        kept.repaired = self.repaired;
    }

    /// Puts back what [`World::keep_for_rollback`] kept, after a step
    /// unwound; the layout is built again from the descriptions at the
    /// next step (its lanes may hold a substep's advance).
    pub(crate) fn roll_back(&mut self) {
        let (kept, bodies) = (&self.rollback, &mut self.bodies);
        bodies.linear_velocity.clone_from(&kept.linear_velocity);
        bodies.angular_velocity.clone_from(&kept.angular_velocity);
        bodies.orientation.clone_from(&kept.orientation);
        self.islands.put_back(&kept.islands);
        self.repaired = kept.repaired;
        self.layout_dirty = true;
    }
}
