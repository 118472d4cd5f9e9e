//! Crafted snapshots: a valid world's snapshot decoded, its state changed
//! field by field (or its payload byte by byte), encoded again with a
//! correct checksum, and restored.

use std::collections::{BTreeMap, BTreeSet};

use glam::{DVec3, Mat3, Quat, Vec3};
use serde::{Deserialize, Serialize};
use vertebra_world::{
    AngularDrive, BodyDesc, BodyHandle, BodyKind, Contact, JointDesc, JointHandle, JointKind,
    LimitSoftness, RodDesc, RodHandle, RodStiffness, Shape, Snapshot, SolverConfig, Spring, Swing,
    SwingTwist, UprightDrive, World, WorldDrive,
};

use crate::input::Input;
use crate::world::{Seen, add_body, add_joint, add_rod, body_drive, set_contacts};

// The payload's layout as the fuzzer sees it: `vertebra_world`'s private
// `State` field for field (postcard is not self-describing). Every valid
// snapshot must decode through it and encode back to the same bytes (the
// target asserts it), so the two cannot drift apart unnoticed.

#[derive(Clone, Serialize, Deserialize)]
struct Slots {
    lineage: u32,
    next_generation: u64,
    generation: Vec<u64>,
    live: Vec<bool>,
    free: BTreeSet<u32>,
}

#[derive(Clone, Serialize, Deserialize)]
struct Bodies {
    slots: Slots,
    kind: Vec<BodyKind>,
    position: Vec<Vec3>,
    position_low: Vec<Vec3>,
    orientation: Vec<Quat>,
    linear_velocity: Vec<Vec3>,
    angular_velocity: Vec<Vec3>,
    mass: Vec<f32>,
    inverse_mass: Vec<f32>,
    inertia: Vec<Mat3>,
    inverse_inertia: Vec<Mat3>,
    force: Vec<Vec3>,
    torque: Vec<Vec3>,
    linear_damping: Vec<f32>,
    angular_damping: Vec<f32>,
}

#[derive(Clone, Copy, Serialize, Deserialize)]
enum Slot {
    Colour(u8),
    Overflow,
}

#[derive(Clone, Serialize, Deserialize)]
struct Colouring {
    body_colours: Vec<u32>,
    members: Vec<BTreeSet<u64>>,
    overflow: BTreeSet<u64>,
    placed: BTreeMap<u64, (Slot, [Option<u32>; 2])>,
}

#[derive(Clone, Copy, Serialize, Deserialize)]
struct Island {
    live: bool,
    asleep: bool,
    split: bool,
    touching: u64,
}

#[derive(Clone, Serialize, Deserialize)]
struct Islands {
    of: Vec<u32>,
    still: Vec<f64>,
    anchor: Vec<(DVec3, Quat)>,
    allowed: Vec<bool>,
    islands: Vec<Island>,
}

#[derive(Clone, Serialize, Deserialize)]
struct State {
    bodies: Bodies,
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

#[derive(Clone, Copy, Default, Serialize, Deserialize)]
struct BodyDrives {
    world: Option<WorldDrive>,
    upright: Option<UprightDrive>,
}

const HEADER: usize = 24;

/// A body handle with any fields (through its serialised form).
fn handle(index: u32, lineage: u32, generation: u64) -> BodyHandle {
    let bytes = postcard::to_allocvec(&(index, lineage, generation)).expect("encodes");
    postcard::from_bytes(&bytes).expect("a handle is its three fields")
}

/// A float that breaks things more often than not.
fn value(input: &mut Input) -> f32 {
    const SPECIAL: [f32; 12] = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        0.0,
        -0.0,
        -1.0,
        1e30,
        2e6,
        1e-40,
        f32::MAX,
        f32::MIN_POSITIVE,
        4.0,
    ];
    match input.pick(SPECIAL.len() + 1) {
        k if k < SPECIAL.len() => SPECIAL[k],
        _ => input.float(10.0),
    }
}

fn vec3(input: &mut Input, v: &mut Vec3) {
    v[input.pick(3)] = value(input);
}

