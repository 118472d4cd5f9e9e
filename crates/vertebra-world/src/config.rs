//! Solver settings.

use glam::Vec3;
use vertebra_math::BackendChoice;
use vertebra_store::{Error, MAX_COORDINATE, MAX_TIME_STEP, check_finite};

/// The most position sweeps (`substeps * iterations`) one step may take.
/// A sweep of the 30-ragdoll drop takes about 66 us on one core, so a step
/// at the bound takes under a second there (and about 6 s for 300
/// ragdolls): bounded, where `u32::MAX` iterations never returned. It is
/// 500 times the paper's 20 and leaves room for both styles: many
/// iterations (100 x 100) or many substeps of one iteration each
/// (Macklin et al.'s "small steps": 10,000 x 1).
pub const MAX_SOLVER_SWEEPS: u32 = 10_000;

/// The most worker threads a world starts: rayon starts every worker up
/// front, and more workers than cores only contend; 256 is above the core
/// count of any machine a game runs on.
pub const MAX_THREADS: usize = 256;

/// The highest `max_linear_speed` (m/s) a world accepts: in one step of at
/// most [`MAX_TIME_STEP`] a body then moves at most [`MAX_COORDINATE`], so
/// a body in range ends a step within twice the range, and positions stay
/// 32 orders of magnitude below `f32` overflow for any game's lifetime
/// (with `f32::MAX` bodies would reach 3e38 m).
pub const MAX_LINEAR_SPEED_LIMIT: f32 = MAX_COORDINATE / MAX_TIME_STEP;

/// The highest `max_angular_speed` (rad/s) a world accepts: `|w|^2` (1e12)
/// is far from overflow, and so is the gyroscopic term `w x (I w)` for any
/// inertia whose inverse exists in `f32` (below about 7e12 kg m^2 per
/// axis). A substep of the shortest length (1e-6 s) turns a body by at
/// most 1 rad.
pub const MAX_ANGULAR_SPEED_LIMIT: f32 = 1.0e6;

/// How each position iteration solves the joints' equality parts (the
/// points of sockets, hinges and fixed joints, the hinge's axis, the fixed
/// joint's lock, the rod's curve and length).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum JointSolver {
    /// Each joint on its own, colour by colour (Gauss-Seidel over the
    /// joints, as the paper and most engines do): cheap per iteration,
    /// slow to converge through long chains and across large mass ratios.
    /// The paper's.
    Iterative,
    /// Every joint of a tree of bodies at once, exactly for the
    /// linearised rows (`docs/direct.md`): after each iteration the
    /// linearised joint error is zero up to round-off, whatever the
    /// chain's length or mass ratios; limits held as one-sided rows of
    /// the same solve. Drives and the rod's soft bend and twist stay
    /// iterative; a joint that closes a loop stays iterative whole. The
    /// default.
    #[default]
    Direct,
}

/// Which trees' contacts with static and kinematic bodies are pins:
/// solved in the tree's own direct solve (`docs/direct.md`, "Contacts in
/// the solve: pins"), so that a light body under a heavy one (a foot
/// under a ragdoll) holds and rubs with its whole tree's mass, where an
/// iterated contact keeps its own share of each push (a standing
/// ragdoll's 1 kg feet sink and slide, and it falls). Needs
/// [`JointSolver::Direct`] (with iterated joints there are no trees).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PinContacts {
    /// No contact is a pin. The default, and the paper's.
    #[default]
    Never,
    /// The contacts of a tree with a drive are pins: one of its joints has
    /// an angular drive, or one of its bodies a world-space or upright
    /// drive (a powered ragdoll standing, walking, getting up). A limp
    /// tree's stay iterated: in a pile of ragdolls pins push joints past
    /// their limits for frames as they land (up to 18 degrees in the
    /// 30-ragdoll drops, against 2 with iterated contacts; `docs/direct.md`,
    /// "Pins in a pile, and a limp ragdoll lying on them"). Decided at
    /// each step from the drives set, so a ragdoll faded limp leaves its
    /// pins as its last drive goes, and that step is a pop: the feet its
    /// pins held give way under iterated contacts (the standing anatomical
    /// humanoid drops 2.3 mm in that frame, its feet 1.5 mm into the
    /// ground; `docs/direct.md`, "Which trees take pins"), which keeps
    /// this from being the default. An uncapped angular drive of a
    /// pinned tree is a spring on its own pair's inertia (a hard row would
    /// overrule the pins' springs), weaker under a load than a capped one:
    /// give a pinned tree's drives torque caps (`docs/direct.md`, "Drives
    /// are rows of the solve").
    Driven,
    /// Every tree's contacts are pins, driven or not.
    Always,
}

