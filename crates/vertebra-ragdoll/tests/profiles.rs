//! Physical-animation profiles: `[[profile]]` tables resolved per joint
//! and body (a bone table's subtree and strength multiplier), the force
//! laws a multiplier and a blend give, refusals that name the table, and
//! `Ragdoll::follow_profile` driving a ragdoll as `follow` does.

mod common;

use core::f32::consts::TAU;

use vertebra_ragdoll::{
    ANATOMICAL_HUMANOID, BuildOptions, JointDriveSetting, PhysicalAnimation, Profile, ProfileBlend,
    Ragdoll, RagdollDesc, RagdollError, SpineMode,
};
use vertebra_world::{SolverConfig, Spring, World};

const DT: f32 = 1.0 / 60.0;

fn frequency(f: f32, z: f32) -> Spring {
    Spring::Frequency {
        frequency: f,
        damping_ratio: z,
    }
}

/// A frequency spring's stiffness and damping per unit inertia.
fn law(s: Option<Spring>) -> (f32, f32) {
    match s {
        Some(Spring::Frequency {
            frequency,
            damping_ratio,
        }) => {
            let w = TAU * frequency;
            (w * w, 2.0 * damping_ratio * w)
        }
        other => panic!("not a frequency spring: {other:?}"),
    }
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-5 * a.abs().max(b.abs()).max(1e-6)
}

#[test]
fn a_bone_table_scales_its_subtree_by_its_multiplier() {
    let desc = RagdollDesc::anatomical_humanoid();
    let standing = desc.profile("standing").unwrap();
    let hit = desc.profile("hit").unwrap();
    let joint = |name: &str| desc.joint_index(name).unwrap();
    let body = |name: &str| desc.body_index(name).unwrap();
    // Standing: the legs and spine at 120 Hz, the neck and the arms (the
    // bone tables, one with the bodies below it) at 8 Hz, all 450 N m.
    let arms = ["neck", "shoulder_l", "elbow_l", "shoulder_r", "elbow_r"];
    for (j, setting) in desc.joints.iter().zip(&standing.joints) {
        let f = if arms.contains(&j.name.as_str()) {
            8.0
        } else {
            120.0
        };
        let want = JointDriveSetting {
            strength: Some(frequency(f, 1.0)),
            max_torque: 450.0,
        };
        assert_eq!(*setting, want, "{}", j.name);
    }
    // Hit is based on standing: its uprights are standing's, at half.
    let upright = hit.bodies[body("chest")].upright.unwrap();
    assert!(close(upright.max_torque, 50.0), "{upright:?}");
    // Hit: the arms and everything below them at 0.2 (later tables win
    // over the hips' 0.5 that covers the whole body), the head at 0.2, the
    // rest at 0.5. A multiplier scales stiffness, damping and caps.
    let cases = [
        ("elbow_l", "forearm_l", 0.2),
        ("shoulder_r", "upper_arm_r", 0.2),
        ("neck", "head", 0.2),
        ("knee_l", "shin_l", 0.5),
        ("spine_2", "spine_upper", 0.5),
    ];
    for (j, b, s) in cases {
        let (k0, d0) = law(standing.joints[joint(j)].strength);
        let (k, d) = law(hit.joints[joint(j)].strength);
        assert!(close(k, s * k0) && close(d, s * d0), "{j}: {k} {d}");
        assert!(close(hit.joints[joint(j)].max_torque, s * 450.0), "{j}");
        let (world0, world) = (standing.bodies[body(b)], hit.bodies[body(b)]);
        let (k0, d0) = law(world0.linear);
        let (k, d) = law(world.linear);
        assert!(close(k, s * k0) && close(d, s * d0), "{b}: {k} {d}");
        assert!(close(world.max_acceleration, s * 4.905), "{b}");
        assert!(close(world.max_torque, s * 20.0), "{b}");
    }
    // The hips (the root: no joint above) and their upright at 0.5.
    let (hips0, hips) = (standing.bodies[body("hips")], hit.bodies[body("hips")]);
    let (up0, up) = (hips0.upright.unwrap(), hips.upright.unwrap());
    let ((k0, _), (k, _)) = (law(Some(up0.strength)), law(Some(up.strength)));
    assert!(close(k, 0.5 * k0) && close(up.max_torque, 50.0));
    // Limp: nothing driven.
    let limp = desc.profile("limp").unwrap();
    assert!(limp.joints.iter().all(|j| j.strength.is_none()));
    assert!(limp.bodies.iter().all(|b| !b.is_driven()));
}

