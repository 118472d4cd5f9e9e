//! Arbitrary sequences of adding and removing bodies, colliders and
//! ragdolls, with snapshots of the world and the collision set (intact and
//! crafted: bytes overwritten, or the decoded state's counters, group ids,
//! lists, handles and margin changed) and steps with collision detection.

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};
use vertebra_collide::{
    Collider, ColliderShape, CollisionGroups, CollisionSnapshot, Collisions,
    MAX_SELF_COLLISION_GROUPS, RagdollPart,
};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, SpineMode};
use vertebra_world::{BodyDesc, BodyHandle, Error, Shape, Snapshot, SolverConfig, World};

use crate::input::Input;

const DT: f32 = 1.0 / 60.0;

/// The world, the collision set and the ragdolls in it, with the bodies
/// added one by one.
struct Scene {
    world: World,
    collisions: Collisions,
    ragdolls: Vec<Ragdoll>,
    bodies: Vec<BodyHandle>,
    desc: RagdollDesc,
}

/// What a refused call must leave as it was: the world (state hash and
/// counts), the set (its snapshot bytes) and every ragdoll's handles.
type Fingerprint = (
    u64,
    usize,
    usize,
    usize,
    Result<CollisionSnapshot, Error>,
    Vec<String>,
);

/// The collision snapshot's payload, as `docs/contacts.md` documents it
/// (format 4; the header is magic 8, version 4, xxh3 8). A valid snapshot
/// must round-trip through it, so a format change fails the corpus replay
/// until this copy follows.
#[derive(Serialize, Deserialize)]
struct Payload {
    census: u64,
    prediction: f32,
    colliders: Vec<Collider>,
    excluded: Vec<(BodyHandle, BodyHandle)>,
    parts: Vec<(BodyHandle, RagdollPart)>,
    touching: Vec<(BodyHandle, BodyHandle)>,
    apart: Vec<(BodyHandle, u64)>,
    next_apart: u64,
}

/// A group counter or group id of the kind that breaks things: the ends of
/// the range, the limit and either side of it, and near `current`.
fn counter(input: &mut Input, current: u64) -> u64 {
    let limit = MAX_SELF_COLLISION_GROUPS;
    let near = [
        0,
        1,
        current.wrapping_sub(1),
        current,
        current.wrapping_add(1),
        limit - 1,
        limit,
        limit + 1,
        u64::MAX,
    ];
    near[input.pick(near.len())]
}

/// `handle` made stale (a later generation), foreign (another lineage) or
/// pointing at another slot.
fn skewed(input: &mut Input, handle: BodyHandle) -> BodyHandle {
    let (index, lineage, generation) = handle.to_raw();
    match input.pick(3) {
        0 => BodyHandle::from_raw(index, lineage, generation + 1),
        1 => BodyHandle::from_raw(index, lineage ^ 1, generation),
        _ => BodyHandle::from_raw(index + 1, lineage, generation),
    }
}

impl Scene {
    fn fingerprint(&self) -> Fingerprint {
        (
            self.world.state_hash(),
            self.world.bodies().len(),
            self.world.joints().count(),
            self.world.rods().count(),
            self.collisions.snapshot(&self.world),
            self.ragdolls
                .iter()
                .map(|r| format!("{:?} {:?} {:?}", r.bodies, r.joints, r.rod))
                .collect(),
        )
    }

    fn body(&self, input: &mut Input) -> Option<BodyHandle> {
        (!self.bodies.is_empty()).then(|| self.bodies[input.pick(self.bodies.len())])
    }

    fn ragdoll(&self, input: &mut Input) -> Option<usize> {
        (!self.ragdolls.is_empty()).then(|| input.pick(self.ragdolls.len()))
    }

