//! Saving a world's full state and restoring it bit for bit: rollback,
//! save games, a server's state sent to its clients.
//!
//! A snapshot holds everything a step reads that outlives a step: the body
//! store (poses, velocities, masses, pending forces, slots), the joints and
//! their slots, the islands and their sleep state, the colouring (its history decides the solve order, so it
//! is saved, not rebuilt), and the contacts set for the next step. The
//! block layout is rebuilt from those on the next step, exactly as it was
//! built before: between steps every lane holds what its description lays
//! out (a moving drive target or rod rest is written back after each step
//! and its lane laid out again from it: `keep_drive_targets` and
//! `keep_rod_rests` in `step.rs`).
//!
//! **Portable.** A snapshot restores into any world of the same build: the
//! world that took it, or a fresh one in another process or on another
//! machine. Nothing of the [`SolverConfig`](crate::SolverConfig) has to
//! match for the snapshot to be accepted (the settings are the world's,
//! not the snapshot's). To step on bit for bit as the original would have,
//! the settings that change results must match: `substeps`, `iterations`,
//! `gravity`, `max_push_out_speed`, `relax_contacts`, `max_linear_speed`,
//! `max_angular_speed`, `sleep`, `joints`; `backend`, `threads` and `parallel_min_blocks` may
//! differ (stepping is bit-identical across them). "The same build" is the
//! same vertebra version and snapshot format; identity across compilers and
//! targets is not promised (see `docs/robustness.md`).
//!
//! **Handles.** The snapshot carries its world's lineage (see
//! [`Slots`]): a world that restores it takes on that lineage, so the
//! handles of the world that took it are valid here (a client acting on
//! its server's handles, a save game's handles after loading) and handles
//! of any other world are refused as foreign. Generations only ever rise:
//! restoring never lowers the world's counter, so a handle issued after the
//! snapshot was taken stays stale after it is restored, and the world never
//! issues it again.
//!
//! **Untrusted.** The checksum only catches accidents: anyone can write a
//! payload that passes it. Restoring decodes and validates the whole state
//! before anything is assigned, with the checks the API applies to the same
//! values (bodies as [`BodyStore::validate`], joints and contacts by their
//! `validate`, with their bodies live and the right lineage; a joint's or
//! a pending contact's bodies may both be kinematic, after
//! `World::set_body_kind`, never both static) and structural
//! ones (slot tables, array lengths, each body's joint count, the colouring
//! as [`Colouring::validate`]), and the islands and sleep state as the API
//! leaves them (`Islands::validate`: a sleeping body at rest, still, allowed
//! to sleep and held by nothing that moves; stillness no longer than a step
//! can accumulate; anchors where a body can be, with unit orientations). A
//! refused snapshot gets
//! `Err(CorruptSnapshot)` naming the item and the reason (or
//! `Err(IncompatibleSnapshot)` for another build) and the world is
//! unchanged.
//!
//! Bytes: `"VTBSNAPA"` (the format), the build id (u64 LE: a hash of the
//! crate version and the format), the xxh3 hash of the payload (u64 LE),
//! then the payload (postcard).

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};

use serde::{Deserialize, Serialize};
use vertebra_scheduler::Colouring;
use vertebra_store::{BodyHandle, BodyStore, Error, Slots};

use crate::body_drive::{self, BodyDrives, moving_links};
use crate::islands::{Islands, links};
use crate::{Contact, JointDesc, RodDesc, World, checks, layout::ROD_KEY};

/// The format: bumped with every change to [`State`] or anything in it, so
/// bytes of another layout are refused by their magic rather than misread.
const FORMAT: u8 = b'A';
const MAGIC: &[u8; 8] = &[b'V', b'T', b'B', b'S', b'N', b'A', b'P', FORMAT];
const HEADER: usize = 24;

/// A world's full state at one instant: [`World::snapshot`] takes it,
/// [`World::restore`] puts it back, into this world or any other of the
/// same build (see the module documentation). Stepping on from a restored
/// world gives the same bits as stepping on from the original did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Snapshot {
    bytes: Vec<u8>,
}

impl Snapshot {
    /// The encoded snapshot (to store or send).
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// A snapshot from bytes [`Snapshot::as_bytes`] gave (in any process);
    /// checked in full when it is restored.
    pub fn from_bytes(bytes: Vec<u8>) -> Self {
        Self { bytes }
    }
}

/// Which run of states a world is on. One begins when the world is made
/// ([`World::new`]) and a new one each time it restores a snapshot
/// ([`World::restore`]); every other call (stepping, adding, removing)
/// stays on it. It is no part of the world's state (not in its snapshot,
/// not in [`World::state_hash`]) and means nothing in another process.
///
/// What it is for: a companion that keeps its own state about the world's
/// bodies, such as a collision set (`vertebra-collide`), records the
/// timeline it serves. A world that restored a snapshot has left it, and
/// the companion refuses it until its own snapshot taken with the world's
/// is restored too (or it is told explicitly that it serves the world as
/// it is), instead of serving a world whose bodies it does not know.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Timeline {
    /// Unique in the process: one counter for every world.
    id: u64,
    restored: bool,
}

