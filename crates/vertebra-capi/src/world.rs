//! The world: its settings, creation and destruction, the step, and what
//! it measures.

use std::sync::Arc;

use vertebra_math::Backend;
use vertebra_world::{
    BackendChoice, JointSolver, PinContacts, SleepSettings, SolverConfig, TaskSystem, World,
};

use crate::error::{Failure, VtResult};
use crate::ffi::{Object, call, enter, free, out, read};
use crate::tasks::{CTasks, VtTaskSystem};
use crate::types::{VtVec3, flag, pick};

/// Which instruction set the kernels use.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtBackend {
    /// The best this CPU has.
    Auto = 0,
    /// One lane, the reference.
    Scalar = 1,
    /// Four lanes of portable SIMD.
    Portable = 2,
    /// Four lanes of SSE4.1.
    Sse41 = 3,
    /// Four lanes of AVX2.
    Avx2x4 = 4,
    /// Eight lanes of AVX2.
    Avx2 = 5,
    /// Four lanes of AArch64 NEON.
    Neon = 6,
    /// Four lanes of WebAssembly SIMD128.
    Simd128 = 7,
}

/// How the joints' equality parts are solved.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtJointSolver {
    /// Each joint on its own, iterated (the paper's solver).
    Iterative = 0,
    /// Every tree of joints at once, each iteration (`docs/direct.md`).
    Direct = 1,
}

/// Which trees' contacts with static and kinematic bodies are solved in
/// their direct joint solve (`PinContacts` in Rust).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtPinContacts {
    /// None (the default, and the paper's).
    Never = 0,
    /// Every tree's (needs the direct joint solve).
    Always = 1,
    /// A tree's with a joint drive or a body's world-space or upright
    /// drive (a powered ragdoll standing on 1 kg feet needs it).
    Driven = 2,
}

/// The values of `VtPinContacts`, in order.
const PIN_CONTACTS: [PinContacts; 3] =
    [PinContacts::Never, PinContacts::Always, PinContacts::Driven];

/// The solver's settings (`SolverConfig` in Rust; its docs give each
/// field's range). `vt_solver_config_default` fills the defaults.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct VtSolverConfig {
    /// Substeps per step (>= 1).
    pub substeps: u32,
    /// Position iterations per substep (>= 1).
    pub iterations: u32,
    /// A `VtBackend`.
    pub backend: u32,
    /// A `VtJointSolver`.
    pub joints: u32,
    /// Worker threads of vertebra's own pool (1: the calling thread);
    /// `vt_world_set_tasks` puts the engine's job system in its place.
    pub threads: u32,
    /// Gravity (m/s^2, world).
    pub gravity: VtVec3,
    /// A colour is split into chunks for the workers from this many blocks
    /// of eight constraints.
    pub parallel_min_blocks: u32,
    /// The fastest overlapping bodies are pushed apart (m/s; infinity: off).
    pub max_push_out_speed: f32,
    /// Bodies never move faster (m/s).
    pub max_linear_speed: f32,
    /// Bodies never spin faster (rad/s).
    pub max_angular_speed: f32,
    /// Non-zero: measure every joint's residual at the end of each step.
    pub measure_residuals: u32,
    /// Non-zero: still islands fall asleep.
    pub sleep: u32,
    /// With `sleep`: the mean speed (m/s) under which an island is still.
    pub sleep_speed: f32,
    /// With `sleep`: how long (s) an island is still before it sleeps.
    pub sleep_time: f32,
    /// Non-zero: a touching contact takes back the separating speed its
    /// own push-out gave (`SolverConfig::relax_contacts`).
    pub relax_contacts: u32,
    /// A `VtPinContacts`: which trees' contacts with static or kinematic
    /// bodies are solved in their direct joint solve
    /// (`SolverConfig::pin_contacts`).
    pub pin_contacts: u32,
}

/// A world's residual joint error: the paper's figure 8 measure.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct VtResiduals {
    /// Summed anchor separation over joints and rods (cm).
    pub eps_lin_cm: f32,
    /// Summed limit overshoot (rad).
    pub eps_ang_rad: f32,
}