/// How the world steps. Games use a fixed iteration count; so does the
/// paper (20 iterations, 1 substep).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverConfig {
    /// Substeps per step (>= 1): each integrates `dt / substeps`. With
    /// `iterations`, at most [`MAX_SOLVER_SWEEPS`] sweeps a step.
    pub substeps: u32,
    /// Position iterations per substep (>= 1). With `substeps`, at most
    /// [`MAX_SOLVER_SWEEPS`] sweeps a step.
    pub iterations: u32,
    /// Instruction set for the kernels.
    pub backend: BackendChoice,
    /// Worker threads (1 to [`MAX_THREADS`]) of the rayon pool
    /// ([`RayonTasks`](crate::RayonTasks)) that [`World::new`](crate::World::new)
    /// starts; 1 solves on the calling thread
    /// ([`SingleThreaded`](crate::SingleThreaded)).
    /// [`World::set_tasks`](crate::World::set_tasks) puts the engine's job
    /// system in their place. Results do not depend on it.
    pub threads: usize,
    /// Gravity (m/s^2, world).
    pub gravity: Vec3,
    /// A colour is split into chunks for the workers when it has at
    /// least this many blocks of eight constraints (a smaller one is one
    /// chunk per joint kind: its kinds may still run on different
    /// workers).
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
    /// After each substep's velocity pass, the touching contacts take back
    /// the separating speed their own push-out gave (each at most its
    /// substep's normal impulse, `lambda_n / h`; a few passes, so the
    /// contacts of one body share it): a body pressed into another by a
    /// joint, a limit or a drive and pushed back out does not fly off, and
    /// piles come to rest. Box2D v3's relax stage, and Müller et al.'s
    /// velocity update where it sets the normal velocity rather than
    /// raising it (`crates/vertebra-kernels/src/contact.rs`, "Relax").
    /// Off, push-out becomes speed (`depth / h`), as in the paper's scenes.
    pub relax_contacts: bool,
    /// Bodies never move faster than this (m/s): velocities are clamped
    /// before each substep moves them (Jolt clamps at 500 m/s too). At most
    /// [`MAX_LINEAR_SPEED_LIMIT`].
    pub max_linear_speed: f32,
    /// Bodies never spin faster than this (rad/s): 50 turns a second by
    /// default, at most [`MAX_ANGULAR_SPEED_LIMIT`].
    pub max_angular_speed: f32,
    /// Measure every joint's and rod's residual error at the end of each
    /// step, from the step's own solved poses ([`World::residuals`]). Off by
    /// default: the measurement is a pass over every constraint, about a
    /// tenth of the reference ragdoll's step at 4 iterations
    /// (`docs/performance.md`), which a game that does not plot the paper's
    /// figure 8 need not pay; any world measures its current poses on
    /// demand with [`World::measure_residuals`]. The scenes turn it on
    /// (their figures are these residuals).
    ///
    /// [`World::residuals`]: crate::World::residuals
    /// [`World::measure_residuals`]: crate::World::measure_residuals
    pub measure_residuals: bool,
    /// When islands fall asleep (`islands.rs`: still bodies stop costing
    /// anything until something wakes them); `None`: never. On by default,
    /// as in Box2D, Jolt and Rapier. The paper's scenes turn it off (their
    /// figures measure every joint at every step).
    pub sleep: Option<SleepSettings>,
    /// How the joints' equality parts are solved ([`JointSolver`]).
    pub joints: JointSolver,
    /// Which trees' contacts with static and kinematic bodies are solved
    /// in their direct joint solve ([`PinContacts`]): none by default; a
    /// powered ragdoll that stands needs `Driven` (or `Always`).
    pub pin_contacts: PinContacts,
}

/// The default: the direct joint solve at 1 substep of 8 iterations, with
/// the contacts relaxed, no contact pinned. In the 30-ragdoll drop it
/// holds joints about 17,000 times tighter than the paper's iterated
/// 1 x 20 at 0.95x (rod spines) to 1.02x (sockets) its frame
/// (`docs/direct.md`, "The default"); 8 iterations are what the contacts
/// need (fewer let fast bodies through the ground and leave resting ones
/// deeper in it; at 8 a pile of ragdolls rests 2 to 5 mm deep, at the
/// paper's 20 about 1 mm). [`SolverConfig::paper`] is the paper's solver.
impl Default for SolverConfig {
    fn default() -> Self {
        Self {
            iterations: 8,
            joints: JointSolver::Direct,
            relax_contacts: true,
            ..Self::paper()
        }
    }
}

