//! How to run a scene: spine, solver settings, ragdoll, seed.

use vertebra_ragdoll::{DriveSettings, RagdollDesc, RagdollError, SpineMode};
use vertebra_world::{
    BackendChoice, JointSolver, PinContacts, SleepSettings, SolverConfig, Spring, World,
};

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
    /// How the joints are solved (`SolverConfig::joints`): iterative, as
    /// the paper, or direct.
    pub joints: JointSolver,
    /// Frames to run (the scene's default when `None`).
    pub frames: Option<usize>,
    /// Kernel backend.
    pub backend: BackendChoice,
    /// Worker threads.
    pub threads: usize,
    /// The ragdoll (when `None`, the reference humanoid in the paper's
    /// scenes, the anatomical humanoid in the hit reaction and the
    /// anatomical drop, [`heavy_chain`](crate::heavy_chain) in the heavy
    /// chain, which refuses any other).
    pub ragdoll: Option<RagdollDesc>,
    /// Ragdolls dropped in the ragdoll-drop scene (the paper's 30; see
    /// [`ragdoll_drop`](crate::ragdoll_drop) for more).
    pub ragdolls: usize,
    /// The start: 0 is the paper's scene exactly; any other seed moves each
    /// ragdoll by at most 1 mm and 0.1 degree ([`crate::seed`]).
    pub seed: u64,
    /// The hit-reaction drive's natural frequency (Hz, finite and above 0).
    pub drive_frequency: f32,
    /// The hit-reaction drive's damping ratio (1 is critical; finite, not
    /// negative).
    pub drive_damping_ratio: f32,
    /// The hit-reaction drive's torque limit per joint (N m; infinity is
    /// unlimited, not negative).
    pub max_torque: f32,
    /// Whether the scene measures its residuals after every frame
    /// (`World::measure_residuals`, outside the frame's own cost:
    /// [`SceneWorld::advance`]): every figure of a scene is measured from
    /// them, so [`SceneConfig::new`] turns it on; off only to time the
    /// step alone (and then [`SceneWorld::measure`] needs
    /// `World::measure_residuals` first).
    ///
    /// [`SceneWorld::measure`]: crate::SceneWorld::measure
    /// [`SceneWorld::advance`]: crate::SceneWorld::advance
    pub measure_residuals: bool,
    /// When islands fall asleep (`SolverConfig::sleep`). Off (`None`) in
    /// [`SceneConfig::new`]: the paper's figures, and the engines they are
    /// compared with, step every body at every frame.
    pub sleep: Option<SleepSettings>,
    /// Whether the contacts take back their push-out's speed
    /// (`SolverConfig::relax_contacts`): off in [`SceneConfig::new`], as
    /// in the paper; on in the world's default.
    pub relax_contacts: bool,
    /// Which ragdolls' contacts with the static world are solved in
    /// their direct joint solve (`SolverConfig::pin_contacts`): never in
    /// [`SceneConfig::new`], as in the paper.
    pub pin_contacts: PinContacts,
}

impl SceneConfig {
    /// The paper's settings for `scene` with `spine`.
    pub fn new(scene: Scene, spine: SpineMode) -> Self {
        Self {
            scene,
            spine,
            iterations: 20,
            substeps: 1,
            joints: JointSolver::Iterative,
            frames: None,
            backend: BackendChoice::Auto,
            threads: 1,
            ragdoll: None,
            ragdolls: 30,
            seed: 0,
            drive_frequency: 16.0,
            drive_damping_ratio: 1.0,
            max_torque: f32::INFINITY,
            measure_residuals: true,
            sleep: None,
            relax_contacts: false,
            pin_contacts: PinContacts::Never,
        }
    }

    /// The hit-reaction drive: a spring at [`Self::drive_frequency`] and
    /// [`Self::drive_damping_ratio`], torque limited to
    /// [`Self::max_torque`]. Refused, naming the field, when out of range
    /// (whichever scene runs, so a bad setting is never silently ignored).
    pub(crate) fn drive(&self) -> Result<DriveSettings, RagdollError> {
        let out = |field: &'static str, value: f32, range: &str| RagdollError::OutOfRange {
            context: "scene".to_owned(),
            field,
            reason: format!("is {value}; must be {range}"),
        };
        let f = self.drive_frequency;
        if !(f.is_finite() && f > 0.0) {
            return Err(out("drive_frequency", f, "finite and above 0 Hz"));
        }
        let r = self.drive_damping_ratio;
        if !(r.is_finite() && r >= 0.0) {
            return Err(out("drive_damping_ratio", r, "finite and not negative"));
        }
        let t = self.max_torque;
        if t.is_nan() || t < 0.0 {
            return Err(out(
                "max_torque",
                t,
                "a number, not negative (inf: unlimited)",
            ));
        }
        let strength = Spring::Frequency {
            frequency: f,
            damping_ratio: r,
        };
        Ok(DriveSettings::uniform(strength).with_max_torque(t))
    }

    pub(crate) fn world(&self) -> Result<World, RagdollError> {
        let config = SolverConfig {
            iterations: self.iterations,
            substeps: self.substeps,
            joints: self.joints,
            backend: self.backend,
            threads: self.threads,
            sleep: self.sleep,
            relax_contacts: self.relax_contacts,
            pin_contacts: self.pin_contacts,
            ..SolverConfig::paper()
        };
        Ok(World::new(config)?)
    }
}