fn quat(input: &mut Input, q: &mut Quat) {
    let mut a = q.to_array();
    a[input.pick(4)] = value(input);
    *q = Quat::from_array(a);
}

/// One field of a drive, crafted.
fn drive(input: &mut Input, d: &mut AngularDrive) {
    match input.pick(4) {
        0 => quat(input, &mut d.target),
        1 => vec3(input, &mut d.target_velocity),
        2 => d.max_torque = value(input),
        _ => {
            d.strength = spring(input);
        }
    }
}

/// A spring of either form from the special values.
fn spring(input: &mut Input) -> Spring {
    match input.flag() {
        true => Spring::Compliance {
            compliance: value(input),
            damping: value(input),
        },
        false => Spring::Frequency {
            frequency: value(input),
            damping_ratio: value(input),
        },
    }
}

fn mat3(input: &mut Input, m: &mut Mat3) {
    let mut a = m.to_cols_array();
    a[input.pick(9)] = value(input);
    *m = Mat3::from_cols_array(&a);
}

/// An index near `n`: in range, just past it, or far past it.
fn index(input: &mut Input, n: usize) -> usize {
    match input.pick(4) {
        0 => n,
        1 => input.pick(1 << 16),
        _ => input.pick(n),
    }
}

fn slots(input: &mut Input, s: &mut Slots) {
    let n = s.live.len();
    match input.pick(6) {
        0 if n > 0 => s.live[input.pick(n)] ^= true,
        1 if n > 0 => s.generation[input.pick(n)] = input.pick(1 << 20) as u64,
        2 => {
            s.free.insert(index(input, n) as u32);
        }
        3 => s.next_generation = [0, 1, 7, 1 << 48, (1 << 48) + 1, u64::MAX][input.pick(6)],
        4 => s.lineage ^= 1 + input.pick(255) as u32,
        _ => {
            s.generation.push(0);
            s.live.push(input.flag());
        }
    }
}

fn body(input: &mut Input, b: &mut Bodies) {
    // Earlier changes may have shortened `position` (and only it).
    let n = b.kind.len().min(b.position.len());
    if n == 0 {
        return slots(input, &mut b.slots);
    }
    let i = input.pick(n);
    match input.pick(17) {
        0 => vec3(input, &mut b.position[i]),
        1 => quat(input, &mut b.orientation[i]),
        2 => vec3(input, &mut b.linear_velocity[i]),
        3 => vec3(input, &mut b.angular_velocity[i]),
        4 => b.mass[i] = value(input),
        5 => b.inverse_mass[i] = value(input),
        6 => mat3(input, &mut b.inertia[i]),
        7 => mat3(input, &mut b.inverse_inertia[i]),
        8 => vec3(input, &mut b.force[i]),
        9 => vec3(input, &mut b.torque[i]),
        10 => b.linear_damping[i] = value(input),
        11 => b.angular_damping[i] = value(input),
        12 => b.kind[i] = [BodyKind::Dynamic, BodyKind::Kinematic, BodyKind::Static][input.pick(3)],
        13 => {
            b.position.pop();
        }
        14 => b.inverse_mass.push(1.0),
        15 => vec3(input, &mut b.position_low[i]),
        _ => slots(input, &mut b.slots),
    }
}

/// A body handle of `state`: live, dead, out of range or of another lineage.
fn body_handle(input: &mut Input, state: &State) -> BodyHandle {
    let s = &state.bodies.slots;
    let i = index(input, s.live.len());
    let generation = s.generation.get(i).copied().unwrap_or(0);
    let lineage = if input.pick(8) == 0 {
        !s.lineage
    } else {
        s.lineage
    };
    handle(i as u32, lineage, generation + (input.pick(8) == 0) as u64)
}

fn limit(input: &mut Input) -> Option<f32> {
    input.flag().then(|| value(input))
}

fn range(input: &mut Input) -> Option<[f32; 2]> {
    input.flag().then(|| [value(input), value(input)])
}

