//! Partial ragdolls: kinematic bodies on the animation every frame, the
//! dynamic rest simulated and jointed to them; kinds switched mid-motion
//! keep momentum; refusals change nothing.

mod common;

#[path = "support/separation.rs"]
mod separation;

use common::{angle, walking};
use glam::{Quat, Vec3};
use separation::worst_separation;
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, RagdollError, SpineMode};
use vertebra_world::{SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

/// A call on a ragdoll in a world that may be refused.
type Call = dyn Fn(&Ragdoll, &mut World) -> Result<(), RagdollError>;

/// Per described body, whether its name is one of `names`.
fn mask(desc: &RagdollDesc, names: &[&str]) -> Vec<bool> {
    desc.bodies
        .iter()
        .map(|b| names.contains(&b.name.as_str()))
        .collect()
}

fn index(desc: &RagdollDesc, name: &str) -> usize {
    desc.bodies.iter().position(|b| b.name == name).unwrap()
}

/// The legs and hips follow a walk kinematically while the upper body is
/// limp: after every step the kinematic bodies sit exactly on the
/// animation, the joints (kinematic to dynamic ones included) hold, and
/// the upper body, no longer held up, folds under gravity until the
/// spine's limits stop it.
#[test]
fn animated_legs_walk_on_the_animation_while_the_limp_upper_body_folds() {
    let desc = RagdollDesc::reference_humanoid();
    let legs = mask(&desc, &["hips", "thigh_l", "shin_l", "thigh_r", "shin_r"]);
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut w = World::new(SolverConfig::default()).unwrap();
        let (start, before) = (walking(&desc, 0.0), walking(&desc, -DT));
        let options = BuildOptions::new(spine);
        let ragdoll = Ragdoll::build(&mut w, &desc, options, &start, Some((&before, DT))).unwrap();
        ragdoll.set_kinematic(&mut w, &legs).unwrap();
        assert_eq!(ragdoll.kinematic(&w).unwrap(), legs);
        let (mut off, mut turned, mut separation) = (0.0f32, 0.0f32, 0.0f32);
        let frames = 180;
        for frame in 1..=frames {
            let target = walking(&desc, frame as f32 * DT);
            ragdoll
                .drive_to_pose_using_kinematics(&mut w, &target, DT)
                .unwrap();
            w.step(DT).unwrap();
            for (k, body) in ragdoll.bodies.iter().enumerate() {
                if let (true, Some(b)) = (legs[k], body) {
                    let s = w.body(*b).unwrap();
                    off = off.max((s.position - target.bones[k].0).length());
                    turned = turned.max(angle(s.orientation, target.bones[k].1));
                }
            }
            separation = separation.max(worst_separation(&mut w));
        }
        let animation = walking(&desc, frames as f32 * DT);
        let (hips, chest) = (index(&desc, "hips"), index(&desc, "chest"));
        let body = |k: usize| w.body(ragdoll.bodies[k].unwrap()).unwrap();
        let drop = animation.bones[chest].0.y - body(chest).position.y;
        let bend = angle(body(chest).orientation, body(hips).orientation);
        eprintln!(
            "{spine:?}: kinematic bodies off the animation by {off:.2e} m, {turned:.2e} rad; \
             worst joint separation {separation:.3} cm; chest {drop:.3} m below the \
             animation's, bent {:.1} degrees from the hips",
            bend.to_degrees()
        );
        assert!(off < 1e-5 && turned < 1e-5, "{off} m, {turned} rad");
        assert!(separation < 1.0, "{separation} cm");
        assert!(drop > 0.05, "the upper body folds: {drop} m");
        assert!(bend > 40f32.to_radians(), "{} degrees", bend.to_degrees());
    }
}

