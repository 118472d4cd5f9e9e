//! Arbitrary call sequences through the C ABI, with the structs filled as
//! a C caller may fill them: any enum value, any float bits, handles that
//! were issued, removed, or never were.
//!
//! The promises checked: no call returns `VT_RESULT_PANIC` (nor, so,
//! `VT_RESULT_POISONED`); a refused call leaves the world and the
//! collision layer as they were (their snapshots' bytes, or the layer's
//! refusal to take one for a world it no longer serves); every body is
//! finite after every step.

use std::ptr::{null, null_mut};

use glam::{Quat, Vec3};
use vertebra_capi::*;

use crate::input::Input;

/// The objects of one run, freed at its end.
struct Run {
    world: *mut VtWorld,
    collisions: *mut VtCollisions,
    desc: *mut VtRagdollDesc,
    ragdolls: Vec<*mut VtRagdoll>,
    bodies: Vec<VtBody>,
    joints: Vec<VtJoint>,
    rods: Vec<VtRod>,
}

impl Drop for Run {
    fn drop(&mut self) {
        // SAFETY: objects made by this run, each destroyed once, here
        // (destroy takes null).
        unsafe {
            for ragdoll in &self.ragdolls {
                vt_ragdoll_destroy(*ragdoll);
            }
            vt_ragdoll_desc_destroy(self.desc);
            vt_collisions_destroy(self.collisions);
            vt_world_destroy(self.world);
        }
    }
}

fn v(p: Vec3) -> VtVec3 {
    p.into()
}

/// A C enum field: one of its `n` values, or (one time in eight) any bits.
fn tag(input: &mut Input, n: usize) -> u32 {
    match input.pick(8) {
        0 => input.pick(usize::MAX) as u32,
        _ => input.pick(n) as u32,
    }
}

/// Snapshot bytes, or nothing (the world refused to take one: a bug).
fn bytes(made: VtResult, bytes: *mut VtBytes) -> Vec<u8> {
    assert_eq!(made, VtResult::Ok, "a snapshot is always taken");
    let (mut data, mut len) = (null(), 0);
    // SAFETY: `bytes` was just made; copied before it is freed.
    unsafe {
        assert_eq!(vt_bytes_data(bytes, &mut data, &mut len), VtResult::Ok);
        let out = std::slice::from_raw_parts(data, len).to_vec();
        vt_bytes_destroy(bytes);
        out
    }
}

impl Run {
    /// The world's and the layer's whole state, as bytes; the layer's
    /// refusal instead when it does not serve the world as it is (the world
    /// was restored without the layer's snapshot after it).
    fn state(&self) -> (Vec<u8>, Result<Vec<u8>, VtResult>) {
        let (mut w, mut c) = (null_mut(), null_mut());
        // SAFETY: live objects of this run; output places on the stack.
        let (a, b) = unsafe {
            (
                vt_world_snapshot(self.world, &mut w),
                vt_collisions_snapshot(self.collisions, self.world, &mut c),
            )
        };
        let layer = match b {
            VtResult::Ok => Ok(bytes(b, c)),
            refused => {
                assert_eq!(refused, VtResult::WorldMismatch, "a layer snapshot refused");
                Err(refused)
            }
        };
        (bytes(a, w), layer)
    }

    fn body(&self, input: &mut Input) -> VtBody {
        match (self.bodies.is_empty(), input.pick(16)) {
            (false, 1..) => self.bodies[input.pick(self.bodies.len())],
            _ => VtBody {
                index: input.pick(4) as u32,
                lineage: input.pick(usize::MAX) as u32,
                generation: input.pick(4) as u64,
            },
        }
    }

    fn shape(input: &mut Input) -> VtShape {
        VtShape {
            kind: tag(input, 3),
            radius: input.float(0.5),
            half_extents: v(input.vec3(0.5)),
            half_segment: v(input.vec3(0.5)),
        }
    }