    /// A dynamic body with an arbitrary collider on it; the body goes again
    /// if the set refuses the collider.
    fn add_body(&mut self, input: &mut Input) -> Result<(), Error> {
        let shape = crate::world::shape(input);
        let body = self.world.add_body(
            BodyDesc::dynamic(Shape::Sphere { radius: 0.2 }.mass_properties(500.0)?)
                .with_position(input.vec3(3.0) + Vec3::Y * 3.0)
                .with_velocity(input.vec3(5.0), input.vec3(5.0)),
        )?;
        let collider = Collider {
            body,
            shape: ColliderShape::Solid(shape),
            friction: input.float(1.0),
            restitution: input.float(1.0),
            groups: Self::groups(input),
        };
        let set = self.collisions.snapshot(&self.world);
        if self.collisions.add(collider).is_err() {
            // The set refused the collider and must be as it was; the body
            // goes again, which the world rightly counts as a change (its
            // slot's generation moved), so this is no refused call.
            assert!(
                self.collisions.snapshot(&self.world) == set,
                "a refused collider changed the set"
            );
            self.world.remove_body(body)?;
        } else {
            self.bodies.push(body);
        }
        Ok(())
    }

    /// A ragdoll built and its colliders added, in two calls or in one.
    fn add_ragdoll(&mut self, input: &mut Input) -> Result<(), Error> {
        let options = BuildOptions::new([SpineMode::Rod, SpineMode::Sockets][input.pick(2)]);
        let pose = Pose::bind(&self.desc).moved(Vec3::ZERO, input.quat(), input.vec3(3.0));
        let refused = |_| Error::InvalidConfig("ragdoll refused");
        let ragdoll = if input.pick(2) == 0 {
            let ragdoll = Ragdoll::build(&mut self.world, &self.desc, options, &pose, None)
                .map_err(refused)?;
            self.collisions.add_ragdoll(&ragdoll).map_err(refused)?;
            ragdoll
        } else {
            self.collisions
                .build_ragdoll(&mut self.world, &self.desc, options, &pose, None)
                .map_err(refused)?
        };
        self.ragdolls.push(ragdoll);
        Ok(())
    }

    /// Groups from a few bits, so that some pairs match and some do not.
    fn groups(input: &mut Input) -> CollisionGroups {
        CollisionGroups {
            membership: input.pick(4) as u32,
            filter: input.pick(4) as u32,
        }
    }

    /// Groups on a body's colliders, on a ragdoll's, or a ragdoll's
    /// self-collision on or off (refused for a body or ragdoll whose
    /// colliders are gone).
    fn set_groups(&mut self, input: &mut Input) -> Result<(), Error> {
        let groups = Self::groups(input);
        match (input.pick(3), self.body(input), self.ragdoll(input)) {
            (0, Some(body), _) => self.collisions.set_body_groups(body, groups),
            (1, _, Some(k)) => self
                .collisions
                .set_ragdoll_groups(&self.ragdolls[k], groups)
                .map_err(|_| Error::InvalidConfig("ragdoll groups refused")),
            (2, _, Some(k)) => {
                let collide = input.pick(2) == 0;
                self.collisions
                    .set_ragdoll_self_collision(&self.ragdolls[k], collide)
                    .map_err(|_| Error::InvalidConfig("ragdoll self-collision refused"))
            }
            _ => Ok(()),
        }
    }

    /// A body out of the world and the set, the world's way first.
    fn remove_body(&mut self, input: &mut Input) -> Result<(), Error> {
        let Some(body) = self.body(input) else {
            return Ok(());
        };
        self.world.remove_body(body)?;
        self.collisions.remove_body(body);
        Ok(())
    }

    /// The last world and set snapshots with the ragdolls of the time
    /// restored together: the set after the world, as documented.
    fn restore(&mut self, saved: &(Snapshot, CollisionSnapshot, Vec<Ragdoll>)) {
        self.world.restore(&saved.0).expect("its own snapshot");
        self.collisions
            .restore(&saved.1, &self.world)
            .expect("the set saved with the world");
        self.ragdolls = saved.2.clone();
    }

    /// A crafted collision snapshot: the saved bytes with a few bytes
    /// overwritten and the checksum made right again (the format is
    /// documented: magic 8, version 4, xxh3 8, payload).
    fn restore_crafted(
        &mut self,
        saved: &CollisionSnapshot,
        input: &mut Input,
    ) -> Result<(), Error> {
        let mut bytes = saved.as_bytes().to_vec();
        for _ in 0..1 + input.pick(4) {
            let at = input.pick(bytes.len());
            bytes[at] = input.pick(256) as u8;
        }
        if bytes.len() >= 20 && input.pick(4) > 0 {
            let sum = xxhash_rust::xxh3::xxh3_64(&bytes[20..]);
            bytes[12..20].copy_from_slice(&sum.to_le_bytes());
        }
        self.collisions
            .restore(&CollisionSnapshot::from_bytes(bytes), &self.world)
    }

