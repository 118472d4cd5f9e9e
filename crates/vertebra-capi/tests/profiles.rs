//! Physical-animation profiles through the C ABI: a blend of the
//! description's named profiles followed each frame gives the Rust API's
//! world bit for bit, and refusals name the item and change nothing.

use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

use vertebra_capi::*;
use vertebra_ragdoll::{BuildOptions, Pose, ProfileBlend, Ragdoll, RagdollDesc, SpineMode};
use vertebra_world::{SolverConfig, World};

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

fn name(text: &str) -> CString {
    CString::new(text).expect("a name")
}

/// The anatomical humanoid standing in a C world and in a Rust world
/// (no ground: the drives hold it), each with a blend at `standing`.
struct Twins {
    c_world: *mut VtWorld,
    c_desc: *mut VtRagdollDesc,
    c_ragdoll: *mut VtRagdoll,
    c_blend: *mut VtProfileBlend,
    world: World,
    desc: RagdollDesc,
    ragdoll: Ragdoll,
    blend: ProfileBlend,
    pose: Vec<VtTransform>,
}

impl Twins {
    fn new(spine: SpineMode) -> Self {
        let desc = RagdollDesc::anatomical_humanoid();
        let bind = Pose::bind(&desc);
        let pose: Vec<VtTransform> = bind.bones.iter().map(|&t| t.into()).collect();
        let (mut c_world, mut c_desc, mut c_ragdoll) = (null_mut(), null_mut(), null_mut());
        let mut c_blend = null_mut();
        let c_spine = match spine {
            SpineMode::Rod => VtSpineMode::Rod,
            SpineMode::Sockets => VtSpineMode::Sockets,
        };
        let options = VtBuildOptions {
            spine: c_spine as u32,
            at_switch: 0,
            stabilise: 0,
            stabilise_ratio: 1.0,
        };
        let standing = name("standing");
        // SAFETY: writable places; a readable pose, options and name; live
        // objects made just before.
        unsafe {
            ok(vt_world_create(null(), &mut c_world));
            ok(vt_ragdoll_desc_humanoid(
                VtHumanoid::Anatomical as u32,
                &mut c_desc,
            ));
            ok(vt_ragdoll_build(
                c_world,
                null_mut(),
                c_desc,
                &options,
                pose.as_ptr(),
                null(),
                pose.len(),
                0.0,
                &mut c_ragdoll,
            ));
            ok(vt_profile_blend_create(
                c_desc,
                standing.as_ptr(),
                &mut c_blend,
            ));
        }
        let mut world = World::new(SolverConfig::default()).expect("a world");
        let ragdoll = Ragdoll::build(&mut world, &desc, BuildOptions::new(spine), &bind, None)
            .expect("built");
        let blend = ProfileBlend::new(desc.profile("standing").expect("shipped").clone());
        Self {
            c_world,
            c_desc,
            c_ragdoll,
            c_blend,
            world,
            desc,
            ragdoll,
            blend,
            pose,
        }
    }

    /// A frame in both: the blend moved on, the profile followed, a step.
    fn frame(&mut self) {
        let (p, n) = (self.pose.as_ptr(), self.pose.len());
        // SAFETY: live objects; `n` readable transforms.
        unsafe {
            ok(vt_profile_blend_advance(self.c_blend, DT));
            ok(vt_ragdoll_follow_profile(
                self.c_ragdoll,
                self.c_world,
                p,
                p,
                n,
                DT,
                self.c_blend,
            ));
            ok(vt_world_step(self.c_world, DT));
        }
        self.blend.advance(DT);
        let profile = self.blend.current().expect("a blend");
        let bind = Pose::bind(&self.desc);
        (self.ragdoll)
            .follow_profile(&mut self.world, (&bind, &bind), DT, &profile)
            .expect("followed");
        self.world.step(DT).expect("a step");
    }

    fn c_hash(&self) -> u64 {
        let mut hash = 0;
        // SAFETY: a live world; writable.
        ok(unsafe { vt_world_state_hash(self.c_world, &mut hash) });
        hash
    }
}