/// Bodies, joints, rods and contacts, and the solver that steps them
/// (opaque; `vt_world_create`, `vt_world_destroy`).
pub struct VtWorld {
    pub(crate) world: World,
    poisoned: bool,
}

impl Object for VtWorld {
    const NAME: &'static str = "world";
    fn poisoned(&mut self) -> &mut bool {
        &mut self.poisoned
    }
}

/// Runs `body` on the world at `world` inside [`call`].
///
/// # Safety
/// `world` is null or a live world used by no other call at once.
pub(crate) unsafe fn with_world(
    world: *mut VtWorld,
    body: impl FnOnce(&mut World) -> Result<(), Failure>,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let mut world = unsafe { enter(world) }?;
        body(&mut world.world)
    })
}

const BACKENDS: [Option<Backend>; 8] = [
    None,
    Some(Backend::Scalar),
    Some(Backend::Portable),
    Some(Backend::Sse41),
    Some(Backend::Avx2x4),
    Some(Backend::Avx2),
    Some(Backend::Neon),
    Some(Backend::Simd128),
];

impl From<&SolverConfig> for VtSolverConfig {
    fn from(c: &SolverConfig) -> Self {
        let backend = match c.backend {
            BackendChoice::Auto => 0,
            BackendChoice::Forced(b) => BACKENDS.iter().position(|x| *x == Some(b)).unwrap_or(0),
        };
        let sleep = c.sleep.unwrap_or_default();
        Self {
            substeps: c.substeps,
            iterations: c.iterations,
            backend: backend as u32,
            joints: match c.joints {
                JointSolver::Iterative => 0,
                JointSolver::Direct => 1,
            },
            threads: c.threads.min(u32::MAX as usize) as u32,
            gravity: c.gravity.into(),
            parallel_min_blocks: c.parallel_min_blocks.min(u32::MAX as usize) as u32,
            max_push_out_speed: c.max_push_out_speed,
            max_linear_speed: c.max_linear_speed,
            max_angular_speed: c.max_angular_speed,
            measure_residuals: u32::from(c.measure_residuals),
            sleep: u32::from(c.sleep.is_some()),
            sleep_speed: sleep.speed,
            sleep_time: sleep.time,
            relax_contacts: u32::from(c.relax_contacts),
            pin_contacts: match c.pin_contacts {
                PinContacts::Never => VtPinContacts::Never as u32,
                PinContacts::Always => VtPinContacts::Always as u32,
                PinContacts::Driven => VtPinContacts::Driven as u32,
            },
        }
    }
}

impl TryFrom<&VtSolverConfig> for SolverConfig {
    type Error = Failure;
    fn try_from(c: &VtSolverConfig) -> Result<Self, Failure> {
        let backend = match pick(c.backend, "config.backend", &BACKENDS)? {
            None => BackendChoice::Auto,
            Some(b) => BackendChoice::Forced(b),
        };
        let joints = pick(
            c.joints,
            "config.joints",
            &[JointSolver::Iterative, JointSolver::Direct],
        )?;
        let sleep = flag(c.sleep).then_some(SleepSettings {
            speed: c.sleep_speed,
            time: c.sleep_time,
        });
        Ok(SolverConfig {
            substeps: c.substeps,
            iterations: c.iterations,
            backend,
            threads: c.threads as usize,
            gravity: c.gravity.into(),
            parallel_min_blocks: c.parallel_min_blocks as usize,
            max_push_out_speed: c.max_push_out_speed,
            relax_contacts: flag(c.relax_contacts),
            max_linear_speed: c.max_linear_speed,
            max_angular_speed: c.max_angular_speed,
            measure_residuals: flag(c.measure_residuals),
            sleep,
            joints,
            pin_contacts: pick(c.pin_contacts, "config.pin_contacts", &PIN_CONTACTS)?,
        })
    }
}

/// Writes the default settings (the direct joint solve at 1 substep of 8
/// iterations, contacts relaxed, the best backend, one thread, gravity
/// -9.81 m/s^2 along y, sleeping on) into `config`.
///
/// # Safety
/// `config` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_solver_config_default(config: *mut VtSolverConfig) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        unsafe { out(config, "config") }?.set((&SolverConfig::default()).into());
        Ok(())
    })
}

