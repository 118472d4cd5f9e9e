//! The vertebra world: bodies and joints, stepped by the coloured XPBD
//! solver at a fixed iteration count, with a hash of the full state and
//! residual metrics (on demand, or after every step when asked for).
//!
//! ```
//! use glam::{Quat, Vec3};
//! use vertebra_world::{BodyDesc, Shape, JointDesc, SolverConfig, World};
//!
//! let mut world = World::new(SolverConfig::default())?;
//! let ground = world.add_body(BodyDesc::fixed())?;
//! let shape = Shape::capsule(Vec3::new(0.0, -0.2, 0.0), Vec3::new(0.0, 0.2, 0.0), 0.05);
//! let bob = world.add_body(
//!     BodyDesc::dynamic(shape.mass_properties_with_mass(2.0)?).with_position(Vec3::new(0.0, -0.25, 0.0)),
//! )?;
//! let joint = JointDesc::socket_at_world_anchor(world.bodies(), ground, bob, Vec3::ZERO, -Vec3::Y)?
//!     .with_swing_limit(0.5);
//! world.add_joint(joint)?;
//! for _ in 0..60 {
//!     world.step(1.0 / 60.0)?;
//! }
//! assert!(world.measure_residuals().eps_lin_cm < 0.01);
//! # Ok::<(), vertebra_world::Error>(())
//! ```

mod bins;
mod body_drive;
mod checks;
mod config;
mod contact;
mod contact_layout;
mod drive;
mod forces;
mod impulse;
mod integrate;
mod islands;
mod joint;
mod joint_wire;
mod kinds;
mod kinematic;
mod layout;
mod lend;
mod metrics;
mod parallel;
mod passes;
mod pin_choice;
mod rod;
mod rollback;
mod sleep;
mod snapshot;
mod spring;
mod stages;
mod start;
mod step;
mod substep;
mod tasks;
mod trees;

use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::Arc;

use glam::{Quat, Vec3};
use vertebra_math::{Backend, DefaultFloatMode};
use vertebra_scheduler::Colouring;
use vertebra_store::Slots;

pub use body_drive::{UprightDrive, WorldDrive};
pub use config::{
    JointSolver, MAX_ANGULAR_SPEED_LIMIT, MAX_LINEAR_SPEED_LIMIT, MAX_SOLVER_SWEEPS, MAX_THREADS,
    PinContacts, SleepSettings, SolverConfig,
};
pub use contact::Contact;
pub use drive::AngularDrive;
pub use forces::{BrokenJoint, JointForce};
pub use joint::{
    JointBreaking, JointDesc, JointHandle, JointKind, LimitSoftness, Swing, SwingTwist,
};
pub use lend::{TaskLoan, lend};
pub use metrics::{JointResidual, Residuals};
pub use rod::{MAX_ROD_LENGTH, RodDesc, RodHandle, RodStiffness, arc_tangent, rod_twist};
pub use snapshot::{Snapshot, Timeline};
pub use spring::{
    MAX_DRIVE_DAMPING_RATIO, MAX_DRIVE_DAMPING_TIME, MIN_DRIVE_FREQUENCY, Spring, SpringField,
};
#[cfg(feature = "stage-timing")]
pub use stages::timing as stage_timing;
pub use tasks::{RayonTasks, SingleThreaded, TaskSystem};
pub use vertebra_kernels::contact::ContactImpulse;
pub use vertebra_kernels::direct::MAX_LIMIT_RETURN_SPEED;
pub use vertebra_math::BackendChoice;
pub use vertebra_store::{
    BodyDesc, BodyHandle, BodyKind, BodyState, BodyStore, Error, MASS_RANGE, MAX_COORDINATE,
    MAX_TIME_STEP, MIN_TIME_STEP, MassProperties, SIZE_RANGE, Shape,
};

