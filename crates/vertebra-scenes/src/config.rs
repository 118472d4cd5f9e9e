//! How to run a scene: spine, solver settings, ragdoll, seed.

use vertebra_ragdoll::{RagdollDesc, RagdollError, SpineMode};
use vertebra_world::{BackendChoice, SolverConfig, World};

use crate::Scene;

/// How to run a scene.
#[derive(Clone, Debug)]
pub struct SceneConfig {
    /// Which scene.
    pub scene: Scene,
    /// Rod (simplified) or sockets (standard).
    pub spine: SpineMode,
    /// Position iterations per substep.
    pub iterations: u32,
    /// Substeps per frame.
    pub substeps: u32,
    /// Frames to run (the scene's default when `None`).
    pub frames: Option<usize>,
    /// Kernel backend.
    pub backend: BackendChoice,
    /// Worker threads.
    pub threads: usize,
    /// The ragdoll (the reference humanoid when `None`).
    pub ragdoll: Option<RagdollDesc>,
    /// Ragdolls dropped in the ragdoll-drop scene (the paper's 30; see
    /// [`ragdoll_drop`](crate::ragdoll_drop) for more).
    pub ragdolls: usize,
    /// The start: 0 is the paper's scene exactly; any other seed moves each
    /// ragdoll by at most 1 mm and 0.1 degree ([`crate::seed`]).
    pub seed: u64,
}

impl SceneConfig {
    /// The paper's settings for `scene` with `spine`.
    pub fn new(scene: Scene, spine: SpineMode) -> Self {
        Self {
            scene,
            spine,
            iterations: 20,
            substeps: 1,
            frames: None,
            backend: BackendChoice::Auto,
            threads: 1,
            ragdoll: None,
            ragdolls: 30,
            seed: 0,
        }
    }

    pub(crate) fn world(&self) -> Result<World, RagdollError> {
        let config = SolverConfig {
            iterations: self.iterations,
            substeps: self.substeps,
            backend: self.backend,
            threads: self.threads,
            ..SolverConfig::default()
        };
        Ok(World::new(config)?)
    }

    pub(crate) fn description(&self) -> RagdollDesc {
        self.ragdoll
            .clone()
            .unwrap_or_else(RagdollDesc::reference_humanoid)
    }
}