impl Timeline {
    /// A timeline no world has been on; `restored` when a restore begins it.
    pub(crate) fn begin(restored: bool) -> Self {
        static NEXT: AtomicU64 = AtomicU64::new(0);
        Self {
            id: NEXT.fetch_add(1, Ordering::Relaxed),
            restored,
        }
    }

    /// Whether it began with a restore (the world's state came from a
    /// snapshot), rather than with [`World::new`].
    pub fn restored(self) -> bool {
        self.restored
    }
}

/// A new world's lineage: different for every world, across processes too
/// (hashed with the process's random hasher keys).
pub(crate) fn new_lineage() -> u32 {
    use std::hash::{BuildHasher, RandomState};
    static NEXT: AtomicU64 = AtomicU64::new(0);
    RandomState::new().hash_one(NEXT.fetch_add(1, Ordering::Relaxed)) as u32
}

/// The build a snapshot must come from: this crate's version and the format.
fn build_id() -> u64 {
    let name = concat!("vertebra-world ", env!("CARGO_PKG_VERSION"), " snapshot ");
    xxhash_rust::xxh3::xxh3_64(&[name.as_bytes(), MAGIC].concat())
}

#[derive(Serialize, Deserialize)]
struct State {
    bodies: BodyStore,
    joints_at: Vec<u32>,
    joint_slots: Slots,
    joints: Vec<Option<JointDesc>>,
    rod_slots: Slots,
    rods: Vec<Option<RodDesc>>,
    body_drives: Vec<BodyDrives>,
    colouring: Colouring,
    islands: Islands,
    contacts: Vec<Contact>,
}

fn corrupt(why: String) -> Error {
    Error::CorruptSnapshot(why)
}

impl State {
    /// The header checked, the payload decoded (nothing validated yet).
    fn decode(bytes: &[u8]) -> Result<Self, Error> {
        if bytes.len() < HEADER || &bytes[..7] != b"VTBSNAP" {
            return Err(corrupt("not a vertebra snapshot".into()));
        }
        if bytes[7] != FORMAT {
            return Err(Error::IncompatibleSnapshot("another snapshot format"));
        }
        let word = |k: usize| u64::from_le_bytes(bytes[k..k + 8].try_into().expect("8 bytes"));
        if word(8) != build_id() {
            return Err(Error::IncompatibleSnapshot(
                "written by another vertebra version",
            ));
        }
        let payload = &bytes[HEADER..];
        if xxhash_rust::xxh3::xxh3_64(payload) != word(16) {
            return Err(corrupt("checksum mismatch".into()));
        }
        match postcard::take_from_bytes(payload) {
            Ok((state, [])) => Ok(state),
            Ok(_) => Err(corrupt("bytes after the state".into())),
            Err(e) => Err(corrupt(format!("undecodable state ({e})"))),
        }
    }

    /// The state's bytes with their header.
    fn encode(&self) -> Vec<u8> {
        let payload = postcard::to_allocvec(self).expect("the state always encodes");
        let mut bytes = Vec::with_capacity(HEADER + payload.len());
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&build_id().to_le_bytes());
        bytes.extend_from_slice(&xxhash_rust::xxh3::xxh3_64(&payload).to_le_bytes());
        bytes.extend_from_slice(&payload);
        bytes
    }

    /// Everything a world built through the API would satisfy (see the
    /// module documentation); the error names the item.
    fn validate(&self) -> Result<(), Error> {
        let bodies = &self.bodies;
        bodies.validate()?;
        if self.joints_at.len() != bodies.capacity() {
            return Err(corrupt(format!(
                "{} joint counts for {} body slots",
                self.joints_at.len(),
                bodies.capacity()
            )));
        }
        let mut edges = BTreeMap::new();
        let mut joints_at = vec![0u32; bodies.capacity()];
        let mut joint = |key: u64, a: BodyHandle, b: BodyHandle| {
            edges.insert(key, checks::dynamic_bodies(bodies, a, b));
            for h in [a, b] {
                joints_at[h.index()] += 1;
            }
        };
        // A joint's bodies may both be kinematic now (made so after it was
        // added), never both static.
        let live = joints("joint", &self.joint_slots, &self.joints, |d| {
            d.validate()?;
            checks::joined_bodies(bodies, d.body_a, d.body_b).map(drop)
        })?;
        for (slot, d) in live {
            joint(slot as u64, d.body_a, d.body_b);
        }
        let rods = joints("rod", &self.rod_slots, &self.rods, |d| {
            d.validate()?;
            checks::joined_bodies(bodies, d.body_a, d.body_b).map(drop)
        })?;
        for (slot, d) in rods {
            joint(slot as u64 + ROD_KEY, d.body_a, d.body_b);
        }
        if let Some(i) = (0..joints_at.len()).find(|&i| joints_at[i] != self.joints_at[i]) {
            return Err(corrupt(format!(
                "body {i}: counted in {} joints, used by {}",
                self.joints_at[i], joints_at[i]
            )));
        }
        self.colouring
            .validate(&edges, bodies.capacity())
            .map_err(|why| corrupt(format!("colouring: {why}")))?;
        body_drive::validate_all(&self.body_drives, bodies).map_err(corrupt)?;
        let links = links(&self.joints, &self.rods).chain(moving_links(&self.body_drives));
        self.islands.validate(bodies, links).map_err(corrupt)?;
        // A pending contact, too, may have lost its dynamic body to a kind
        // change since it was set.
        for (k, c) in self.contacts.iter().enumerate() {
            c.validate()
                .and_then(|()| checks::joined_bodies(bodies, c.body_a, c.body_b).map(drop))
                .map_err(|e| corrupt(format!("contact {k}: {e}")))?;
        }
        Ok(())
    }
}