/// Bodies, joints and the solver that steps them.
///
/// Every call that computes (adding bodies and joints, setting poses,
/// forces, impulses, rods, drives and contacts, restoring, stepping) does so in the
/// default floating-point mode, whatever mode (FTZ, DAZ, rounding) the
/// caller's thread runs in, and gives the caller its mode back: equal calls
/// give equal worlds on every host ([`vertebra_math::float_mode`]).
pub struct World {
    config: SolverConfig,
    backend: Backend,
    tasks: Arc<dyn TaskSystem>,
    bodies: BodyStore,
    joints_at: Vec<u32>,
    joint_slots: Slots,
    joints: Vec<Option<joint::JointDesc>>,
    rod_slots: Slots,
    rods: Vec<Option<RodDesc>>,
    /// The bodies' drives by slot, no longer than the last driven body's
    /// slot (`body_drive.rs`).
    body_drives: Vec<body_drive::BodyDrives>,
    /// Scratch of the step: which trees' contacts are pins
    /// (`pin_choice.rs`).
    pinned_trees: Vec<bool>,
    colouring: Colouring,
    islands: islands::Islands,
    /// Scratch of the step: this step's solve bins (`bins.rs`).
    bins: bins::Bins,
    layout: layout::Layout,
    layout_dirty: bool,
    contacts: Vec<Contact>,
    /// The contacts the last step solved (no part of the state: the
    /// step's output, with `impulses`).
    solved: Vec<Contact>,
    /// The impulse each of `solved` applied.
    impulses: Vec<ContactImpulse>,
    /// Steps taken since the world was made (no part of the state).
    step_count: u64,
    /// Each joint slot's force and torque over the last step it was
    /// solved in (`forces.rs`; output, not state).
    joint_forces: Vec<JointForce>,
    /// The joints the last step broke (output, not state).
    broken: Vec<BrokenJoint>,
    /// Counts every call that may have moved a body or changed which
    /// bodies there are (no part of the state).
    pose_version: u64,
    contact_layout: contact_layout::ContactLayout,
    rows: parallel::Scratch,
    previous: Vec<(Vec3, Quat)>,
    /// Scratch of the step: which slots the body passes move (live, not
    /// static, not asleep).
    moving: Vec<bool>,
    /// Scratch of the step: the counters of a substep's stages.
    stages: stages::Stages,
    residuals: Residuals,
    /// `residuals` holds the current poses' measurement (false after a step
    /// that did not measure).
    residuals_measured: bool,
    residual_lanes: metrics::LaneResiduals,
    /// Bodies put back by the step's last-line NaN guard, ever.
    repaired: u64,
    /// The run of states the world is on (no part of its state).
    timeline: snapshot::Timeline,
    /// What a step that unwinds puts back (`rollback.rs`).
    rollback: rollback::Rollback,
}

impl World {
    /// An empty world; `Err` for an invalid config or a forced backend this
    /// CPU lacks.
    pub fn new(config: SolverConfig) -> Result<Self, Error> {
        config.validate()?;
        let backend = config
            .backend
            .resolve()
            .map_err(|_| Error::InvalidConfig("the forced backend is not supported by this CPU"))?;
        let tasks: Arc<dyn TaskSystem> = if config.threads > 1 {
            Arc::new(
                RayonTasks::new(config.threads)
                    .ok_or(Error::InvalidConfig("could not start the worker threads"))?,
            )
        } else {
            Arc::new(SingleThreaded)
        };
        let lineage = snapshot::new_lineage();
        Ok(Self {
            config,
            backend,
            tasks,
            bodies: BodyStore::with_lineage(lineage),
            joints_at: Vec::new(),
            joint_slots: Slots::new(lineage),
            joints: Vec::new(),
            rod_slots: Slots::new(lineage),
            rods: Vec::new(),
            body_drives: Vec::new(),
            pinned_trees: Vec::new(),
            colouring: Colouring::new(),
            islands: islands::Islands::default(),
            bins: bins::Bins::default(),
            layout: layout::Layout::default(),
            layout_dirty: false,
            contacts: Vec::new(),
            solved: Vec::new(),
            impulses: Vec::new(),
            step_count: 0,
            joint_forces: Vec::new(),
            broken: Vec::new(),
            pose_version: 0,
            contact_layout: contact_layout::ContactLayout::default(),
            rows: parallel::Scratch::default(),
            previous: Vec::new(),
            moving: Vec::new(),
            stages: stages::Stages::default(),
            residuals: Residuals::default(),
            residuals_measured: false,
            residual_lanes: metrics::LaneResiduals::default(),
            repaired: 0,
            timeline: snapshot::Timeline::begin(false),
            rollback: rollback::Rollback::default(),
        })
    }