/// Any kind, its limits and softness from the special values.
fn kind(input: &mut Input) -> JointKind {
    let softness = if input.flag() {
        LimitSoftness::Soft(spring(input))
    } else {
        LimitSoftness::Hard
    };
    let swing = match input.pick(4) {
        0 => Swing::Free,
        1 => Swing::Cone(value(input)),
        2 => Swing::Ellipse {
            y: value(input),
            z: value(input),
        },
        _ => Swing::Pyramid {
            y: [value(input), value(input)],
            z: [value(input), value(input)],
        },
    };
    match input.pick(3) {
        0 => JointKind::Hinge {
            range: range(input),
            softness,
        },
        1 => JointKind::Fixed,
        _ => JointKind::Socket(SwingTwist {
            swing,
            twist: range(input),
            softness,
        }),
    }
}

fn socket(input: &mut Input, state: &mut State) {
    let n = state.joints.len();
    if n == 0 {
        return slots(input, &mut state.joint_slots);
    }
    let slot = input.pick(n);
    let handle = body_handle(input, state);
    let Some(s) = state.joints[slot].as_mut() else {
        return slots(input, &mut state.joint_slots);
    };
    match input.pick(10) {
        0 => s.body_a = handle,
        1 => s.body_b = handle,
        2 => vec3(input, &mut s.anchor_a),
        3 => quat(input, &mut s.frame_b),
        4 => s.kind = kind(input),
        5 => {
            if let JointKind::Socket(limits) = &mut s.kind {
                limits.twist = Some([value(input), value(input)]);
            }
        }
        6 => {
            if let Some(d) = s.drive.as_mut() {
                drive(input, d);
            }
        }
        7 => state.joints[slot] = None,
        8 => state.joints.push(None),
        _ => slots(input, &mut state.joint_slots),
    }
}

fn rod(input: &mut Input, state: &mut State) {
    let n = state.rods.len();
    if n == 0 {
        return slots(input, &mut state.rod_slots);
    }
    let slot = input.pick(n);
    let handle = body_handle(input, state);
    let Some(r) = state.rods[slot].as_mut() else {
        return slots(input, &mut state.rod_slots);
    };
    match input.pick(16) {
        0 => r.body_a = handle,
        1 => r.body_b = handle,
        2 => quat(input, &mut r.frame_a),
        10 => r.max_torque = value(input),
        12 => r.twisting = RodStiffness::Relaxation(value(input)),
        11 => {
            r.bending = RodStiffness::Spring {
                frequency: value(input),
                damping_ratio: value(input),
            }
        }
        3 => r.rest_length = value(input),
        4 => vec3(input, &mut r.bend_rest),
        5 => r.twist_rest = value(input),
        6 => r.bending = RodStiffness::Kirchhoff(value(input)),
        7 => {
            r.twisting = RodStiffness::Damped {
                stiffness: value(input),
                damping: value(input),
            }
        }
        8 => r.bend_limit = limit(input),
        9 => state.rods[slot] = None,
        13 => vec3(input, &mut r.bend_rest_velocity),
        14 => r.twist_rest_velocity = value(input),
        _ => slots(input, &mut state.rod_slots),
    }
}

fn colouring(input: &mut Input, c: &mut Colouring) {
    let keys: Vec<u64> = c.placed.keys().copied().collect();
    let key = keys.get(input.pick(keys.len())).copied().unwrap_or(0);
    match input.pick(6) {
        0 => {
            let colour = input.pick(30) as u8;
            if let Some(p) = c.placed.get_mut(&key) {
                p.0 = Slot::Colour(colour);
            }
            if let Some(m) = c.members.get_mut(colour as usize) {
                m.insert(key);
            }
        }
        1 => {
            if let Some(p) = c.placed.get_mut(&key) {
                p.1[input.pick(2)] = input.flag().then(|| input.pick(1 << 16) as u32);
            }
        }
        2 => {
            let n = c.body_colours.len();
            if n > 0 {
                c.body_colours[input.pick(n)] ^= 1 << input.pick(32);
            }
        }
        3 => {
            c.placed.remove(&key);
        }
        4 => {
            c.overflow.insert(key);
        }
        _ => {
            c.members.pop();
        }
    }
}