impl Drop for Twins {
    fn drop(&mut self) {
        // SAFETY: made above, freed once.
        unsafe {
            vt_profile_blend_destroy(self.c_blend);
            vt_ragdoll_destroy(self.c_ragdoll);
            vt_ragdoll_desc_destroy(self.c_desc);
            vt_world_destroy(self.c_world);
        }
    }
}

#[test]
fn a_blend_of_profiles_from_c_is_the_rust_blend_bit_for_bit() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut t = Twins::new(spine);
        for _ in 0..20 {
            t.frame();
        }
        assert_eq!(t.c_hash(), t.world.state_hash(), "{spine:?} standing");
        // The hit profile blended in, the left arm fading further out,
        // then back to standing.
        let hit = name("hit");
        let arm = t.desc.body_index("upper_arm_l").expect("a body");
        // SAFETY: a live blend; a NUL-terminated name.
        unsafe {
            ok(vt_profile_blend_switch(t.c_blend, hit.as_ptr(), 0.2));
        }
        let to = t.desc.profile("hit").expect("shipped").clone();
        t.blend.switch_to(to, 0.2).expect("a switch");
        for _ in 0..6 {
            t.frame();
        }
        // SAFETY: a live blend.
        ok(unsafe { vt_profile_blend_scale(t.c_blend, arm, 1, 0.5, 0.1) });
        let scaled = (t.blend.target().scaled(&t.desc, arm, true, 0.5)).expect("scaled");
        t.blend.switch_to(scaled, 0.1).expect("a switch");
        for _ in 0..12 {
            t.frame();
        }
        let mut progress = 0.0;
        // SAFETY: a live blend; writable.
        ok(unsafe { vt_profile_blend_progress(t.c_blend, &mut progress) });
        assert_eq!(progress, 1.0);
        assert_eq!(t.c_hash(), t.world.state_hash(), "{spine:?} hit");
    }
}

#[test]
fn refused_profile_calls_name_the_item_and_change_nothing() {
    let t = Twins::new(SpineMode::Sockets);
    let (unknown, hit) = (name("flying"), name("hit"));
    let mut blend = null_mut();
    let (mut before, mut after) = (0.0, 0.0);
    // SAFETY: live objects, NUL-terminated names and writable places; each
    // call is given one bad argument.
    unsafe {
        refused(
            vt_profile_blend_create(t.c_desc, unknown.as_ptr(), &mut blend),
            VtResult::Ragdoll,
            &["flying", "profile"],
        );
        assert!(blend.is_null());
        refused(
            vt_profile_blend_create(t.c_desc, null(), &mut blend),
            VtResult::NullPointer,
            &["name"],
        );
        ok(vt_profile_blend_switch(t.c_blend, hit.as_ptr(), 1.0));
        ok(vt_profile_blend_advance(t.c_blend, 0.25));
        ok(vt_profile_blend_progress(t.c_blend, &mut before));
        refused(
            vt_profile_blend_switch(t.c_blend, unknown.as_ptr(), 0.5),
            VtResult::Ragdoll,
            &["flying"],
        );
        refused(
            vt_profile_blend_switch(t.c_blend, hit.as_ptr(), -1.0),
            VtResult::Ragdoll,
            &["duration"],
        );
        refused(
            vt_profile_blend_scale(t.c_blend, 99, 0, 0.5, 0.1),
            VtResult::Ragdoll,
            &["body"],
        );
        refused(
            vt_profile_blend_scale(t.c_blend, 0, 1, 1.5, 0.1),
            VtResult::Ragdoll,
            &["strength_multiplier"],
        );
        ok(vt_profile_blend_progress(t.c_blend, &mut after));
        refused(
            vt_profile_blend_progress(null_mut(), &mut after),
            VtResult::NullPointer,
            &["profile blend"],
        );
    }
    assert_eq!(before, 0.25);
    assert_eq!(after, before, "a refused call moved the blend");
}