/// The hips carried by a character controller (kinematic, moving and
/// turning) while every other body is dynamic: the hips are on the
/// controller after every step, the rest hangs from them (legs below,
/// joints holding) and is carried along at the controller's velocity.
#[test]
fn hips_carried_by_a_controller_carry_the_hanging_rest() {
    let desc = RagdollDesc::reference_humanoid();
    let hips = index(&desc, "hips");
    let pivot = desc.bodies[hips].centre();
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut w = World::new(SolverConfig::default()).unwrap();
        let bind = Pose::bind(&desc);
        let ragdoll = Ragdoll::build(&mut w, &desc, BuildOptions::new(spine), &bind, None).unwrap();
        ragdoll.set_body_kinematic(&mut w, "hips", true).unwrap();
        // The controller: up to 1.5 m/s along +X in half a second, bobbing
        // 5 cm, turning at 0.3 rad/s.
        let (mut x, mut speed) = (0.0f32, 0.0f32);
        let (mut off, mut separation) = (0.0f32, 0.0f32);
        let mut carried = Vec::new();
        let frames = 300;
        for frame in 1..=frames {
            let t = frame as f32 * DT;
            speed = (speed + 3.0 * DT).min(1.5);
            x += speed * DT;
            let at = Vec3::new(x, 0.05 * (core::f32::consts::TAU * t).sin(), 0.0);
            let target = bind.moved(pivot, Quat::from_rotation_y(0.3 * t), at);
            ragdoll
                .drive_to_pose_using_kinematics(&mut w, &target, DT)
                .unwrap();
            w.step(DT).unwrap();
            let s = w.body(ragdoll.bodies[hips].unwrap()).unwrap();
            off = off.max((s.position - target.bones[hips].0).length());
            off = off.max(angle(s.orientation, target.bones[hips].1));
            separation = separation.max(worst_separation(&mut w));
            if frame > frames - 60 {
                let (mut momentum, mut mass) = (Vec3::ZERO, 0.0);
                for (k, b) in ragdoll.bodies.iter().enumerate() {
                    if let (false, Some(b)) = (k == hips, b) {
                        let m = w.bodies().mass[b.index()];
                        momentum += w.body(*b).unwrap().linear_velocity * m;
                        mass += m;
                    }
                }
                carried.push(momentum / mass);
            }
        }
        let mean = carried.iter().sum::<Vec3>() / carried.len() as f32;
        let h = w.body(ragdoll.bodies[hips].unwrap()).unwrap().position;
        let lowest_shin = ["shin_l", "shin_r"]
            .map(|n| {
                w.body(ragdoll.bodies[index(&desc, n)].unwrap())
                    .unwrap()
                    .position
                    .y
            })
            .into_iter()
            .fold(f32::MAX, f32::min);
        eprintln!(
            "{spine:?}: hips off the controller by {off:.2e}; worst joint separation \
             {separation:.3} cm; the rest's mean velocity over the last second {mean} \
             (controller 1.5 m/s along x); shins down to {:.2} m below the hips",
            h.y - lowest_shin
        );
        assert!(off < 1e-5, "{off}");
        assert!(separation < 1.0, "{separation} cm");
        assert!(h.y - lowest_shin > 0.5, "the legs hang");
        assert!((mean - Vec3::new(1.5, 0.0, 0.0)).length() < 0.1, "{mean}");
    }
}