impl SolverConfig {
    /// The paper's solver: every joint iterated (Gauss-Seidel), 1 substep
    /// of 20 iterations, contacts not relaxed; everything else as the
    /// default (sleeping on). The paper's scenes run it, and its figures
    /// are measured with it.
    pub fn paper() -> Self {
        Self {
            substeps: 1,
            iterations: 20,
            backend: BackendChoice::Auto,
            threads: 1,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            parallel_min_blocks: 4,
            max_push_out_speed: f32::INFINITY,
            relax_contacts: false,
            max_linear_speed: 500.0,
            max_angular_speed: 100.0 * core::f32::consts::PI,
            measure_residuals: false,
            sleep: Some(SleepSettings::default()),
            joints: JointSolver::Iterative,
            pin_contacts: PinContacts::Never,
        }
    }

    /// Checks every field.
    pub fn validate(&self) -> Result<(), Error> {
        if self.substeps == 0 {
            return Err(Error::InvalidConfig("substeps must be at least 1"));
        }
        if self.iterations == 0 {
            return Err(Error::InvalidConfig("iterations must be at least 1"));
        }
        if u64::from(self.substeps) * u64::from(self.iterations) > u64::from(MAX_SOLVER_SWEEPS) {
            return Err(Error::InvalidConfig(
                "substeps x iterations must be at most 10000",
            ));
        }
        if self.threads == 0 {
            return Err(Error::InvalidConfig("threads must be at least 1"));
        }
        if self.threads > MAX_THREADS {
            return Err(Error::InvalidConfig("threads must be at most 256"));
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
        for (speed, ceiling, what) in [
            (
                self.max_linear_speed,
                MAX_LINEAR_SPEED_LIMIT,
                "max_linear_speed must be positive and at most 1e6 m/s",
            ),
            (
                self.max_angular_speed,
                MAX_ANGULAR_SPEED_LIMIT,
                "max_angular_speed must be positive and at most 1e6 rad/s",
            ),
        ] {
            if !(speed > 0.0 && speed <= ceiling) {
                return Err(Error::InvalidConfig(what));
            }
        }
        if let Some(sleep) = &self.sleep {
            sleep.validate()?;
        }
        // `Driven` with iterated joints pins nothing (there are no trees),
        // as its doc says, and is accepted.
        if self.pin_contacts == PinContacts::Always && self.joints != JointSolver::Direct {
            return Err(Error::InvalidConfig(
                "pin_contacts Always needs the direct joint solve (joints: Direct)",
            ));
        }
        check_finite("gravity", self.gravity)
    }
}

/// When bodies fall asleep ([`SolverConfig::sleep`](crate::SolverConfig::sleep)):
/// a body is still while the mean speed of its mass over each window of
/// `time` stays below `speed`, and an island sleeps when all its bodies
/// have been still for `time`. Defaults as Box2D's (0.05 m/s, 0.5 s).
///
/// The speed is of the body's mass, not of its centre: how far its points
/// have moved from where the window began, as the root mean square over
/// its mass (`sqrt(|dx|^2 + v^T (I / m) v)`, `dx` the centre's move, `v`
/// twice the vector part of the turn, `I` the body-frame inertia, `m` the
/// mass; exact for any turn). So a turn counts by how far it carries the
/// body's mass: a limb twisting by 2 degrees about its own axis moves its
/// surface a millimetre and is still, a limb swinging by the same angle
/// moves its far end a centimetre (as Jolt tests points on the body, and
/// Box2D its extent times its angular speed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SleepSettings {
    /// The mean speed of a still body's mass stays below this (m/s, at
    /// least 0).
    pub speed: f32,
    /// An island sleeps once every body in it has been still this long (s,
    /// positive, at most 1e6).
    pub time: f32,
}

impl Default for SleepSettings {
    fn default() -> Self {
        Self {
            speed: 0.05,
            time: 0.5,
        }
    }
}

impl SleepSettings {
    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), Error> {
        if !(self.speed.is_finite() && self.speed >= 0.0) {
            return Err(Error::InvalidConfig(
                "sleep.speed must be finite and at least 0",
            ));
        }
        if !(self.time > 0.0 && self.time <= 1.0e6) {
            return Err(Error::InvalidConfig(
                "sleep.time must be positive and at most 1e6 s",
            ));
        }
        Ok(())
    }
}