/// The live joints of one kind, each checked by `validate` (the API's own
/// check), with their slots; a description must be present exactly where
/// its slot is live.
fn joints<'s, D>(
    kind: &str,
    slots: &Slots,
    descs: &'s [Option<D>],
    validate: impl Fn(&D) -> Result<(), Error>,
) -> Result<Vec<(usize, &'s D)>, Error> {
    slots.validate(kind)?;
    if descs.len() != slots.capacity() {
        return Err(corrupt(format!(
            "{} {kind} descriptions for {} slots",
            descs.len(),
            slots.capacity()
        )));
    }
    let mut live = Vec::new();
    for (slot, desc) in descs.iter().enumerate() {
        match (slots.is_live(slot), desc) {
            (true, Some(d)) => {
                validate(d).map_err(|e| corrupt(format!("{kind} {slot}: {e}")))?;
                live.push((slot, d));
            }
            (false, None) => {}
            (true, None) => {
                return Err(corrupt(format!(
                    "{kind} {slot}: live without a description"
                )));
            }
            (false, Some(_)) => {
                return Err(corrupt(format!(
                    "{kind} {slot}: a description in a free slot"
                )));
            }
        }
    }
    Ok(live)
}

impl World {
    /// The world's full state now (see [`Snapshot`]).
    pub fn snapshot(&self) -> Snapshot {
        let state = State {
            bodies: self.bodies.clone(),
            joints_at: self.joints_at.clone(),
            joint_slots: self.joint_slots.clone(),
            joints: self.joints.clone(),
            rod_slots: self.rod_slots.clone(),
            rods: self.rods.clone(),
            body_drives: self.body_drives.clone(),
            colouring: self.colouring.clone(),
            islands: self.islands.clone(),
            contacts: self.contacts.clone(),
        };
        Snapshot {
            bytes: state.encode(),
        }
    }

    /// Puts the world in `snapshot`'s state: bodies, joints and contacts
    /// added since are gone, removed ones are back, and the handles of the
    /// snapshot's world are valid (see the module documentation for what
    /// another world's snapshot needs). Handles issued after the snapshot
    /// was taken stay stale. `Err(IncompatibleSnapshot)` for another
    /// build's snapshot, `Err(CorruptSnapshot)` naming the item for damaged
    /// or crafted bytes; the world is unchanged on error.
    ///
    /// A successful restore begins a new [`Timeline`] (see
    /// [`World::timeline`]): companions of the world, such as its collision
    /// set, are restored after it from their own snapshots.
    pub fn restore(&mut self, snapshot: &Snapshot) -> Result<(), Error> {
        let _mode = vertebra_math::DefaultFloatMode::enter();
        let mut state = State::decode(&snapshot.bytes)?;
        state.validate()?;
        state.bodies.issue_after(&self.bodies);
        state.joint_slots.issue_after(&self.joint_slots);
        state.rod_slots.issue_after(&self.rod_slots);
        self.bodies = state.bodies;
        self.joints_at = state.joints_at;
        self.joint_slots = state.joint_slots;
        self.joints = state.joints;
        self.rod_slots = state.rod_slots;
        self.rods = state.rods;
        self.body_drives = state.body_drives;
        self.colouring = state.colouring;
        self.islands = state.islands;
        self.islands.derive();
        self.contacts = state.contacts;
        self.solved.clear();
        self.impulses.clear();
        self.joint_forces.clear();
        self.broken.clear();
        self.pose_version += 1;
        self.layout_dirty = true;
        self.timeline = Timeline::begin(true);
        self.measure_residuals();
        Ok(())
    }