    /// One call; its result.
    fn call(&mut self, input: &mut Input) -> VtResult {
        let (world, collisions) = (self.world, self.collisions);
        // SAFETY: live objects of this run and pointers to locals of the
        // lengths passed.
        unsafe {
            match input.pick(15) {
                0 | 1 => {
                    let mut desc = VtBodyDesc {
                        kind: tag(input, 3),
                        position: v(input.vec3(3.0)),
                        orientation: input.quat().into(),
                        linear_velocity: v(input.vec3(5.0)),
                        angular_velocity: v(input.vec3(5.0)),
                        has_mass: 0,
                        mass: VtMassProperties {
                            mass: 0.0,
                            inertia: [0.0; 9],
                        },
                        linear_damping: input.tame(1.0).abs(),
                        angular_damping: input.tame(1.0).abs(),
                    };
                    if input.flag() {
                        let shape = Self::shape(input);
                        let made =
                            vt_shape_mass_properties(&shape, input.float(50.0), &mut desc.mass);
                        desc.has_mass = u32::from(made == VtResult::Ok || input.flag());
                    }
                    let mut body = VtBody {
                        index: 0,
                        lineage: 0,
                        generation: 0,
                    };
                    let result = vt_world_add_body(world, &desc, &mut body);
                    if result == VtResult::Ok {
                        self.bodies.push(body);
                        let collider = VtCollider {
                            body,
                            kind: tag(input, 2),
                            shape: Self::shape(input),
                            plane_normal: v(input.vec3(1.0)),
                            friction: input.float(1.0),
                            restitution: input.tame(1.0).abs(),
                            membership: u32::MAX,
                            filter: u32::MAX,
                        };
                        let added = vt_collisions_add(collisions, &collider, null_mut());
                        assert_ne!(added, VtResult::Panic);
                    }
                    result
                }
                2 => {
                    let (a, b) = (self.body(input), self.body(input));
                    let mut desc = std::mem::zeroed::<VtJointDesc>();
                    let made = vt_joint_at_world_anchor(
                        world,
                        tag(input, 3),
                        a,
                        b,
                        v(input.vec3(3.0)),
                        v(input.vec3(1.0)),
                        &mut desc,
                    );
                    if made != VtResult::Ok {
                        return made;
                    }
                    desc.swing.kind = tag(input, 4);
                    desc.swing.half_angle = input.float(3.5);
                    desc.swing.half_angle_y = input.float(3.5);
                    desc.swing.half_angle_z = input.float(3.5);
                    desc.has_range = u32::from(input.flag());
                    desc.range_min = input.float(3.5);
                    desc.range_max = input.float(3.5);
                    desc.softness = VtSoftness {
                        kind: tag(input, 3),
                        a: input.float(100.0),
                        b: input.float(10.0),
                    };
                    desc.has_drive = u32::from(input.flag());
                    desc.drive.target = input.quat().into();
                    desc.drive.strength = VtSoftness {
                        kind: tag(input, 3),
                        a: input.float(100.0),
                        b: input.float(10.0),
                    };
                    desc.drive.max_torque = input.float(1e3);
                    desc.has_breaking = u32::from(input.flag());
                    desc.break_force = input.float(500.0);
                    desc.break_torque = input.float(100.0);
                    let mut joint = std::mem::zeroed();
                    let result = vt_world_add_joint(world, &desc, &mut joint);
                    if result == VtResult::Ok {
                        self.joints.push(joint);
                    }
                    result
                }
                3 => {
                    let (a, b) = (self.body(input), self.body(input));
                    let through = [v(input.vec3(3.0))];
                    let mut desc = std::mem::zeroed::<VtRodDesc>();
                    let made =
                        vt_rod_from_pose(world, a, b, through.as_ptr(), input.pick(2), &mut desc);
                    if made != VtResult::Ok {
                        return made;
                    }
                    desc.bending = VtStiffness {
                        kind: tag(input, 4),
                        a: input.float(100.0),
                        b: input.float(10.0),
                    };
                    desc.has_bend_limit = u32::from(input.flag());
                    desc.bend_limit = input.float(3.5);
                    let mut rod = std::mem::zeroed();
                    let result = vt_world_add_rod(world, &desc, &mut rod);
                    if result == VtResult::Ok {
                        self.rods.push(rod);
                    }
                    result
                }
                4 => vt_world_step(world, input.float(0.05)),
                5 => {
                    let body = self.body(input);
                    vt_world_push(world, body, tag(input, 4), v(input.vec3(50.0)))
                }
                6 => {
                    let body = self.body(input);
                    vt_world_push_at(
                        world,
                        body,
                        tag(input, 4),
                        v(input.vec3(50.0)),
                        v(input.vec3(3.0)),
                    )
                }
                7 => {
                    let body = self.body(input);
                    match input.pick(4) {
                        0 => vt_world_set_body_pose(
                            world,
                            body,
                            v(input.vec3(3.0)),
                            input.quat().into(),
                        ),
                        1 => vt_world_set_body_velocity(
                            world,
                            body,
                            v(input.vec3(5.0)),
                            v(input.vec3(5.0)),
                        ),
                        2 => vt_world_set_body_kind(world, body, tag(input, 3)),
                        _ => vt_world_move_kinematic(
                            world,
                            body,
                            v(input.vec3(3.0)),
                            input.quat().into(),
                            input.float(0.05),
                        ),
                    }
                }
                8 => match input.pick(3) {
                    0 => vt_world_remove_body(world, self.body(input)),
                    1 if !self.joints.is_empty() => {
                        vt_world_remove_joint(world, self.joints[input.pick(self.joints.len())])
                    }
                    _ if !self.rods.is_empty() => {
                        vt_world_remove_rod(world, self.rods[input.pick(self.rods.len())])
                    }
                    _ => VtResult::Ok,
                },
                9 => {
                    let contacts: Vec<VtContact> = (0..input.pick(4))
                        .map(|_| VtContact {
                            body_a: self.body(input),
                            body_b: self.body(input),
                            point: v(input.vec3(3.0)),
                            normal: v(input.vec3(1.0)),
                            depth: input.float(0.1),
                            friction: input.float(1.0),
                            restitution: input.tame(1.0),
                        })
                        .collect();
                    vt_world_set_contacts(world, contacts.as_ptr(), contacts.len())
                }
                10 => vt_collisions_update(collisions, world, input.float(0.05)),
                11 => {
                    let mut pose = vec![VtTransform::from((Vec3::ZERO, Quat::IDENTITY)); 13];
                    assert_eq!(
                        vt_ragdoll_desc_bind_pose(self.desc, pose.as_mut_ptr(), 13),
                        VtResult::Ok
                    );
                    let lift = input.vec3(3.0);
                    for body in &mut pose {
                        body.position = v(Vec3::from(body.position) + lift);
                    }
                    let options = VtBuildOptions {
                        spine: tag(input, 2),
                        at_switch: u32::from(input.flag()),
                        stabilise: u32::from(input.flag()),
                        stabilise_ratio: input.float(10.0),
                    };
                    let layer = if input.flag() { collisions } else { null_mut() };
                    let mut ragdoll = null_mut();
                    let result = vt_ragdoll_build(
                        world,
                        layer,
                        self.desc,
                        &options,
                        pose.as_ptr(),
                        null(),
                        13,
                        1.0 / 60.0,
                        &mut ragdoll,
                    );
                    if result == VtResult::Ok {
                        self.ragdolls.push(ragdoll);
                    }
                    result
                }
                12 if !self.ragdolls.is_empty() => {
                    let ragdoll = self.ragdolls[input.pick(self.ragdolls.len())];
                    match input.pick(4) {
                        0 => {
                            let settings = VtDriveSettings {
                                strength: VtStrength {
                                    kind: tag(input, 3),
                                    a: input.float(1.0),
                                    b: input.float(2.0),
                                },
                                damping: input.float(10.0),
                                max_torque: input.float(1e3),
                            };
                            let mut pose =
                                vec![VtTransform::from((Vec3::ZERO, Quat::IDENTITY)); 13];
                            vt_ragdoll_desc_bind_pose(self.desc, pose.as_mut_ptr(), 13);
                            vt_ragdoll_drive_to(ragdoll, world, pose.as_ptr(), 13, &settings)
                        }
                        1 => vt_ragdoll_apply_impulse(
                            ragdoll,
                            world,
                            c"hips".as_ptr(),
                            v(input.vec3(50.0)),
                            null(),
                        ),
                        2 => vt_ragdoll_set_velocity(
                            ragdoll,
                            world,
                            v(input.vec3(5.0)),
                            v(input.vec3(5.0)),
                        ),
                        _ => vt_ragdoll_remove(
                            ragdoll,
                            world,
                            if input.flag() { collisions } else { null_mut() },
                        ),
                    }
                }
                13 => self.game_call(input),
                _ => {
                    // A snapshot taken and restored, or crafted bytes; the
                    // layer's restored after it, or not (then the layer
                    // refuses the world until a later restore of both).
                    let (mut world_bytes, layer_bytes) = self.state();
                    if input.flag() && !world_bytes.is_empty() {
                        let at = input.pick(world_bytes.len());
                        world_bytes[at] ^= 1 << input.pick(8);
                    }
                    let restored = vt_world_restore(world, world_bytes.as_ptr(), world_bytes.len());
                    if let (VtResult::Ok, Ok(layer_bytes), true) =
                        (restored, layer_bytes, input.flag())
                    {
                        let before = self.state();
                        let r = vt_collisions_restore(
                            collisions,
                            world,
                            layer_bytes.as_ptr(),
                            layer_bytes.len(),
                        );
                        assert!(!matches!(r, VtResult::Panic | VtResult::Poisoned));
                        if r != VtResult::Ok {
                            assert!(self.state() == before, "a refused layer restore changed it");
                        }
                    }
                    restored
                }
            }
        }
    }