/// A ragdoll moved kinematically at 2 m/s and let go mid-motion moves on:
/// each body keeps the velocity it had, bit for bit, and the ragdoll's
/// momentum is then `M (v + g t)`, as for any free body under gravity
/// (its joints only pass momentum between its bodies).
#[test]
fn a_kinematic_ragdoll_let_go_mid_motion_keeps_its_momentum() {
    let desc = RagdollDesc::reference_humanoid();
    let g = SolverConfig::default().gravity;
    let v = Vec3::new(2.0, 0.5, -1.0);
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut w = World::new(SolverConfig::default()).unwrap();
        let bind = Pose::bind(&desc);
        let ragdoll = Ragdoll::build(&mut w, &desc, BuildOptions::new(spine), &bind, None).unwrap();
        let all: Vec<bool> = ragdoll.bodies.iter().map(Option::is_some).collect();
        ragdoll.set_kinematic(&mut w, &all).unwrap();
        for frame in 1..=30 {
            let target = bind.moved(Vec3::ZERO, Quat::IDENTITY, v * (frame as f32 * DT));
            ragdoll
                .drive_to_pose_using_kinematics(&mut w, &target, DT)
                .unwrap();
            w.step(DT).unwrap();
        }
        let bodies: Vec<_> = ragdoll.bodies.iter().flatten().copied().collect();
        let before: Vec<_> = bodies.iter().map(|&b| w.body(b).unwrap()).collect();
        ragdoll
            .set_kinematic(&mut w, &vec![false; all.len()])
            .unwrap();
        for (&b, s) in bodies.iter().zip(&before) {
            assert_eq!(w.body(b).unwrap(), *s, "letting go moves nothing");
            assert!(
                (s.linear_velocity - v).length() < 1e-5,
                "{}",
                s.linear_velocity
            );
        }
        let mass: f32 = bodies.iter().map(|&b| w.bodies().mass[b.index()]).sum();
        let steps = 60;
        for _ in 0..steps {
            w.step(DT).unwrap();
        }
        let momentum: Vec3 = bodies
            .iter()
            .map(|&b| w.body(b).unwrap().linear_velocity * w.bodies().mass[b.index()])
            .sum();
        let expected = mass * (v + g * (steps as f32 * DT));
        let off = (momentum - expected).length() / expected.length();
        eprintln!("{spine:?}: momentum {momentum} against M (v + g t) = {expected}: {off:.1e}");
        assert!((mass - 69.0).abs() < 1e-3, "{mass}");
        assert!(off < 1e-4, "{off}");
    }
}

/// Every refused call names the body or the field and changes nothing (the
/// world's state hash): unknown names, a simplified ragdoll's interior
/// spine bone, a mask of the wrong length or marking a bone without a
/// body, a bad pose or time step, a move beyond the speed limits (after
/// other bodies' moves were set: they are put back), a removed ragdoll.
#[test]
fn refused_partial_calls_name_the_item_and_change_nothing() {
    let desc = RagdollDesc::reference_humanoid();
    let mut w = World::new(SolverConfig::default()).unwrap();
    let bind = Pose::bind(&desc);
    let mut ragdoll = Ragdoll::build(
        &mut w,
        &desc,
        BuildOptions::new(SpineMode::Rod),
        &bind,
        None,
    )
    .unwrap();
    let legs = mask(&desc, &["hips", "thigh_l", "shin_l", "thigh_r", "shin_r"]);
    ragdoll.set_kinematic(&mut w, &legs).unwrap();
    w.step(DT).unwrap();
    let far = {
        let mut pose = bind.clone();
        pose.bones[index(&desc, "shin_r")].0.x += 100.0;
        pose
    };
    let mut nan = bind.clone();
    nan.bones[0].0.y = f32::NAN;
    let mut spine_true = legs.clone();
    spine_true[index(&desc, "spine_lower")] = true;
    let cases: Vec<(&str, Box<Call>)> = vec![
        (
            "set_body_kinematic: body `toe` is not a body",
            Box::new(|r, w| r.set_body_kinematic(w, "toe", true)),
        ),
        (
            "set_body_kinematic (an interior spine bone of a simplified ragdoll has no body): \
             body `spine_upper` is not a body",
            Box::new(|r, w| r.set_body_kinematic(w, "spine_upper", true)),
        ),
        (
            "set_kinematic: kinematic has 3 entries; needs one per described body (13)",
            Box::new(|r, w| r.set_kinematic(w, &[true; 3])),
        ),
        (
            "body `spine_lower`: kinematic is true, but an interior spine bone of a simplified \
             ragdoll has no body (make the rod's ends kinematic)",
            Box::new(move |r, w| r.set_kinematic(w, &spine_true)),
        ),
        (
            "bad pose: bone `hips`: position is not finite",
            Box::new(move |r, w| r.drive_to_pose_using_kinematics(w, &nan, DT)),
        ),
        (
            "drive_to_pose_using_kinematics: dt is 0; must be a time step of 0.000001 s to 1 s",
            Box::new(|r, w| r.drive_to_pose_using_kinematics(w, &Pose::bind(r.description()), 0.0)),
        ),
        (
            "body `shin_r`: position (reaching it in dt needs more than max_linear_speed) is \
             out of range",
            Box::new(move |r, w| r.drive_to_pose_using_kinematics(w, &far, DT)),
        ),
    ];
    for (expected, call) in &cases {
        let hash = w.state_hash();
        let error = call(&ragdoll, &mut w).expect_err(expected);
        assert_eq!(error.to_string(), *expected);
        assert_eq!(w.state_hash(), hash, "{expected}: the world changed");
    }
    // The velocities of the bodies before `shin_r` were set, then put back.
    let hips = w
        .body(ragdoll.bodies[index(&desc, "hips")].unwrap())
        .unwrap();
    assert_eq!(hips.linear_velocity, Vec3::ZERO);
    ragdoll.set_kinematic(&mut w, &[false; 13]).unwrap();
    ragdoll.remove(&mut w).unwrap();
    let hash = w.state_hash();
    let removed = ragdoll.set_kinematic(&mut w, &legs).unwrap_err();
    assert_eq!(
        removed,
        RagdollError::Removed {
            ragdoll: desc.name.clone()
        }
    );
    let one = ragdoll
        .set_body_kinematic(&mut w, "hips", true)
        .unwrap_err();
    assert_eq!(
        one.to_string(),
        "ragdoll `reference-humanoid` has been removed from the world; build it again"
    );
    assert!(ragdoll.kinematic(&w).is_err());
    assert_eq!(w.state_hash(), hash);
}