fn contact(input: &mut Input, state: &mut State) {
    let handle = body_handle(input, state);
    let Some(c) = state.contacts.first_mut() else {
        return;
    };
    match input.pick(6) {
        0 => c.body_a = handle,
        1 => c.body_b = handle,
        2 => vec3(input, &mut c.point),
        3 => vec3(input, &mut c.normal),
        4 => c.depth = value(input),
        _ => c.restitution = value(input),
    }
}

/// A change to the islands' state: a body moved to another island (or to
/// none), a stillness or anchor broken, an island's flags flipped.
fn islands(input: &mut Input, islands: &mut Islands) {
    let n = islands.of.len().max(1);
    match input.pick(4) {
        0 => {
            if let Some(of) = islands.of.get_mut(input.pick(n)) {
                *of = [0, 1, u32::MAX][input.pick(3)];
            }
        }
        1 => {
            if let Some(still) = islands.still.get_mut(input.pick(n)) {
                *still = f64::from(value(input));
            }
        }
        2 => {
            if let Some(anchor) = islands.anchor.get_mut(input.pick(n)) {
                anchor.0.y = f64::from(value(input));
            }
        }
        _ => {
            let k = islands.islands.len();
            match k {
                0 => islands.islands.push(Island {
                    live: true,
                    asleep: true,
                    split: false,
                    touching: 0,
                }),
                _ => {
                    let island = &mut islands.islands[input.pick(k)];
                    island.live = !island.live;
                    island.asleep = !island.asleep;
                }
            }
        }
    }
}

/// One change to the state, chosen by the input.
fn change(input: &mut Input, state: &mut State) {
    match input.pick(9) {
        8 => body_drives(input, state),
        7 => islands(input, &mut state.islands),
        0 | 1 => body(input, &mut state.bodies),
        2 => socket(input, state),
        3 => rod(input, state),
        4 => colouring(input, &mut state.colouring),
        5 => contact(input, state),
        _ => {
            let n = state.joints_at.len();
            match n {
                0 => state.joints_at.push(1),
                _ => state.joints_at[input.pick(n)] = input.pick(4) as u32,
            }
        }
    }
}

/// A body's drives changed: a field to any value, a drive on any slot,
/// or an undriven slot at the end.
fn body_drives(input: &mut Input, state: &mut State) {
    let n = state.body_drives.len();
    if n == 0 || input.flag() {
        let mut d = BodyDrives::default();
        if input.flag() {
            d.upright = Some(UprightDrive::new(Vec3::Y, Vec3::Y, Spring::RIGID));
        }
        let at = input.pick(n + 2);
        state
            .body_drives
            .resize(state.body_drives.len().max(at + 1), BodyDrives::default());
        state.body_drives[at] = d;
        return;
    }
    let d = &mut state.body_drives[input.pick(n)];
    if let Some(w) = d.world.as_mut() {
        match input.pick(5) {
            0 => vec3(input, &mut w.position),
            1 => quat(input, &mut w.orientation),
            2 => vec3(input, &mut w.linear_velocity),
            3 => w.max_force = value(input),
            _ => w.linear = Some(spring(input)),
        }
    } else if let Some(u) = d.upright.as_mut() {
        match input.pick(3) {
            0 => vec3(input, &mut u.axis),
            1 => u.max_torque = value(input),
            _ => u.strength = spring(input),
        }
    }
}