    /// One of the calls a game makes every frame: the frame in one call,
    /// what follows a step, queries and shots with any filter and shape,
    /// and the step's outputs read into arrays of any capacity.
    fn game_call(&mut self, input: &mut Input) -> VtResult {
        let (world, collisions) = (self.world, self.collisions);
        let filter = VtQueryFilter {
            membership: input.pick(usize::MAX) as u32,
            filter: input.pick(usize::MAX) as u32,
            has_exclude_body: u32::from(input.flag()),
            exclude_body: self.body(input),
            has_exclude_ragdoll: u32::from(input.flag()),
            exclude_ragdoll: self.body(input),
            static_bodies: u32::from(input.flag()),
            kinematic_bodies: u32::from(input.flag()),
            dynamic_bodies: u32::from(input.flag()),
        };
        let capacity = input.pick(8);
        let mut count = 0;
        // SAFETY: live objects of this run; output places on the stack or
        // in vectors of `capacity` items (plain structs: zeroed is a
        // value).
        unsafe {
            let (mut hit, mut found) = (std::mem::zeroed::<VtQueryHit>(), 0);
            match input.pick(8) {
                0 => vt_collisions_step(collisions, world, input.float(0.05)),
                1 => vt_collisions_after_step(collisions, world),
                2 => vt_collisions_cast_ray(
                    collisions,
                    world,
                    v(input.vec3(5.0)),
                    v(input.vec3(1.0)),
                    input.float(20.0),
                    &filter,
                    &mut hit,
                    &mut found,
                ),
                3 => vt_collisions_shoot(
                    collisions,
                    world,
                    v(input.vec3(5.0)),
                    v(input.vec3(1.0)),
                    input.float(20.0),
                    input.float(100.0),
                    &filter,
                    &mut hit,
                    &mut found,
                ),
                4 | 5 => {
                    let shape = VtQueryShape {
                        kind: tag(input, 2),
                        radius: input.float(1.0),
                        half_segment: v(input.vec3(1.0)),
                    };
                    let pose = VtTransform::from((input.vec3(5.0), input.quat()));
                    let mut out = vec![std::mem::zeroed::<VtOverlap>(); capacity];
                    match input.flag() {
                        true => vt_collisions_cast_shape(
                            collisions,
                            world,
                            &shape,
                            pose,
                            v(input.vec3(1.0)),
                            input.float(20.0),
                            &filter,
                            &mut hit,
                            &mut found,
                        ),
                        false => vt_collisions_overlaps(
                            collisions,
                            world,
                            &shape,
                            pose,
                            &filter,
                            out.as_mut_ptr(),
                            capacity,
                            &mut count,
                        ),
                    }
                }
                6 => {
                    let mut touching = vec![std::mem::zeroed::<VtTouching>(); capacity];
                    let mut ended = vec![std::mem::zeroed::<VtContactEnded>(); capacity];
                    let mut contacts = vec![std::mem::zeroed::<VtContact>(); capacity];
                    let mut impulses = vec![std::mem::zeroed::<VtContactImpulse>(); capacity];
                    let mut broken = vec![std::mem::zeroed::<VtBrokenJoint>(); capacity];
                    match input.pick(5) {
                        0 => vt_collisions_began(
                            collisions,
                            touching.as_mut_ptr(),
                            capacity,
                            &mut count,
                        ),
                        1 => vt_collisions_touching(
                            collisions,
                            touching.as_mut_ptr(),
                            capacity,
                            &mut count,
                        ),
                        2 => vt_collisions_ended(
                            collisions,
                            ended.as_mut_ptr(),
                            capacity,
                            &mut count,
                        ),
                        3 => vt_world_solved_contacts(
                            world,
                            contacts.as_mut_ptr(),
                            impulses.as_mut_ptr(),
                            capacity,
                            &mut count,
                        ),
                        _ => {
                            vt_world_broken_joints(world, broken.as_mut_ptr(), capacity, &mut count)
                        }
                    }
                }
                _ => {
                    let joint = match self.joints.is_empty() {
                        false => self.joints[input.pick(self.joints.len())],
                        true => VtJoint::default(),
                    };
                    let (mut load, mut residual) =
                        (std::mem::zeroed::<VtJointForce>(), std::mem::zeroed());
                    let (mut island, mut present) = (0, 0);
                    match input.pick(3) {
                        0 => vt_world_joint_force(world, joint, &mut load),
                        1 => vt_world_joint_residual(world, joint, &mut residual),
                        _ => vt_world_island(world, self.body(input), &mut island, &mut present),
                    }
                }
            }
        }
    }