    /// A crafted collision state: the saved snapshot decoded through the
    /// documented layout (which must give its bytes back), one to three of
    /// its values changed (the group counter and group ids to the ends of
    /// their range, the limit and either side of it; the world's bodies it
    /// was taken with; the lists' order, repeats and a pair's bodies; a
    /// handle made stale, foreign or another slot; the margin; groups),
    /// encoded and sealed, and restored. When the set takes it, every
    /// ragdoll's self-collision is turned off once more, which must give a
    /// new group or be refused with nothing changed.
    fn restore_crafted_state(
        &mut self,
        saved: &CollisionSnapshot,
        input: &mut Input,
    ) -> Result<(), Error> {
        let bytes = saved.as_bytes();
        let mut p: Payload = postcard::from_bytes(&bytes[20..]).expect("the documented layout");
        let body = postcard::to_allocvec(&p).expect("encodes");
        assert!(body == bytes[20..], "the layout copy is out of date");
        for _ in 0..1 + input.pick(3) {
            match input.pick(10) {
                0 | 1 => p.next_apart = counter(input, p.next_apart),
                2 if !p.apart.is_empty() => {
                    let k = input.pick(p.apart.len());
                    p.apart[k].1 = counter(input, p.next_apart);
                }
                3 => p.census ^= 1 << input.pick(64),
                4 if p.excluded.len() > 1 => {
                    let k = 1 + input.pick(p.excluded.len() - 1);
                    p.excluded.swap(0, k);
                }
                4 | 5 if !p.excluded.is_empty() => {
                    let k = input.pick(p.excluded.len());
                    let (a, b) = p.excluded[k];
                    if input.flag() {
                        p.excluded[k] = (b, a);
                    } else {
                        p.excluded.insert(k, (a, b));
                    }
                }
                6 if !p.apart.is_empty() => {
                    let k = input.pick(p.apart.len());
                    match input.pick(3) {
                        0 => p.apart.insert(k, p.apart[k]),
                        1 => drop(p.apart.remove(k)),
                        _ => p.apart[k].0 = skewed(input, p.apart[k].0),
                    }
                }
                7 if !p.colliders.is_empty() => {
                    let k = input.pick(p.colliders.len());
                    let collider = &mut p.colliders[k];
                    if input.flag() {
                        collider.body = skewed(input, collider.body);
                    } else {
                        collider.groups = Self::groups(input);
                    }
                }
                8 => p.prediction = [f32::NAN, -1.0, 0.0, 1e30][input.pick(4)],
                _ => {}
            }
        }
        let body = postcard::to_allocvec(&p).expect("encodes");
        let mut crafted = [&bytes[..20], &body[..]].concat();
        let sum = xxhash_rust::xxh3::xxh3_64(&crafted[20..]);
        crafted[12..20].copy_from_slice(&sum.to_le_bytes());
        self.collisions
            .restore(&CollisionSnapshot::from_bytes(crafted), &self.world)?;
        for k in 0..self.ragdolls.len() {
            let before = self.fingerprint();
            let turned = self
                .collisions
                .set_ragdoll_self_collision(&self.ragdolls[k], false);
            if turned.is_err() {
                assert!(self.fingerprint() == before, "refused but changed");
            }
            self.check();
        }
        Ok(())
    }

    /// Collision detection and a step: contacts always come (no collider
    /// outlives its body here), and the world always takes them.
    fn step(&mut self) -> Result<(), Error> {
        let contacts = self
            .collisions
            .find_contacts(&self.world, DT)
            .expect("every collider's body is in the world");
        self.world
            .set_contacts(&contacts)
            .expect("the world takes every contact found");
        self.world.step(DT)
    }

    /// Every collider's body is in the world, every pending contact's too,
    /// and every body is finite; the set serves the world, and its own
    /// snapshot restores with the same bytes (a group counter that had
    /// wrapped made it refuse its own snapshot).
    fn check(&self) {
        let own = self
            .collisions
            .snapshot(&self.world)
            .expect("the set serves its world");
        let mut copy = self.collisions.clone();
        copy.restore(&own, &self.world)
            .expect("the set's own snapshot restores");
        assert!(copy.snapshot(&self.world).as_ref() == Ok(&own));
        let live = |b: BodyHandle| self.world.body(b).is_ok();
        assert!(self.collisions.colliders().all(|c| live(c.body)));
        assert!(
            self.world
                .contacts()
                .iter()
                .all(|c| live(c.body_a) && live(c.body_b))
        );
        let store = self.world.bodies();
        for i in (0..store.capacity()).filter(|&i| store.is_live(i)) {
            assert!(store.is_finite(i), "body {i} went non-finite");
        }
    }
}