/// A small valid world from the input: up to 6 bodies, joints (their
/// drives' targets moving, but the second's, fourth's, ... still), rods
/// (the first, third, ... with moving rest shapes), contacts, some steps
/// and removals (refused calls skipped).
fn build(input: &mut Input) -> World {
    let mut world = World::new(SolverConfig::default()).expect("a valid config");
    let mut seen = Seen::default();
    for _ in 0..2 + input.pick(5) {
        if let Ok(h) = add_body(&mut world, input) {
            seen.bodies.push(h);
        }
    }
    for _ in 0..input.pick(6) {
        let _ = match input.pick(3) {
            0 => add_joint(&mut world, &seen, input).and_then(|h| {
                seen.joints.push(h);
                match seen.joints.len() % 2 {
                    0 => still(&mut world, h),
                    _ => Ok(()),
                }
            }),
            1 => add_rod(&mut world, &seen, input).and_then(|h| {
                seen.rods.push(h);
                match seen.rods.len() % 2 {
                    1 => moving(&mut world, h),
                    _ => Ok(()),
                }
            }),
            _ => world.step(1.0 / 60.0),
        };
    }
    if input.flag() && !seen.joints.is_empty() {
        let _ = world.remove_joint(seen.joints[0]);
    }
    if input.flag() && !seen.bodies.is_empty() {
        let _ = world.remove_body(seen.bodies[input.pick(seen.bodies.len())]);
    }
    let _ = set_contacts(&mut world, &seen, input);
    if input.flag() {
        world = asleep(&world, &seen);
    }
    // Last, so that the sleep seeds still reach their sleep state.
    for _ in 0..input.pick(3) {
        if !seen.bodies.is_empty() {
            let body = seen.bodies[input.pick(seen.bodies.len())];
            let _ = body_drive(&mut world, body, input);
        }
    }
    world
}

/// `world` moved into a world without gravity, its bodies stopped, two
/// more still ones added (a ball, and a pair held by a socket), and
/// stepped for a second: the two and every island of `world`'s that its
/// drives and rest shapes leave still fall asleep, so the snapshot carries
/// a real sleep state (asleep and awake islands, stillness, anchors) for
/// the changes to break.
fn asleep(world: &World, seen: &Seen) -> World {
    let config = SolverConfig {
        gravity: Vec3::ZERO,
        ..SolverConfig::default()
    };
    let mut calm = World::new(config).expect("a valid config");
    calm.restore(&world.snapshot())
        .expect("a world's own snapshot restores");
    for &body in &seen.bodies {
        let _ = calm.set_body_velocity(body, Vec3::ZERO, Vec3::ZERO);
    }
    let ball = Shape::Sphere { radius: 0.1 }
        .mass_properties_with_mass(1.0)
        .expect("a valid ball");
    let [_, a, b] = [-2.0f32, 2.0, 2.3].map(|x| {
        calm.add_body(BodyDesc::dynamic(ball).with_position(Vec3::new(x, 5.0, 0.0)))
            .expect("a valid body")
    });
    let socket =
        JointDesc::socket_at_world_anchor(calm.bodies(), a, b, Vec3::new(2.15, 5.0, 0.0), Vec3::X)
            .expect("a valid socket");
    calm.add_joint(socket).expect("a valid joint");
    for _ in 0..60 {
        calm.step(1.0 / 60.0).expect("a valid time step");
    }
    calm
}

/// The rod's rest shape set moving (fixed rates: reading them from the
/// input would give older corpus files another meaning).
fn moving(world: &mut World, rod: RodHandle) -> Result<(), vertebra_world::Error> {
    let desc = world.rod(rod)?;
    world.set_rod(rod, desc.with_rest_velocity(Vec3::new(0.4, -1.5, 0.9), 2.5))
}

/// The joint's drive, if it has one, made still (the input's drives all
/// move: a tame velocity is never zero).
fn still(world: &mut World, joint: JointHandle) -> Result<(), vertebra_world::Error> {
    let Some(drive) = world.joint(joint)?.drive else {
        return Ok(());
    };
    world.set_joint_drive(joint, Some(drive.with_target_velocity(Vec3::ZERO)))
}

/// Restores `snapshot` (`world`'s own, untouched) into a fresh world, and
/// after each of 3 steps the world's new snapshot into another: every copy
/// must step on bit for bit as the world does (equal state hashes after
/// every step), moving drives and rest shapes included, however many steps
/// the world had taken. Then puts `world` back to `snapshot`.
fn continues_bit_for_bit(world: &mut World, snapshot: &Snapshot) {
    let mut copies: Vec<World> = Vec::new();
    for k in 0..4 {
        let mut copy = World::new(*world.config()).expect("a valid config");
        let taken = if k == 0 {
            snapshot.clone()
        } else {
            world.snapshot()
        };
        copy.restore(&taken)
            .expect("a world's own snapshot restores");
        copies.push(copy);
        world.step(1.0 / 60.0).expect("a valid time step");
        for (c, copy) in copies.iter_mut().enumerate() {
            copy.step(1.0 / 60.0).expect("a valid time step");
            assert_eq!(
                copy.state_hash(),
                world.state_hash(),
                "restored after {c} steps, diverged {} steps later",
                k - c + 1
            );
        }
    }
    world
        .restore(snapshot)
        .expect("a world's own snapshot restores");
}