    /// The settings this world steps with.
    pub fn config(&self) -> &SolverConfig {
        &self.config
    }

    /// Runs the world's parallel work on `tasks`, the engine's job system,
    /// from the next step on (in place of the pool of
    /// [`SolverConfig::threads`] workers, or the calling thread, that
    /// [`World::new`] starts). Results do not change, bit for bit, whatever
    /// `tasks` is and does (`tasks.rs`).
    pub fn set_tasks(&mut self, tasks: Arc<dyn TaskSystem>) {
        self.tasks = tasks;
    }

    /// The task system the world runs its parallel work on.
    pub fn tasks(&self) -> &Arc<dyn TaskSystem> {
        &self.tasks
    }

    /// The backend the kernels run on.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// Read access to every body's state (structure of arrays).
    pub fn bodies(&self) -> &BodyStore {
        &self.bodies
    }

    /// Adds a body; `Err` (and no change) for invalid input.
    pub fn add_body(&mut self, desc: BodyDesc) -> Result<BodyHandle, Error> {
        let _mode = DefaultFloatMode::enter();
        let handle = self.bodies.insert(&desc)?;
        self.pose_version += 1;
        if self.joints_at.len() < self.bodies.capacity() {
            self.joints_at.resize(self.bodies.capacity(), 0);
        }
        self.joints_at[handle.index()] = 0;
        let i = handle.index();
        self.islands
            .add_body(i, self.bodies.kind[i], self.bodies.capacity());
        Ok(handle)
    }

    /// Removes a body that no joint uses, with the contacts set for the
    /// next step that name it (nothing acts on a removed body, nor on a new
    /// body that reuses its slot). A collision layer's colliders on it are
    /// the layer's to remove (`Collisions::remove_body`).
    pub fn remove_body(&mut self, handle: BodyHandle) -> Result<(), Error> {
        let i = self.bodies.index(handle)?;
        if self.joints_at[i] > 0 {
            return Err(Error::BodyInUse);
        }
        self.layout_dirty |= self.islands.take_out(i);
        self.bodies.remove(handle)?;
        self.clear_body_drives(i);
        self.pose_version += 1;
        self.contacts
            .retain(|c| c.body_a != handle && c.body_b != handle);
        Ok(())
    }

    /// A body's position, orientation and velocities.
    pub fn body(&self, handle: BodyHandle) -> Result<BodyState, Error> {
        self.bodies.state(handle)
    }

    /// Teleports a body (centre of mass, m, world; unit orientation).
    pub fn set_body_pose(
        &mut self,
        handle: BodyHandle,
        position: Vec3,
        orientation: Quat,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        self.bodies.set_pose(handle, position, orientation)?;
        self.pose_version += 1;
        self.wake_islands_of(handle);
        Ok(())
    }

    /// Sets a body's velocities (m/s, rad/s, world).
    pub fn set_body_velocity(
        &mut self,
        handle: BodyHandle,
        linear: Vec3,
        angular: Vec3,
    ) -> Result<(), Error> {
        self.bodies.set_velocity(handle, linear, angular)?;
        self.wake_islands_of(handle);
        Ok(())
    }