#[test]
fn profiles_read_back_from_the_file_they_write() {
    let desc = RagdollDesc::anatomical_humanoid();
    let back = RagdollDesc::from_toml(&desc.to_toml()).unwrap();
    assert_eq!(back.profiles, desc.profiles);
    // A profile made in code, scaled and blended to odd values.
    let mut desc = desc;
    let hit = desc.profile("hit").unwrap().clone();
    let odd = (desc.profile("standing").unwrap().blended(&hit, 0.37))
        .unwrap()
        .scaled(&desc, desc.body_index("thigh_l").unwrap(), true, 0.3)
        .unwrap();
    desc.profiles.push(Profile {
        name: "odd".to_owned(),
        ..odd
    });
    desc.validate().unwrap();
    let back = RagdollDesc::from_toml(&desc.to_toml()).unwrap();
    assert_eq!(back.profiles, desc.profiles);
}

#[test]
fn blends_interpolate_the_force_laws_and_end_on_the_target() {
    let desc = RagdollDesc::anatomical_humanoid();
    let (standing, hit) = (
        desc.profile("standing").unwrap(),
        desc.profile("hit").unwrap(),
    );
    assert_eq!(
        &standing.blended(hit, 0.0).unwrap().joints,
        &standing.joints
    );
    assert_eq!(&standing.blended(hit, 1.0).unwrap(), hit);
    let elbow = desc.joint_index("elbow_l").unwrap();
    for a in [0.1, 0.5, 0.9] {
        let mid = standing.blended(hit, a).unwrap();
        let (x, y, m) = (
            law(standing.joints[elbow].strength),
            law(hit.joints[elbow].strength),
            law(mid.joints[elbow].strength),
        );
        assert!(close(m.0, x.0 + (y.0 - x.0) * a), "{a}: {m:?}");
        assert!(close(m.1, x.1 + (y.1 - x.1) * a), "{a}: {m:?}");
        let cap = 450.0 + (90.0 - 450.0) * a;
        assert!(close(mid.joints[elbow].max_torque, cap), "{a}");
    }
    // Fading into limp scales the forces and caps down to nothing.
    let limp = desc.profile("limp").unwrap();
    let faded = standing.blended(limp, 0.75).unwrap();
    let (k0, _) = law(standing.joints[elbow].strength);
    let (k, _) = law(faded.joints[elbow].strength);
    assert!(close(k, 0.25 * k0) && close(faded.joints[elbow].max_torque, 112.5));
    assert_eq!(&standing.blended(limp, 1.0).unwrap(), limp);
}

#[test]
fn a_blend_moves_with_time_and_a_switch_starts_where_it_stands() {
    let desc = RagdollDesc::anatomical_humanoid();
    let standing = desc.profile("standing").unwrap().clone();
    let limp = desc.profile("limp").unwrap().clone();
    let mut blend = ProfileBlend::new(standing.clone());
    blend.switch_to(limp.clone(), 1.0).unwrap();
    for _ in 0..30 {
        blend.advance(DT);
    }
    assert!((blend.progress() - 0.5).abs() < 1e-5);
    let half = blend.current().unwrap();
    assert_eq!(half, standing.blended(&limp, blend.progress()).unwrap());
    // Back toward standing from half-faded, not from limp.
    blend.switch_to(standing.clone(), 0.5).unwrap();
    assert_eq!(blend.current().unwrap().joints, half.joints);
    for _ in 0..60 {
        blend.advance(DT);
    }
    assert_eq!(blend.current().unwrap(), standing);
    // Refused, unchanged: a negative duration, a profile of another shape.
    let before = blend.clone();
    assert!(blend.switch_to(limp.clone(), -1.0).is_err());
    let reference = Profile::limp("limp", &RagdollDesc::reference_humanoid());
    let mut wrong = reference.clone();
    wrong.joints.pop();
    let e = blend.switch_to(wrong, 0.1).unwrap_err().to_string();
    assert!(e.contains("profile `limp`"), "{e}");
    assert_eq!(blend, before);
}

