//! Solver settings.

use glam::Vec3;
use vertebra_math::BackendChoice;
use vertebra_store::{Error, check_finite};

/// How the world steps. Games use a fixed iteration count; so does the
/// paper (20 iterations, 1 substep).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverConfig {
    /// Substeps per step (>= 1): each integrates `dt / substeps`.
    pub substeps: u32,
    /// Position iterations per substep (>= 1).
    pub iterations: u32,
    /// Instruction set for the kernels.
    pub backend: BackendChoice,
    /// Worker threads (>= 1); 1 solves on the calling thread.
    pub threads: usize,
    /// Gravity (m/s^2, world).
    pub gravity: Vec3,
    /// A colour is split over threads when it has at least this many
    /// blocks of eight constraints (smaller ones run on one thread).
    pub parallel_min_blocks: usize,
    /// The fastest (m/s) overlapping bodies are pushed apart: a step removes
    /// at most `max_push_out_speed * dt` of a contact's overlap (Box2D's
    /// `contactPushMaxVelocity`, PhysX's `maxDepenetrationVelocity`). A body
    /// teleported into another comes out over a few steps; it is not fired
    /// out at `depth / dt`. Off (infinity) by default, as in PhysX: in a
    /// pile of ragdolls, slower push-out leaves more of the contacts'
    /// conflict to the joints (the drop's joint error rose 7%-38% at
    /// 3 m/s). A game that teleports bodies sets it (Box2D uses 3 m/s).
    pub max_push_out_speed: f32,
    /// Bodies never move faster than this (m/s): velocities are clamped
    /// before each substep moves them (Jolt clamps at 500 m/s too).
    pub max_linear_speed: f32,
    /// Bodies never spin faster than this (rad/s): 50 turns a second.
    pub max_angular_speed: f32,
}

impl Default for SolverConfig {
    fn default() -> Self {
        Self {
            substeps: 1,
            iterations: 20,
            backend: BackendChoice::Auto,
            threads: 1,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            parallel_min_blocks: 4,
            max_push_out_speed: f32::INFINITY,
            max_linear_speed: 500.0,
            max_angular_speed: 100.0 * core::f32::consts::PI,
        }
    }
}

impl SolverConfig {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), Error> {
        if self.substeps == 0 {
            return Err(Error::InvalidConfig("substeps must be at least 1"));
        }
        if self.iterations == 0 {
            return Err(Error::InvalidConfig("iterations must be at least 1"));
        }
        if self.threads == 0 {
            return Err(Error::InvalidConfig("threads must be at least 1"));
        }
        if self.parallel_min_blocks == 0 {
            return Err(Error::InvalidConfig(
                "parallel_min_blocks must be at least 1",
            ));
        }
        if self.max_push_out_speed.is_nan() || self.max_push_out_speed < 0.0 {
            return Err(Error::InvalidConfig(
                "max_push_out_speed must be zero or positive",
            ));
        }
        for (speed, what) in [
            (
                self.max_linear_speed,
                "max_linear_speed must be positive and finite",
            ),
            (
                self.max_angular_speed,
                "max_angular_speed must be positive and finite",
            ),
        ] {
            if !(speed.is_finite() && speed > 0.0) {
                return Err(Error::InvalidConfig(what));
            }
        }
        check_finite("gravity", self.gravity)
    }
}
