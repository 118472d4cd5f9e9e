//! A ragdoll following an animation frame by frame with its joints' and
//! world drives (`Ragdoll::follow_profile`): what a scene with a powered ragdoll
//! does before each step.

use glam::Vec3;
use vertebra_ragdoll::{Profile, Ragdoll, RagdollDesc, RagdollError};
use vertebra_world::World;

use crate::Walk;

/// The animation a scene's first ragdoll follows, and how.
#[derive(Clone, Debug)]
pub struct Following {
    /// The ragdoll's description (the walk's poses are built on it).
    pub desc: RagdollDesc,
    /// The animation: a walk, or (starting at infinity) standing.
    pub walk: Walk,
    /// The drives' settings.
    pub animation: Profile,
}

impl Following {
    /// Before frame `frame`'s step of `dt` seconds: every drive of
    /// `ragdoll` set to follow the animation from its pose at the frame's
    /// start to its pose at the frame's end. Depends on the frame alone,
    /// so a restored world follows on as the saved one would.
    pub fn follow(
        &self,
        ragdoll: &Ragdoll,
        world: &mut World,
        frame: usize,
        dt: f32,
    ) -> Result<(), RagdollError> {
        let prev = self.walk.pose(&self.desc, frame as f32 * dt)?;
        let pose = self.walk.pose(&self.desc, (frame + 1) as f32 * dt)?;
        ragdoll.follow_profile(world, (&prev, &pose), dt, &self.animation)
    }

    /// Where the animation has the hips at the end of frame `frame` (m,
    /// world).
    pub fn hips(&self, frame: usize, dt: f32) -> Vec3 {
        self.walk.hips((frame + 1) as f32 * dt)
    }
}
