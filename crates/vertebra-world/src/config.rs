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
        check_finite("gravity", self.gravity)
    }
}