/// Up to 48 calls on a world with a ground plane, its collision set and
/// ragdolls: bodies with arbitrary colliders added and removed, ragdolls
/// added (in one call or two), removed, recreated (also after a joint of
/// theirs was removed by hand), pairs excluded, groups set on bodies and
/// ragdolls, ragdolls' self-collision turned off and on, the margin set, both snapshots taken and
/// restored, crafted collision snapshots restored (bytes, or decoded
/// values: counters, group ids, lists, handles), steps with detection.
/// No panic; a refused call leaves the world, the set and the ragdolls as
/// they were; no collider or contact outlives its body; the set's own
/// snapshot always restores.
pub fn collisions(data: &[u8]) {
    let mut input = Input::new(data);
    let mut world = World::new(SolverConfig::default()).expect("a valid config");
    let mut collisions = Collisions::new();
    let ground = world
        .add_body(BodyDesc::fixed())
        .expect("a fixed body at the origin");
    collisions
        .add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .expect("the ground plane");
    let mut scene = Scene {
        world,
        collisions,
        ragdolls: Vec::new(),
        bodies: Vec::new(),
        desc: RagdollDesc::reference_humanoid(),
    };
    let mut saved = (
        scene.world.snapshot(),
        scene
            .collisions
            .snapshot(&scene.world)
            .expect("a new set serves its world"),
        Vec::new(),
    );
    for _ in 0..48 {
        if input.is_empty() {
            break;
        }
        let before = scene.fingerprint();
        let result = match input.pick(13) {
            0 => scene.add_body(&mut input),
            1 => scene.add_ragdoll(&mut input),
            2 => scene.remove_body(&mut input),
            3 => match scene.ragdoll(&mut input) {
                Some(k) => scene
                    .collisions
                    .remove_ragdoll(&mut scene.world, &mut scene.ragdolls[k])
                    .map_err(|_| Error::InvalidConfig("ragdoll removal refused")),
                None => Ok(()),
            },
            4 => match scene.ragdoll(&mut input) {
                Some(k) => {
                    let pose = Pose::bind(&scene.desc).moved(
                        Vec3::ZERO,
                        Quat::IDENTITY,
                        input.vec3(3.0) + Vec3::Y,
                    );
                    scene
                        .collisions
                        .recreate_ragdoll(&mut scene.world, &mut scene.ragdolls[k], &pose, None)
                        .map_err(|_| Error::InvalidConfig("ragdoll recreation refused"))
                }
                None => Ok(()),
            },
            5 => match scene.ragdoll(&mut input) {
                Some(k) => {
                    let sockets = &scene.ragdolls[k].joints;
                    match sockets[input.pick(sockets.len())] {
                        Some(socket) => scene.world.remove_joint(socket),
                        None => Ok(()),
                    }
                }
                None => Ok(()),
            },
            6 => {
                saved = (
                    scene.world.snapshot(),
                    scene
                        .collisions
                        .snapshot(&scene.world)
                        .expect("serves its world"),
                    scene.ragdolls.clone(),
                );
                Ok(())
            }
            7 => {
                scene.restore(&saved);
                Ok(())
            }
            8 if input.flag() => scene.restore_crafted(&saved.1, &mut input),
            8 => scene.restore_crafted_state(&saved.1, &mut input),
            9 => {
                if let (Some(a), Some(b)) = (scene.body(&mut input), scene.body(&mut input)) {
                    scene.collisions.exclude(a, b);
                }
                Ok(())
            }
            10 => scene.collisions.set_prediction(input.float(0.1)),
            11 => scene.set_groups(&mut input),
            _ => scene.step(),
        };
        if let Err(error) = result {
            assert!(!error.to_string().is_empty());
            assert!(
                scene.fingerprint() == before,
                "refused ({error}) but changed something"
            );
        }
        scene.check();
    }
}