/// Writes the paper's settings (every joint iterated, 1 substep of 20
/// iterations, contacts not relaxed; the rest as the default) into
/// `config`.
///
/// # Safety
/// `config` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_solver_config_paper(config: *mut VtSolverConfig) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        unsafe { out(config, "config") }?.set((&SolverConfig::paper()).into());
        Ok(())
    })
}

/// Makes an empty world with `config` (null: the defaults) and writes it
/// to `world`. The caller owns it: free it with `vt_world_destroy`.
/// Refused for settings out of range or a forced backend this CPU lacks.
///
/// # Safety
/// `config` is null or readable; `world` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_create(
    config: *const VtSolverConfig,
    world: *mut *mut VtWorld,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let world = unsafe { out(world, "world") }?;
        let config = match config.is_null() {
            true => SolverConfig::default(),
            // SAFETY: the function's contract.
            false => (&unsafe { read(config, "config") }?).try_into()?,
        };
        let made = World::new(config)?;
        world.set(crate::ffi::boxed(VtWorld {
            world: made,
            poisoned: false,
        }));
        Ok(())
    })
}

/// Frees a world made by `vt_world_create` (null does nothing). Ragdolls
/// and collision layers built on it are separate objects: destroy them as
/// well; they must not be used with another world afterwards.
///
/// # Safety
/// `world` is null or a world not yet destroyed, used by no other call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_destroy(world: *mut VtWorld) {
    // SAFETY: the function's contract.
    unsafe { free(world) }
}

/// Writes the world's settings into `config`.
///
/// # Safety
/// `world` is a live world; `config` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_config(
    world: *mut VtWorld,
    config: *mut VtSolverConfig,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (world, config) = unsafe { (enter(world)?, out(config, "config")?) };
        config.set(world.world.config().into());
        Ok(())
    })
}

/// Advances the world by `dt` seconds (in [1e-6, 1] s): the contacts set
/// for this step, then every substep's solve. Refused, with nothing moved,
/// for a `dt` out of range.
///
/// # Safety
/// `world` is a live world.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_step(world: *mut VtWorld, dt: f32) -> VtResult {
    // SAFETY: the function's contract.
    unsafe { with_world(world, |w| Ok(w.step(dt)?)) }
}

/// Writes a hash of every body's state (poses and velocities, bit for bit)
/// into `hash`: equal hashes, equal worlds.
///
/// # Safety
/// `world` is a live world; `hash` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_state_hash(world: *mut VtWorld, hash: *mut u64) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (world, hash) = unsafe { (enter(world)?, out(hash, "hash")?) };
        hash.set(world.world.state_hash());
        Ok(())
    })
}

/// Measures the joints' and rods' residual error at the current poses.
///
/// # Safety
/// `world` is a live world; `residuals` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_measure_residuals(
    world: *mut VtWorld,
    residuals: *mut VtResiduals,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (mut world, residuals) = unsafe { (enter(world)?, out(residuals, "residuals")?) };
        let r = world.world.measure_residuals();
        residuals.set(VtResiduals {
            eps_lin_cm: r.eps_lin_cm,
            eps_ang_rad: r.eps_ang_rad,
        });
        Ok(())
    })
}

/// Runs the world's parallel work on the engine's job system from the
/// next step on (results do not change, bit for bit). vertebra keeps a
/// copy of `tasks`; its `context` must stay valid, and its `parallel_for`
/// callable from the stepping thread, until the world is destroyed or
/// given other tasks.
///
/// # Safety
/// `world` is a live world; `tasks` is readable and follows
/// `VtTaskSystem`'s contract.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn vt_world_set_tasks(
    world: *mut VtWorld,
    tasks: *const VtTaskSystem,
) -> VtResult {
    call(|| {
        // SAFETY: the function's contract.
        let (mut world, tasks) = unsafe { (enter(world)?, read(tasks, "tasks")?) };
        let tasks: Arc<dyn TaskSystem> = Arc::new(CTasks::new(tasks)?);
        world.world.set_tasks(tasks);
        Ok(())
    })
}
