//! The C ABI called as C calls it, through the crate's `extern "C"`
//! functions: every refusal's code and message, the promise that a refused
//! call changes nothing and writes no output, the round trips through
//! snapshots, and the objects built through C equal to those built through
//! the Rust API, bit for bit.

use std::ffi::{CStr, CString, c_char, c_void};
use std::ptr::{null, null_mut};

use glam::{Quat, Vec3};
use vertebra_capi::*;
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{
    BuildOptions, DriveSettings, LocalPose, Pose, Ragdoll, RagdollDesc, Skeleton, SkeletonMapper,
    SpineMapping, SpineMode, Transform,
};
use vertebra_world::{
    AngularDrive, BodyDesc, JointDesc, JointKind, JointSolver, LimitSoftness, PinContacts, RodDesc,
    RodStiffness, Shape, SolverConfig, Spring, Swing, SwingTwist, World,
};

const DT: f32 = 1.0 / 60.0;

/// This thread's last refusal's message.
fn message() -> String {
    // SAFETY: vt_last_error_message returns a NUL-terminated string valid
    // until this thread's next refusal.
    unsafe { CStr::from_ptr(vt_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

/// Asserts `result` is the refusal `code` with a message naming each of
/// `words`.
#[track_caller]
fn refused(result: VtResult, code: VtResult, words: &[&str]) {
    let text = message();
    assert_eq!(result, code, "{text}");
    for word in words {
        assert!(text.contains(word), "`{text}` does not name `{word}`");
    }
}

#[track_caller]
fn ok(result: VtResult) {
    assert_eq!(result, VtResult::Ok, "{}", message());
}

fn v(x: f32, y: f32, z: f32) -> VtVec3 {
    VtVec3 { x, y, z }
}

const IDENTITY: VtQuat = VtQuat {
    x: 0.0,
    y: 0.0,
    z: 0.0,
    w: 1.0,
};

/// A world (default settings), freed on drop.
struct CWorld(*mut VtWorld);

impl CWorld {
    fn new() -> Self {
        let mut world = null_mut();
        // SAFETY: null config (the defaults); `world` is a writable place.
        ok(unsafe { vt_world_create(null(), &mut world) });
        Self(world)
    }

    fn hash(&self) -> u64 {
        let mut hash = 0;
        // SAFETY: a live world; `hash` is writable.
        ok(unsafe { vt_world_state_hash(self.0, &mut hash) });
        hash
    }

    /// The world's whole state (bodies, joints, rods, contacts, sleep) as
    /// its snapshot's bytes.
    fn bytes(&self) -> Vec<u8> {
        let mut snapshot = null_mut();
        // SAFETY: a live world; `snapshot` is writable.
        ok(unsafe { vt_world_snapshot(self.0, &mut snapshot) });
        let (mut data, mut length) = (null(), 0);
        // SAFETY: live bytes; the outputs are writable.
        ok(unsafe { vt_bytes_data(snapshot, &mut data, &mut length) });
        // SAFETY: `data` holds `length` bytes until vt_bytes_destroy.
        let copy = unsafe { std::slice::from_raw_parts(data, length) }.to_vec();
        // SAFETY: made by vt_world_snapshot, freed once.
        unsafe { vt_bytes_destroy(snapshot) };
        copy
    }

    fn step(&self, steps: usize) {
        for _ in 0..steps {
            // SAFETY: a live world.
            ok(unsafe { vt_world_step(self.0, DT) });
        }
    }

    fn add(&self, desc: &VtBodyDesc) -> VtBody {
        let mut body = bits_body();
        // SAFETY: a live world; `desc` readable, `body` writable.
        ok(unsafe { vt_world_add_body(self.0, desc, &mut body) });
        body
    }
}

impl Drop for CWorld {
    fn drop(&mut self) {
        // SAFETY: made by vt_world_create, freed once.
        unsafe { vt_world_destroy(self.0) }
    }
}

/// A body handle of made-up bits.
fn bits_body() -> VtBody {
    VtBody {
        index: 7777,
        lineage: 0xdead,
        generation: 99,
    }
}

/// A dynamic box of 2 kg, 0.2 m by 0.4 m by 0.2 m, at `position`.
fn box_desc(position: VtVec3) -> VtBodyDesc {
    let shape = VtShape {
        kind: VtShapeKind::Box as u32,
        radius: 0.0,
        half_extents: v(0.1, 0.2, 0.1),
        half_segment: v(0.0, 0.0, 0.0),
    };
    let mut desc = body_desc(VtBodyKind::Dynamic);
    // SAFETY: `shape` readable, `mass` writable.
    ok(unsafe { vt_shape_mass_properties(&shape, 2.0, &mut desc.mass) });
    desc.has_mass = 1;
    desc.position = position;
    desc
}

fn body_desc(kind: VtBodyKind) -> VtBodyDesc {
    let mut desc = std::mem::MaybeUninit::<VtBodyDesc>::uninit();
    // SAFETY: `desc` is writable; vt_body_desc_default writes it whole.
    ok(unsafe { vt_body_desc_default(kind as u32, desc.as_mut_ptr()) });
    // SAFETY: written just above.
    unsafe { desc.assume_init() }
}

/// The Rust twin of [`box_desc`].
fn rust_box(position: Vec3) -> BodyDesc {
    let shape = Shape::Box {
        half_extents: Vec3::new(0.1, 0.2, 0.1),
    };
    let mass = shape.mass_properties_with_mass(2.0).expect("mass");
    BodyDesc {
        position,
        ..BodyDesc::dynamic(mass)
    }
}

/// A world with a static ground body, two boxes jointed by a socket, a
/// third box on a rod from the second, and a contact: something of every
/// part for refused calls to leave alone.
struct Scene {
    world: CWorld,
    ground: VtBody,
    a: VtBody,
    b: VtBody,
    c: VtBody,
    joint: VtJoint,
    rod: VtRod,
}

impl Scene {
    fn new() -> Self {
        let world = CWorld::new();
        let ground = world.add(&body_desc(VtBodyKind::Static));
        let a = world.add(&box_desc(v(0.0, 1.0, 0.0)));
        let b = world.add(&box_desc(v(0.0, 1.4, 0.0)));
        let c = world.add(&box_desc(v(0.0, 1.8, 0.1)));
        let joint = socket(&world, a, b, v(0.0, 1.2, 0.0));
        let rod = rod(&world, b, c);
        let contact = VtContact {
            body_a: ground,
            body_b: a,
            point: v(0.0, 0.8, 0.0),
            normal: v(0.0, 1.0, 0.0),
            depth: 0.01,
            friction: 0.5,
            restitution: 0.0,
        };
        // SAFETY: a live world; one readable contact.
        ok(unsafe { vt_world_set_contacts(world.0, &contact, 1) });
        world.step(3);
        Self {
            world,
            ground,
            a,
            b,
            c,
            joint,
            rod,
        }
    }

    fn w(&self) -> *mut VtWorld {
        self.world.0
    }

    /// Runs `call`, which must be refused with `code` naming `words`, and
    /// checks that the world is exactly as before.
    #[track_caller]
    fn refuses(&self, code: VtResult, words: &[&str], call: impl FnOnce() -> VtResult) {
        let before = self.world.bytes();
        refused(call(), code, words);
        assert!(
            before == self.world.bytes(),
            "a refused call changed the world"
        );
    }
}

fn joint_desc_at(
    world: &CWorld,
    kind: VtJointKind,
    a: VtBody,
    b: VtBody,
    at: VtVec3,
) -> VtJointDesc {
    let mut desc = std::mem::MaybeUninit::<VtJointDesc>::uninit();
    // SAFETY: a live world; `desc` is writable and written whole on success.
    ok(unsafe {
        vt_joint_at_world_anchor(
            world.0,
            kind as u32,
            a,
            b,
            at,
            v(0.0, 1.0, 0.0),
            desc.as_mut_ptr(),
        )
    });
    // SAFETY: written just above.
    unsafe { desc.assume_init() }
}

fn socket(world: &CWorld, a: VtBody, b: VtBody, at: VtVec3) -> VtJoint {
    let desc = joint_desc_at(world, VtJointKind::Socket, a, b, at);
    let mut joint = VtJoint {
        index: 0,
        lineage: 0,
        generation: 0,
    };
    // SAFETY: a live world; `desc` readable, `joint` writable.
    ok(unsafe { vt_world_add_joint(world.0, &desc, &mut joint) });
    joint
}

fn rod_desc(world: &CWorld, a: VtBody, b: VtBody) -> VtRodDesc {
    let mut desc = std::mem::MaybeUninit::<VtRodDesc>::uninit();
    // SAFETY: a live world; no points; `desc` writable.
    ok(unsafe { vt_rod_from_pose(world.0, a, b, null(), 0, desc.as_mut_ptr()) });
    // SAFETY: written just above.
    unsafe { desc.assume_init() }
}

fn rod(world: &CWorld, a: VtBody, b: VtBody) -> VtRod {
    let desc = rod_desc(world, a, b);
    let mut rod = VtRod {
        index: 0,
        lineage: 0,
        generation: 0,
    };
    // SAFETY: a live world; `desc` readable, `rod` writable.
    ok(unsafe { vt_world_add_rod(world.0, &desc, &mut rod) });
    rod
}

const NULL: VtResult = VtResult::NullPointer;

#[test]
fn a_null_world_is_refused_by_every_world_call() {
    let s = Scene::new();
    let w: *mut VtWorld = null_mut();
    let (a, b) = (s.a, s.b);
    let mut config = std::mem::MaybeUninit::<VtSolverConfig>::uninit();
    let (mut hash, mut residuals) = (0u64, VtResiduals::default());
    let desc = box_desc(v(0.0, 0.0, 0.0));
    let mut body = bits_body();
    let mut state = std::mem::MaybeUninit::<VtBodyState>::uninit();
    let mut flag = 7u32;
    let mut jdesc = joint_desc_at(&s.world, VtJointKind::Fixed, a, b, v(0.0, 1.2, 0.0));
    let mut joint = s.joint;
    let mut rdesc = rod_desc(&s.world, a, b);
    let mut rod = s.rod;
    let mut count = 0usize;
    let mut snapshot = null_mut();
    let tasks = VtTaskSystem {
        workers: 2,
        parallel_for: Some(serial),
        context: null_mut(),
    };
    // SAFETY: every call gets a null world (refused before it is read) and
    // otherwise valid places.
    let calls: Vec<(&str, VtResult)> = unsafe {
        vec![
            ("config", vt_world_config(w, config.as_mut_ptr())),
            ("step", vt_world_step(w, DT)),
            ("hash", vt_world_state_hash(w, &mut hash)),
            ("residuals", vt_world_measure_residuals(w, &mut residuals)),
            ("tasks", vt_world_set_tasks(w, &tasks)),
            ("add_body", vt_world_add_body(w, &desc, &mut body)),
            ("remove_body", vt_world_remove_body(w, a)),
            ("body_state", vt_world_body_state(w, a, state.as_mut_ptr())),
            (
                "pose",
                vt_world_set_body_pose(w, a, v(0.0, 0.0, 0.0), IDENTITY),
            ),
            (
                "velocity",
                vt_world_set_body_velocity(w, a, v(0.0, 0.0, 0.0), v(0.0, 0.0, 0.0)),
            ),
            ("kind", vt_world_set_body_kind(w, a, 1)),
            (
                "kinematic",
                vt_world_move_kinematic(w, a, v(0.0, 0.0, 0.0), IDENTITY, DT),
            ),
            ("push", vt_world_push(w, a, 0, v(0.0, 1.0, 0.0))),
            (
                "push_at",
                vt_world_push_at(w, a, 0, v(0.0, 1.0, 0.0), v(0.0, 0.0, 0.0)),
            ),
            ("wake", vt_world_wake(w, a)),
            ("asleep", vt_world_is_asleep(w, a, &mut flag)),
            ("sleep_allowed", vt_world_set_sleep_allowed(w, a, 1)),
            (
                "joint_at",
                vt_joint_at_world_anchor(
                    w,
                    0,
                    a,
                    b,
                    v(0.0, 0.0, 0.0),
                    v(1.0, 0.0, 0.0),
                    &mut jdesc,
                ),
            ),
            ("add_joint", vt_world_add_joint(w, &jdesc, &mut joint)),
            ("remove_joint", vt_world_remove_joint(w, joint)),
            ("joint", vt_world_joint(w, joint, &mut jdesc)),
            ("drive", vt_world_set_joint_drive(w, joint, null())),
            ("world_drive", vt_world_set_world_drive(w, a, null())),
            ("upright_drive", vt_world_set_upright_drive(w, a, null())),
            (
                "rod_from_pose",
                vt_rod_from_pose(w, a, b, null(), 0, &mut rdesc),
            ),
            ("add_rod", vt_world_add_rod(w, &rdesc, &mut rod)),
            ("set_rod", vt_world_set_rod(w, rod, &rdesc)),
            ("rod", vt_world_rod(w, rod, &mut rdesc)),
            ("remove_rod", vt_world_remove_rod(w, rod)),
            ("set_contacts", vt_world_set_contacts(w, null(), 0)),
            ("contacts", vt_world_contacts(w, null_mut(), 0, &mut count)),
            ("snapshot", vt_world_snapshot(w, &mut snapshot)),
            ("restore", vt_world_restore(w, null(), 0)),
        ]
    };
    for (name, result) in calls {
        assert_eq!(result, NULL, "{name}");
    }
    assert_eq!(message(), "world is null");
    // Nothing was written.
    assert_eq!((hash, flag, count), (0, 7, 0));
    assert_eq!(body, bits_body());
    assert!(snapshot.is_null());
}

/// A job system that runs every item on the calling thread, in order.
///
/// # Safety
/// As `VtParallelFor`: `task` and `task_context` are the world's item.
unsafe extern "C" fn serial(
    _context: *mut c_void,
    count: u32,
    task: VtTaskFn,
    task_context: *const c_void,
) {
    for i in 0..count {
        // SAFETY: the world's item, called as VtParallelFor's contract says.
        unsafe { task(task_context, i) };
    }
}

#[test]
fn a_null_argument_is_refused_naming_it_and_changes_nothing() {
    let s = Scene::new();
    let (w, a, b) = (s.w(), s.a, s.b);
    let desc = box_desc(v(0.0, 3.0, 0.0));
    let jdesc = joint_desc_at(&s.world, VtJointKind::Fixed, a, s.c, v(0.0, 1.6, 0.0));
    let rdesc = rod_desc(&s.world, a, s.c);
    // Every call below: a live world, null where the argument
    // named is refused, and otherwise writable places.
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["config"], || unsafe {
        vt_world_config(w, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["hash"], || unsafe {
        vt_world_state_hash(w, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["residuals"], || unsafe {
        vt_world_measure_residuals(w, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["tasks"], || unsafe {
        vt_world_set_tasks(w, null())
    });
    let no_callback = VtTaskSystem {
        workers: 2,
        parallel_for: None,
        context: null_mut(),
    };
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["tasks.parallel_for"], || unsafe {
        vt_world_set_tasks(w, &no_callback)
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["desc"], || unsafe {
        vt_world_add_body(w, null(), &mut bits_body())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["body"], || unsafe {
        vt_world_add_body(w, &desc, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["state"], || unsafe {
        vt_world_body_state(w, a, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["asleep"], || unsafe {
        vt_world_is_asleep(w, a, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["desc"], || unsafe {
        vt_joint_at_world_anchor(w, 0, a, b, v(0.0, 1.2, 0.0), v(0.0, 1.0, 0.0), null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["desc"], || unsafe {
        vt_world_add_joint(w, null(), &mut s.joint.clone())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["joint"], || unsafe {
        vt_world_add_joint(w, &jdesc, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["desc"], || unsafe {
        vt_world_joint(w, s.joint, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["through"], || unsafe {
        vt_rod_from_pose(w, a, b, null(), 2, &mut rod_desc(&s.world, a, b))
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["desc"], || unsafe {
        vt_rod_from_pose(w, a, b, null(), 0, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["desc"], || unsafe {
        vt_world_add_rod(w, null(), &mut s.rod.clone())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["rod"], || unsafe {
        vt_world_add_rod(w, &rdesc, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["desc"], || unsafe {
        vt_world_set_rod(w, s.rod, null())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["desc"], || unsafe {
        vt_world_rod(w, s.rod, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["contacts"], || unsafe {
        vt_world_set_contacts(w, null(), 3)
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["count"], || unsafe {
        vt_world_contacts(w, null_mut(), 0, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["snapshot"], || unsafe {
        vt_world_snapshot(w, null_mut())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(NULL, &["data"], || unsafe {
        vt_world_restore(w, null(), 10)
    });
    // SAFETY: null places are refused before anything is read.
    unsafe {
        refused(vt_world_create(null(), null_mut()), NULL, &["world"]);
        refused(vt_solver_config_default(null_mut()), NULL, &["config"]);
        refused(vt_solver_config_paper(null_mut()), NULL, &["config"]);
        refused(vt_body_desc_default(0, null_mut()), NULL, &["desc"]);
        let mut mass = desc.mass;
        refused(
            vt_shape_mass_properties(null(), 1.0, &mut mass),
            NULL,
            &["shape"],
        );
        let shape = VtShape {
            kind: 0,
            radius: 1.0,
            half_extents: v(0.0, 0.0, 0.0),
            half_segment: v(0.0, 0.0, 0.0),
        };
        refused(
            vt_shape_mass_properties(&shape, 1.0, null_mut()),
            NULL,
            &["mass_properties"],
        );
        let (mut data, mut length) = (null(), 0usize);
        refused(
            vt_bytes_data(null(), &mut data, &mut length),
            NULL,
            &["bytes"],
        );
        // Destroying null does nothing.
        vt_world_destroy(null_mut());
        vt_bytes_destroy(null_mut());
        vt_collisions_destroy(null_mut());
        vt_ragdoll_desc_destroy(null_mut());
        vt_ragdoll_destroy(null_mut());
        vt_skeleton_destroy(null_mut());
        vt_skeleton_mapper_destroy(null_mut());
    }
}

#[test]
fn a_misaligned_pointer_is_refused_naming_it() {
    let s = Scene::new();
    let mut storage = [0u64; 4];
    let odd = storage.as_mut_ptr().cast::<u8>().wrapping_add(1);
    // SAFETY: a live world; the misaligned place is refused before use.
    s.refuses(NULL, &["hash", "aligned"], || unsafe {
        vt_world_state_hash(s.w(), odd.cast())
    });
    let misaligned_world = s.w().cast::<u8>().wrapping_add(1).cast::<VtWorld>();
    // SAFETY: refused before it is read.
    refused(
        unsafe { vt_world_step(misaligned_world, DT) },
        NULL,
        &["world", "aligned"],
    );
    assert_eq!(storage, [0; 4]);
}

/// The two presets are Rust's: the default (the direct solve, 1 x 8,
/// contacts relaxed) and the paper's (iterated, 1 x 20, not relaxed).
#[test]
fn the_presets_are_the_default_and_the_papers_settings() {
    for (preset, rust) in [
        (
            vt_solver_config_default as unsafe extern "C" fn(*mut VtSolverConfig) -> VtResult,
            SolverConfig::default(),
        ),
        (vt_solver_config_paper, SolverConfig::paper()),
    ] {
        let mut config = std::mem::MaybeUninit::<VtSolverConfig>::uninit();
        // SAFETY: writable.
        ok(unsafe { preset(config.as_mut_ptr()) });
        // SAFETY: written just above.
        let config = unsafe { config.assume_init() };
        assert_eq!(
            (config.joints, config.iterations, config.substeps),
            (
                u32::from(rust.joints == JointSolver::Direct),
                rust.iterations,
                rust.substeps
            )
        );
        assert_eq!(config.relax_contacts, u32::from(rust.relax_contacts));
        let pins = [
            (VtPinContacts::Never, PinContacts::Never),
            (VtPinContacts::Always, PinContacts::Always),
            (VtPinContacts::Driven, PinContacts::Driven),
        ];
        let pins = pins.iter().find(|(_, p)| *p == rust.pin_contacts);
        assert_eq!(Some(config.pin_contacts), pins.map(|(c, _)| *c as u32));
    }
    assert_eq!(
        (
            SolverConfig::default().joints,
            SolverConfig::default().iterations
        ),
        (JointSolver::Direct, 8)
    );
    assert_eq!(
        (
            SolverConfig::paper().joints,
            SolverConfig::paper().iterations
        ),
        (JointSolver::Iterative, 20)
    );
    assert!(SolverConfig::default().relax_contacts && !SolverConfig::paper().relax_contacts);
}

const ENUM: VtResult = VtResult::InvalidEnum;

#[test]
fn an_enum_out_of_range_is_refused_naming_the_field() {
    let s = Scene::new();
    let (w, a, b) = (s.w(), s.a, s.b);
    let mut body = bits_body();
    let mut desc = box_desc(v(0.0, 3.0, 0.0));
    desc.kind = 3;
    // Every call below: a live world and valid places; only the
    // enum is out of range.
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(ENUM, &["body.kind", "3"], || unsafe {
        vt_world_add_body(w, &desc, &mut body)
    });
    assert_eq!(body, bits_body());
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(ENUM, &["kind", "9"], || unsafe {
        vt_world_set_body_kind(w, a, 9)
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(ENUM, &["push"], || unsafe {
        vt_world_push(w, a, 4, v(0.0, 1.0, 0.0))
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(ENUM, &["push"], || unsafe {
        vt_world_push_at(w, a, 1, v(0.0, 1.0, 0.0), v(0.0, 1.0, 0.0))
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(ENUM, &["kind"], || unsafe {
        vt_joint_at_world_anchor(
            w,
            3,
            a,
            b,
            v(0.0, 1.2, 0.0),
            v(0.0, 1.0, 0.0),
            &mut joint_desc_at(&s.world, VtJointKind::Socket, a, b, v(0.0, 1.2, 0.0)),
        )
    });
    let good = joint_desc_at(&s.world, VtJointKind::Socket, a, s.c, v(0.0, 1.6, 0.0));
    let mut joint = s.joint;
    for (field, edit) in [
        (
            "joint.kind",
            (|d: &mut VtJointDesc| d.kind = 3) as fn(&mut VtJointDesc),
        ),
        ("swing.kind", |d| d.swing.kind = 4),
        ("softness.kind", |d| d.softness.kind = 3),
        ("drive.strength.kind", |d| {
            d.has_drive = 1;
            d.drive.strength.kind = 0;
        }),
        ("softness.kind", |d| {
            d.has_drive = 1;
            d.drive.strength.kind = 7;
        }),
    ] {
        let mut bad = good;
        edit(&mut bad);
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(ENUM, &[field], || unsafe {
            vt_world_add_joint(w, &bad, &mut joint)
        });
        assert_eq!(joint, s.joint);
    }
    let mut rod = rod_desc(&s.world, a, s.c);
    rod.bending.kind = 4;
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(ENUM, &["stiffness.kind"], || unsafe {
        vt_world_add_rod(w, &rod, &mut s.rod.clone())
    });
    let mut config = std::mem::MaybeUninit::<VtSolverConfig>::uninit();
    // SAFETY: writable.
    ok(unsafe { vt_solver_config_default(config.as_mut_ptr()) });
    // SAFETY: written just above.
    let config = unsafe { config.assume_init() };
    let mut made = null_mut();
    for (field, bad) in [
        (
            "config.backend",
            VtSolverConfig {
                backend: 8,
                ..config
            },
        ),
        (
            "config.joints",
            VtSolverConfig {
                joints: 2,
                ..config
            },
        ),
        (
            "config.pin_contacts",
            VtSolverConfig {
                pin_contacts: 3,
                ..config
            },
        ),
    ] {
        // SAFETY: readable config, writable place.
        refused(unsafe { vt_world_create(&bad, &mut made) }, ENUM, &[field]);
        assert!(made.is_null());
    }
    let mut out = desc;
    // SAFETY: writable.
    refused(
        unsafe { vt_body_desc_default(3, &mut out) },
        ENUM,
        &["kind"],
    );
    assert_eq!(out.kind, 3, "the output was written");
    let mut ragdoll_desc = null_mut();
    // SAFETY: writable.
    refused(
        unsafe { vt_ragdoll_desc_humanoid(2, &mut ragdoll_desc) },
        ENUM,
        &["humanoid"],
    );
    assert!(ragdoll_desc.is_null());
}

#[test]
fn a_stale_foreign_or_made_up_handle_is_refused() {
    let s = Scene::new();
    let other = Scene::new();
    let w = s.w();
    let extra = s.world.add(&box_desc(v(3.0, 0.0, 0.0)));
    // SAFETY: a live world.
    ok(unsafe { vt_world_remove_body(w, extra) });
    let mut state = std::mem::MaybeUninit::<VtBodyState>::uninit();
    let cases = [
        (extra, VtResult::StaleHandle),
        (other.a, VtResult::ForeignHandle),
        (bits_body(), VtResult::ForeignHandle),
        (
            VtBody {
                index: 1,
                generation: 12345,
                ..s.a
            },
            VtResult::StaleHandle,
        ),
        (
            VtBody {
                index: u32::MAX,
                ..s.a
            },
            VtResult::StaleHandle,
        ),
    ];
    for (body, code) in cases {
        // Each call: a live world and valid places; only the handle is bad.
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(code, &["body"], || unsafe {
            vt_world_body_state(w, body, state.as_mut_ptr())
        });
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(code, &["body"], || unsafe { vt_world_remove_body(w, body) });
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(code, &["body"], || unsafe {
            vt_world_set_body_pose(w, body, v(0.0, 0.0, 0.0), IDENTITY)
        });
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(code, &["body"], || unsafe {
            vt_world_push(w, body, 2, v(0.0, 1.0, 0.0))
        });
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(code, &["body"], || unsafe { vt_world_wake(w, body) });
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(code, &[], || unsafe {
            vt_joint_at_world_anchor(
                w,
                0,
                s.a,
                body,
                v(0.0, 0.0, 0.0),
                v(0.0, 1.0, 0.0),
                &mut joint_desc_at(&s.world, VtJointKind::Socket, s.a, s.b, v(0.0, 1.2, 0.0)),
            )
        });
        let contact = VtContact {
            body_a: s.a,
            body_b: body,
            point: v(0.0, 0.0, 0.0),
            normal: v(0.0, 1.0, 0.0),
            depth: 0.0,
            friction: 0.5,
            restitution: 0.0,
        };
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(code, &["body"], || unsafe {
            vt_world_set_contacts(w, &contact, 1)
        });
    }
    let joint = VtJoint {
        generation: s.joint.generation + 1,
        ..s.joint
    };
    let mut jdesc = joint_desc_at(&s.world, VtJointKind::Socket, s.a, s.b, v(0.0, 1.2, 0.0));
    // Each call: a live world and valid places.
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::StaleHandle, &["joint"], || unsafe {
        vt_world_joint(w, joint, &mut jdesc)
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::ForeignHandle, &["joint"], || unsafe {
        vt_world_remove_joint(w, other.joint)
    });
    let rod = VtRod { index: 40, ..s.rod };
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::StaleHandle, &["rod"], || unsafe {
        vt_world_remove_rod(w, rod)
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::ForeignHandle, &["rod"], || unsafe {
        vt_world_rod(w, other.rod, &mut rod_desc(&s.world, s.a, s.b))
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::BodyInUse, &[], || unsafe {
        vt_world_remove_body(w, s.a)
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    jdesc.body_b = jdesc.body_a;
    let mut joint = s.joint;
    // SAFETY: live objects; readable and writable places.
    s.refuses(VtResult::SameBody, &[], || unsafe {
        vt_world_add_joint(w, &jdesc, &mut joint)
    });
    assert_eq!(joint, s.joint);
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::NotDynamic, &[], || unsafe {
        vt_world_push(w, s.ground, 2, v(0.0, 1.0, 0.0))
    });
}

const NAN: f32 = f32::NAN;
const INF: f32 = f32::INFINITY;

#[test]
fn a_non_finite_or_non_unit_value_is_refused_and_changes_nothing() {
    let s = Scene::new();
    let (w, a) = (s.w(), s.a);
    let half = VtQuat {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 0.5,
    };
    // Every call below: a live world; only the value is bad.
    for bad in [NAN, INF, -INF] {
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["position"], || unsafe {
            vt_world_set_body_pose(w, a, v(bad, 0.0, 0.0), IDENTITY)
        });
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["velocity"], || unsafe {
            vt_world_set_body_velocity(w, a, v(0.0, bad, 0.0), v(0.0, 0.0, 0.0))
        });
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["impulse"], || unsafe {
            vt_world_push(w, a, 2, v(0.0, 0.0, bad))
        });
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["force"], || unsafe {
            vt_world_push(w, a, 0, v(bad, 0.0, 0.0))
        });
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["torque"], || unsafe {
            vt_world_push(w, a, 1, v(bad, 0.0, 0.0))
        });
        let mut desc = box_desc(v(0.0, bad, 0.0));
        let mut body = bits_body();
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["position"], || unsafe {
            vt_world_add_body(w, &desc, &mut body)
        });
        desc.position = v(0.0, 0.0, 0.0);
        desc.mass.inertia[4] = bad;
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &[], || unsafe {
            vt_world_add_body(w, &desc, &mut body)
        });
        assert_eq!(body, bits_body());
        let contact = VtContact {
            body_a: s.ground,
            body_b: a,
            point: v(0.0, 0.0, 0.0),
            normal: v(0.0, 1.0, 0.0),
            depth: bad,
            friction: 0.5,
            restitution: 0.0,
        };
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["contact", "depth"], || unsafe {
            vt_world_set_contacts(w, &contact, 1)
        });
        let mut joint = joint_desc_at(&s.world, VtJointKind::Socket, a, s.c, v(0.0, 1.6, 0.0));
        joint.anchor_a.y = bad;
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["anchor"], || unsafe {
            vt_world_add_joint(w, &joint, &mut s.joint.clone())
        });
        let mut rod = rod_desc(&s.world, a, s.c);
        rod.rest_length = bad;
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["rest"], || unsafe {
            vt_world_add_rod(w, &rod, &mut s.rod.clone())
        });
        let mut same_bodies = rod_desc(&s.world, s.b, s.c);
        same_bodies.rest_length = bad;
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["rest"], || unsafe {
            vt_world_set_rod(w, s.rod, &same_bodies)
        });
        let through = v(bad, 0.0, 0.0);
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &[], || unsafe {
            vt_rod_from_pose(w, a, s.c, &through, 1, &mut rod)
        });
        let drive = VtDrive {
            target: VtQuat { x: bad, ..IDENTITY },
            target_velocity: v(0.0, 0.0, 0.0),
            strength: VtSoftness {
                kind: 1,
                a: 0.0,
                b: 0.0,
            },
            max_torque: INF,
        };
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::NonFinite, &["target"], || unsafe {
            vt_world_set_joint_drive(w, s.joint, &drive)
        });
    }
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::NotNormalized, &["orientation"], || unsafe {
        vt_world_set_body_pose(w, a, v(0.0, 0.0, 0.0), half)
    });
    let mut joint = joint_desc_at(&s.world, VtJointKind::Hinge, a, s.c, v(0.0, 1.6, 0.0));
    joint.frame_b = half;
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::NotNormalized, &["frame"], || unsafe {
        vt_world_add_joint(w, &joint, &mut s.joint.clone())
    });
    let contact = VtContact {
        body_a: s.ground,
        body_b: a,
        point: v(0.0, 0.0, 0.0),
        normal: v(0.0, 2.0, 0.0),
        depth: 0.0,
        friction: 0.5,
        restitution: 0.0,
    };
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::NotNormalized, &["contact", "normal"], || unsafe {
        vt_world_set_contacts(w, &contact, 1)
    });
    for (dt, code) in [
        (NAN, VtResult::NonFinite),
        (INF, VtResult::NonFinite),
        (0.0, VtResult::NonPositive),
        (-DT, VtResult::NonPositive),
        (2.0, VtResult::OutOfRange),
    ] {
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(code, &["time step"], || unsafe { vt_world_step(w, dt) });
    }
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::OutOfRange, &["position"], || unsafe {
        vt_world_set_body_pose(w, a, v(1e30, 0.0, 0.0), IDENTITY)
    });
}

#[test]
fn a_world_pushed_to_the_limits_of_f32_stays_finite() {
    let s = Scene::new();
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    let w = s.w();
    // The largest values each call takes, again and again: every body
    // state stays finite.
    for _ in 0..10 {
        for body in [s.a, s.b, s.c] {
            // Each call: a live world; refusals are fine here, a
            // non-finite state is not.
            // SAFETY: live objects; every pointer null (refused) or valid for its type.
            unsafe {
                vt_world_push(w, body, 0, v(f32::MAX, -f32::MAX, f32::MAX));
                vt_world_push(w, body, 1, v(f32::MAX, f32::MAX, -f32::MAX));
                vt_world_push(w, body, 2, v(1e30, 1e30, 1e30));
                vt_world_push(w, body, 3, v(1e30, -1e30, 1e30));
                vt_world_push_at(w, body, 2, v(1e20, 0.0, 0.0), v(0.0, 1e6, 0.0));
                vt_world_set_body_velocity(w, body, v(f32::MAX, 0.0, 0.0), v(0.0, f32::MAX, 0.0));
            }
        }
        s.world.step(1);
    }
    for body in [s.a, s.b, s.c] {
        let mut state = std::mem::MaybeUninit::<VtBodyState>::uninit();
        // SAFETY: a live world; a writable place.
        ok(unsafe { vt_world_body_state(w, body, state.as_mut_ptr()) });
        // SAFETY: written just above.
        let state = unsafe { state.assume_init() };
        let numbers = [
            state.position.x,
            state.position.y,
            state.position.z,
            state.orientation.x,
            state.orientation.y,
            state.orientation.z,
            state.orientation.w,
            state.linear_velocity.x,
            state.linear_velocity.y,
            state.linear_velocity.z,
            state.angular_velocity.x,
            state.angular_velocity.y,
            state.angular_velocity.z,
        ];
        assert!(numbers.iter().all(|x| x.is_finite()), "{state:?}");
    }
}

#[test]
fn a_buffer_too_small_gets_only_the_needed_length() {
    let s = Scene::new();
    let w = s.w();
    let sentinel = VtContact {
        body_a: bits_body(),
        body_b: bits_body(),
        point: v(9.0, 9.0, 9.0),
        normal: v(9.0, 9.0, 9.0),
        depth: 9.0,
        friction: 9.0,
        restitution: 9.0,
    };
    let mut place = [sentinel; 2];
    let mut count = 77usize;
    let two = [
        VtContact {
            body_a: s.ground,
            body_b: s.a,
            point: v(0.0, 0.8, 0.0),
            normal: v(0.0, 1.0, 0.0),
            depth: 0.01,
            friction: 0.5,
            restitution: 0.0,
        },
        VtContact {
            body_a: s.ground,
            body_b: s.b,
            point: v(0.0, 0.8, 0.0),
            normal: v(0.0, 1.0, 0.0),
            depth: 0.0,
            friction: 0.5,
            restitution: 0.5,
        },
    ];
    // SAFETY: two readable contacts.
    ok(unsafe { vt_world_set_contacts(w, two.as_ptr(), 2) });
    // SAFETY: a live world; `count` writable; null with capacity 0 asks.
    s.refuses(VtResult::BufferTooSmall, &["contacts", "0"], || unsafe {
        vt_world_contacts(w, null_mut(), 0, &mut count)
    });
    assert_eq!(count, 2);
    // SAFETY: room for one contact.
    s.refuses(VtResult::BufferTooSmall, &["1", "2"], || unsafe {
        vt_world_contacts(w, place.as_mut_ptr(), 1, &mut count)
    });
    assert_eq!(count, 2);
    assert_eq!(format!("{:?}", place[0]), format!("{sentinel:?}"));
    // SAFETY: room for two.
    ok(unsafe { vt_world_contacts(w, place.as_mut_ptr(), 2, &mut count) });
    assert_eq!(format!("{place:?}"), format!("{two:?}"));

    let desc = humanoid();
    let mut buffer = [b'#' as c_char; 8];
    let mut length = 0usize;
    // SAFETY: a live description; 3 writable bytes of 8.
    refused(
        unsafe { vt_ragdoll_desc_body_name(desc.0, 0, buffer.as_mut_ptr(), 3, &mut length) },
        VtResult::BufferTooSmall,
        &["3", "5"],
    );
    assert_eq!(length, 5, "`hips` and its NUL");
    assert!(buffer.iter().all(|&c| c == b'#' as c_char));
    // SAFETY: as above, with room.
    ok(unsafe { vt_ragdoll_desc_body_name(desc.0, 0, buffer.as_mut_ptr(), 8, &mut length) });
    assert_eq!(&buffer[..5], b"hips\0".map(|c| c as c_char).as_slice());
    // SAFETY: as above; the index is out of range.
    refused(
        unsafe { vt_ragdoll_desc_body_name(desc.0, 13, buffer.as_mut_ptr(), 8, &mut length) },
        VtResult::OutOfRange,
        &["body 13", "13"],
    );

    let skeleton = CSkeleton::reference();
    let mut buffer = [b'#' as c_char; 64];
    length = 0;
    // SAFETY: a live skeleton; null buffer with capacity 0 asks.
    refused(
        unsafe { vt_skeleton_bone_name(skeleton.0, 0, null_mut(), 0, &mut length) },
        VtResult::BufferTooSmall,
        &[],
    );
    let needed = length;
    assert!(needed > 1);
    // SAFETY: one byte short.
    refused(
        unsafe {
            vt_skeleton_bone_name(skeleton.0, 0, buffer.as_mut_ptr(), needed - 1, &mut length)
        },
        VtResult::BufferTooSmall,
        &[],
    );
    assert!(buffer.iter().all(|&c| c == b'#' as c_char));
    // SAFETY: exactly enough.
    ok(unsafe { vt_skeleton_bone_name(skeleton.0, 0, buffer.as_mut_ptr(), needed, &mut length) });
    assert_eq!(buffer[needed - 1], 0);
    assert_eq!(buffer[needed], b'#' as c_char);

    // Pose arrays of the wrong length: refused, nothing written.
    let sentinel = VtTransform {
        position: v(9.0, 9.0, 9.0),
        rotation: IDENTITY,
    };
    for count in [12, 14] {
        let mut pose = vec![sentinel; 14];
        // SAFETY: `count` writable transforms.
        refused(
            unsafe { vt_ragdoll_desc_bind_pose(desc.0, pose.as_mut_ptr(), count) },
            VtResult::BufferTooSmall,
            &[&count.to_string(), "13"],
        );
        assert!(pose.iter().all(|t| t.position == sentinel.position));
    }
    let mut bones = vec![sentinel; 70];
    let mut count = 0;
    // SAFETY: a live skeleton; writable.
    ok(unsafe { vt_skeleton_bone_count(skeleton.0, &mut count) });
    // SAFETY: `count - 1` writable transforms.
    refused(
        unsafe { vt_skeleton_bind_pose(skeleton.0, bones.as_mut_ptr(), count - 1) },
        VtResult::BufferTooSmall,
        &[&(count - 1).to_string(), &count.to_string()],
    );
    assert!(bones.iter().all(|t| t.position == sentinel.position));
}

/// A ragdoll description, freed on drop.
struct CDesc(*mut VtRagdollDesc);

impl Drop for CDesc {
    fn drop(&mut self) {
        // SAFETY: made by a vt_ragdoll_desc_ function, freed once.
        unsafe { vt_ragdoll_desc_destroy(self.0) }
    }
}

fn humanoid() -> CDesc {
    let mut desc = null_mut();
    // SAFETY: writable.
    ok(unsafe { vt_ragdoll_desc_humanoid(VtHumanoid::Reference as u32, &mut desc) });
    CDesc(desc)
}

/// A skeleton, freed on drop.
struct CSkeleton(*mut VtSkeleton);

impl CSkeleton {
    fn reference() -> Self {
        let mut skeleton = null_mut();
        // SAFETY: writable.
        ok(unsafe { vt_skeleton_reference(&mut skeleton) });
        Self(skeleton)
    }
}

impl Drop for CSkeleton {
    fn drop(&mut self) {
        // SAFETY: made by vt_skeleton_reference, freed once.
        unsafe { vt_skeleton_destroy(self.0) }
    }
}

#[test]
fn the_last_message_is_per_thread_and_stays_valid() {
    let s = Scene::new();
    // SAFETY: a live world; the step is refused.
    refused(
        unsafe { vt_world_step(s.w(), -1.0) },
        VtResult::NonPositive,
        &["time step"],
    );
    let mine = vt_last_error_message();
    let text = message();
    std::thread::spawn(|| {
        assert_eq!(message(), "", "a new thread has no refusal");
        // SAFETY: null is refused.
        refused(unsafe { vt_world_step(null_mut(), DT) }, NULL, &["world"]);
    })
    .join()
    .expect("the other thread");
    // Successful calls leave it, and another thread's refusal does not touch it.
    s.world.step(2);
    assert_eq!(vt_last_error_message(), mine);
    // SAFETY: the pointer is valid until this thread's next refusal.
    assert_eq!(
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        unsafe { CStr::from_ptr(mine) }.to_str().expect("UTF-8"),
        text
    );
}

#[test]
fn every_result_code_has_its_name() {
    let codes = [
        (VtResult::Ok, "VT_RESULT_OK"),
        (VtResult::NullPointer, "VT_RESULT_NULL_POINTER"),
        (VtResult::InvalidEnum, "VT_RESULT_INVALID_ENUM"),
        (VtResult::NotUtf8, "VT_RESULT_NOT_UTF8"),
        (VtResult::BufferTooSmall, "VT_RESULT_BUFFER_TOO_SMALL"),
        (VtResult::NonFinite, "VT_RESULT_NON_FINITE"),
        (VtResult::NotNormalized, "VT_RESULT_NOT_NORMALIZED"),
        (VtResult::NonPositive, "VT_RESULT_NON_POSITIVE"),
        (VtResult::InvalidInertia, "VT_RESULT_INVALID_INERTIA"),
        (VtResult::DegenerateShape, "VT_RESULT_DEGENERATE_SHAPE"),
        (VtResult::SameBody, "VT_RESULT_SAME_BODY"),
        (VtResult::StaleHandle, "VT_RESULT_STALE_HANDLE"),
        (VtResult::ForeignHandle, "VT_RESULT_FOREIGN_HANDLE"),
        (VtResult::BodyInUse, "VT_RESULT_BODY_IN_USE"),
        (VtResult::NoDynamicBody, "VT_RESULT_NO_DYNAMIC_BODY"),
        (VtResult::NotDynamic, "VT_RESULT_NOT_DYNAMIC"),
        (VtResult::WrongKind, "VT_RESULT_WRONG_KIND"),
        (VtResult::InvalidLimit, "VT_RESULT_INVALID_LIMIT"),
        (VtResult::InvalidConfig, "VT_RESULT_INVALID_CONFIG"),
        (VtResult::InvalidJoint, "VT_RESULT_INVALID_JOINT"),
        (VtResult::OutOfRange, "VT_RESULT_OUT_OF_RANGE"),
        (
            VtResult::IncompatibleSnapshot,
            "VT_RESULT_INCOMPATIBLE_SNAPSHOT",
        ),
        (VtResult::CorruptSnapshot, "VT_RESULT_CORRUPT_SNAPSHOT"),
        (VtResult::Collider, "VT_RESULT_COLLIDER"),
        (VtResult::Ragdoll, "VT_RESULT_RAGDOLL"),
        (VtResult::Panic, "VT_RESULT_PANIC"),
        (VtResult::Poisoned, "VT_RESULT_POISONED"),
        (VtResult::WorldMismatch, "VT_RESULT_WORLD_MISMATCH"),
    ];
    for (k, (code, name)) in codes.into_iter().enumerate() {
        assert_eq!(code as u32, k as u32, "{name}: the codes count up from 0");
        // SAFETY: vt_result_name returns a static NUL-terminated string.
        let got = unsafe { CStr::from_ptr(vt_result_name(code as u32)) };
        assert_eq!(got.to_str(), Ok(name));
    }
    for unknown in [28, 1000, u32::MAX] {
        // SAFETY: as above.
        let got = unsafe { CStr::from_ptr(vt_result_name(unknown)) };
        assert_eq!(got.to_str(), Ok("VT_RESULT_UNKNOWN"));
    }
}

/// A collision layer, freed on drop.
struct CLayer(*mut VtCollisions);

impl CLayer {
    fn new() -> Self {
        let mut layer = null_mut();
        // SAFETY: writable.
        ok(unsafe { vt_collisions_create(&mut layer) });
        Self(layer)
    }

    /// The layer's snapshot, taken with `world`, which it serves.
    fn bytes(&self, world: &CWorld) -> Vec<u8> {
        let mut snapshot = null_mut();
        // SAFETY: live objects; writable.
        ok(unsafe { vt_collisions_snapshot(self.0, world.0, &mut snapshot) });
        let (mut data, mut length) = (null(), 0);
        // SAFETY: live bytes; writable outputs.
        ok(unsafe { vt_bytes_data(snapshot, &mut data, &mut length) });
        // SAFETY: `data` holds `length` bytes until vt_bytes_destroy.
        let copy = unsafe { std::slice::from_raw_parts(data, length) }.to_vec();
        // SAFETY: made above, freed once.
        unsafe { vt_bytes_destroy(snapshot) };
        copy
    }
}

impl Drop for CLayer {
    fn drop(&mut self) {
        // SAFETY: made by vt_collisions_create, freed once.
        unsafe { vt_collisions_destroy(self.0) }
    }
}

fn plane(body: VtBody) -> VtCollider {
    VtCollider {
        body,
        kind: VtColliderKind::Plane as u32,
        shape: VtShape {
            kind: 0,
            radius: 0.0,
            half_extents: v(0.0, 0.0, 0.0),
            half_segment: v(0.0, 0.0, 0.0),
        },
        plane_normal: v(0.0, 1.0, 0.0),
        friction: 0.6,
        restitution: 0.0,
        membership: u32::MAX,
        filter: u32::MAX,
    }
}

/// `vt_collider_default` on `body`.
fn default_collider(body: VtBody) -> VtCollider {
    let mut collider = std::mem::MaybeUninit::<VtCollider>::uninit();
    // SAFETY: `collider` is writable; vt_collider_default writes it whole.
    ok(unsafe { vt_collider_default(body, collider.as_mut_ptr()) });
    // SAFETY: written just above.
    unsafe { collider.assume_init() }
}

/// Where a box (0.1 x 0.2 x 0.1 m half extents) dropped from 0.5 m onto a
/// ground plane is after a second (its centre's height, m), both colliders
/// made from `collider` with the shape or plane set.
fn dropped_box(collider: impl Fn(VtBody) -> VtCollider) -> f32 {
    let world = CWorld::new();
    let layer = CLayer::new();
    let ground = world.add(&body_desc(VtBodyKind::Static));
    let mut plane = collider(ground);
    plane.kind = VtColliderKind::Plane as u32;
    plane.plane_normal = v(0.0, 1.0, 0.0);
    let body = world.add(&box_desc(v(0.0, 0.5, 0.0)));
    let mut solid = collider(body);
    solid.kind = VtColliderKind::Solid as u32;
    solid.shape = VtShape {
        kind: VtShapeKind::Box as u32,
        radius: 0.0,
        half_extents: v(0.1, 0.2, 0.1),
        half_segment: v(0.0, 0.0, 0.0),
    };
    for c in [plane, solid] {
        // SAFETY: a live layer; readable collider.
        ok(unsafe { vt_collisions_add(layer.0, &c, null_mut()) });
    }
    for _ in 0..60 {
        // SAFETY: live objects.
        ok(unsafe { vt_collisions_update(layer.0, world.0, DT) });
        world.step(1);
    }
    let mut state = std::mem::MaybeUninit::<VtBodyState>::uninit();
    // SAFETY: a live world; writable.
    ok(unsafe { vt_world_body_state(world.0, body, state.as_mut_ptr()) });
    // SAFETY: written by the call that succeeded.
    unsafe { state.assume_init() }.position.y
}

/// A zero-initialised `VtCollider` (groups 0) collides with nothing: a box on one falls through the ground without an error.
/// `vt_collider_default` gives the Rust API's `Collider::new`: every
/// group, friction 0.6, no restitution; a box on it rests on the ground.
/// Its shape left as written (a sphere of radius 0) is refused by
/// `vt_collisions_add`, naming the collider, so a forgotten shape is never
/// added; a null output is refused.
#[test]
fn a_default_collider_collides_with_everything_and_a_zeroed_one_with_nothing() {
    let fell = dropped_box(|body| VtCollider {
        body,
        friction: 0.6,
        // SAFETY: every field of VtCollider is a plain number: zero is valid.
        ..unsafe { std::mem::zeroed() }
    });
    assert!(fell < -1.0, "through the ground: {fell} m");
    let rests = dropped_box(default_collider);
    assert!((rests - 0.2).abs() < 0.01, "on the ground: {rests} m");
    let body = bits_body();
    let c = default_collider(body);
    let rust = Collider::new(body.into(), ColliderShape::Plane(Vec3::Y));
    assert_eq!((c.membership, c.filter), (u32::MAX, u32::MAX));
    assert_eq!(
        (c.friction, c.restitution),
        (rust.friction, rust.restitution)
    );
    assert_eq!(c.kind, VtColliderKind::Solid as u32);
    let layer = CLayer::new();
    // SAFETY: a live layer; readable collider.
    let r = unsafe { vt_collisions_add(layer.0, &c, null_mut()) };
    refused(r, VtResult::Collider, &["collider 0", "radius"]);
    // SAFETY: null is refused before anything is written.
    let r = unsafe { vt_collider_default(body, null_mut()) };
    refused(r, VtResult::NullPointer, &["collider"]);
}

/// A world with the humanoid dropped on a ground plane through the
/// collision layer: its world, layer, description and ragdoll.
struct Drop_ {
    world: CWorld,
    layer: CLayer,
    desc: CDesc,
    ragdoll: *mut VtRagdoll,
}

impl Drop_ {
    fn new(spine: VtSpineMode) -> Self {
        let world = CWorld::new();
        let layer = CLayer::new();
        let ground = world.add(&body_desc(VtBodyKind::Static));
        let mut index = 99usize;
        // SAFETY: a live layer; readable collider; writable index.
        ok(unsafe { vt_collisions_add(layer.0, &plane(ground), &mut index) });
        assert_eq!(index, 0);
        let desc = humanoid();
        let pose = lifted_bind(&desc, 0.3);
        let options = VtBuildOptions {
            spine: spine as u32,
            at_switch: 0,
            stabilise: 0,
            stabilise_ratio: 1.0,
        };
        let mut ragdoll = null_mut();
        // SAFETY: live objects; readable options and pose; writable place.
        ok(unsafe {
            vt_ragdoll_build(
                world.0,
                layer.0,
                desc.0,
                &options,
                pose.as_ptr(),
                null(),
                pose.len(),
                DT,
                &mut ragdoll,
            )
        });
        // SAFETY: live objects.
        ok(unsafe {
            vt_ragdoll_set_velocity(ragdoll, world.0, v(0.0, 0.0, 0.5), v(2.0, 0.0, 0.0))
        });
        Self {
            world,
            layer,
            desc,
            ragdoll,
        }
    }

    fn step(&self, steps: usize) {
        for _ in 0..steps {
            // SAFETY: live objects.
            ok(unsafe { vt_collisions_update(self.layer.0, self.world.0, DT) });
            self.world.step(1);
        }
    }
}

impl Drop for Drop_ {
    fn drop(&mut self) {
        // SAFETY: made by vt_ragdoll_build, freed once.
        unsafe { vt_ragdoll_destroy(self.ragdoll) }
    }
}

/// The description's bind pose moved up by `lift` (m).
fn lifted_bind(desc: &CDesc, lift: f32) -> Vec<VtTransform> {
    let mut count = 0;
    // SAFETY: a live description; writable.
    ok(unsafe { vt_ragdoll_desc_body_count(desc.0, &mut count) });
    let mut pose = vec![
        VtTransform {
            position: v(0.0, 0.0, 0.0),
            rotation: IDENTITY,
        };
        count
    ];
    // SAFETY: `count` writable transforms.
    ok(unsafe { vt_ragdoll_desc_bind_pose(desc.0, pose.as_mut_ptr(), count) });
    for t in &mut pose {
        t.position.y += lift;
    }
    pose
}

#[test]
fn a_snapshot_restored_into_a_fresh_world_steps_as_the_original() {
    let scene = Drop_::new(VtSpineMode::Rod);
    scene.step(20);
    let (world_bytes, layer_bytes) = (scene.world.bytes(), scene.layer.bytes(&scene.world));
    let fresh = CWorld::new();
    let layer = CLayer::new();
    // SAFETY: live objects; the bytes are readable.
    ok(unsafe { vt_world_restore(fresh.0, world_bytes.as_ptr(), world_bytes.len()) });
    // SAFETY: as above.
    ok(unsafe { vt_collisions_restore(layer.0, fresh.0, layer_bytes.as_ptr(), layer_bytes.len()) });
    assert_eq!(fresh.hash(), scene.world.hash());
    assert!(layer.bytes(&fresh) == layer_bytes);
    scene.step(30);
    for _ in 0..30 {
        // SAFETY: live objects.
        ok(unsafe { vt_collisions_update(layer.0, fresh.0, DT) });
        fresh.step(1);
    }
    assert_eq!(fresh.hash(), scene.world.hash());
    assert_ne!(fresh.hash(), CWorld::new().hash(), "the ragdoll moved");
}

/// Through C, a world restored without its layer's snapshot (here, to
/// before its ragdoll fell 20 frames) is refused by every layer call that
/// takes it (`VT_RESULT_WORLD_MISMATCH`), the layer unchanged, until the
/// layer's snapshot taken with the world's is restored; a new layer refuses
/// a restored world until it is restored or attached.
#[test]
fn a_world_restored_without_its_layer_is_refused_through_c() {
    let scene = Drop_::new(VtSpineMode::Rod);
    let (world_bytes, layer_bytes) = (scene.world.bytes(), scene.layer.bytes(&scene.world));
    scene.step(20);
    let restore_world = |world: &CWorld| {
        // SAFETY: a live world; readable bytes.
        ok(unsafe { vt_world_restore(world.0, world_bytes.as_ptr(), world_bytes.len()) })
    };
    restore_world(&scene.world);
    // SAFETY: live objects.
    let r = unsafe { vt_collisions_update(scene.layer.0, scene.world.0, DT) };
    refused(r, VtResult::WorldMismatch, &["restored a snapshot"]);
    let mut snapshot = null_mut();
    // SAFETY: live objects; writable.
    let r = unsafe { vt_collisions_snapshot(scene.layer.0, scene.world.0, &mut snapshot) };
    refused(r, VtResult::WorldMismatch, &["restored a snapshot"]);
    assert!(snapshot.is_null(), "nothing written");
    // SAFETY: live objects; readable bytes.
    ok(unsafe {
        vt_collisions_restore(
            scene.layer.0,
            scene.world.0,
            layer_bytes.as_ptr(),
            layer_bytes.len(),
        )
    });
    scene.step(20);
    // A new layer for a loaded world: refused, then attached.
    let loaded = CWorld::new();
    restore_world(&loaded);
    let layer = CLayer::new();
    // SAFETY: live objects.
    let r = unsafe { vt_collisions_update(layer.0, loaded.0, DT) };
    refused(r, VtResult::WorldMismatch, &["never served"]);
    // SAFETY: live objects.
    ok(unsafe { vt_collisions_attach(layer.0, loaded.0) });
    // SAFETY: live objects.
    ok(unsafe { vt_collisions_update(layer.0, loaded.0, DT) });
}

#[test]
fn corrupt_snapshot_bytes_are_refused_with_the_world_unchanged() {
    let scene = Drop_::new(VtSpineMode::Rod);
    scene.step(5);
    let bytes = scene.world.bytes();
    let layer_bytes = scene.layer.bytes(&scene.world);
    let target = Scene::new();
    let layer = CLayer::new();
    let before = (target.world.bytes(), layer.bytes(&target.world));
    let mut rejected = 0;
    let cuts = [0, 1, 8, bytes.len() / 2, bytes.len() - 1];
    for cut in cuts {
        // SAFETY: `cut` readable bytes (a dangling pointer for 0 is never read).
        let r = unsafe { vt_world_restore(target.w(), bytes.as_ptr(), cut) };
        assert!(
            matches!(
                r,
                VtResult::CorruptSnapshot | VtResult::IncompatibleSnapshot
            ),
            "{cut} bytes: {r:?} {}",
            message()
        );
        rejected += 1;
    }
    for cut in [0, 1, layer_bytes.len() / 2, layer_bytes.len() - 1] {
        // SAFETY: as above.
        let r = unsafe { vt_collisions_restore(layer.0, target.w(), layer_bytes.as_ptr(), cut) };
        assert_ne!(r, VtResult::Ok, "{cut} bytes");
    }
    // Every byte's bits flipped in turn, in a stride: refused, or a world
    // that is whole (every state finite: it steps).
    for at in (0..bytes.len()).step_by(7) {
        let mut damaged = bytes.clone();
        damaged[at] ^= 0xff;
        let probe = CWorld::new();
        let fresh = probe.bytes();
        // SAFETY: readable bytes.
        let r = unsafe { vt_world_restore(probe.0, damaged.as_ptr(), damaged.len()) };
        if r == VtResult::Ok {
            probe.step(1);
        } else {
            assert!(probe.bytes() == fresh, "byte {at}: changed on refusal");
        }
    }
    assert!(rejected > 0);
    assert!(before == (target.world.bytes(), layer.bytes(&target.world)));
    // The layer's snapshot needs the bodies it names: refused against a
    // world without them.
    let empty = CWorld::new();
    // SAFETY: live objects; readable bytes.
    let r =
        unsafe { vt_collisions_restore(layer.0, empty.0, layer_bytes.as_ptr(), layer_bytes.len()) };
    assert_ne!(r, VtResult::Ok);
    assert!(layer.bytes(&target.world) == before.1);
}

/// The layer's snapshot `bytes` with its last varint (the group counter)
/// set to `given` and the payload checksum made right again (the format
/// is documented: magic 8, version 4, xxh3 8, payload).
fn with_group_counter(bytes: &[u8], mut given: u64) -> Vec<u8> {
    assert_eq!(bytes.last(), Some(&1), "one group given");
    let mut out = bytes[..bytes.len() - 1].to_vec();
    while given >= 0x80 {
        out.push(given as u8 | 0x80);
        given >>= 7;
    }
    out.push(given as u8);
    let sum = xxhash_rust::xxh3::xxh3_64(&out[20..]);
    out[12..20].copy_from_slice(&sum.to_le_bytes());
    out
}

/// Through C, a layer's snapshot whose group counter is `u64::MAX`
/// (checksum made right) is refused by `vt_collisions_restore`, the layer
/// unchanged (accepted, the next ragdoll's self-collision turned off would
/// wrap it); at the limit it restores, and the group past it is refused
/// (`VT_RESULT_COLLIDER`, the ragdoll's first body named), the layer
/// unchanged.
#[test]
fn a_crafted_group_counter_is_refused_through_c() {
    let scene = Drop_::new(VtSpineMode::Sockets);
    // SAFETY: live objects.
    ok(unsafe { vt_collisions_set_ragdoll_self_collision(scene.layer.0, scene.ragdoll, 0) });
    let good = scene.layer.bytes(&scene.world);
    let world = scene.world.0;
    let restore = |bytes: &[u8]| {
        // SAFETY: live objects; readable bytes.
        unsafe { vt_collisions_restore(scene.layer.0, world, bytes.as_ptr(), bytes.len()) }
    };
    let wrapped = with_group_counter(&good, u64::MAX);
    refused(
        restore(&wrapped),
        VtResult::CorruptSnapshot,
        &["self-collision groups", "18446744073709551615 given"],
    );
    assert!(
        scene.layer.bytes(&scene.world) == good,
        "refused, unchanged"
    );
    ok(restore(&with_group_counter(
        &good,
        vertebra_collide::MAX_SELF_COLLISION_GROUPS,
    )));
    let at_limit = scene.layer.bytes(&scene.world);
    // SAFETY: live objects.
    ok(unsafe { vt_collisions_set_ragdoll_self_collision(scene.layer.0, scene.ragdoll, 1) });
    let on = scene.layer.bytes(&scene.world);
    assert!(on != at_limit);
    // SAFETY: live objects.
    let r = unsafe { vt_collisions_set_ragdoll_self_collision(scene.layer.0, scene.ragdoll, 0) };
    refused(r, VtResult::Collider, &["self-collision group", "2^48"]);
    assert!(scene.layer.bytes(&scene.world) == on, "refused, unchanged");
    scene.step(2);
}

/// One C world and its Rust twin with the same three boxes.
struct Twins {
    c: CWorld,
    cb: [VtBody; 3],
    rust: World,
    rb: [vertebra_world::BodyHandle; 3],
}

impl Twins {
    fn new() -> Self {
        let c = CWorld::new();
        let mut rust = World::new(SolverConfig::default()).expect("a world");
        let at = [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.05, 1.4, 0.0),
            Vec3::new(0.0, 1.8, 0.1),
        ];
        let cb = at.map(|p| c.add(&box_desc(p.into())));
        let rb = at.map(|p| rust.add_body(rust_box(p)).expect("a body"));
        Self { c, cb, rust, rb }
    }

    /// Steps both and compares their states.
    fn step_and_compare(&mut self, steps: usize) {
        let start = self.c.hash();
        for _ in 0..steps {
            self.c.step(1);
            self.rust.step(DT).expect("a step");
        }
        assert_eq!(self.c.hash(), self.rust.state_hash());
        assert_ne!(self.c.hash(), start, "the bodies moved");
    }
}

/// A joint's description with its bodies' handles zeroed, to compare two
/// worlds' joints (their handles differ by lineage).
fn without_bodies(mut d: VtJointDesc) -> String {
    let zero = VtBody {
        index: 0,
        lineage: 0,
        generation: 0,
    };
    (d.body_a, d.body_b) = (zero, zero);
    format!("{d:?}")
}

/// A joint's kind, its limits and drive set through C, and the same set
/// through Rust.
type JointCase = (
    VtJointKind,
    Box<dyn Fn(&mut VtJointDesc)>,
    Box<dyn Fn(&mut JointDesc)>,
);

#[test]
fn joints_built_through_c_equal_joints_built_through_rust() {
    let spring = VtSoftness {
        kind: VtSoftnessKind::Spring as u32,
        a: 4.0,
        b: 0.7,
    };
    let drive = VtDrive {
        target: Quat::from_rotation_z(0.3).into(),
        target_velocity: v(0.0, 0.0, 0.5),
        strength: VtSoftness {
            kind: VtSoftnessKind::Compliance as u32,
            a: 1e-3,
            b: 2.0,
        },
        max_torque: 40.0,
    };
    let swings = [
        (VtSwingKind::Free, Swing::Free),
        (VtSwingKind::Cone, Swing::Cone(0.6)),
        (VtSwingKind::Ellipse, Swing::Ellipse { y: 0.4, z: 0.9 }),
        (
            VtSwingKind::Pyramid,
            Swing::Pyramid {
                y: [-0.3, 0.5],
                z: [-0.8, 0.2],
            },
        ),
    ];
    let mut cases: Vec<JointCase> = Vec::new();
    for (c_swing, rust_swing) in swings {
        cases.push((
            VtJointKind::Socket,
            Box::new(move |d| {
                d.swing.kind = c_swing as u32;
                match c_swing {
                    VtSwingKind::Free => {}
                    VtSwingKind::Cone => d.swing.half_angle = 0.6,
                    VtSwingKind::Ellipse => {
                        (d.swing.half_angle_y, d.swing.half_angle_z) = (0.4, 0.9)
                    }
                    VtSwingKind::Pyramid => {
                        (d.swing.min_y, d.swing.max_y) = (-0.3, 0.5);
                        (d.swing.min_z, d.swing.max_z) = (-0.8, 0.2);
                    }
                }
                (d.has_range, d.range_min, d.range_max) = (1, -0.4, 0.7);
                d.softness = spring;
            }),
            Box::new(move |d| {
                d.kind = JointKind::Socket(SwingTwist {
                    swing: rust_swing,
                    twist: Some([-0.4, 0.7]),
                    softness: LimitSoftness::Soft(Spring::Frequency {
                        frequency: 4.0,
                        damping_ratio: 0.7,
                    }),
                });
            }),
        ));
    }
    cases.push((
        VtJointKind::Hinge,
        Box::new(move |d| {
            (d.has_range, d.range_min, d.range_max) = (1, -1.0, 0.2);
            (d.has_drive, d.drive) = (1, drive);
        }),
        Box::new(|d| {
            d.kind = JointKind::Hinge {
                range: Some([-1.0, 0.2]),
                softness: LimitSoftness::Hard,
            };
            d.drive = Some(AngularDrive {
                target: Quat::from_rotation_z(0.3),
                target_velocity: Vec3::new(0.0, 0.0, 0.5),
                strength: Spring::Compliance {
                    compliance: 1e-3,
                    damping: 2.0,
                },
                max_torque: 40.0,
            });
        }),
    ));
    cases.push((VtJointKind::Fixed, Box::new(|_| {}), Box::new(|_| {})));
    cases.push((
        VtJointKind::Socket,
        Box::new(move |d| {
            d.softness = VtSoftness {
                kind: VtSoftnessKind::Compliance as u32,
                a: 1e-4,
                b: 0.5,
            };
            d.swing.kind = VtSwingKind::Cone as u32;
            d.swing.half_angle = 0.2;
            (d.has_drive, d.drive) = (
                1,
                VtDrive {
                    strength: spring,
                    ..drive
                },
            );
        }),
        Box::new(|d| {
            d.kind = JointKind::Socket(SwingTwist {
                swing: Swing::Cone(0.2),
                twist: None,
                softness: LimitSoftness::Soft(Spring::Compliance {
                    compliance: 1e-4,
                    damping: 0.5,
                }),
            });
            d.drive = Some(AngularDrive {
                target: Quat::from_rotation_z(0.3),
                target_velocity: Vec3::new(0.0, 0.0, 0.5),
                strength: Spring::Frequency {
                    frequency: 4.0,
                    damping_ratio: 0.7,
                },
                max_torque: 40.0,
            });
        }),
    ));
    for (k, (kind, edit_c, edit_rust)) in cases.into_iter().enumerate() {
        let mut t = Twins::new();
        let anchor = Vec3::new(0.0, 1.2, 0.0);
        let axis = Vec3::new(0.1, 1.0, 0.0).normalize();
        let mut again = std::mem::MaybeUninit::<VtJointDesc>::uninit();
        // SAFETY: a live world; writable.
        ok(unsafe {
            vt_joint_at_world_anchor(
                t.c.0,
                kind as u32,
                t.cb[0],
                t.cb[1],
                anchor.into(),
                axis.into(),
                again.as_mut_ptr(),
            )
        });
        // SAFETY: written just above.
        let mut desc = unsafe { again.assume_init() };
        edit_c(&mut desc);
        let mut joint = VtJoint {
            index: 0,
            lineage: 0,
            generation: 0,
        };
        // SAFETY: a live world; readable, writable.
        ok(unsafe { vt_world_add_joint(t.c.0, &desc, &mut joint) });
        let (a, b) = (t.rb[0], t.rb[1]);
        let bodies = t.rust.bodies();
        let mut rust = match kind {
            VtJointKind::Socket => JointDesc::socket_at_world_anchor(bodies, a, b, anchor, axis),
            VtJointKind::Hinge => JointDesc::hinge_at_world_anchor(bodies, a, b, anchor, axis),
            VtJointKind::Fixed => JointDesc::fixed_at(bodies, a, b, anchor),
        }
        .expect("a joint");
        edit_rust(&mut rust);
        let handle = t.rust.add_joint(rust).expect("added");
        let mut back = std::mem::MaybeUninit::<VtJointDesc>::uninit();
        // SAFETY: a live world; writable.
        ok(unsafe { vt_world_joint(t.c.0, joint, back.as_mut_ptr()) });
        // SAFETY: written just above.
        let back = unsafe { back.assume_init() };
        let twin = VtJointDesc::from(&t.rust.joint(handle).expect("the joint"));
        assert_eq!(without_bodies(back), without_bodies(twin), "case {k}");
        assert_eq!(
            without_bodies(back),
            without_bodies(desc),
            "case {k}: round trip"
        );
        // The third body pushed about, so that limits and drives act.
        // SAFETY: a live world.
        ok(unsafe { vt_world_push(t.c.0, t.cb[1], 3, v(0.3, 0.2, -0.4)) });
        t.rust
            .apply_angular_impulse(t.rb[1], Vec3::new(0.3, 0.2, -0.4))
            .expect("an impulse");
        t.step_and_compare(40);
    }
}

#[test]
fn rods_built_through_c_equal_rods_built_through_rust() {
    let mut t = Twins::new();
    let through = [v(0.02, 1.2, 0.0), v(0.03, 1.3, 0.0)];
    let mut desc = std::mem::MaybeUninit::<VtRodDesc>::uninit();
    // SAFETY: a live world; two readable points; writable.
    ok(unsafe {
        vt_rod_from_pose(
            t.c.0,
            t.cb[0],
            t.cb[1],
            through.as_ptr(),
            2,
            desc.as_mut_ptr(),
        )
    });
    // SAFETY: written just above.
    let mut desc = unsafe { desc.assume_init() };
    desc.bending = VtStiffness {
        kind: VtStiffnessKind::Damped as u32,
        a: 50.0,
        b: 0.5,
    };
    desc.twisting = VtStiffness {
        kind: VtStiffnessKind::Spring as u32,
        a: 3.0,
        b: 0.4,
    };
    (desc.has_bend_limit, desc.bend_limit) = (1, 0.8);
    (desc.has_twist_limit, desc.twist_min, desc.twist_max) = (1, -0.3, 0.3);
    desc.max_torque = 500.0;
    let mut rod = VtRod {
        index: 0,
        lineage: 0,
        generation: 0,
    };
    // SAFETY: a live world; readable, writable.
    ok(unsafe { vt_world_add_rod(t.c.0, &desc, &mut rod) });
    let points = [Vec3::new(0.02, 1.2, 0.0), Vec3::new(0.03, 1.3, 0.0)];
    let mut rust = RodDesc::from_pose(t.rust.bodies(), t.rb[0], t.rb[1], &points).expect("a rod");
    rust.bending = RodStiffness::Damped {
        stiffness: 50.0,
        damping: 0.5,
    };
    rust.twisting = RodStiffness::Spring {
        frequency: 3.0,
        damping_ratio: 0.4,
    };
    rust.bend_limit = Some(0.8);
    rust.twist_limit = Some([-0.3, 0.3]);
    rust.max_torque = 500.0;
    let handle = t.rust.add_rod(rust).expect("added");
    let mut back = std::mem::MaybeUninit::<VtRodDesc>::uninit();
    // SAFETY: a live world; writable.
    ok(unsafe { vt_world_rod(t.c.0, rod, back.as_mut_ptr()) });
    // SAFETY: written just above.
    let back = unsafe { back.assume_init() };
    let twin = VtRodDesc::from(&t.rust.rod(handle).expect("the rod"));
    let strip = |mut d: VtRodDesc| {
        d.body_a = bits_body();
        d.body_b = bits_body();
        format!("{d:?}")
    };
    assert_eq!(strip(back), strip(twin));
    assert_eq!(strip(back), strip(desc));
    t.step_and_compare(40);
}

/// The Rust twin of [`Drop_`].
struct RustDrop {
    world: World,
    layer: Collisions,
    desc: RagdollDesc,
    ragdoll: Ragdoll,
    contacts: Vec<vertebra_world::Contact>,
}

impl RustDrop {
    fn new(spine: SpineMode) -> Self {
        let mut world = World::new(SolverConfig::default()).expect("a world");
        let mut layer = Collisions::new();
        let ground = world.add_body(BodyDesc::fixed()).expect("ground");
        let mut plane = Collider::new(ground, ColliderShape::Plane(Vec3::Y));
        plane.friction = 0.6;
        layer.add(plane).expect("the plane");
        let desc = RagdollDesc::reference_humanoid();
        let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::Y * 0.3);
        let ragdoll = layer
            .build_ragdoll(&mut world, &desc, BuildOptions::new(spine), &pose, None)
            .expect("the ragdoll");
        ragdoll
            .set_velocity(
                &mut world,
                Vec3::new(0.0, 0.0, 0.5),
                Vec3::new(2.0, 0.0, 0.0),
            )
            .expect("a velocity");
        Self {
            world,
            layer,
            desc,
            ragdoll,
            contacts: Vec::new(),
        }
    }

    fn step(&mut self, steps: usize) {
        for _ in 0..steps {
            self.layer
                .find_contacts_into(&self.world, DT, &mut self.contacts)
                .expect("contacts");
            self.world
                .swap_contacts(&mut self.contacts)
                .expect("contacts");
            self.world.step(DT).expect("a step");
        }
    }
}

fn crouch(desc: &RagdollDesc) -> Pose {
    Pose::bind(desc).moved(
        Vec3::new(0.0, 1.0, 0.0),
        Quat::from_rotation_x(0.4),
        Vec3::Y * 0.1,
    )
}

#[test]
fn a_ragdoll_driven_and_hit_through_c_moves_as_through_rust() {
    for (c_spine, spine) in [
        (VtSpineMode::Rod, SpineMode::Rod),
        (VtSpineMode::Sockets, SpineMode::Sockets),
    ] {
        let c = Drop_::new(c_spine);
        let mut rust = RustDrop::new(spine);
        c.step(10);
        rust.step(10);
        assert_eq!(c.world.hash(), rust.world.state_hash());
        let target = crouch(&rust.desc);
        let c_target: Vec<VtTransform> = target.bones.iter().map(|&t| t.into()).collect();
        let settings = VtDriveSettings {
            strength: VtStrength {
                kind: VtStrengthKind::Spring as u32,
                a: 5.0,
                b: 0.8,
            },
            damping: 0.0,
            max_torque: 300.0,
        };
        // SAFETY: live objects; readable pose and settings.
        ok(unsafe {
            vt_ragdoll_drive_to(
                c.ragdoll,
                c.world.0,
                c_target.as_ptr(),
                c_target.len(),
                &settings,
            )
        });
        let rust_settings = DriveSettings::uniform(Spring::Frequency {
            frequency: 5.0,
            damping_ratio: 0.8,
        })
        .with_max_torque(300.0);
        rust.ragdoll
            .drive_to(&mut rust.world, &target, &rust_settings)
            .expect("driven");
        let name = CString::new("chest").expect("a name");
        let point = v(0.0, 1.5, 0.1);
        // SAFETY: live objects; a NUL-terminated name; readable point.
        ok(unsafe {
            vt_ragdoll_apply_impulse(
                c.ragdoll,
                c.world.0,
                name.as_ptr(),
                v(5.0, 0.0, 2.0),
                &point,
            )
        });
        // SAFETY: as above; a null point is the centre of mass.
        ok(unsafe {
            vt_ragdoll_apply_impulse(
                c.ragdoll,
                c.world.0,
                name.as_ptr(),
                v(0.0, 3.0, 0.0),
                null(),
            )
        });
        rust.ragdoll
            .apply_impulse(
                &mut rust.world,
                "chest",
                Vec3::new(5.0, 0.0, 2.0),
                Some(Vec3::new(0.0, 1.5, 0.1)),
            )
            .expect("an impulse");
        rust.ragdoll
            .apply_impulse(&mut rust.world, "chest", Vec3::new(0.0, 3.0, 0.0), None)
            .expect("an impulse");
        c.step(30);
        rust.step(30);
        assert_eq!(c.world.hash(), rust.world.state_hash());
        // SAFETY: live objects.
        ok(unsafe { vt_ragdoll_release_drives(c.ragdoll, c.world.0) });
        rust.ragdoll
            .release_drives(&mut rust.world)
            .expect("released");
        c.step(10);
        rust.step(10);
        assert_eq!(c.world.hash(), rust.world.state_hash());
        // A refused drive changes nothing: NaN in the pose, a wrong length.
        let mut bad = c_target.clone();
        bad[3].position.y = NAN;
        let before = c.world.bytes();
        // SAFETY: live objects; readable.
        let r = unsafe {
            vt_ragdoll_drive_to(c.ragdoll, c.world.0, bad.as_ptr(), bad.len(), &settings)
        };
        refused(r, VtResult::Ragdoll, &["chest", "position"]);
        // SAFETY: as above, one transform short.
        let r =
            unsafe { vt_ragdoll_drive_to(c.ragdoll, c.world.0, c_target.as_ptr(), 12, &settings) };
        refused(r, VtResult::Ragdoll, &["12", "13"]);
        let unknown = CString::new("tail").expect("a name");
        // SAFETY: as above.
        let r = unsafe {
            vt_ragdoll_apply_impulse(
                c.ragdoll,
                c.world.0,
                unknown.as_ptr(),
                v(1.0, 0.0, 0.0),
                null(),
            )
        };
        refused(r, VtResult::Ragdoll, &["tail"]);
        assert!(before == c.world.bytes());
    }
}

#[test]
fn a_ragdoll_is_removed_with_and_without_its_collision_layer() {
    let c = Drop_::new(VtSpineMode::Rod);
    c.step(3);
    let other = CWorld::new();
    let before = c.world.bytes();
    // SAFETY: live objects; the ragdoll is not in `other`.
    let r = unsafe { vt_ragdoll_remove(c.ragdoll, other.0, null_mut()) };
    assert!(
        matches!(r, VtResult::ForeignHandle | VtResult::Ragdoll),
        "{r:?}: {}",
        message()
    );
    assert!(before == c.world.bytes());
    // SAFETY: live objects.
    ok(unsafe { vt_ragdoll_remove(c.ragdoll, c.world.0, c.layer.0) });
    // Only the ground is left, in the world and in the layer.
    let mut count = 0usize;
    c.step(1);
    // SAFETY: a live world; asking the number.
    let _ = unsafe { vt_world_contacts(c.world.0, null_mut(), 0, &mut count) };
    assert_eq!(count, 0);
    // Removed again: refused by name, as every call on a removed ragdoll
    // is, with nothing written.
    let removed = c.world.bytes();
    // SAFETY: live objects.
    let again = unsafe { vt_ragdoll_remove(c.ragdoll, c.world.0, null_mut()) };
    refused(
        again,
        VtResult::StaleHandle,
        &["ragdoll `reference-humanoid`"],
    );
    assert!(removed == c.world.bytes());
    let mut body = bits_body();
    let mut present = 9u32;
    for index in [0, 13, usize::MAX] {
        // SAFETY: live objects; writable places.
        let r = unsafe { vt_ragdoll_body(c.ragdoll, index, &mut body, &mut present) };
        refused(r, VtResult::StaleHandle, &["has been removed"]);
    }
    assert_eq!((present, body), (9, bits_body()));
    // A built one names an index past the end.
    let built = Drop_::new(VtSpineMode::Rod);
    for index in [13, usize::MAX] {
        // SAFETY: live objects; writable places.
        let r = unsafe { vt_ragdoll_body(built.ragdoll, index, &mut body, &mut present) };
        refused(r, VtResult::OutOfRange, &["of a ragdoll of 13"]);
    }
    assert_eq!(present, 9);

    // Without the layer: the layer keeps its colliders (the layer's to remove).
    let d = Drop_::new(VtSpineMode::Sockets);
    // SAFETY: live objects.
    ok(unsafe { vt_ragdoll_remove(d.ragdoll, d.world.0, null_mut()) });
    // SAFETY: live objects: the colliders name removed bodies, and the
    // layer says so rather than hand the world contacts on them.
    let r = unsafe { vt_collisions_update(d.layer.0, d.world.0, DT) };
    assert!(
        matches!(r, VtResult::Ok | VtResult::Collider | VtResult::StaleHandle),
        "{r:?}"
    );
}

#[test]
fn a_ragdoll_used_with_another_world_is_refused() {
    let c = Drop_::new(VtSpineMode::Rod);
    let other = Scene::new();
    let pose = lifted_bind(&c.desc, 0.0);
    let settings = VtDriveSettings {
        strength: VtStrength {
            kind: 0,
            a: 0.0,
            b: 0.0,
        },
        damping: 0.0,
        max_torque: INF,
    };
    let name = CString::new("hips").expect("a name");
    let mut root = VtTransform {
        position: v(9.0, 9.0, 9.0),
        rotation: IDENTITY,
    };
    let (o, r) = (other.w(), c.ragdoll);
    // Each call: live objects of the wrong pairing.
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    other.refuses(VtResult::ForeignHandle, &[], || unsafe {
        vt_ragdoll_drive_to(r, o, pose.as_ptr(), pose.len(), &settings)
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    other.refuses(VtResult::ForeignHandle, &[], || unsafe {
        vt_ragdoll_release_drives(r, o)
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    other.refuses(VtResult::ForeignHandle, &["hips"], || unsafe {
        vt_ragdoll_apply_impulse(r, o, name.as_ptr(), v(1.0, 0.0, 0.0), null())
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    other.refuses(VtResult::ForeignHandle, &[], || unsafe {
        vt_ragdoll_set_velocity(r, o, v(1.0, 0.0, 0.0), v(0.0, 0.0, 0.0))
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    other.refuses(VtResult::ForeignHandle, &["hips"], || unsafe {
        vt_ragdoll_set_body_kinematic(r, o, name.as_ptr(), 1)
    });
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    other.refuses(VtResult::ForeignHandle, &["hips"], || unsafe {
        vt_ragdoll_placement(r, o, &mut root, null_mut(), null_mut())
    });
    assert_eq!(root.position, v(9.0, 9.0, 9.0));
}

/// A refused mapping: the code and words, the ragdoll and world, the
/// animation, the mapping and the count.
type MapCase<'a> = (
    VtResult,
    &'a [&'a str],
    *mut VtRagdoll,
    *mut VtWorld,
    &'a [VtTransform],
    u32,
    usize,
);

#[test]
fn the_mapper_through_c_maps_as_through_rust_bit_for_bit() {
    let c = Drop_::new(VtSpineMode::Rod);
    let mut rust = RustDrop::new(SpineMode::Rod);
    c.step(25);
    rust.step(25);
    let skeleton = CSkeleton::reference();
    let mut mapper = null_mut();
    // SAFETY: live objects; writable.
    ok(unsafe {
        vt_skeleton_mapper_create(skeleton.0, c.desc.0, VtSpineMode::Rod as u32, &mut mapper)
    });
    let rust_skeleton = Skeleton::reference();
    let rust_mapper =
        SkeletonMapper::new(&rust_skeleton, &rust.desc, SpineMode::Rod).expect("a mapper");
    let animation: LocalPose = rust_skeleton.bind_pose();
    let c_animation: Vec<VtTransform> = animation.bones.iter().map(|&t| t.into()).collect();
    let model_to_world = Transform::new(Vec3::new(0.1, 0.0, -0.2), Quat::from_rotation_y(0.3));
    let sentinel = VtTransform {
        position: v(9.0, 9.0, 9.0),
        rotation: IDENTITY,
    };
    for (c_mapping, mapping) in [
        (VtSpineMapping::Orientation, SpineMapping::Orientation),
        (
            VtSpineMapping::PositionOrientation,
            SpineMapping::PositionOrientation,
        ),
        (VtSpineMapping::Arc, SpineMapping::Arc),
    ] {
        let mut bones = vec![sentinel; c_animation.len()];
        // SAFETY: live objects; `count` readable and writable transforms.
        ok(unsafe {
            vt_skeleton_mapper_map_to_skeleton(
                mapper,
                c.ragdoll,
                c.world.0,
                c_animation.as_ptr(),
                model_to_world.into(),
                c_mapping as u32,
                bones.as_mut_ptr(),
                bones.len(),
            )
        });
        let twin = rust_mapper
            .map_to_skeleton(
                &rust.ragdoll,
                &rust.world,
                &animation,
                model_to_world,
                mapping,
            )
            .expect("mapped");
        let bits = |t: &VtTransform| {
            [
                t.position.x,
                t.position.y,
                t.position.z,
                t.rotation.x,
                t.rotation.y,
                t.rotation.z,
                t.rotation.w,
            ]
            .map(f32::to_bits)
        };
        let twin: Vec<VtTransform> = twin.bones.iter().map(|&t| t.into()).collect();
        assert_eq!(
            bones.iter().map(bits).collect::<Vec<_>>(),
            twin.iter().map(bits).collect::<Vec<_>>()
        );
    }
    // Refused: a wrong length, an unknown mapping, NaN in the animation,
    // a ragdoll of another spine mode; nothing written.
    let sockets = Drop_::new(VtSpineMode::Sockets);
    let mut bad = c_animation.clone();
    bad[5].rotation.w = NAN;
    let mut bones = vec![sentinel; c_animation.len()];
    let n = bones.len();
    let cases: [MapCase; 4] = [
        (
            VtResult::BufferTooSmall,
            &[],
            c.ragdoll,
            c.world.0,
            &c_animation,
            2,
            n - 1,
        ),
        (
            VtResult::InvalidEnum,
            &["mapping"],
            c.ragdoll,
            c.world.0,
            &c_animation,
            3,
            n,
        ),
        (
            VtResult::Ragdoll,
            &["animation"],
            c.ragdoll,
            c.world.0,
            &bad,
            2,
            n,
        ),
        (
            VtResult::Ragdoll,
            &["ragdoll"],
            sockets.ragdoll,
            sockets.world.0,
            &c_animation,
            2,
            n,
        ),
    ];
    for (code, words, ragdoll, world, animation, mapping, count) in cases {
        // SAFETY: live objects; `count` readable and writable transforms.
        let r = unsafe {
            vt_skeleton_mapper_map_to_skeleton(
                mapper,
                ragdoll,
                world,
                animation.as_ptr(),
                model_to_world.into(),
                mapping,
                bones.as_mut_ptr(),
                count,
            )
        };
        if code == VtResult::BufferTooSmall && r == VtResult::Ragdoll {
            // The Rust API refuses the short animation first.
            refused(r, VtResult::Ragdoll, &["animation"]);
        } else {
            refused(r, code, words);
        }
        assert!(bones.iter().all(|t| t.position == sentinel.position));
    }
    // SAFETY: made above, freed once.
    unsafe { vt_skeleton_mapper_destroy(mapper) };
}

/// How the test job system runs a `parallel_for`'s items.
#[derive(Clone, Copy)]
enum Mode {
    /// Each item on its own std thread.
    Threads,
    /// On the calling thread, last to first.
    Reverse,
    /// Only the even items; the world finishes the others' work.
    Even,
    /// None at all.
    Nothing,
}

/// A `VtParallelFor` whose context is a [`Mode`].
///
/// # Safety
/// `context` points to a live `Mode`; `task` and `task_context` are the
/// world's item.
unsafe extern "C" fn job_system(
    context: *mut c_void,
    count: u32,
    task: VtTaskFn,
    task_context: *const c_void,
) {
    // SAFETY: the context given with the task system is a live `Mode`.
    let mode = unsafe { *context.cast::<Mode>() };
    let run = |i: u32| {
        // SAFETY: the world's item, called while parallel_for runs.
        unsafe { task(task_context, i) }
    };
    match mode {
        Mode::Threads => {
            let shared = task_context as usize;
            std::thread::scope(|scope| {
                for i in 0..count {
                    scope.spawn(move || {
                        // SAFETY: as above; the item may run on any thread
                        // (VtParallelFor's contract), and the scope joins
                        // every thread before parallel_for returns.
                        unsafe { task(shared as *const c_void, i) }
                    });
                }
            });
        }
        Mode::Reverse => (0..count).rev().for_each(run),
        Mode::Even => (0..count).step_by(2).for_each(run),
        Mode::Nothing => {}
    }
}

#[test]
fn the_engines_job_system_gives_the_single_threaded_world() {
    let reference = Drop_::new(VtSpineMode::Rod);
    reference.step(20);
    for mode in [Mode::Threads, Mode::Reverse, Mode::Even, Mode::Nothing] {
        let mut mode = mode;
        let scene = Drop_::new(VtSpineMode::Rod);
        let tasks = VtTaskSystem {
            workers: 4,
            parallel_for: Some(job_system),
            context: (&raw mut mode).cast(),
        };
        // SAFETY: a live world; `mode` outlives the world's steps below.
        ok(unsafe { vt_world_set_tasks(scene.world.0, &tasks) });
        scene.step(20);
        assert_eq!(scene.world.hash(), reference.world.hash());
    }
    let s = Scene::new();
    for workers in [0, 257] {
        let tasks = VtTaskSystem {
            workers,
            parallel_for: Some(job_system),
            context: null_mut(),
        };
        // SAFETY: a live world; readable tasks (refused).
        s.refuses(
            VtResult::InvalidConfig,
            &["tasks.workers", &workers.to_string()],
            // SAFETY: as the comment above the call says.
            || unsafe { vt_world_set_tasks(s.w(), &tasks) },
        );
    }
}

fn desc_from(text: &str) -> Result<CDesc, (VtResult, String)> {
    let text = CString::new(text).expect("no NUL");
    let mut desc = null_mut();
    // SAFETY: a NUL-terminated string; writable.
    match unsafe { vt_ragdoll_desc_from_string(text.as_ptr(), &mut desc) } {
        VtResult::Ok => Ok(CDesc(desc)),
        r => {
            assert!(desc.is_null(), "written on refusal");
            Err((r, message()))
        }
    }
}

#[test]
fn a_broken_description_is_refused_naming_the_line() {
    let good = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../vertebra-ragdoll/models/humanoid.toml"),
    )
    .expect("the humanoid");
    assert!(desc_from(&good).is_ok());
    let broken = good.replacen(
        "radius = 0.10\nmass = 6.0",
        "radius = 0.10\nmass = = 6.0",
        1,
    );
    let line = broken
        .lines()
        .position(|l| l.contains("= ="))
        .expect("broken")
        + 1;
    let (code, text) = desc_from(&broken).err().expect("refused");
    assert_eq!(code, VtResult::Ragdoll);
    assert!(
        text.contains(&format!("line {line}")) || text.contains(&format!("{line}:")),
        "{text}"
    );
    let negative = good.replacen("mass = 6.0", "mass = -6.0", 1);
    let (code, text) = desc_from(&negative).err().expect("refused");
    assert_eq!(code, VtResult::Ragdoll);
    assert!(
        text.contains("spine_lower") && text.contains("mass"),
        "{text}"
    );
    // Empty, no bodies, deeply nested, huge: refused, never a panic.
    for text in [
        String::new(),
        "name = \"empty\"\n".to_owned(),
        "name = \"none\"\ntotal_mass = 1.0\nbody = []\n".to_owned(),
        format!("name = {}1{}", "[".repeat(100_000), "]".repeat(100_000)),
        format!("name = \"{}\"", "x".repeat(1 << 20)),
    ] {
        let (code, _) = desc_from(&text).err().expect("refused");
        assert_eq!(code, VtResult::Ragdoll);
    }
    // Not UTF-8.
    let bytes = b"name = \"\xff\"\0";
    let mut desc = null_mut();
    // SAFETY: NUL-terminated; writable.
    let r = unsafe { vt_ragdoll_desc_from_string(bytes.as_ptr().cast(), &mut desc) };
    refused(r, VtResult::NotUtf8, &["toml"]);
    let mut skeleton = null_mut();
    // SAFETY: as above.
    let r = unsafe { vt_skeleton_from_string(bytes.as_ptr().cast(), &mut skeleton) };
    refused(r, VtResult::NotUtf8, &["toml"]);
    for text in [
        "",
        "[[bone]]\nname = \"a\"\nparent = \"a\"\n",
        "[[bone]]\nname = 3\n",
    ] {
        let text = CString::new(text).expect("no NUL");
        // SAFETY: as above.
        let r = unsafe { vt_skeleton_from_string(text.as_ptr(), &mut skeleton) };
        assert_eq!(r, VtResult::Ragdoll, "{}", message());
        assert!(skeleton.is_null());
    }
    let missing = CString::new("/nonexistent/ragdoll.toml").expect("no NUL");
    // SAFETY: as above.
    let r = unsafe { vt_ragdoll_desc_from_file(missing.as_ptr(), &mut desc) };
    refused(r, VtResult::Ragdoll, &["/nonexistent/ragdoll.toml"]);
    assert!(desc.is_null());
}

#[test]
fn a_ragdoll_built_at_a_bad_pose_is_refused_with_nothing_added() {
    let s = Scene::new();
    let desc = humanoid();
    let mut pose = lifted_bind(&desc, 0.0);
    let options = VtBuildOptions {
        spine: 1,
        at_switch: 0,
        stabilise: 0,
        stabilise_ratio: 1.0,
    };
    let mut ragdoll = null_mut();
    let w = s.w();
    pose[4].rotation.x = NAN;
    // Each call: live objects; readable pose; writable place.
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::Ragdoll, &["head"], || unsafe {
        vt_ragdoll_build(
            w,
            null_mut(),
            desc.0,
            &options,
            pose.as_ptr(),
            null(),
            pose.len(),
            DT,
            &mut ragdoll,
        )
    });
    pose[4].rotation.x = 0.0;
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::Ragdoll, &["12", "13"], || unsafe {
        vt_ragdoll_build(
            w,
            null_mut(),
            desc.0,
            &options,
            pose.as_ptr(),
            null(),
            12,
            DT,
            &mut ragdoll,
        )
    });
    for dt in [0.0, NAN, -1.0] {
        // SAFETY: live objects; every pointer null (refused) or valid for its type.
        s.refuses(VtResult::Ragdoll, &["time"], || unsafe {
            vt_ragdoll_build(
                w,
                null_mut(),
                desc.0,
                &options,
                pose.as_ptr(),
                pose.as_ptr(),
                pose.len(),
                dt,
                &mut ragdoll,
            )
        });
    }
    let bad = VtBuildOptions {
        spine: 2,
        ..options
    };
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(ENUM, &["options.spine"], || unsafe {
        vt_ragdoll_build(
            w,
            null_mut(),
            desc.0,
            &bad,
            pose.as_ptr(),
            null(),
            pose.len(),
            DT,
            &mut ragdoll,
        )
    });
    let bad = VtBuildOptions {
        stabilise: 1,
        stabilise_ratio: NAN,
        ..options
    };
    // SAFETY: live objects; every pointer null (refused) or valid for its type.
    s.refuses(VtResult::Ragdoll, &["stabilise"], || unsafe {
        vt_ragdoll_build(
            w,
            null_mut(),
            desc.0,
            &bad,
            pose.as_ptr(),
            null(),
            pose.len(),
            DT,
            &mut ragdoll,
        )
    });
    assert!(ragdoll.is_null());
}

#[test]
fn a_count_no_array_can_hold_is_refused_naming_it() {
    // A count whose bytes exceed isize::MAX describes no array: refused,
    // naming it, before any slice is made of it.
    let s = Scene::new();
    let w = s.w();
    let desc = humanoid();
    let through = [v(0.0, 0.0, 0.0); 2];
    let huge = usize::MAX / 2;
    // Each call: live objects; the count is refused before the
    // pointer is read past its first item.
    // SAFETY: live objects and valid places, but for the argument refused.
    s.refuses(VtResult::OutOfRange, &["contacts"], || unsafe {
        let contact = std::mem::zeroed::<VtContact>();
        vt_world_set_contacts(w, &contact, huge)
    });
    // SAFETY: live objects and valid places, but for the argument refused.
    s.refuses(VtResult::OutOfRange, &["through"], || unsafe {
        vt_rod_from_pose(
            w,
            s.a,
            s.b,
            through.as_ptr(),
            usize::MAX,
            &mut rod_desc(&s.world, s.a, s.b),
        )
    });
    // SAFETY: live objects and valid places, but for the argument refused.
    s.refuses(VtResult::OutOfRange, &["data"], || unsafe {
        vt_world_restore(w, through.as_ptr().cast(), usize::MAX)
    });
    let mut pose = [VtTransform {
        position: v(0.0, 0.0, 0.0),
        rotation: IDENTITY,
    }; 2];
    // SAFETY: as above.
    refused(
        unsafe { vt_ragdoll_desc_bind_pose(desc.0, pose.as_mut_ptr(), huge) },
        VtResult::OutOfRange,
        &["pose"],
    );
    let options = VtBuildOptions {
        spine: 0,
        at_switch: 0,
        stabilise: 0,
        stabilise_ratio: 1.0,
    };
    let mut ragdoll = null_mut();
    // SAFETY: live objects and valid places, but for the argument refused.
    s.refuses(VtResult::OutOfRange, &["pose"], || unsafe {
        vt_ragdoll_build(
            w,
            null_mut(),
            desc.0,
            &options,
            pose.as_ptr(),
            null(),
            huge,
            DT,
            &mut ragdoll,
        )
    });
    assert!(ragdoll.is_null());
    let skeleton = CSkeleton::reference();
    // SAFETY: as above.
    refused(
        unsafe { vt_skeleton_bind_pose(skeleton.0, pose.as_mut_ptr(), huge) },
        VtResult::OutOfRange,
        &["local"],
    );
}

#[test]
fn a_refused_collider_call_writes_nothing_and_adds_nothing() {
    let s = Scene::new();
    let layer = CLayer::new();
    let before = layer.bytes(&s.world);
    let mut storage = [0u64; 2];
    let odd = storage
        .as_mut_ptr()
        .cast::<u8>()
        .wrapping_add(1)
        .cast::<usize>();
    // SAFETY: a live layer; readable collider; `odd` is refused.
    refused(
        unsafe { vt_collisions_add(layer.0, &plane(s.ground), odd) },
        NULL,
        &["index", "aligned"],
    );
    assert!(
        layer.bytes(&s.world) == before,
        "a refused add added a collider"
    );
    let mut bad = plane(s.ground);
    bad.plane_normal = v(0.0, NAN, 0.0);
    // SAFETY: as above.
    refused(
        unsafe { vt_collisions_add(layer.0, &bad, null_mut()) },
        VtResult::Collider,
        &["normal"],
    );
    bad = plane(s.ground);
    bad.friction = -1.0;
    // SAFETY: as above.
    refused(
        unsafe { vt_collisions_add(layer.0, &bad, null_mut()) },
        VtResult::Collider,
        &["friction"],
    );
    bad = plane(s.ground);
    bad.kind = 2;
    // SAFETY: as above.
    refused(
        unsafe { vt_collisions_add(layer.0, &bad, null_mut()) },
        ENUM,
        &["collider.kind"],
    );
    for margin in [NAN, INF, -1.0] {
        // SAFETY: a live layer.
        let r = unsafe { vt_collisions_set_prediction(layer.0, margin) };
        assert_ne!(r, VtResult::Ok, "{margin}");
    }
    assert!(layer.bytes(&s.world) == before);
}

#[test]
fn a_refused_placement_writes_none_of_its_outputs() {
    let c = Drop_::new(VtSpineMode::Rod);
    let sentinel = v(9.0, 9.0, 9.0);
    let (mut low, mut high) = (sentinel, sentinel);
    let mut storage = [0u64; 8];
    let odd = storage
        .as_mut_ptr()
        .cast::<u8>()
        .wrapping_add(1)
        .cast::<VtTransform>();
    // SAFETY: live objects; `odd` is refused.
    refused(
        unsafe { vt_ragdoll_placement(c.ragdoll, c.world.0, odd, &mut low, &mut high) },
        NULL,
        &["root", "aligned"],
    );
    assert_eq!((low, high), (sentinel, sentinel));
    let odd = odd.cast::<VtVec3>();
    // SAFETY: as above.
    refused(
        unsafe { vt_ragdoll_placement(c.ragdoll, c.world.0, null_mut(), &mut low, odd) },
        NULL,
        &["max", "aligned"],
    );
    assert_eq!(low, sentinel);
    assert_eq!(storage, [0; 8]);
    let mut root = VtTransform {
        position: sentinel,
        rotation: IDENTITY,
    };
    // SAFETY: live objects; writable places.
    ok(unsafe { vt_ragdoll_placement(c.ragdoll, c.world.0, &mut root, &mut low, &mut high) });
    assert!(low.y < root.position.y && root.position.y < high.y);
}

#[test]
fn a_refused_contact_is_named_by_its_place_in_the_list() {
    let s = Scene::new();
    let good = VtContact {
        body_a: s.ground,
        body_b: s.a,
        point: v(0.0, 0.8, 0.0),
        normal: v(0.0, 1.0, 0.0),
        depth: 0.0,
        friction: 0.5,
        restitution: 0.0,
    };
    let mut list = [good; 4];
    list[2].body_b = bits_body();
    // SAFETY: a live world; four readable contacts.
    s.refuses(VtResult::ForeignHandle, &["contact 2", "body"], || unsafe {
        vt_world_set_contacts(s.w(), list.as_ptr(), list.len())
    });
    list[2] = good;
    list[3].friction = NAN;
    // SAFETY: as above.
    s.refuses(VtResult::NonFinite, &["contact 3", "friction"], || unsafe {
        vt_world_set_contacts(s.w(), list.as_ptr(), list.len())
    });
}

#[test]
fn a_null_array_with_room_is_refused_without_its_count_written() {
    // The count (or length) is written on success and, as the needed
    // length, when the array is too small; a null array said to have room
    // is neither: refused, nothing written.
    let s = Scene::new();
    let contact = VtContact {
        body_a: s.ground,
        body_b: s.a,
        point: v(0.0, 0.8, 0.0),
        normal: v(0.0, 1.0, 0.0),
        depth: 0.0,
        friction: 0.5,
        restitution: 0.0,
    };
    // SAFETY: a live world; one readable contact.
    ok(unsafe { vt_world_set_contacts(s.w(), &contact, 1) });
    let mut count = 77usize;
    // SAFETY: a live world; a null array (refused); `count` writable.
    s.refuses(NULL, &["contacts"], || unsafe {
        vt_world_contacts(s.w(), null_mut(), 5, &mut count)
    });
    assert_eq!(count, 77);
    let desc = humanoid();
    let mut length = 77usize;
    // SAFETY: a live description; a null buffer (refused); writable length.
    let r = unsafe { vt_ragdoll_desc_body_name(desc.0, 0, null_mut(), 64, &mut length) };
    refused(r, NULL, &["buffer"]);
    assert_eq!(length, 77);
    let skeleton = CSkeleton::reference();
    // SAFETY: as above.
    let r = unsafe { vt_skeleton_bone_name(skeleton.0, 0, null_mut(), 64, &mut length) };
    refused(r, NULL, &["buffer"]);
    assert_eq!(length, 77);
}

#[test]
fn a_pose_mapped_in_place_equals_one_mapped_into_another_array() {
    // The input and output arrays may be one (valid C: both are
    // `VtTransform *`); the input is read whole before the output is
    // written.
    let c = Drop_::new(VtSpineMode::Rod);
    c.step(10);
    let skeleton = CSkeleton::reference();
    let mut mapper = null_mut();
    // SAFETY: live objects; writable.
    ok(unsafe {
        vt_skeleton_mapper_create(skeleton.0, c.desc.0, VtSpineMode::Rod as u32, &mut mapper)
    });
    let mut count = 0;
    // SAFETY: a live skeleton; writable.
    ok(unsafe { vt_skeleton_bone_count(skeleton.0, &mut count) });
    let start = VtTransform {
        position: v(0.0, 0.0, 0.0),
        rotation: IDENTITY,
    };
    let mut local = vec![start; count];
    // SAFETY: `count` writable transforms.
    ok(unsafe { vt_skeleton_bind_pose(skeleton.0, local.as_mut_ptr(), count) });
    let model_to_world = VtTransform {
        position: v(0.2, 0.0, 0.1),
        rotation: Quat::from_rotation_y(0.5).into(),
    };
    let mut apart = vec![start; count];
    // SAFETY: live objects; `count` readable and writable transforms.
    ok(unsafe {
        vt_skeleton_mapper_map_to_skeleton(
            mapper,
            c.ragdoll,
            c.world.0,
            local.as_ptr(),
            model_to_world,
            VtSpineMapping::Arc as u32,
            apart.as_mut_ptr(),
            count,
        )
    });
    let mut in_place = local.clone();
    let shared = in_place.as_mut_ptr();
    // SAFETY: as above, one array for both.
    ok(unsafe {
        vt_skeleton_mapper_map_to_skeleton(
            mapper,
            c.ragdoll,
            c.world.0,
            shared,
            model_to_world,
            VtSpineMapping::Arc as u32,
            shared,
            count,
        )
    });
    assert_eq!(format!("{in_place:?}"), format!("{apart:?}"));
    // Model-space bones mapped onto the bodies, in place in an array long
    // enough for either.
    let mut model = vec![start; count];
    let model_pose = Skeleton::reference()
        .bind_pose()
        .to_model(&Skeleton::reference())
        .expect("the model pose");
    for (to, from) in model.iter_mut().zip(&model_pose.bones) {
        *to = (*from).into();
    }
    let bodies = lifted_bind(&c.desc, 0.0).len();
    let mut apart = vec![start; bodies];
    // SAFETY: a live mapper; readable and writable arrays of their counts.
    ok(unsafe {
        vt_skeleton_mapper_map_to_ragdoll(
            mapper,
            model.as_ptr(),
            count,
            model_to_world,
            apart.as_mut_ptr(),
            bodies,
        )
    });
    let shared = model.as_mut_ptr();
    // SAFETY: as above; the output is the start of the input's array.
    ok(unsafe {
        vt_skeleton_mapper_map_to_ragdoll(mapper, shared, count, model_to_world, shared, bodies)
    });
    assert_eq!(format!("{:?}", &model[..bodies]), format!("{apart:?}"));
    // SAFETY: made above, freed once.
    unsafe { vt_skeleton_mapper_destroy(mapper) };
}

/// The C ABI's string entry points read at most `MAX_FILE_BYTES` (the
/// Rust loaders behind them would parse any length): a string longer than
/// that is refused before it is parsed, with the Rust API's message;
/// nothing is written.
#[test]
fn a_string_longer_than_a_file_may_be_is_refused_before_it_is_parsed() {
    let cap = vertebra_ragdoll::MAX_FILE_BYTES as usize;
    let mut long = String::from("[[[ not toml\n");
    long.push_str(&"#".repeat(cap + 1 - long.len()));
    let long = CString::new(long).expect("no NUL");
    let (mut desc, mut skeleton) = (null_mut(), null_mut());
    // SAFETY: NUL-terminated strings; writable places.
    let (d, s) = unsafe {
        (
            vt_ragdoll_desc_from_string(long.as_ptr(), &mut desc),
            vt_skeleton_from_string(long.as_ptr(), &mut skeleton),
        )
    };
    refused(
        s,
        VtResult::Ragdoll,
        &[
            "the skeleton text is larger than MAX_FILE_BYTES (1048576 bytes) and is refused before it is parsed",
        ],
    );
    assert_eq!(d, VtResult::Ragdoll);
    assert!(desc.is_null() && skeleton.is_null());
    let refusal = desc_from(long.to_str().unwrap()).err().unwrap();
    assert!(
        refusal.1.starts_with(
            "the ragdoll text is larger than MAX_FILE_BYTES (1048576 bytes) and is refused before it is parsed"
        ),
        "{refusal:?}"
    );
}

/// A removed ragdoll is refused by every call that takes it (mapped onto
/// the skeleton by `vt_skeleton_mapper_map_to_skeleton` or
/// `vt_transition_skeleton_pose` it would put every bone at the world
/// origin; driven or removed again it would do nothing): a stale handle,
/// naming the ragdoll, with the world, the layer and every output as they
/// were.
#[test]
fn a_removed_ragdoll_is_refused_by_every_call_naming_it() {
    let c = Drop_::new(VtSpineMode::Rod);
    c.step(3);
    let skeleton = CSkeleton::reference();
    let mut mapper = null_mut();
    // SAFETY: live objects; writable.
    ok(unsafe {
        vt_skeleton_mapper_create(skeleton.0, c.desc.0, VtSpineMode::Rod as u32, &mut mapper)
    });
    let animation: Vec<VtTransform> = Skeleton::reference()
        .bind_pose()
        .bones
        .iter()
        .map(|&t| t.into())
        .collect();
    let place: VtTransform = Transform::IDENTITY.into();
    let mut transition = null_mut();
    // SAFETY: live objects; `count` readable transforms; writable place.
    ok(unsafe {
        vt_transition_create(
            mapper,
            c.ragdoll,
            c.world.0,
            animation.as_ptr(),
            animation.len(),
            place,
            VtSpineMapping::Arc as u32,
            0.3,
            &mut transition,
        )
    });
    // SAFETY: live objects.
    ok(unsafe { vt_ragdoll_remove(c.ragdoll, c.world.0, c.layer.0) });
    let (world, layer) = (c.world.bytes(), c.layer.bytes(&c.world));
    let sentinel = VtTransform {
        position: v(9.0, 9.0, 9.0),
        rotation: IDENTITY,
    };
    let mut bones = vec![sentinel; animation.len()];
    let pose = lifted_bind(&c.desc, 0.0);
    let settings = VtDriveSettings {
        strength: VtStrength {
            kind: 0,
            a: 0.0,
            b: 0.0,
        },
        damping: 0.0,
        max_torque: INF,
    };
    let world_settings = world_drive_settings(&[]);
    let name = CString::new("chest").expect("a name");
    let (r, w, l) = (c.ragdoll, c.world.0, c.layer.0);
    let (mut body, mut present, mut again) = (bits_body(), 7u32, null_mut());
    let (mut root, mut low) = (sentinel, v(9.0, 9.0, 9.0));
    // SAFETY: every call's objects are live, each pointer valid for its
    // type and length.
    let calls: Vec<(&str, VtResult)> = unsafe {
        vec![
            (
                "vt_skeleton_mapper_map_to_skeleton",
                vt_skeleton_mapper_map_to_skeleton(
                    mapper,
                    r,
                    w,
                    animation.as_ptr(),
                    place,
                    VtSpineMapping::Arc as u32,
                    bones.as_mut_ptr(),
                    bones.len(),
                ),
            ),
            (
                "vt_transition_skeleton_pose",
                vt_transition_skeleton_pose(
                    transition,
                    mapper,
                    r,
                    w,
                    animation.as_ptr(),
                    place,
                    0.1,
                    bones.as_mut_ptr(),
                    bones.len(),
                ),
            ),
            (
                "vt_transition_create",
                vt_transition_create(
                    mapper,
                    r,
                    w,
                    animation.as_ptr(),
                    animation.len(),
                    place,
                    VtSpineMapping::Arc as u32,
                    0.3,
                    &mut again,
                ),
            ),
            (
                "vt_ragdoll_drive_to",
                vt_ragdoll_drive_to(r, w, pose.as_ptr(), pose.len(), &settings),
            ),
            (
                "vt_ragdoll_drive_following",
                vt_ragdoll_drive_following(
                    r,
                    w,
                    pose.as_ptr(),
                    pose.as_ptr(),
                    pose.len(),
                    DT,
                    &settings,
                ),
            ),
            ("vt_ragdoll_release_drives", vt_ragdoll_release_drives(r, w)),
            (
                "vt_ragdoll_world_drive_following",
                vt_ragdoll_world_drive_following(
                    r,
                    w,
                    pose.as_ptr(),
                    pose.as_ptr(),
                    pose.len(),
                    DT,
                    &world_settings,
                ),
            ),
            (
                "vt_ragdoll_follow",
                vt_ragdoll_follow(
                    r,
                    w,
                    pose.as_ptr(),
                    pose.as_ptr(),
                    pose.len(),
                    DT,
                    &settings,
                    &world_settings,
                ),
            ),
            (
                "vt_ragdoll_release_world_drives",
                vt_ragdoll_release_world_drives(r, w),
            ),
            (
                "vt_ragdoll_apply_impulse",
                vt_ragdoll_apply_impulse(r, w, name.as_ptr(), v(1.0, 0.0, 0.0), null()),
            ),
            (
                "vt_ragdoll_set_velocity",
                vt_ragdoll_set_velocity(r, w, v(1.0, 0.0, 0.0), v(0.0, 0.0, 0.0)),
            ),
            (
                "vt_ragdoll_set_body_kinematic",
                vt_ragdoll_set_body_kinematic(r, w, name.as_ptr(), 1),
            ),
            (
                "vt_ragdoll_placement",
                vt_ragdoll_placement(r, w, &mut root, &mut low, null_mut()),
            ),
            (
                "vt_ragdoll_body",
                vt_ragdoll_body(r, 0, &mut body, &mut present),
            ),
            ("vt_ragdoll_remove", vt_ragdoll_remove(r, w, l)),
            (
                "vt_collisions_set_ragdoll_groups",
                vt_collisions_set_ragdoll_groups(l, r, 1, 1),
            ),
            (
                "vt_collisions_set_ragdoll_self_collision",
                vt_collisions_set_ragdoll_self_collision(l, r, 0),
            ),
        ]
    };
    for (call, result) in calls {
        assert_eq!(result, VtResult::StaleHandle, "{call}");
    }
    // The last message is the last call's; each names the ragdoll (the
    // Rust error's text, checked in vertebra-ragdoll's tests/removed.rs).
    assert!(
        message().contains("ragdoll `reference-humanoid` has been removed from the world"),
        "{}",
        message()
    );
    // SAFETY: as above.
    let mapped = unsafe {
        vt_skeleton_mapper_map_to_skeleton(
            mapper,
            r,
            w,
            animation.as_ptr(),
            place,
            VtSpineMapping::Arc as u32,
            bones.as_mut_ptr(),
            bones.len(),
        )
    };
    refused(
        mapped,
        VtResult::StaleHandle,
        &["ragdoll `reference-humanoid` has been removed from the world"],
    );
    assert!(bones.iter().all(|b| b.position == sentinel.position));
    assert_eq!((root.position, low), (sentinel.position, v(9.0, 9.0, 9.0)));
    assert_eq!((present, body), (7, bits_body()));
    assert!(again.is_null());
    assert!(world == c.world.bytes() && layer == c.layer.bytes(&c.world));
    // SAFETY: made above, freed once.
    unsafe {
        vt_transition_destroy(transition);
        vt_skeleton_mapper_destroy(mapper);
    }
}

/// A rod spine asked of a description without a `[spine]` through the C ABI
/// (`vt_ragdoll_build`, with and without the collision layer, and
/// `vt_skeleton_mapper_create`) is refused by name.
#[test]
fn a_rod_spine_of_a_description_without_a_spine_is_refused_through_c() {
    let reference = vertebra_ragdoll::REFERENCE_HUMANOID;
    let no_spine = desc_from(&reference[..reference.find("\n[spine]").unwrap()])
        .unwrap_or_else(|e| panic!("{e:?}"));
    let expected = "ragdoll `reference-humanoid`: spine is a rod (SpineMode::Rod), but the \
                    description has no [spine] for one to replace";
    let world = CWorld::new();
    let layer = CLayer::new();
    let (before, layer_before) = (world.bytes(), layer.bytes(&world));
    let pose = lifted_bind(&no_spine, 0.0);
    let options = VtBuildOptions {
        spine: VtSpineMode::Rod as u32,
        at_switch: 0,
        stabilise: 0,
        stabilise_ratio: 1.0,
    };
    for collisions in [null_mut(), layer.0] {
        let mut ragdoll = null_mut();
        // SAFETY: live objects; readable options and pose; writable place.
        let built = unsafe {
            vt_ragdoll_build(
                world.0,
                collisions,
                no_spine.0,
                &options,
                pose.as_ptr(),
                null(),
                pose.len(),
                DT,
                &mut ragdoll,
            )
        };
        refused(built, VtResult::Ragdoll, &[expected]);
        assert!(ragdoll.is_null());
    }
    assert!(before == world.bytes() && layer_before == layer.bytes(&world));
    let skeleton = CSkeleton::reference();
    let mut mapper = null_mut();
    // SAFETY: live objects; writable.
    let made = unsafe {
        vt_skeleton_mapper_create(skeleton.0, no_spine.0, VtSpineMode::Rod as u32, &mut mapper)
    };
    refused(made, VtResult::Ragdoll, &[expected]);
    assert!(mapper.is_null());
}

fn spring(frequency: f32, damping_ratio: f32) -> VtSoftness {
    VtSoftness {
        kind: VtSoftnessKind::Spring as u32,
        a: frequency,
        b: damping_ratio,
    }
}

#[test]
fn world_and_upright_drives_round_trip_pull_and_refuse_by_name() {
    let s = Scene::new();
    let target = v(0.5, 1.8, 0.1);
    let drive = VtWorldDrive {
        position: target,
        orientation: IDENTITY,
        linear_velocity: v(0.0, 0.0, 0.0),
        angular_velocity: v(0.0, 0.0, 0.0),
        has_linear: 1,
        linear: spring(4.0, 1.0),
        has_angular: 0,
        angular: spring(1.0, 1.0),
        max_force: 200.0,
        max_torque: f32::INFINITY,
    };
    let upright = VtUprightDrive {
        axis: v(0.0, 1.0, 0.0),
        up: v(0.0, 1.0, 0.0),
        strength: spring(2.0, 1.0),
        max_torque: 30.0,
    };
    // Refusals name the field and change nothing.
    let hard = VtWorldDrive {
        linear: VtSoftness {
            kind: VtSoftnessKind::Hard as u32,
            ..drive.linear
        },
        ..drive
    };
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    s.refuses(VtResult::InvalidEnum, &["drive.linear.kind"], || unsafe {
        vt_world_set_world_drive(s.w(), s.c, &hard)
    });
    let nan = VtWorldDrive {
        max_force: f32::NAN,
        ..drive
    };
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    s.refuses(VtResult::NonFinite, &["world drive max force"], || unsafe {
        vt_world_set_world_drive(s.w(), s.c, &nan)
    });
    let tilted = VtUprightDrive {
        axis: v(0.0, 2.0, 0.0),
        ..upright
    };
    s.refuses(
        VtResult::NotNormalized,
        &["upright drive axis"],
        // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
        || unsafe { vt_world_set_upright_drive(s.w(), s.c, &tilted) },
    );
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    s.refuses(VtResult::NotDynamic, &["driven body"], || unsafe {
        vt_world_set_world_drive(s.w(), s.ground, &drive)
    });
    let mut has = 7u32;
    let mut read = drive;
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    s.refuses(VtResult::NullPointer, &["has"], || unsafe {
        vt_world_world_drive(s.w(), s.c, null_mut(), &mut read)
    });
    assert_eq!(has, 7, "a refused call wrote its output");
    // Set, read back, pull.
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    ok(unsafe { vt_world_set_world_drive(s.w(), s.c, &drive) });
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    ok(unsafe { vt_world_set_upright_drive(s.w(), s.c, &upright) });
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    ok(unsafe { vt_world_world_drive(s.w(), s.c, &mut has, &mut read) });
    assert_eq!(has, 1);
    assert_eq!((read.position.x, read.max_force), (0.5, 200.0));
    assert_eq!((read.has_linear, read.has_angular), (1, 0));
    let mut up = upright;
    up.max_torque = 0.0;
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    ok(unsafe { vt_world_upright_drive(s.w(), s.c, &mut has, &mut up) });
    assert_eq!((has, up.max_torque), (1, 30.0));
    let mut before = std::mem::MaybeUninit::<VtBodyState>::uninit();
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    ok(unsafe { vt_world_body_state(s.w(), s.c, before.as_mut_ptr()) });
    // SAFETY: written by the call above.
    let before = unsafe { before.assume_init() }.position.x;
    s.world.step(60);
    let mut after = std::mem::MaybeUninit::<VtBodyState>::uninit();
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    ok(unsafe { vt_world_body_state(s.w(), s.c, after.as_mut_ptr()) });
    // SAFETY: written by the call above.
    let after = unsafe { after.assume_init() }.position.x;
    assert!(
        (after - 0.5).abs() < (before - 0.5).abs(),
        "{before} -> {after}"
    );
    // Cleared by null.
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    ok(unsafe { vt_world_set_world_drive(s.w(), s.c, null()) });
    // SAFETY: a live world; readable inputs, writable outputs (or the null tested).
    ok(unsafe { vt_world_world_drive(s.w(), s.c, &mut has, &mut read) });
    assert_eq!(has, 0);
}

/// Every body's world drive at 2 Hz, ratio 1, capped at half its weight
/// and 20 N m, with `uprights`.
fn world_drive_settings(uprights: &[VtUpright]) -> VtWorldDriveSettings {
    VtWorldDriveSettings {
        has_linear: 1,
        linear: spring(2.0, 1.0),
        has_angular: 1,
        angular: spring(2.0, 1.0),
        max_acceleration: 4.9,
        max_torque: 20.0,
        uprights: uprights.as_ptr(),
        upright_count: uprights.len(),
    }
}

#[test]
fn a_ragdoll_follows_its_animation_in_the_world_from_c() {
    let c = Drop_::new(VtSpineMode::Sockets);
    let pose = lifted_bind(&c.desc, 0.3);
    let joints = VtDriveSettings {
        strength: VtStrength {
            kind: 2,
            a: 8.0,
            b: 1.0,
        },
        damping: 0.0,
        max_torque: 300.0,
    };
    let (r, w) = (c.ragdoll, c.world.0);
    let (name, mut index) = (CString::new("chest").expect("a name"), 0usize);
    // SAFETY: a live description; a NUL-terminated name; writable.
    ok(unsafe { vt_ragdoll_desc_body_index(c.desc.0, name.as_ptr(), &mut index) });
    let chest = VtUpright {
        body: index as u32,
        strength: spring(2.0, 1.0),
        max_torque: 100.0,
    };
    let hard = VtUpright {
        strength: VtSoftness {
            kind: VtSoftnessKind::Hard as u32,
            a: 0.0,
            b: 0.0,
        },
        ..chest
    };
    let follow = |settings: &VtWorldDriveSettings| {
        // SAFETY: live objects; `count` readable transforms; readable
        // settings whose uprights are as they say.
        unsafe {
            vt_ragdoll_follow(
                r,
                w,
                pose.as_ptr(),
                pose.as_ptr(),
                pose.len(),
                DT,
                &joints,
                settings,
            )
        }
    };
    let before = c.world.bytes();
    let mut nulled = world_drive_settings(&[chest]);
    nulled.uprights = null();
    refused(
        follow(&nulled),
        VtResult::NullPointer,
        &["settings.uprights"],
    );
    refused(
        follow(&world_drive_settings(&[hard])),
        VtResult::InvalidEnum,
        &["settings.uprights[0].strength.kind"],
    );
    let too_far = VtUpright { body: 99, ..chest };
    refused(
        follow(&world_drive_settings(&[too_far])),
        VtResult::Ragdoll,
        &["world drive upright 0", "body"],
    );
    assert!(
        before == c.world.bytes(),
        "a refused call changed the world"
    );
    ok(follow(&world_drive_settings(&[chest])));
    let mut count = 0;
    // SAFETY: a live description; writable.
    ok(unsafe { vt_ragdoll_desc_body_count(c.desc.0, &mut count) });
    let mut uprights = 0;
    for k in 0..count {
        let (mut body, mut present) = (bits_body(), 0u32);
        // SAFETY: live objects; writable.
        ok(unsafe { vt_ragdoll_body(r, k, &mut body, &mut present) });
        assert_eq!(present, 1, "body {k}");
        let (mut has, mut drive) = (0u32, std::mem::MaybeUninit::<VtWorldDrive>::uninit());
        // SAFETY: a live world; writable outputs.
        ok(unsafe { vt_world_world_drive(w, body, &mut has, drive.as_mut_ptr()) });
        assert_eq!(has, 1, "body {k}");
        // SAFETY: written by the call above.
        let drive = unsafe { drive.assume_init() };
        assert_eq!((drive.has_linear, drive.max_torque), (1, 20.0));
        let mut up = std::mem::MaybeUninit::<VtUprightDrive>::uninit();
        // SAFETY: a live world; writable outputs.
        ok(unsafe { vt_world_upright_drive(w, body, &mut has, up.as_mut_ptr()) });
        uprights += has;
    }
    assert_eq!(uprights, 1);
    // SAFETY: live objects.
    ok(unsafe { vt_ragdoll_release_world_drives(r, w) });
}