#[test]
fn follow_profile_drives_as_follow_does() {
    let desc = RagdollDesc::reference_humanoid();
    let animation = PhysicalAnimation {
        joints: vertebra_ragdoll::DriveSettings::uniform(frequency(6.0, 0.7))
            .with_max_torque(200.0),
        world: vertebra_ragdoll::WorldDriveSettings {
            linear: Some(frequency(2.0, 1.0)),
            angular: Some(frequency(3.0, 1.0)),
            max_acceleration: 4.0,
            max_torque: 30.0,
            uprights: vec![vertebra_ragdoll::Upright {
                body: desc.body_index("chest").unwrap(),
                strength: frequency(2.0, 1.0),
                max_torque: 80.0,
            }],
        },
    };
    let profile = Profile::from_animation("walk", &desc, &animation).unwrap();
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let run = |by: Drive| {
            let (world, ragdoll, last) = walk_driven(&desc, spine, 30, by);
            // Driven, the chest keeps to the walk's turn.
            let chest = desc.body_index("chest").unwrap();
            let turn = world
                .body(ragdoll.bodies[chest].unwrap())
                .unwrap()
                .orientation;
            let off = common::angle(turn, last.bones[chest].1);
            assert!(off < 0.2, "{spine:?}: chest {off} rad off the walk");
            world.state_hash()
        };
        let (by_profile, by_follow) = (Drive::Profile(&profile), Drive::Follow(&animation));
        assert_eq!(run(by_profile), run(by_follow), "{spine:?}");
    }
}

#[test]
fn refused_profiles_name_the_table_and_change_nothing() {
    let at = |marker: &str| {
        ANATOMICAL_HUMANOID
            .lines()
            .position(|l| l.contains(marker))
            .unwrap()
            + 1
    };
    let refused = |from: &str, to: &str| {
        let text = ANATOMICAL_HUMANOID.replacen(from, to, 1);
        assert_ne!(text, ANATOMICAL_HUMANOID, "{from}");
        RagdollDesc::from_toml(&text).unwrap_err().to_string()
    };
    let standing = at("name = \"standing\"") - 1;
    let e = refused("body = \"upper_arm_l\"\nbelow", "body = \"wing\"\nbelow");
    assert!(
        e.starts_with(&format!("line {standing}: profile `standing` bone 1")) && e.contains("wing"),
        "{e}"
    );
    let e = refused("strength_multiplier = 0.2", "strength_multiplier = 1.5");
    assert!(
        e.contains("profile `hit` bone 1") && e.contains("strength_multiplier"),
        "{e}"
    );
    let e = refused("base = \"standing\"", "base = \"running\"");
    assert!(
        e.contains("profile `hit`") && e.contains("base") && e.contains("running"),
        "{e}"
    );
    let e = refused("name = \"limp\"", "name = \"hit\"");
    assert!(e.contains("hit") && e.contains("profile"), "{e}");
    let e = refused(
        "{ body = \"chest\", frequency = 2.0, damping_ratio = 1.0, max_torque = 100.0 },\n]",
        "{ body = \"hips\", frequency = 2.0, damping_ratio = 1.0, max_torque = 100.0 },\n]",
    );
    assert!(
        e.contains("profile `standing` upright 1") && e.contains("body"),
        "{e}"
    );
    let e = refused("max_acceleration = 4.905", "max_acceleration = -1.0");
    assert!(
        e.contains("profile `standing` world") && e.contains("max_acceleration"),
        "{e}"
    );
    let e = refused(
        "joints = { frequency = 120.0, damping_ratio = 1.0, max_torque = 450.0 }",
        "joints = { frequency = 0.0, damping_ratio = 1.0 }",
    );
    assert!(
        e.contains("profile `standing`") && e.contains("drive"),
        "{e}"
    );

    // A profile made for another ragdoll is refused by follow_profile,
    // naming it, and the world is as it was.
    let desc = RagdollDesc::anatomical_humanoid();
    let mut world = World::new(SolverConfig::default()).unwrap();
    let pose = vertebra_ragdoll::Pose::bind(&desc);
    let options = BuildOptions::new(SpineMode::Rod);
    let ragdoll = Ragdoll::build(&mut world, &desc, options, &pose, None).unwrap();
    let standing = desc.profile("standing").unwrap();
    ragdoll
        .follow_profile(&mut world, (&pose, &pose), DT, standing)
        .unwrap();
    let hash = world.state_hash();
    // (The reference humanoid has as many joints and bodies.)
    let mut other = Profile::limp("other", &RagdollDesc::reference_humanoid());
    other.joints.pop();
    let mut nan = standing.clone();
    nan.bodies[3].max_torque = f32::NAN;
    for (bad, names) in [(other, "profile `other`"), (nan, "body `chest`")] {
        let e: RagdollError =
            (ragdoll.follow_profile(&mut world, (&pose, &pose), DT, &bad)).unwrap_err();
        assert!(e.to_string().contains(names), "{e}");
        assert_eq!(world.state_hash(), hash);
    }
}