    /// The run of states the world is on (see [`Timeline`]): the one
    /// [`World::new`] began, or the one the last successful
    /// [`World::restore`] began.
    pub fn timeline(&self) -> Timeline {
        self.timeline
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::*;
    use crate::islands::{Island, NO_ISLAND};
    use crate::{
        AngularDrive, BodyDesc, BodyKind, JointKind, LimitSoftness, RodStiffness, Shape,
        SolverConfig, Spring, Swing, SwingTwist, UprightDrive, WorldDrive,
    };

    #[test]
    fn lineages_differ() {
        assert_ne!(new_lineage(), new_lineage());
    }

    /// A world's timeline changes with every restore that succeeds, and
    /// only then: not with steps, additions or a refused restore.
    #[test]
    fn a_timeline_begins_at_new_and_at_each_restore() {
        let mut w = world();
        let made = w.timeline();
        assert!(!made.restored());
        let saved = w.snapshot();
        w.add_body(BodyDesc::fixed()).unwrap();
        w.step(1.0 / 60.0).unwrap();
        assert_eq!(w.timeline(), made);
        let mut bytes = saved.as_bytes().to_vec();
        bytes.truncate(bytes.len() - 1);
        assert!(w.restore(&Snapshot::from_bytes(bytes)).is_err());
        assert_eq!(w.timeline(), made, "a refused restore changes nothing");
        w.restore(&saved).unwrap();
        let restored = w.timeline();
        assert!(restored.restored() && restored != made);
        w.restore(&saved).unwrap();
        assert_ne!(w.timeline(), restored, "each restore begins its own");
        assert_ne!(
            World::new(SolverConfig::default()).unwrap().timeline(),
            made
        );
    }

    /// Ground, three capsules hanging from it by a socket, a rod and a
    /// driven socket, a contact pending, a removed body's slot: every part
    /// of the state in use.
    fn world() -> World {
        let mut world = World::new(SolverConfig::default()).unwrap();
        let ground = world.add_body(BodyDesc::fixed()).unwrap();
        let mass = Shape::capsule(-0.2 * Vec3::Y, 0.2 * Vec3::Y, 0.05)
            .mass_properties_with_mass(2.0)
            .unwrap();
        let links: Vec<_> = (1..=3)
            .map(|k| {
                let at = Vec3::new(0.0, -0.5 * k as f32, 0.0);
                world
                    .add_body(BodyDesc::dynamic(mass).with_position(at))
                    .unwrap()
            })
            .collect();
        let gone = world.add_body(BodyDesc::fixed()).unwrap();
        world.remove_body(gone).unwrap();
        let bodies = world.bodies();
        let socket =
            JointDesc::socket_at_world_anchor(bodies, ground, links[0], -0.25 * Vec3::Y, -Vec3::Y)
                .unwrap()
                .with_swing_limit(1.0);
        let rod = RodDesc::from_pose(bodies, links[0], links[1], &[])
            .unwrap()
            .with_stiffness(RodStiffness::Kirchhoff(5.0), RodStiffness::Relaxation(0.5))
            .with_rest_velocity(Vec3::new(0.0, 0.0, 0.3), -0.2);
        let drive = AngularDrive::spring(Quat::IDENTITY, 4.0, 0.7)
            .with_target_velocity(Vec3::new(0.0, 0.5, 0.0))
            .with_max_torque(30.0);
        let driven = JointDesc::socket_at_world_anchor(
            bodies,
            links[1],
            links[2],
            -1.25 * Vec3::Y,
            -Vec3::Y,
        )
        .unwrap()
        .with_drive(drive);
        world.add_joint(socket).unwrap();
        world.add_rod(rod).unwrap();
        world.add_joint(driven).unwrap();
        world.set_body_velocity(links[2], Vec3::X, Vec3::Z).unwrap();
        let pose = WorldDrive::new(Vec3::Y, Quat::IDENTITY, Spring::RIGID).with_caps(30.0, 5.0);
        world.set_world_drive(links[1], Some(pose)).unwrap();
        let upright = UprightDrive::new(Vec3::Y, Vec3::Y, Spring::RIGID).with_max_torque(2.0);
        world.set_upright_drive(links[2], Some(upright)).unwrap();
        for _ in 0..5 {
            world.step(1.0 / 60.0).unwrap();
        }
        let contact = Contact {
            body_a: ground,
            body_b: links[2],
            point: -1.6 * Vec3::Y,
            normal: -Vec3::Y,
            depth: 0.01,
            friction: 0.5,
            restitution: 0.0,
        };
        world.set_contacts(&[contact]).unwrap();
        world
    }

    /// `world`'s snapshot decoded, changed by `change` and encoded again
    /// with a correct checksum: what an attacker can send.
    fn crafted(world: &World, change: impl FnOnce(&mut State)) -> Snapshot {
        let mut state = State::decode(world.snapshot().as_bytes()).unwrap();
        change(&mut state);
        Snapshot::from_bytes(state.encode())
    }

    /// The error restoring `snapshot` gives, after checking that the world
    /// is exactly as it was.
    fn refusal(world: &mut World, snapshot: &Snapshot) -> String {
        let before = world.snapshot();
        let error = world.restore(snapshot).unwrap_err();
        assert_eq!(world.snapshot(), before, "{error} changed the world");
        error.to_string()
    }

    #[test]
    fn an_unchanged_state_round_trips() {
        let mut world = world();
        let snapshot = crafted(&world, |_| {});
        assert_eq!(snapshot, world.snapshot());
        world.restore(&snapshot).unwrap();
    }

    /// One change to a decoded state.
    type Change = Box<dyn FnOnce(&mut State)>;

    /// Payloads that, unvalidated, would put NaN into the world or panic in
    /// `restore` or the next step.
    #[test]
    fn crafted_states_are_refused_by_name_and_change_nothing() {
        let mut world = world();
        const NAN: f32 = f32::NAN;
        let cases: Vec<(Change, &str)> = vec![
            (
                Box::new(|s| s.joints[0].as_mut().unwrap().anchor_a.x = NAN),
                "joint 0: anchor a is not finite",
            ),
            (
                Box::new(|s| s.rods[0].as_mut().unwrap().rest_length = -0.4),
                "rod 0: rod rest length must be positive",
            ),
            (
                Box::new(|s| s.rods[0].as_mut().unwrap().max_torque = NAN),
                "rod 0: rod max torque is not finite",
            ),
            (
                Box::new(|s| s.rods[0].as_mut().unwrap().bend_rest_velocity.z = NAN),
                "rod 0: rod rest bend velocity is not finite",
            ),
            (
                Box::new(|s| s.rods[0].as_mut().unwrap().bend_rest_velocity.x = 2e6),
                "rod 0: rod rest bend velocity (at most MAX_ANGULAR_SPEED_LIMIT) is out of range",
            ),
            (
                Box::new(|s| s.rods[0].as_mut().unwrap().twist_rest_velocity = f32::INFINITY),
                "rod 0: rod rest twist velocity is not finite",
            ),
            (
                Box::new(|s| s.rods[0].as_mut().unwrap().twist_rest_velocity = -2e6),
                "rod 0: rod rest twist velocity (at most MAX_ANGULAR_SPEED_LIMIT) is out of range",
            ),
            (
                Box::new(|s| {
                    s.rods[0].as_mut().unwrap().bending = RodStiffness::Spring {
                        frequency: 2.0,
                        damping_ratio: 2e3,
                    }
                }),
                "rod 0: rod damping ratio (at most 1e3) is out of range",
            ),
            (
                Box::new(|s| s.bodies.inverse_mass[1] = NAN),
                "body 1: inverse mass is not 1/mass (0 for kinematic and static bodies)",
            ),
            (
                Box::new(|s| s.bodies.inverse_mass[2] *= 2.0),
                "body 2: inverse mass is not 1/mass (0 for kinematic and static bodies)",
            ),
            (
                Box::new(|s| s.bodies.inverse_inertia[3].x_axis.x = 1e30),
                "body 3: inverse inertia is not the inertia's inverse (0 for kinematic and static bodies)",
            ),
            (
                Box::new(|s| s.bodies.mass[0] = 1.0),
                "body 0: mass of a static body is not zero",
            ),
            (
                // Made kinematic without World::set_body_kind: its inverse
                // mass is still a dynamic body's.
                Box::new(|s| s.bodies.kind[2] = BodyKind::Kinematic),
                "body 2: inverse mass is not 1/mass (0 for kinematic and static bodies)",
            ),
            (
                Box::new(|s| s.bodies.position[3].y = 2e6),
                "body 3: position is out of range",
            ),
            (
                Box::new(|s| s.bodies.orientation[1] = Quat::from_xyzw(0.0, 0.0, 0.0, 2.0)),
                "body 1: orientation is not normalised",
            ),
            (
                Box::new(|s| s.bodies.linear_velocity[0] = Vec3::X),
                "body 0: a static body moves",
            ),
            (
                // The removed body's slot: the step uploads every slot.
                Box::new(|s| s.bodies.angular_velocity[4].z = f32::INFINITY),
                "body 4: angular velocity is not finite",
            ),
            (
                Box::new(|s| s.bodies.force[2].y = NAN),
                "body 2: accumulated force is not finite",
            ),
            (
                Box::new(|s| s.bodies.linear_damping[1] = -1.0),
                "body 1: linear damping must be positive",
            ),
            (
                Box::new(|s| {
                    s.bodies.mass.pop();
                }),
                "bodies: 4 mass entries for 5 slots",
            ),
            (
                Box::new(|s| s.joints_at[1] -= 1),
                "body 1: counted in 1 joints, used by 2",
            ),
            (
                Box::new(|s| s.body_drives.push(BodyDrives::default())),
                "body drives: the list ends in an undriven slot",
            ),
            (
                Box::new(|s| s.body_drives[2].world.as_mut().unwrap().max_force = -1.0),
                "body 2: world drive max force must be positive",
            ),
            (
                Box::new(|s| s.body_drives[3].upright.as_mut().unwrap().axis = Vec3::X * 2.0),
                "body 3: upright drive axis is not normalised",
            ),
            (
                Box::new(|s| {
                    s.body_drives.resize(5, BodyDrives::default());
                    s.body_drives[4] = s.body_drives[3];
                }),
                "body 4: drives on no live body",
            ),
            (
                Box::new(|s| s.joints_at.push(0)),
                "6 joint counts for 5 body slots",
            ),
            (
                Box::new(|s| s.joints[1] = None),
                "joint 1: live without a description",
            ),
            (
                Box::new(|s| s.rods.push(None)),
                "2 rod descriptions for 1 slots",
            ),
            (
                Box::new(|s| {
                    let rod = s.rods[0].as_mut().unwrap();
                    rod.body_b = rod.body_a;
                }),
                "rod 0: a joint, rod or contact needs two different bodies",
            ),
            (
                Box::new(|s| {
                    let socket = s.joints[1].as_mut().unwrap();
                    socket.drive.as_mut().unwrap().max_torque = -1.0;
                }),
                "joint 1: drive max torque must be positive",
            ),
            (
                Box::new(|s| {
                    let socket = s.joints[1].as_mut().unwrap();
                    socket.drive.as_mut().unwrap().target_velocity.y = f32::NAN;
                }),
                "joint 1: drive target velocity is not finite",
            ),
            (
                Box::new(|s| {
                    let socket = s.joints[1].as_mut().unwrap();
                    socket.drive.as_mut().unwrap().strength = Spring::Frequency {
                        frequency: 0.0,
                        damping_ratio: 1.0,
                    };
                }),
                "joint 1: drive frequency (at least 1e-3 Hz) is out of range",
            ),
            (
                Box::new(|s| s.joints[1].as_mut().unwrap().kind = JointKind::Fixed),
                "joint 1: invalid joint: drive (a fixed joint has no rotation to drive)",
            ),
            (
                Box::new(|s| {
                    let swing = Swing::Ellipse { y: NAN, z: 0.5 };
                    s.joints[0].as_mut().unwrap().kind =
                        JointKind::Socket(SwingTwist::FREE.with_swing(swing));
                }),
                "joint 0: swing ellipse y is not finite",
            ),
            (
                Box::new(|s| {
                    s.joints[0].as_mut().unwrap().kind = JointKind::Hinge {
                        range: Some([1.0, -1.0]),
                        softness: LimitSoftness::compliant(0.1),
                    }
                }),
                "joint 0: invalid hinge range limit",
            ),
            (
                Box::new(|s| {
                    let soft = SwingTwist::FREE.with_softness(LimitSoftness::compliant(-1.0));
                    s.joints[0].as_mut().unwrap().kind = JointKind::Socket(soft);
                }),
                "joint 0: limit compliance must be positive",
            ),
            (
                Box::new(|s| {
                    let spring = LimitSoftness::Soft(Spring::Frequency {
                        frequency: 5.0,
                        damping_ratio: f32::NAN,
                    });
                    s.joints[0].as_mut().unwrap().kind = JointKind::Hinge {
                        range: Some([-1.0, 1.0]),
                        softness: spring,
                    }
                }),
                "joint 0: limit damping ratio is not finite",
            ),
            (
                Box::new(|s| s.colouring = Colouring::new()),
                "colouring: constraint 0 is not coloured",
            ),
            (
                Box::new(|s| {
                    s.colouring.remove(0);
                    s.colouring.add(0, [Some(3), None]);
                }),
                "colouring: constraint 0 is coloured over other bodies",
            ),
            (
                Box::new(|s| s.contacts[0].normal = Vec3::ZERO),
                "contact 0: contact normal is not normalised",
            ),
            (
                Box::new(|s| s.contacts[0].body_b = s.contacts[0].body_a),
                "contact 0: a joint, rod or contact needs two different bodies",
            ),
            (
                Box::new(|s| {
                    s.islands.of.pop();
                }),
                "islands: per-body arrays for 5 body slots",
            ),
            (
                Box::new(|s| s.islands.of[0] = 0),
                "body 0: in an island but not dynamic",
            ),
            (
                Box::new(|s| s.islands.of[1] = NO_ISLAND),
                "body 1: dynamic in no island",
            ),
            (
                Box::new(|s| s.islands.of[2] = 1),
                "body 2: in island 1, which is not live",
            ),
            (
                Box::new(|s| s.islands.still[3] = f64::NAN),
                "body 3: stillness NaN (0 to 9.007199254740992e15 s)",
            ),
            (
                Box::new(|s| s.islands.anchor[3].0.x = f64::INFINITY),
                "body 3: stillness anchor not finite",
            ),
            (
                Box::new(|s| s.islands.islands[1].live = true),
                "island 1: live without bodies, or free with them",
            ),
            (
                Box::new(|s| {
                    s.islands.islands[1].live = true;
                    s.islands.of[3] = 1;
                }),
                "bodies 2 and 3: linked but in islands 0 and 1",
            ),
        ];
        for (change, expected) in cases {
            let snapshot = crafted(&world, change);
            assert_eq!(
                refusal(&mut world, &snapshot),
                format!("corrupt snapshot: {expected}")
            );
        }
        world.step(1.0 / 60.0).unwrap();
    }

    /// Without gravity: a ball hanging from the ground by a socket with a
    /// still drive (body 2), one hanging from a kinematic body at rest by a
    /// socket (body 3 from body 1), and a free ball (body 4); after 40 steps
    /// all three islands sleep.
    fn sleeping_world() -> World {
        let mut world = World::new(SolverConfig {
            gravity: Vec3::ZERO,
            ..SolverConfig::default()
        })
        .unwrap();
        let ground = world.add_body(BodyDesc::fixed()).unwrap();
        let kinematic = BodyDesc {
            kind: BodyKind::Kinematic,
            ..BodyDesc::fixed().with_position(Vec3::new(2.0, 0.0, 0.0))
        };
        let holder = world.add_body(kinematic).unwrap();
        let mass = Shape::Sphere { radius: 0.1 }
            .mass_properties_with_mass(1.0)
            .unwrap();
        let ball = |x: f32| BodyDesc::dynamic(mass).with_position(Vec3::new(x, -0.5, 0.0));
        let a = world.add_body(ball(0.0)).unwrap();
        let b = world.add_body(ball(2.0)).unwrap();
        let free = world.add_body(ball(5.0)).unwrap();
        let bodies = world.bodies();
        let drive = AngularDrive::spring(Quat::IDENTITY, 4.0, 0.7);
        let driven =
            JointDesc::socket_at_world_anchor(bodies, ground, a, -0.25 * Vec3::Y, -Vec3::Y)
                .unwrap()
                .with_drive(drive);
        let held = JointDesc::socket_at_world_anchor(
            bodies,
            holder,
            b,
            Vec3::new(2.0, -0.25, 0.0),
            -Vec3::Y,
        )
        .unwrap();
        world.add_joint(driven).unwrap();
        world.add_joint(held).unwrap();
        let still = WorldDrive::new(Vec3::new(5.0, -0.5, 0.0), Quat::IDENTITY, Spring::RIGID);
        world.set_world_drive(free, Some(still)).unwrap();
        for _ in 0..40 {
            world.step(1.0 / 60.0).unwrap();
        }
        assert_eq!(world.island_count(), (3, 3), "every island sleeps");
        world
    }

    /// Sleep states the API could never produce, accepted before restore
    /// checked the sleep state: a sleeping island moving at 400 m/s (6.67 m
    /// in its first step awake), a sleeper held by a moving drive or a
    /// moving kinematic body, a zero anchor orientation, a stillness of
    /// 1e308 s; and every other value falling asleep or staying asleep
    /// rules out.
    #[test]
    fn sleep_states_the_api_could_not_produce_are_refused_by_name() {
        let mut world = sleeping_world();
        let island = world.islands.of[2] as usize;
        let free = world.islands.islands.len();
        let cases: Vec<(Change, String)> = vec![
            (
                Box::new(|s| s.bodies.linear_velocity[2] = Vec3::new(400.0, 0.0, 0.0)),
                "body 2: asleep but its linear velocity is [400, 0, 0]".into(),
            ),
            (
                Box::new(|s| s.bodies.angular_velocity[4].z = -3.0),
                "body 4: asleep but its angular velocity is [0, 0, -3]".into(),
            ),
            (
                Box::new(|s| s.bodies.force[2] = Vec3::Y),
                "body 2: asleep but its force is [0, 1, 0]".into(),
            ),
            (
                Box::new(|s| s.bodies.torque[3] = Vec3::X),
                "body 3: asleep but its torque is [1, 0, 0]".into(),
            ),
            (
                Box::new(|s| {
                    let drive = s.joints[0].as_mut().unwrap().drive.as_mut().unwrap();
                    drive.target_velocity = Vec3::new(0.0, 0.5, 0.0);
                }),
                "body 2: asleep, held by a moving drive or rod rest (to body 0)".into(),
            ),
            (
                Box::new(|s| s.body_drives[4].world.as_mut().unwrap().linear_velocity = Vec3::X),
                "body 4: asleep, held by a moving drive or rod rest (to body 4)".into(),
            ),
            (
                Box::new(|s| s.bodies.linear_velocity[1] = Vec3::X),
                "body 3: asleep, linked to kinematic body 1, which moves".into(),
            ),
            (
                Box::new(|s| s.islands.anchor[2].1 = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)),
                "body 2: stillness anchor orientation is not normalised".into(),
            ),
            (
                Box::new(|s| s.islands.anchor[4].0.x = 2e6),
                "body 4: stillness anchor is out of range".into(),
            ),
            (
                Box::new(|s| s.islands.still[2] = 1e308),
                "body 2: stillness 1e308 (0 to 9.007199254740992e15 s)".into(),
            ),
            (
                Box::new(|s| s.islands.still[2] = 0.0),
                "body 2: asleep but never still".into(),
            ),
            (
                Box::new(|s| s.islands.still[0] = 1.0),
                "body 0: stillness 1 in no island".into(),
            ),
            (
                Box::new(|s| s.islands.allowed[3] = false),
                "body 3: asleep but not allowed to sleep".into(),
            ),
            (
                Box::new(move |s| s.islands.islands[island].split = true),
                format!("island {island}: asleep with a split pending"),
            ),
            (
                Box::new(|s| {
                    s.islands.islands.push(Island {
                        asleep: true,
                        ..Island::default()
                    })
                }),
                format!("island {free}: free but flagged"),
            ),
        ];
        for (change, expected) in cases {
            let snapshot = crafted(&world, change);
            assert_eq!(
                refusal(&mut world, &snapshot),
                format!("corrupt snapshot: {expected}")
            );
        }
        // The untouched sleeping state restores.
        world.restore(&world.snapshot()).unwrap();
    }