/// `payload` under `header`'s format and build, with a correct checksum.
fn sealed(header: &[u8], payload: &[u8]) -> Snapshot {
    let mut bytes = header[..16].to_vec();
    bytes.extend_from_slice(&xxhash_rust::xxh3::xxh3_64(payload).to_le_bytes());
    bytes.extend_from_slice(payload);
    Snapshot::from_bytes(bytes)
}

/// Builds a small world from the input, snapshots it, checks that fresh
/// worlds restoring its snapshots step on bit for bit as it does
/// (`continues_bit_for_bit`) and puts it back to the snapshot; then
/// changes the decoded state (up to 4 field changes: floats to NaN,
/// infinities, huge values; indices, generations, lineages, lengths,
/// colours) or the payload's bytes (then re-checksummed), and restores the
/// result into the world and into a fresh one. Each restore either refuses with a named error and leaves
/// its world exactly as it was, or accepts, and then 3 steps keep every
/// body finite without the step's NaN guard firing.
pub fn snapshot(data: &[u8]) {
    let mut input = Input::new(data);
    let mut world = build(&mut input);
    let original = world.snapshot();
    continues_bit_for_bit(&mut world, &original);
    let (header, payload) = original.as_bytes().split_at(HEADER);
    let mut state: State = postcard::from_bytes(payload).expect("a valid snapshot decodes");
    let encoded = postcard::to_allocvec(&state).expect("encodes");
    assert_eq!(
        encoded, payload,
        "the fuzzer's State has drifted from the world's"
    );
    let crafted = if input.pick(4) == 0 {
        let mut bytes = encoded;
        for _ in 0..1 + input.pick(4) {
            let k = input.pick(bytes.len());
            match (input.pick(3), bytes.get_mut(k)) {
                (0, Some(byte)) => *byte ^= 1 << input.pick(8),
                (1, Some(byte)) => *byte = input.pick(256) as u8,
                _ => bytes.truncate(k),
            }
        }
        sealed(header, &bytes)
    } else {
        for _ in 0..1 + input.pick(4) {
            change(&mut input, &mut state);
        }
        sealed(header, &postcard::to_allocvec(&state).expect("encodes"))
    };
    let fresh = World::new(*world.config()).expect("a valid config");
    for mut target in [world, fresh] {
        let before = target.snapshot();
        match target.restore(&crafted) {
            Err(error) => {
                assert!(!error.to_string().is_empty());
                assert_eq!(target.snapshot(), before, "refused ({error}) but changed");
            }
            Ok(()) => {
                for _ in 0..3 {
                    target.step(1.0 / 60.0).expect("a valid time step");
                    let store = target.bodies();
                    for i in 0..store.capacity() {
                        assert!(store.is_finite(i), "body {i} went non-finite");
                    }
                }
                assert_eq!(target.repaired_bodies(), 0, "the NaN guard fired");
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    /// The corpus's sleep seeds build worlds with islands asleep and awake
    /// (the target's changes then break a real sleep state).
    #[test]
    fn the_sleep_seeds_reach_a_sleep_state() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus/snapshot");
        let mut seeds = 0;
        let mut some_awake = false;
        for entry in std::fs::read_dir(dir).expect("the corpus") {
            let path = entry.expect("an entry").path();
            if !path.to_string_lossy().contains("seed-sleep") {
                continue;
            }
            let data = std::fs::read(&path).expect("a seed");
            let world = build(&mut Input::new(&data));
            let (islands, asleep) = world.island_count();
            assert!(
                asleep >= 2,
                "{}: {asleep} of {islands} islands asleep",
                path.display()
            );
            some_awake |= asleep < islands;
            seeds += 1;
        }
        assert!(seeds >= 8, "{seeds} sleep seeds");
        assert!(some_awake, "no sleep seed keeps an island awake");
    }
}