/// The anatomical humanoid's file with `extra` tables after it.
fn with(extra: &str) -> Result<RagdollDesc, String> {
    RagdollDesc::from_toml(&format!("{ANATOMICAL_HUMANOID}\n{extra}")).map_err(|e| e.to_string())
}

#[test]
fn an_unlimited_cap_blends_into_a_finite_one_without_a_nan() {
    let desc = with(
        "[[profile]]\nname = \"a\"\njoints = { frequency = 8.0, damping_ratio = 1.0 }\n\
         world = { linear = { frequency = 2.0, damping_ratio = 1.0 } }\n\
         [[profile]]\nname = \"b\"\n\
         joints = { frequency = 8.0, damping_ratio = 1.0, max_torque = 300.0 }\n\
         world = { linear = { frequency = 2.0, damping_ratio = 1.0 }, max_acceleration = 4.0 }\n",
    )
    .unwrap();
    let (a, b) = (desc.profile("a").unwrap(), desc.profile("b").unwrap());
    for k in 1..100 {
        let t = k as f32 / 100.0;
        for mid in [a.blended(b, t).unwrap(), b.blended(a, t).unwrap()] {
            mid.validate(&desc).unwrap();
            assert_eq!(mid.joints[0].max_torque, f32::INFINITY, "{t}");
            assert_eq!(mid.bodies[0].max_acceleration, f32::INFINITY, "{t}");
        }
    }
}

#[test]
fn strengths_far_out_scale_and_read_back() {
    // A frequency whose square overflows f32, scaled by a multiplier.
    let desc = with(
        "[[profile]]\nname = \"x\"\njoints = { frequency = 1e20, damping_ratio = 1.0 }\n\
         [[profile.bone]]\nbody = \"head\"\nstrength_multiplier = 0.5\n",
    )
    .unwrap();
    let neck = desc.joint_index("neck").unwrap();
    let strength = desc.profile("x").unwrap().joints[neck].strength;
    let (f, z) = (1e20 * 0.5_f32.sqrt(), 0.5_f32.sqrt());
    assert_eq!(strength, Some(frequency(f, z)));
    assert_eq!(RagdollDesc::from_toml(&desc.to_toml()).unwrap(), desc);
    // An infinite frequency (rigid to the world) is refused in a profile:
    // a file could not write it back.
    let mut inf = Profile::limp("inf", &desc);
    inf.joints[neck].strength = Some(frequency(f32::INFINITY, 1.0));
    let e = inf.validate(&desc).unwrap_err().to_string();
    assert!(
        e.contains("joint `neck`") && e.contains("infinite frequency"),
        "{e}"
    );
}

/// Settings `follow` takes give a profile `follow_profile` and a blend
/// take: an infinite frequency (rigid to the world) becomes a zero
/// compliance, and follows as it does.
#[test]
fn a_profile_from_rigid_frequencies_is_one_a_blend_takes() {
    let desc = RagdollDesc::anatomical_humanoid();
    let rigid = frequency(f32::INFINITY, 1.0);
    let animation = PhysicalAnimation {
        joints: vertebra_ragdoll::DriveSettings::uniform(rigid),
        world: vertebra_ragdoll::WorldDriveSettings {
            linear: Some(rigid),
            angular: Some(rigid),
            max_acceleration: 4.0,
            max_torque: 30.0,
            uprights: vec![vertebra_ragdoll::Upright {
                body: desc.body_index("chest").unwrap(),
                strength: rigid,
                max_torque: 80.0,
            }],
        },
    };
    let profile = Profile::from_animation("rigid", &desc, &animation).unwrap();
    profile.validate(&desc).unwrap();
    assert!(
        profile
            .joints
            .iter()
            .all(|j| j.strength == Some(Spring::RIGID))
    );
    let mut blend = ProfileBlend::new(Profile::limp("limp", &desc));
    blend.switch_to(profile.clone(), 0.5).unwrap();
    let run = |by: Drive| walk_driven(&desc, SpineMode::Rod, 10, by).0.state_hash();
    let followed = run(Drive::Follow(&animation));
    assert_eq!(followed, run(Drive::Profile(&profile)));
}