    /// Adds a force (N, world) through the centre of mass, for the next step.
    pub fn add_force(&mut self, handle: BodyHandle, force: Vec3) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        self.bodies.add_force(handle, force)?;
        self.wake_islands_of(handle);
        Ok(())
    }

    /// Adds a force (N, world) at a world point (m), for the next step.
    pub fn add_force_at(
        &mut self,
        handle: BodyHandle,
        force: Vec3,
        point: Vec3,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        self.bodies.add_force_at(handle, force, point)?;
        self.wake_islands_of(handle);
        Ok(())
    }

    /// Adds a torque (N m, world), for the next step.
    pub fn add_torque(&mut self, handle: BodyHandle, torque: Vec3) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        self.bodies.add_torque(handle, torque)?;
        self.wake_islands_of(handle);
        Ok(())
    }

    /// Applies a linear impulse (N s, world) through a dynamic body's
    /// centre of mass: its velocity changes by `impulse / mass` now, not
    /// at the next step (Jolt's `AddImpulse`, Rapier's `apply_impulse`), and
    /// is held to `max_linear_speed`. For a hit, a jump, an explosion: a
    /// force `F` held for one step of `dt` is the impulse `F dt`, spread
    /// over the step. Refused, with nothing changed: a static or kinematic
    /// body (`NotDynamic`: infinite mass; set a kinematic body's velocity
    /// instead), a non-finite impulse, one whose velocity change overflows
    /// `f32`.
    pub fn apply_impulse(&mut self, handle: BodyHandle, impulse: Vec3) -> Result<(), Error> {
        self.apply_impulses(handle, impulse, Vec3::ZERO)
    }

    /// Applies a linear impulse (N s, world) at a world point (m, within
    /// twice [`MAX_COORDINATE`] on every axis, as [`World::add_force_at`]
    /// takes): the impulse through the centre of mass `x` and the angular
    /// impulse `(point - x) x impulse` about it, so the velocity changes
    /// by `impulse / mass` and the angular velocity by
    /// `I_w^-1 ((point - x) x impulse)` (`I_w^-1`: the world inverse
    /// inertia at the body's orientation), now; held to the speed limits.
    /// Refused as [`World::apply_impulse`], and for a point out of range.
    pub fn apply_impulse_at(
        &mut self,
        handle: BodyHandle,
        impulse: Vec3,
        point: Vec3,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        let moment = impulse::moment_at(&self.bodies, handle, impulse, point)?;
        self.apply_impulses(handle, impulse, moment)
    }

    /// Applies an angular impulse (N m s, world, about the centre of mass):
    /// the angular velocity changes by `I_w^-1 angular_impulse` (the world
    /// inverse inertia at the body's orientation) now, held to
    /// `max_angular_speed`. Refused as [`World::apply_impulse`].
    pub fn apply_angular_impulse(
        &mut self,
        handle: BodyHandle,
        angular_impulse: Vec3,
    ) -> Result<(), Error> {
        self.apply_impulses(handle, Vec3::ZERO, angular_impulse)
    }

    /// The one path of the three impulse calls (see `impulse.rs`).
    fn apply_impulses(
        &mut self,
        handle: BodyHandle,
        linear: Vec3,
        angular: Vec3,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        let limits = (self.config.max_linear_speed, self.config.max_angular_speed);
        impulse::apply(&mut self.bodies, handle, linear, angular, limits)?;
        self.wake_islands_of(handle);
        Ok(())
    }

    /// Adds a joint; `Err` (and no change) for invalid input.
    pub fn add_joint(&mut self, desc: JointDesc) -> Result<JointHandle, Error> {
        let _mode = DefaultFloatMode::enter();
        desc.validate_with(&self.bodies)?;
        let handle: JointHandle = self.joint_slots.insert();
        let slot = handle.index();
        if slot == self.joints.len() {
            self.joints.push(None);
        }
        self.joints[slot] = Some(desc);
        self.connect(slot as u64, desc.body_a, desc.body_b);
        Ok(handle)
    }

    /// Removes a joint.
    pub fn remove_joint(&mut self, handle: JointHandle) -> Result<(), Error> {
        self.joint_slots.check(handle, "joint")?;
        self.joint_slots.remove(handle);
        let desc = self.joints[handle.index()]
            .take()
            .expect("live joint has a description");
        self.colouring.remove(handle.index() as u64);
        self.joints_at[desc.body_a.index()] -= 1;
        self.joints_at[desc.body_b.index()] -= 1;
        self.islands
            .unlink(desc.body_a.index(), desc.body_b.index());
        self.layout_dirty = true;
        Ok(())
    }

    /// Adds a rod constraint; `Err` (and no change) for invalid input.
    pub fn add_rod(&mut self, desc: RodDesc) -> Result<RodHandle, Error> {
        let _mode = DefaultFloatMode::enter();
        desc.validate_with(&self.bodies)?;
        let handle: RodHandle = self.rod_slots.insert();
        let slot = handle.index();
        if slot == self.rods.len() {
            self.rods.push(None);
        }
        self.rods[slot] = Some(desc);
        self.connect(slot as u64 + layout::ROD_KEY, desc.body_a, desc.body_b);
        Ok(handle)
    }

    /// Removes a rod constraint.
    pub fn remove_rod(&mut self, handle: RodHandle) -> Result<(), Error> {
        self.rod_slots.check(handle, "rod")?;
        self.rod_slots.remove(handle);
        let desc = self.rods[handle.index()]
            .take()
            .expect("live rod has a description");
        self.disconnect(
            handle.index() as u64 + layout::ROD_KEY,
            desc.body_a,
            desc.body_b,
        );
        Ok(())
    }

    /// Changes a rod's rest shape, stiffness and limits in place (its bodies
    /// must stay the same, and may both be kinematic by now): how a powered
    /// ragdoll drives its spine. Other bodies (or the same two swapped:
    /// `body_a` is the rod's base) are refused with
    /// [`Error::InvalidJoint`], naming the rod's bodies: remove the rod and
    /// add one between the new bodies.
    pub fn set_rod(&mut self, handle: RodHandle, desc: RodDesc) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        let old = self.rod(handle)?;
        if (old.body_a, old.body_b) != (desc.body_a, desc.body_b) {
            return Err(Error::InvalidJoint(
                "rod bodies (body_a, body_b) cannot change; remove the rod and add one between the new bodies",
            ));
        }
        desc.validate()?;
        self.rods[handle.index()] = Some(desc);
        self.wake_islands_of(desc.body_a);
        self.wake_islands_of(desc.body_b);
        if !self.layout_dirty {
            self.layout.update_rod(handle.index(), &desc, &self.bodies);
        }
        Ok(())
    }

    /// A rod's description.
    pub fn rod(&self, handle: RodHandle) -> Result<RodDesc, Error> {
        self.rod_slots.check(handle, "rod")?;
        Ok(self.rods[handle.index()].expect("live rod has a description"))
    }

    /// Colours a new joint and counts it at its bodies.
    fn connect(&mut self, key: u64, a: BodyHandle, b: BodyHandle) {
        self.colouring
            .add(key, checks::dynamic_bodies(&self.bodies, a, b));
        self.joints_at[a.index()] += 1;
        self.joints_at[b.index()] += 1;
        self.islands.link(a.index(), b.index());
        self.layout_dirty = true;
    }

    /// The inverse of [`World::connect`].
    fn disconnect(&mut self, key: u64, a: BodyHandle, b: BodyHandle) {
        self.colouring.remove(key);
        self.joints_at[a.index()] -= 1;
        self.joints_at[b.index()] -= 1;
        self.islands.unlink(a.index(), b.index());
        self.layout_dirty = true;
    }

    /// Every live joint with its description, in slot order.
    pub fn joints(&self) -> impl Iterator<Item = (JointHandle, JointDesc)> + '_ {
        self.joints.iter().enumerate().filter_map(|(i, desc)| {
            let handle = self.joint_slots.handle_at(i)?;
            desc.map(|d| (handle, d))
        })
    }

    /// Every live rod with its description, in slot order.
    pub fn rods(&self) -> impl Iterator<Item = (RodHandle, RodDesc)> + '_ {
        self.rods.iter().enumerate().filter_map(|(i, desc)| {
            let handle = self.rod_slots.handle_at(i)?;
            desc.map(|d| (handle, d))
        })
    }

    /// A joint's description.
    pub fn joint(&self, handle: JointHandle) -> Result<JointDesc, Error> {
        self.joint_slots.check(handle, "joint")?;
        Ok(self.joints[handle.index()].expect("live joint has a description"))
    }

    /// Sets or clears a joint's drive. Changing a drive's settings is done
    /// in place; adding or removing one moves the joint to other blocks at
    /// the next step (no re-colouring).
    pub fn set_joint_drive(
        &mut self,
        handle: JointHandle,
        drive: Option<AngularDrive>,
    ) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        let mut desc = self.joint(handle)?;
        joint::validate_drive_for(&desc.kind, drive.as_ref())?;
        let regroup = desc.drive.is_some() != drive.is_some();
        desc.drive = drive;
        self.joints[handle.index()] = Some(desc);
        self.wake_islands_of(desc.body_a);
        self.wake_islands_of(desc.body_b);
        if regroup {
            // Driven and plain joints live in different blocks.
            self.layout_dirty = true;
        } else if !self.layout_dirty {
            self.layout
                .update_joint(handle.index(), &desc, &self.bodies);
        }
        Ok(())
    }

    /// How many colours the joints use (after the last step's layout).
    #[cfg(feature = "harness")]
    pub fn colour_count(&self) -> usize {
        self.layout.colour_count
    }

    /// How many joints are in the overflow set (solved one at a time by
    /// the scalar kernel because their bodies used every colour).
    #[cfg(feature = "harness")]
    pub fn overflow_count(&self) -> usize {
        self.colouring.overflow().len()
    }

    /// Sets the contacts for the next step (they apply to that step only:
    /// feed them every step), copied into the world's own list (whose
    /// capacity is kept from step to step). The whole list is checked
    /// first; on error the previous list stays. [`World::swap_contacts`]
    /// hands a list over without the copy.
    pub fn set_contacts(&mut self, contacts: &[Contact]) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        contact::validate_all(contacts, &self.bodies)?;
        self.contacts.clear();
        self.contacts.extend_from_slice(contacts);
        Ok(())
    }

    /// Sets the contacts for the next step as [`World::set_contacts`] does,
    /// without copying them: the world takes `contacts`' vector and leaves
    /// its own in its place, emptied, with its capacity. A detection that
    /// fills the same vector every step (`Collisions::find_contacts_into`)
    /// and swaps it in then moves the two vectors back and forth and, once
    /// both have grown to the contact count, allocates nothing. The whole
    /// list is checked first; on error nothing is swapped and both lists
    /// stay as they were.
    pub fn swap_contacts(&mut self, contacts: &mut Vec<Contact>) -> Result<(), Error> {
        let _mode = DefaultFloatMode::enter();
        contact::validate_all(contacts, &self.bodies)?;
        core::mem::swap(&mut self.contacts, contacts);
        contacts.clear();
        Ok(())
    }

    /// The contacts set for the next step.
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }

    /// The contacts the last step solved: the list set for it, in its
    /// order (empty before the first step and after a restore). With
    /// [`World::contact_impulses`], what a game reads after a step for
    /// sounds and damage (Box2D v3's contact events; the collision layer
    /// turns them into began and ended events per pair of bodies). Copied
    /// into a buffer the world keeps: a steady step allocates nothing for
    /// them.
    pub fn solved_contacts(&self) -> &[Contact] {
        &self.solved
    }

    /// The impulse each of [`World::solved_contacts`] applied over the
    /// last step, index for index: along its normal (N s, pushing
    /// `body_b`; 0 for a gap that never closed, or a contact left out
    /// between sleeping bodies) and its friction (N s, world, on
    /// `body_b`); `body_a` took their opposite. Reading them changes
    /// nothing: the solve never reads what it records here.
    pub fn contact_impulses(&self) -> &[ContactImpulse] {
        &self.impulses
    }

    /// A number that changes whenever a body may have moved or a body was
    /// added or removed (a step, a pose set, a body added or removed, a
    /// snapshot restored), and at no other call: with the world's
    /// [`Timeline`], when a cache of the bodies' poses (the collision
    /// layer's query tree) is still right. No part of the state.
    pub fn pose_version(&self) -> u64 {
        self.pose_version
    }

    /// How many steps this world object has taken since it was made
    /// (restores included, refused steps not): with the world's
    /// [`Timeline`], which step a companion's record belongs to. No part
    /// of the state (not in snapshots or the state hash).
    pub fn step_count(&self) -> u64 {
        self.step_count
    }

    /// Measures the residual joint error of the current poses, without
    /// stepping (e.g. right after building a ragdoll, or after a step of a
    /// world that does not measure every step:
    /// [`SolverConfig::measure_residuals`]). [`World::residuals`] returns it
    /// until the next step.
    pub fn measure_residuals(&mut self) -> &Residuals {
        let _mode = DefaultFloatMode::enter();
        self.refresh_layout();
        step::upload(&self.bodies, self.rows.get());
        self.layout.start_step(&self.bodies);
        metrics::residuals(self);
        self.residuals_measured = true;
        &self.residuals
    }

    fn refresh_layout(&mut self) {
        if self.layout_dirty {
            self.layout = layout::Layout::build(
                &self.colouring,
                &self.joints,
                &self.rods,
                &self.bodies,
                self.islands.asleep(),
                (
                    &self.bins,
                    (self.config.joints == JointSolver::Direct).then_some(self.backend),
                ),
            );
            self.layout_dirty = false;
        }
    }

    /// Residual joint error as of the last step, when it was measured: by
    /// the step itself ([`SolverConfig::measure_residuals`] on: the step's
    /// solved poses), or by [`World::measure_residuals`] since. `None` after
    /// a step that did not measure (nor any call since): stale figures are
    /// never shown as current.
    pub fn residuals(&self) -> Option<&Residuals> {
        self.residuals_measured.then_some(&self.residuals)
    }

    /// How many times a step found a body's state no longer finite and put
    /// it back to its pose before the substep, at rest (since the world was
    /// made). Zero in every test scene; see docs/robustness.md.
    pub fn repaired_bodies(&self) -> u64 {
        self.repaired
    }

    /// A 64-bit hash, bit for bit, of everything a step reads that outlives
    /// the step (what a [`Snapshot`] holds): every body's kind, pose (its
    /// coordinate to double precision), velocities, mass and inertia,
    /// damping and pending forces and torques; which slots are live and
    /// free; the joints; the colouring (the solve order); the contacts set
    /// for the next step. Two worlds with the same hash step on to the same
    /// bits (with overwhelming likelihood): for rollback, a desync shows in
    /// the hash.
    ///
    /// Not covered: the settings ([`SolverConfig`]; backend and thread count
    /// do not change results), residuals and counters, and what no step
    /// reads of the handles: the world's lineage and the generations. Equal
    /// worlds built apart (in two processes, or restored from a snapshot)
    /// hash alike.
    pub fn state_hash(&self) -> u64 {
        metrics::state_hash(self)
    }

    /// Advances the world by `dt` seconds (finite, positive). The step
    /// computes in the default floating-point mode on every thread it uses,
    /// whatever mode (FTZ, DAZ, rounding) the caller runs in, and gives the
    /// caller's mode back ([`vertebra_math::float_mode`]).
    /// It measures the residuals afterwards only when the config asks
    /// ([`SolverConfig::measure_residuals`]). Once its buffers have grown to
    /// the world's bodies, joints and contacts, a step allocates nothing on
    /// one thread (`crates/vertebra-scenes/tests/allocation.rs`).
    ///
    /// **A task system that panics** ([`World::set_tasks`]: its
    /// [`TaskSystem::workers`] or [`TaskSystem::parallel_for`], or an item
    /// it runs) leaves the world unchanged: the step puts back everything
    /// it had changed, bit for bit (state hash, snapshot bytes, sleep
    /// state, the contacts set for the step, the NaN guard's count), and
    /// the panic goes on to the caller. A caller that catches it may fix or
    /// replace the task system and step again, as if the failed call had
    /// never been made. (With one worker the step does not call the task
    /// system past `workers`; the step's own code does not panic on any
    /// state the API accepts, so nothing needs putting back there.)
    pub fn step(&mut self, dt: f32) -> Result<(), Error> {
        self.check_time_step(dt)?;
        let _mode = DefaultFloatMode::enter();
        // Asked once, before anything changes: a task system whose answer
        // changes from call to call, or that panics here, changes nothing.
        let workers = self.tasks.workers();
        if workers <= 1 {
            self.advance(dt, workers);
            return Ok(());
        }
        // Foreign code runs inside the step from here: what it may leave
        // half done is kept first, and put back if the step unwinds.
        self.keep_for_rollback();
        if let Err(panic) = catch_unwind(AssertUnwindSafe(|| self.advance(dt, workers))) {
            self.roll_back();
            resume_unwind(panic);
        }
        Ok(())
    }

    /// Whether [`World::step`] takes `dt` (s): finite, positive, at most
    /// [`MAX_TIME_STEP`], each substep at least [`MIN_TIME_STEP`]; the
    /// refusal `step` gives otherwise.
    pub fn check_time_step(&self, dt: f32) -> Result<(), Error> {
        vertebra_store::check_positive("time step", dt)?;
        if dt > vertebra_store::MAX_TIME_STEP {
            return Err(Error::OutOfRange("time step (at most 1 s)"));
        }
        if dt / (self.config.substeps as f32) < vertebra_store::MIN_TIME_STEP {
            return Err(Error::OutOfRange(
                "time step (each substep at least 1e-6 s)",
            ));
        }
        Ok(())
    }

    /// The step of a valid `dt` on `workers` workers (the task system's
    /// count, asked once).
    fn advance(&mut self, dt: f32, workers: usize) {
        self.layout_dirty |= match self.config.sleep {
            Some(_) => self.islands.touch(&self.contacts, &self.bodies),
            None => self.islands.wake_all(),
        };
        self.layout_dirty |= self.bins.assign(
            &self.bodies,
            self.islands.asleep(),
            &self.joints,
            &self.rods,
            &self.contacts,
            &self.joints_at,
            workers,
        );
        self.refresh_layout();
        let (max_linear, max_angular) =
            (self.config.max_linear_speed, self.config.max_angular_speed);
        integrate::hold_speeds(&mut self.bodies, &self.islands, max_linear, max_angular);
        let max_depth = self.config.max_push_out_speed * dt;
        let asleep = self.islands.asleep();
        self.contact_layout
            .plan(&self.contacts, &self.bodies, asleep, &self.bins);
        let (trees, takes) = (&mut self.layout.trees, &mut self.pinned_trees);
        if pin_choice::choose(&self.config, trees, &self.joints, &self.body_drives, takes) {
            (self.contact_layout).pin(&self.contacts, &self.bodies, trees, takes, max_depth);
        }
        // The contacts' lanes and the joints' start of step, on the workers
        // when there are many (step::start_blocks_all).
        step::start_blocks_all(self, max_depth, workers);
        self.contact_layout.check();
        // Each substep launches the task system's workers once
        // (step::solve_substep).
        step::solve(self, dt, workers);
        let h = dt / self.config.substeps as f32;
        self.contact_layout
            .impulses(self.contacts.len(), h, &mut self.impulses);
        forces::read(self, h, dt);
        forces::break_joints(self);
        if let Some(settings) = &self.config.sleep {
            let links = islands::links(&self.joints, &self.rods)
                .chain(body_drive::moving_links(&self.body_drives));
            self.layout_dirty |=
                self.islands
                    .settle(settings, dt, &mut self.bodies, links, &self.contacts);
        }
        // The solved list is the step's output, copied (so the list a
        // caller swapped in comes back at the next swap, as documented;
        // no allocation once `solved` has grown).
        self.solved.clear();
        self.solved.extend_from_slice(&self.contacts);
        self.contacts.clear();
        self.step_count += 1;
        self.pose_version += 1;
        self.residuals_measured = self.config.measure_residuals;
        if self.residuals_measured {
            metrics::residuals(self);
        }
    }
}