    /// The other sleep state a crafted snapshot can hold: every island of a
    /// world with a moving drive put to sleep as it moves.
    #[test]
    fn every_island_put_to_sleep_while_a_drive_moves_is_refused() {
        let mut world = world();
        let moving = crafted(&world, |s| {
            for island in s.islands.islands.iter_mut().filter(|x| x.live) {
                island.asleep = true;
            }
        });
        assert_eq!(
            refusal(&mut world, &moving),
            "corrupt snapshot: body 1: asleep but never still"
        );
        // Even at rest, still and with no force, the drive keeps it awake.
        let at_rest = crafted(&world, |s| {
            for island in s.islands.islands.iter_mut().filter(|x| x.live) {
                island.asleep = true;
            }
            for i in 1..=3 {
                s.bodies.linear_velocity[i] = Vec3::ZERO;
                s.bodies.angular_velocity[i] = Vec3::ZERO;
                s.islands.still[i] = 1.0;
            }
        });
        assert_eq!(
            refusal(&mut world, &at_rest),
            "corrupt snapshot: body 2: asleep, held by a moving drive or rod rest (to body 3)"
        );
    }

    #[test]
    fn a_removed_or_foreign_body_in_a_joint_is_refused() {
        let mut world = world();
        let mut other = World::new(SolverConfig::default()).unwrap();
        let foreign = other.add_body(BodyDesc::fixed()).unwrap();
        let removed = {
            let mut w = World::new(SolverConfig::default()).unwrap();
            w.restore(&world.snapshot()).unwrap();
            let h = w.add_body(BodyDesc::fixed()).unwrap();
            w.remove_body(h).unwrap();
            h
        };
        let cases = [
            (foreign, "joint 0: body handle of another world"),
            (removed, "joint 0: stale or unknown body handle"),
        ];
        for (body, expected) in cases {
            let snapshot = crafted(&world, |s| s.joints[0].as_mut().unwrap().body_a = body);
            assert_eq!(
                refusal(&mut world, &snapshot),
                format!("corrupt snapshot: {expected}")
            );
        }
    }

