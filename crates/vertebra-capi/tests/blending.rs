//! Per-joint drive strengths, per-bone blending and the blend back through
//! the C ABI: bit for bit what the Rust API does, and refusals that name
//! the item and change nothing.

use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

use glam::{Quat, Vec3};
use vertebra_capi::*;
use vertebra_ragdoll::{
    BlendBack, BuildOptions, DriveSettings, GetUp, LocalPose, Pose, Ragdoll, RagdollDesc, Skeleton,
    SpineMapping, SpineMode,
};
use vertebra_world::{SolverConfig, Spring, World};

const DT: f32 = 1.0 / 60.0;

fn ok(result: VtResult) {
    assert_eq!(result, VtResult::Ok, "{}", message());
}

fn message() -> String {
    // SAFETY: the message is a NUL-terminated string valid until this
    // thread's next refusal.
    unsafe { CStr::from_ptr(vt_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

fn refused(result: VtResult, code: VtResult, words: &[&str]) {
    assert_eq!(result, code, "{}", message());
    let text = message();
    for word in words {
        assert!(text.contains(word), "`{text}` names {word}");
    }
}

fn c_pose(pose: &Pose) -> Vec<VtTransform> {
    pose.bones.iter().map(|&t| t.into()).collect()
}

fn rust_pose(pose: &[VtTransform]) -> Pose {
    Pose {
        bones: pose.iter().map(|&t| t.into()).collect(),
    }
}

/// A crouch: the bind pose turned about the hips.
fn crouch(desc: &RagdollDesc) -> Pose {
    Pose::bind(desc).moved(
        Vec3::new(0.0, 1.0, 0.0),
        Quat::from_rotation_x(0.4),
        Vec3::Y * 0.1,
    )
}

/// The reference humanoid in a C world and in a Rust world, both falling
/// from its bind pose.
struct Twins {
    c_world: *mut VtWorld,
    c_desc: *mut VtRagdollDesc,
    c_ragdoll: *mut VtRagdoll,
    world: World,
    desc: RagdollDesc,
    ragdoll: Ragdoll,
}

impl Twins {
    fn new() -> Self {
        let desc = RagdollDesc::reference_humanoid();
        let bind = c_pose(&Pose::bind(&desc));
        let (mut c_world, mut c_desc, mut c_ragdoll) = (null_mut(), null_mut(), null_mut());
        let options = VtBuildOptions {
            spine: VtSpineMode::Rod as u32,
            at_switch: 0,
            stabilise: 0,
            stabilise_ratio: 1.0,
        };
        // SAFETY: writable places; a readable pose and options; live
        // objects made just before.
        unsafe {
            ok(vt_world_create(null(), &mut c_world));
            ok(vt_ragdoll_desc_humanoid(
                VtHumanoid::Reference as u32,
                &mut c_desc,
            ));
            ok(vt_ragdoll_build(
                c_world,
                null_mut(),
                c_desc,
                &options,
                bind.as_ptr(),
                null(),
                bind.len(),
                0.0,
                &mut c_ragdoll,
            ));
        }
        let mut world = World::new(SolverConfig::default()).expect("a world");
        let options = BuildOptions::new(SpineMode::Rod);
        let ragdoll =
            Ragdoll::build(&mut world, &desc, options, &Pose::bind(&desc), None).expect("built");
        Self {
            c_world,
            c_desc,
            c_ragdoll,
            world,
            desc,
            ragdoll,
        }
    }

    fn step(&mut self, steps: usize) {
        for _ in 0..steps {
            // SAFETY: a live world.
            ok(unsafe { vt_world_step(self.c_world, DT) });
            self.world.step(DT).expect("a step");
        }
    }

    fn c_hash(&self) -> u64 {
        let mut hash = 0;
        // SAFETY: a live world; writable.
        ok(unsafe { vt_world_state_hash(self.c_world, &mut hash) });
        hash
    }

    fn joint(&self, name: &str) -> u32 {
        let name = CString::new(name).expect("a name");
        let mut index = 0;
        // SAFETY: a live description; a NUL-terminated name; writable.
        ok(unsafe { vt_ragdoll_desc_joint_index(self.c_desc, name.as_ptr(), &mut index) });
        index as u32
    }
}

impl Drop for Twins {
    fn drop(&mut self) {
        // SAFETY: made above, freed once.
        unsafe {
            vt_ragdoll_destroy(self.c_ragdoll);
            vt_ragdoll_desc_destroy(self.c_desc);
            vt_world_destroy(self.c_world);
        }
    }
}

fn spring(frequency: f32) -> VtStrength {
    VtStrength {
        kind: VtStrengthKind::Spring as u32,
        a: frequency,
        b: 0.8,
    }
}

#[test]
fn joints_driven_at_strengths_of_their_own_move_as_in_rust() {
    let mut t = Twins::new();
    let target = crouch(&t.desc);
    let previous = Pose::bind(&t.desc);
    let (c_target, c_previous) = (c_pose(&target), c_pose(&previous));
    let settings = VtDriveSettings {
        strength: spring(4.0),
        damping: 0.0,
        max_torque: 200.0,
    };
    let (neck, elbow) = (t.joint("neck"), t.joint("elbow_l"));
    let overrides = [
        VtJointStrength {
            joint: neck,
            strength: spring(12.0),
        },
        VtJointStrength {
            joint: elbow,
            strength: VtStrength {
                kind: VtStrengthKind::Infinite as u32,
                a: 0.0,
                b: 0.0,
            },
        },
    ];
    let mut rust = DriveSettings::uniform(Spring::Frequency {
        frequency: 4.0,
        damping_ratio: 0.8,
    })
    .with_max_torque(200.0);
    rust.joints = vec![None; t.desc.joints.len()];
    rust.joints[neck as usize] = Some(Spring::Frequency {
        frequency: 12.0,
        damping_ratio: 0.8,
    });
    rust.joints[elbow as usize] = Some(Spring::RIGID);
    // SAFETY: live objects; readable arrays of the counts given.
    ok(unsafe {
        vt_ragdoll_drive_following_with(
            t.c_ragdoll,
            t.c_world,
            c_previous.as_ptr(),
            c_target.as_ptr(),
            c_target.len(),
            DT,
            &settings,
            overrides.as_ptr(),
            overrides.len(),
        )
    });
    (t.ragdoll)
        .drive_following(&mut t.world, &previous, &target, DT, &rust)
        .expect("driven");
    t.step(20);
    assert_eq!(t.c_hash(), t.world.state_hash());
    // SAFETY: as above.
    ok(unsafe {
        vt_ragdoll_drive_to_with(
            t.c_ragdoll,
            t.c_world,
            c_target.as_ptr(),
            c_target.len(),
            &settings,
            overrides.as_ptr(),
            overrides.len(),
        )
    });
    (t.ragdoll)
        .drive_to(&mut t.world, &target, &rust)
        .expect("driven");
    t.step(20);
    assert_eq!(t.c_hash(), t.world.state_hash());
    // The overrides matter: without them the world goes otherwise.
    let mut plain = Twins::new();
    // SAFETY: as above, no overrides.
    ok(unsafe {
        vt_ragdoll_drive_to_with(
            plain.c_ragdoll,
            plain.c_world,
            c_target.as_ptr(),
            c_target.len(),
            &settings,
            null(),
            0,
        )
    });
    plain.step(40);
    assert_ne!(plain.c_hash(), t.c_hash());
    // Refused, naming the override, with nothing changed.
    let before = t.c_hash();
    let mut twice = overrides;
    twice[1].joint = neck;
    let mut past = overrides;
    past[0].joint = t.desc.joints.len() as u32;
    let mut bad = overrides;
    bad[0].strength.a = -1.0;
    for (list, code, words) in [
        (twice, VtResult::OutOfRange, &["overrides[1]", "neck"][..]),
        (past, VtResult::OutOfRange, &["overrides[0]", "joints"][..]),
        (
            bad,
            VtResult::Ragdoll,
            &["joint `neck`", "drive frequency"][..],
        ),
    ] {
        // SAFETY: as above.
        let r = unsafe {
            vt_ragdoll_drive_to_with(
                t.c_ragdoll,
                t.c_world,
                c_target.as_ptr(),
                c_target.len(),
                &settings,
                list.as_ptr(),
                list.len(),
            )
        };
        refused(r, code, words);
    }
    // SAFETY: as above, a null list with a count.
    let r = unsafe {
        vt_ragdoll_drive_to_with(
            t.c_ragdoll,
            t.c_world,
            c_target.as_ptr(),
            c_target.len(),
            &settings,
            null(),
            2,
        )
    };
    refused(r, VtResult::NullPointer, &["overrides"]);
    assert_eq!(t.c_hash(), before, "refused: nothing changed");
    t.step(5);
    assert_eq!(t.c_hash(), t.world.state_hash());
}

#[test]
fn poses_blend_bone_by_bone_as_in_rust() {
    let desc = RagdollDesc::reference_humanoid();
    let mut c_desc = null_mut();
    // SAFETY: writable.
    ok(unsafe { vt_ragdoll_desc_humanoid(VtHumanoid::Reference as u32, &mut c_desc) });
    let (a, b) = (Pose::bind(&desc), crouch(&desc));
    let weights: Vec<f32> = (0..desc.bodies.len())
        .map(|k| k as f32 / (desc.bodies.len() - 1) as f32)
        .collect();
    let mut out = c_pose(&a);
    let (ca, cb) = (c_pose(&a), c_pose(&b));
    // SAFETY: a live description; arrays of `count`; `out` writable.
    ok(unsafe {
        vt_ragdoll_pose_blend(
            c_desc,
            ca.as_ptr(),
            cb.as_ptr(),
            weights.as_ptr(),
            ca.len(),
            out.as_mut_ptr(),
        )
    });
    let expected = a.blend(&desc, &b, &weights).expect("blended");
    assert_eq!(rust_pose(&out), expected);
    assert_eq!(out[0], ca[0], "weight 0 is the first pose exactly");
    assert_eq!(
        *out.last().unwrap(),
        *cb.last().unwrap(),
        "weight 1 the second"
    );
    // A weight out of range is refused, naming the body; out untouched.
    let mut bad = weights.clone();
    bad[2] = 1.5;
    let kept = out.clone();
    // SAFETY: as above.
    let r = unsafe {
        vt_ragdoll_pose_blend(
            c_desc,
            ca.as_ptr(),
            cb.as_ptr(),
            bad.as_ptr(),
            ca.len(),
            out.as_mut_ptr(),
        )
    };
    refused(r, VtResult::Ragdoll, &[&desc.bodies[2].name, "weight"]);
    assert_eq!(out, kept);
    // SAFETY: made above, freed once.
    unsafe { vt_ragdoll_desc_destroy(c_desc) };

    // A skeleton's local poses.
    let skeleton = Skeleton::reference();
    let mut c_skeleton = null_mut();
    // SAFETY: writable.
    ok(unsafe { vt_skeleton_reference(&mut c_skeleton) });
    let la = skeleton.bind_pose();
    let mut lb = la.clone();
    for bone in &mut lb.bones {
        bone.rotation = (bone.rotation * Quat::from_rotation_z(0.3)).normalize();
    }
    let half = vec![0.5; skeleton.len()];
    let (cla, clb): (Vec<VtTransform>, Vec<VtTransform>) = (
        la.bones.iter().map(|&t| t.into()).collect(),
        lb.bones.iter().map(|&t| t.into()).collect(),
    );
    let mut out = cla.clone();
    // SAFETY: a live skeleton; arrays of `count`; `out` writable.
    ok(unsafe {
        vt_skeleton_pose_blend(
            c_skeleton,
            cla.as_ptr(),
            clb.as_ptr(),
            half.as_ptr(),
            cla.len(),
            out.as_mut_ptr(),
        )
    });
    let expected = la.blend(&skeleton, &lb, &half).expect("blended");
    let got = LocalPose {
        bones: out.iter().map(|&t| t.into()).collect(),
    };
    assert_eq!(got, expected);
    // SAFETY: made above, freed once.
    unsafe { vt_skeleton_destroy(c_skeleton) };
}

#[test]
fn a_blend_back_fades_to_the_animation_as_in_rust() {
    let desc = RagdollDesc::reference_humanoid();
    let mut c_desc = null_mut();
    // SAFETY: writable.
    ok(unsafe { vt_ragdoll_desc_humanoid(VtHumanoid::Reference as u32, &mut c_desc) });
    let simulated = crouch(&desc);
    let animation = |t: f32| Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::Z * t);
    let c_simulated = c_pose(&simulated);
    let mut blend = null_mut();
    // SAFETY: a live description; a readable pose; writable.
    let r = unsafe {
        vt_blend_back_create_ragdoll(
            c_desc,
            c_simulated.as_ptr(),
            c_simulated.len(),
            0.0,
            &mut blend,
        )
    };
    refused(r, VtResult::Ragdoll, &["duration"]);
    assert!(blend.is_null(), "nothing made");
    // SAFETY: as above.
    ok(unsafe {
        vt_blend_back_create_ragdoll(
            c_desc,
            c_simulated.as_ptr(),
            c_simulated.len(),
            0.25,
            &mut blend,
        )
    });
    let mut rust = BlendBack::new(&desc, simulated.clone(), 0.25).expect("a blend");
    let mut frames = 0;
    loop {
        let now = animation(frames as f32 * DT);
        let mut out = c_pose(&now);
        let (mut weight, mut done) = (0.0, 0);
        // SAFETY: a live blend; arrays of `count`; writable outputs.
        unsafe {
            ok(vt_blend_back_weight(blend, &mut weight, &mut done));
            ok(vt_blend_back_pose(
                blend,
                out.as_ptr(),
                out.len(),
                out.as_mut_ptr(),
            ));
        }
        assert_eq!(weight, rust.weight());
        assert_eq!(done != 0, rust.is_done());
        assert_eq!(rust_pose(&out), rust.pose(&desc, &now).expect("a pose"));
        if frames == 0 {
            assert_eq!(out, c_simulated, "the first frame is the ragdoll's");
        }
        if done != 0 {
            assert_eq!(rust_pose(&out), now, "the animation's at the end");
            break;
        }
        // SAFETY: a live blend.
        ok(unsafe { vt_blend_back_advance(blend, DT) });
        rust.advance(DT).expect("advanced");
        frames += 1;
    }
    assert!((15..=16).contains(&frames), "0.25 s at 60 Hz: {frames}");
    // SAFETY: a live blend.
    let r = unsafe { vt_blend_back_advance(blend, f32::NAN) };
    refused(r, VtResult::Ragdoll, &["dt"]);
    // SAFETY: made above, freed once.
    unsafe {
        vt_blend_back_destroy(blend);
        vt_ragdoll_desc_destroy(c_desc);
    }

    // On a skeleton's local poses.
    let skeleton = Skeleton::reference();
    let mut c_skeleton = null_mut();
    // SAFETY: writable.
    ok(unsafe { vt_skeleton_reference(&mut c_skeleton) });
    let mut held = skeleton.bind_pose();
    held.bones[0].translation += Vec3::X;
    let c_held: Vec<VtTransform> = held.bones.iter().map(|&t| t.into()).collect();
    let mut blend = null_mut();
    // SAFETY: a live skeleton; a readable pose; writable.
    ok(unsafe {
        vt_blend_back_create_skeleton(c_skeleton, c_held.as_ptr(), c_held.len(), 0.1, &mut blend)
    });
    let mut rust = BlendBack::new(&skeleton, held, 0.1).expect("a blend");
    let bind: Vec<VtTransform> = skeleton
        .bind_pose()
        .bones
        .iter()
        .map(|&t| t.into())
        .collect();
    for _ in 0..3 {
        // SAFETY: a live blend.
        ok(unsafe { vt_blend_back_advance(blend, DT) });
        rust.advance(DT).expect("advanced");
    }
    let mut out = bind.clone();
    // SAFETY: a live blend; arrays of `count`.
    ok(unsafe { vt_blend_back_pose(blend, bind.as_ptr(), bind.len(), out.as_mut_ptr()) });
    let expected = rust.pose(&skeleton, &skeleton.bind_pose()).expect("a pose");
    let got = LocalPose {
        bones: out.iter().map(|&t| t.into()).collect(),
    };
    assert_eq!(got, expected);
    // One bone short: refused.
    // SAFETY: as above, a shorter count.
    let r = unsafe { vt_blend_back_pose(blend, bind.as_ptr(), bind.len() - 1, out.as_mut_ptr()) };
    assert_ne!(r, VtResult::Ok);
    // SAFETY: made above, freed once.
    unsafe {
        vt_blend_back_destroy(blend);
        vt_skeleton_destroy(c_skeleton);
    }
}

/// A rod-spined ragdoll's pose read through the C ABI, as it falls, is the
/// Rust API's bit for bit, for every spine mapping; a pose of the wrong
/// length is refused, naming it, and nothing is written.
#[test]
fn a_ragdolls_pose_reads_as_in_rust() {
    let mut t = Twins::new();
    t.step(20);
    let mappings = [
        (VtSpineMapping::Orientation, SpineMapping::Orientation),
        (
            VtSpineMapping::PositionOrientation,
            SpineMapping::PositionOrientation,
        ),
        (VtSpineMapping::Arc, SpineMapping::Arc),
    ];
    for (c, rust) in mappings {
        let mut pose = c_pose(&Pose::bind(&t.desc));
        // SAFETY: live objects; `pose` holds `len` writable transforms.
        ok(unsafe {
            vt_ragdoll_pose(
                t.c_ragdoll,
                t.c_world,
                c as u32,
                pose.as_mut_ptr(),
                pose.len(),
            )
        });
        let expected = t.ragdoll.skeleton_pose(&t.world, rust).expect("a pose");
        assert_eq!(rust_pose(&pose), expected, "{rust:?}");
    }
    let mut short = c_pose(&Pose::bind(&t.desc));
    short.pop();
    let before = short.clone();
    // SAFETY: as above, one transform short.
    let r = unsafe {
        vt_ragdoll_pose(
            t.c_ragdoll,
            t.c_world,
            VtSpineMapping::Arc as u32,
            short.as_mut_ptr(),
            short.len(),
        )
    };
    refused(r, VtResult::BufferTooSmall, &["pose"]);
    assert_eq!(short, before, "a refusal writes nothing");
}

/// The get-up clip chosen and placed through the C ABI is the Rust API's,
/// bit for bit; refusals name the item and write nothing.
#[test]
fn a_get_up_clip_is_chosen_and_placed_as_in_rust() {
    let desc = RagdollDesc::reference_humanoid();
    let mut c_desc = null_mut();
    // SAFETY: writable.
    ok(unsafe { vt_ragdoll_desc_humanoid(VtHumanoid::Reference as u32, &mut c_desc) });
    let root = Pose::bind(&desc).bones[desc.root].0;
    let laid = |quarter: f32| {
        let turn = Quat::from_rotation_x(quarter * core::f32::consts::FRAC_PI_2);
        Pose::bind(&desc).moved(root, turn, Vec3::Y * 0.1 - root)
    };
    let clips = [laid(1.0), laid(-1.0)];
    let lying = clips[1].moved(root, Quat::from_rotation_y(2.5), Vec3::new(3.0, 0.0, -4.0));
    let rust = GetUp::choose(&desc, &lying, &clips, Vec3::Y).expect("a clip");
    let c_lying = c_pose(&lying);
    let c_frames: Vec<VtTransform> = clips.iter().flat_map(c_pose).collect();
    let choose = |frames: &[VtTransform], clips: usize, up: Vec3, out: &mut VtGetUp| {
        // SAFETY: a live description; arrays of the lengths given; writable.
        unsafe {
            vt_get_up_choose(
                c_desc,
                c_lying.as_ptr(),
                c_lying.len(),
                frames.as_ptr(),
                clips,
                up.into(),
                out,
            )
        }
    };
    let mut c = VtGetUp {
        clip: usize::MAX,
        place: (Vec3::ZERO, Quat::IDENTITY).into(),
        misfit: -1.0,
    };
    ok(choose(&c_frames, 2, Vec3::Y, &mut c));
    assert_eq!(c.clip, rust.clip);
    assert_eq!(c.clip, 1, "it lies as the second clip starts");
    let place: (Vec3, Quat) = c.place.into();
    assert_eq!(place, (rust.translation, rust.turn));
    assert_eq!(c.misfit, rust.misfit);
    let untouched = c;
    refused(
        choose(&c_frames, 0, Vec3::Y, &mut c),
        VtResult::Ragdoll,
        &["first_frames"],
    );
    refused(
        choose(&c_frames, 2, Vec3::Y * 2.0, &mut c),
        VtResult::Ragdoll,
        &["up"],
    );
    let mut broken = c_frames.clone();
    broken[c_lying.len() + 2].rotation = Quat::from_xyzw(0.0, 0.0, 0.0, 2.0).into();
    refused(
        choose(&broken, 2, Vec3::Y, &mut c),
        VtResult::Ragdoll,
        &["clip 1's first frame"],
    );
    assert_eq!(c, untouched, "a refusal writes nothing");
    // SAFETY: made above, freed once.
    unsafe { vt_ragdoll_desc_destroy(c_desc) };
}