/// How [`walk_driven`] drives a ragdoll each frame.
#[derive(Clone, Copy)]
enum Drive<'a> {
    /// `Ragdoll::follow` with these settings.
    Follow(&'a PhysicalAnimation),
    /// `Ragdoll::follow_profile` with this profile.
    Profile(&'a Profile),
}

/// A ragdoll of `desc` built on the walk's first pose in a world of its
/// own and driven along the walk for `frames` frames: the world, the
/// ragdoll and the walk's last pose.
fn walk_driven(
    desc: &RagdollDesc,
    spine: SpineMode,
    frames: usize,
    by: Drive,
) -> (World, Ragdoll, vertebra_ragdoll::Pose) {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let first = common::walking(desc, 0.0);
    let ragdoll = Ragdoll::build(&mut world, desc, BuildOptions::new(spine), &first, None).unwrap();
    let mut prev = first;
    for k in 1..=frames {
        let pose = common::walking(desc, k as f32 * DT);
        let poses = (&prev, &pose);
        match by {
            Drive::Follow(animation) => ragdoll.follow(&mut world, poses, DT, animation),
            Drive::Profile(profile) => ragdoll.follow_profile(&mut world, poses, DT, profile),
        }
        .unwrap();
        world.step(DT).unwrap();
        prev = pose;
    }
    (world, ragdoll, prev)
}

#[test]
fn a_bone_table_driving_the_joint_above_the_root_is_refused() {
    let e = with(
        "[[profile]]\nname = \"x\"\n[[profile.bone]]\nbody = \"hips\"\n\
         joints = { frequency = 8.0, damping_ratio = 1.0 }\n",
    )
    .unwrap_err();
    assert!(
        e.contains("profile `x` bone 0") && e.contains("root"),
        "{e}"
    );
    // With below = true it drives the joints below the root.
    let desc = with(
        "[[profile]]\nname = \"x\"\n[[profile.bone]]\nbody = \"hips\"\nbelow = true\n\
         joints = { frequency = 8.0, damping_ratio = 1.0 }\n",
    )
    .unwrap();
    let x = desc.profile("x").unwrap();
    assert!(
        x.joints
            .iter()
            .all(|j| j.strength == Some(frequency(8.0, 1.0)))
    );
}

#[test]
fn a_ragdoll_driven_in_a_world_not_its_own_is_refused_not_a_panic() {
    let desc = RagdollDesc::anatomical_humanoid();
    let pose = vertebra_ragdoll::Pose::bind(&desc);
    let standing = desc.profile("standing").unwrap();
    let mut world = World::new(SolverConfig::default()).unwrap();
    let options = BuildOptions::new(SpineMode::Sockets);
    let ragdoll = Ragdoll::build(&mut world, &desc, options, &pose, None).unwrap();
    let mut other = World::new(SolverConfig::default()).unwrap();
    let e = (ragdoll.follow_profile(&mut other, (&pose, &pose), DT, standing)).unwrap_err();
    assert!(e.to_string().contains("body `hips`"), "{e}");
    let e = ragdoll.release_world_drives(&mut other).unwrap_err();
    assert!(e.to_string().contains("body `hips`"), "{e}");
    // A joint removed behind the ragdoll's back: refused, naming it, and
    // nothing set.
    let last = *ragdoll.joints.iter().rev().flatten().next().unwrap();
    world.remove_joint(last).unwrap();
    let hash = world.state_hash();
    let e = (ragdoll.follow_profile(&mut world, (&pose, &pose), DT, standing)).unwrap_err();
    assert!(e.to_string().contains("joint `ankle_r`"), "{e}");
    assert_eq!(world.state_hash(), hash, "a refused call changed the world");
}