    #[test]
    fn other_formats_builds_and_damage_are_refused() {
        let mut world = world();
        let good = world.snapshot().as_bytes().to_vec();
        let mut other_format = good.clone();
        other_format[7] = b'1';
        // The format before rods' rest rates: its rods lack two fields.
        let mut previous_format = good.clone();
        previous_format[7] = b'7';
        let mut other_build = good.clone();
        other_build[8] ^= 1;
        let mut trailing = State::decode(&good).unwrap().encode();
        trailing.push(0);
        let sum = xxhash_rust::xxh3::xxh3_64(&trailing[HEADER..]);
        trailing[16..24].copy_from_slice(&sum.to_le_bytes());
        let cases = [
            (
                other_format,
                "incompatible snapshot: another snapshot format",
            ),
            (
                previous_format,
                "incompatible snapshot: another snapshot format",
            ),
            (
                other_build,
                "incompatible snapshot: written by another vertebra version",
            ),
            (trailing, "corrupt snapshot: bytes after the state"),
            (
                good[..HEADER - 1].to_vec(),
                "corrupt snapshot: not a vertebra snapshot",
            ),
        ];
        for (bytes, expected) in cases {
            assert_eq!(refusal(&mut world, &Snapshot::from_bytes(bytes)), expected);
        }
    }
}