    /// Every live body is finite.
    fn check_finite(&self) {
        for body in &self.bodies {
            let mut state = std::mem::MaybeUninit::<VtBodyState>::uninit();
            // SAFETY: a live world; an output place on the stack.
            if unsafe { vt_world_body_state(self.world, *body, state.as_mut_ptr()) } == VtResult::Ok
            {
                // SAFETY: written by the call that succeeded.
                let s = unsafe { state.assume_init() };
                let p = [s.position.x, s.position.y, s.position.z, s.orientation.w];
                assert!(
                    p.iter().all(|x| x.is_finite()),
                    "a body is not finite: {s:?}"
                );
            }
        }
    }
}

/// Arbitrary call sequences through the C ABI (module docs).
pub fn capi(data: &[u8]) {
    let mut input = Input::new(data);
    let mut config = std::mem::MaybeUninit::<VtSolverConfig>::uninit();
    // SAFETY: an output place on the stack.
    let made = unsafe { vt_solver_config_default(config.as_mut_ptr()) };
    assert_eq!(made, VtResult::Ok);
    // SAFETY: written by the call that succeeded.
    let mut config = unsafe { config.assume_init() };
    config.iterations = 1 + input.pick(8) as u32;
    config.joints = tag(&mut input, 2);
    let mut run = Run {
        world: null_mut(),
        collisions: null_mut(),
        desc: null_mut(),
        ragdolls: Vec::new(),
        bodies: Vec::new(),
        joints: Vec::new(),
        rods: Vec::new(),
    };
    // SAFETY: output places in `run`; the config on the stack.
    unsafe {
        if vt_world_create(&config, &mut run.world) != VtResult::Ok {
            assert_eq!(vt_world_create(null(), &mut run.world), VtResult::Ok);
        }
        assert_eq!(vt_collisions_create(&mut run.collisions), VtResult::Ok);
        let humanoid = VtHumanoid::Reference as u32;
        assert_eq!(
            vt_ragdoll_desc_humanoid(humanoid, &mut run.desc),
            VtResult::Ok
        );
    }
    for _ in 0..48 {
        if input.is_empty() {
            break;
        }
        let before = run.state();
        let result = run.call(&mut input);
        assert!(
            !matches!(result, VtResult::Panic | VtResult::Poisoned),
            "a call panicked: {result:?}"
        );
        if result != VtResult::Ok {
            assert!(
                run.state() == before,
                "a refused call ({result:?}) changed the world"
            );
        }
        run.check_finite();
    }
}