/// A simplified ragdoll with both rod ends kinematic (the spine animated
/// through its ends): the rod then joins two kinematic bodies and moves
/// neither, still takes drives (`drive_to` sets its rest shape), and the
/// interior spine bones are placed between the animated ends.
#[test]
fn a_rod_spine_with_both_ends_kinematic_is_animated_through_its_ends() {
    let desc = RagdollDesc::reference_humanoid();
    let mut w = World::new(SolverConfig::default()).unwrap();
    let (start, before) = (walking(&desc, 0.0), walking(&desc, -DT));
    let options = BuildOptions::new(SpineMode::Rod);
    let ragdoll = Ragdoll::build(&mut w, &desc, options, &start, Some((&before, DT))).unwrap();
    ragdoll.set_body_kinematic(&mut w, "hips", true).unwrap();
    ragdoll.set_body_kinematic(&mut w, "chest", true).unwrap();
    let settings = vertebra_ragdoll::DriveSettings::uniform(vertebra_world::Spring::RIGID);
    let (hips, chest) = (index(&desc, "hips"), index(&desc, "chest"));
    let mut worst = 0.0f32;
    for frame in 1..=60 {
        let target = walking(&desc, frame as f32 * DT);
        ragdoll.drive_to(&mut w, &target, &settings).unwrap();
        ragdoll
            .drive_to_pose_using_kinematics(&mut w, &target, DT)
            .unwrap();
        w.step(DT).unwrap();
        let bones = ragdoll
            .skeleton_pose(&w, vertebra_ragdoll::SpineMapping::Arc)
            .unwrap();
        for k in [hips, chest] {
            worst = worst.max((bones.bones[k].0 - target.bones[k].0).length());
        }
        for name in ["spine_lower", "spine_upper"] {
            let y = bones.bones[index(&desc, name)].0.y;
            assert!(
                bones.bones[hips].0.y < y && y < bones.bones[chest].0.y,
                "{name}"
            );
        }
    }
    assert!(worst < 1e-5, "{worst}");
    ragdoll.release_drives(&mut w).unwrap();
}
