//! The stagger: the anatomical humanoid on flat ground with nothing
//! kinematic, following a standing and then a walking animation with its
//! joints' drives and capped world drives (the description's
//! `standing` profile: `stagger_profile`). The walk
//! is a gait (its feet planted while down, its hips bobbing, its arms
//! against its legs) that starts from standing without a jump; the
//! ragdoll stands, walks at 1.5 m/s with its hips near the animation's,
//! takes a 40 N s hit on the chest from every side and recovers, and a
//! hit beyond what its capped drives can hold fells it.

use glam::{Quat, Vec3};
use vertebra_ragdoll::{Pose, RagdollDesc, SpineMode};
use vertebra_scenes::{
    Activity, FRAME_DT, Gait, Scene, SceneConfig, Side, StaggerSweep, WALK_SPEED, WALK_START, Walk,
    build, stagger_profile, stagger_walk,
};
use vertebra_world::{JointSolver, PinContacts, SolverConfig};

const G: f32 = 9.81;

/// The scene under `joints`' solve as `vertebra scene stagger` runs it:
/// the world's default with its driven ragdoll's contacts with the ground
/// pinned (its 1 kg feet need them), or the paper's iterated one.
fn config(spine: SpineMode, joints: JointSolver) -> SceneConfig {
    let solver = match joints {
        JointSolver::Direct => SolverConfig::default(),
        JointSolver::Iterative => SolverConfig::paper(),
    };
    let mut config = SceneConfig::new(Scene::Stagger, spine);
    config.joints = solver.joints;
    config.iterations = solver.iterations;
    config.substeps = solver.substeps;
    config.relax_contacts = solver.relax_contacts;
    config.pin_contacts = match joints {
        JointSolver::Direct => PinContacts::Driven,
        JointSolver::Iterative => PinContacts::Never,
    };
    config
}

const SPINES: [SpineMode; 2] = [SpineMode::Sockets, SpineMode::Rod];

/// Where body `name`'s segment end `end` is in `pose` (m, world).
fn end(desc: &RagdollDesc, pose: &Pose, name: &str, end: usize) -> Vec3 {
    let k = desc.body_index(name).unwrap();
    let (at, turn) = pose.bones[k];
    at + turn * (desc.bodies[k].segment[end] - desc.bodies[k].centre())
}

fn walk() -> (RagdollDesc, Walk) {
    let desc = RagdollDesc::anatomical_humanoid();
    let walk = stagger_walk(&desc, 0, WALK_START).unwrap();
    (desc, walk)
}

#[test]
fn the_walk_starts_from_the_standing_pose_without_a_jump() {
    let (desc, walk) = walk();
    let standing = walk.pose(&desc, 0.0).unwrap();
    let still = walk.pose(&desc, 0.99 * WALK_START).unwrap();
    assert_eq!(
        standing.bones, still.bones,
        "standing still before the walk"
    );
    let bind = Pose::bind(&desc);
    let lift = standing.bones[0].0 - bind.bones[0].0;
    for (k, (a, b)) in standing.bones.iter().zip(&bind.bones).enumerate() {
        assert!(
            (a.0 - b.0 - lift).length() < 1e-5,
            "bone {k} at the bind pose"
        );
        assert!(a.1.angle_between(b.1) < 1e-3, "bone {k} turned");
    }
    // Every bone's largest speed and acceleration frame by frame, from
    // standing through the start and the ramp: about as at full speed (a
    // jump of 4 mm in a frame would add 14 m/s^2).
    let extremes = |from: f32, to: f32| {
        let frames = ((to - from) / FRAME_DT) as usize;
        let poses: Vec<Pose> = (0..frames)
            .map(|f| walk.pose(&desc, from + f as f32 * FRAME_DT).unwrap())
            .collect();
        let (mut fastest, mut sharpest) = (0.0f32, 0.0f32);
        for w in poses.windows(3) {
            for k in 0..desc.bodies.len() {
                let (a, b, c) = (w[0].bones[k].0, w[1].bones[k].0, w[2].bones[k].0);
                fastest = fastest.max((c - b).length() / FRAME_DT);
                sharpest = sharpest.max((c - 2.0 * b + a).length() / (FRAME_DT * FRAME_DT));
            }
        }
        (fastest, sharpest)
    };
    let full = WALK_START + walk.gait.ramp;
    let starting = extremes(WALK_START - 0.5, full);
    let walking = extremes(full + 1.0, full + 3.0);
    eprintln!(
        "fastest bone, largest acceleration: {:.2} m/s, {:.1} m/s^2 from standing to full speed; {:.2} m/s, {:.1} m/s^2 at full speed",
        starting.0, starting.1, walking.0, walking.1
    );
    assert!(starting.0 <= walking.0, "{starting:?} {walking:?}");
    assert!(starting.1 <= 1.15 * walking.1, "{starting:?} {walking:?}");
}

#[test]
fn the_walk_is_a_gait_at_its_speed() {
    let (desc, walk) = walk();
    let g = walk.gait;
    let full = WALK_START + g.ramp;
    let hips = |t: f32| walk.hips(t);
    let speed = (hips(full + 4.0).z - hips(full).z).abs() / 4.0;
    eprintln!("root speed after the ramp {speed:.3} m/s");
    assert!((speed - WALK_SPEED).abs() < 0.01, "{speed} m/s");
    let (mut feet_low, mut feet_high, mut bob) =
        ([f32::MAX; 2], [f32::MIN; 2], (f32::MAX, f32::MIN));
    let mut planted_drift = [0.0f32; 2];
    let feet = ["foot_l", "foot_r"].map(|n| desc.body_index(n).unwrap());
    let (mut knee, mut arms_against_legs) = (0.0f32, 0);
    let frames = (2.0 / FRAME_DT) as usize;
    let mut before: Option<Pose> = None;
    for f in 0..frames {
        let t = full + f as f32 * FRAME_DT;
        let pose = walk.pose(&desc, t).unwrap();
        let y = pose.bones[0].0.y;
        bob = (bob.0.min(y), bob.1.max(y));
        for (side, &k) in feet.iter().enumerate() {
            let foot = pose.bones[k].0;
            feet_low[side] = feet_low[side].min(foot.y);
            feet_high[side] = feet_high[side].max(foot.y);
            // While down, the foot stays put.
            let down_now = g.foot(side, t - WALK_START).down;
            let down_before = g.foot(side, t - FRAME_DT - WALK_START).down;
            if let (Some(prev), true, true) = (&before, down_now, down_before) {
                let moved = (foot - prev.bones[k].0).length();
                planted_drift[side] = planted_drift[side].max(moved);
            }
        }
        let k = desc.body_index("shin_l").unwrap();
        let t_k = desc.body_index("thigh_l").unwrap();
        knee = knee.max(pose.bones[t_k].1.angle_between(pose.bones[k].1));
        // The left hand ahead of the hips exactly when the left foot is
        // behind them (and the other way round), away from the crossings.
        let hand = end(&desc, &pose, "forearm_l", 1).z - pose.bones[0].0.z;
        let foot = pose.bones[feet[0]].0.z - pose.bones[0].0.z;
        if hand.abs() > 0.05 && foot.abs() > 0.1 && hand.signum() != foot.signum() {
            arms_against_legs += 1;
        }
        before = Some(pose);
    }
    eprintln!(
        "feet from {:.3?} to {:.3?} m, planted feet move at most {:.4?} mm a frame, hips bob {:.1} cm, knee bends {:.0} degrees, arms against legs {arms_against_legs} of {frames} frames",
        feet_low,
        feet_high,
        planted_drift.map(|d| d * 1e3),
        (bob.1 - bob.0) * 100.0,
        knee.to_degrees()
    );
    for side in 0..2 {
        assert!(feet_high[side] - feet_low[side] > 0.04, "foot {side} lifts");
        assert!(planted_drift[side] < 1e-4, "foot {side} slides");
    }
    assert!(bob.1 - bob.0 > 0.01, "the hips bob");
    assert!(knee.to_degrees() > 40.0, "the knee bends as the leg swings");
    assert!(arms_against_legs > frames / 2, "{arms_against_legs}");
}

#[test]
fn the_world_drives_caps_stay_under_the_ragdolls_weight() {
    let desc = RagdollDesc::anatomical_humanoid();
    let profile = stagger_profile(&desc).unwrap();
    assert!(profile.bodies.iter().all(|b| b.max_acceleration < G));
    let mut scene = build(&config(SpineMode::Sockets, JointSolver::Direct)).unwrap();
    scene.frame(Scene::Stagger, 0, FRAME_DT).unwrap();
    let bodies = scene.ragdolls[0].bodies.iter().flatten();
    let (mut caps, mut mass) = (0.0, 0.0);
    for &b in bodies {
        caps += scene.world.world_drive(b).unwrap().unwrap().max_force;
        mass += scene.world.bodies().mass[b.index()];
    }
    eprintln!(
        "force caps {caps:.1} N against a weight of {:.1} N",
        mass * G
    );
    assert!(caps < mass * G, "{caps} N");
}

#[test]
fn it_stands_for_a_minute_with_its_hips_within_2_cm() {
    for spine in SPINES {
        let mut scene = build(&config(spine, JointSolver::Direct)).unwrap();
        scene.hits.clear();
        // Standing throughout: the walk never starts.
        let following = scene.following.as_mut().unwrap();
        following.walk.start = f32::INFINITY;
        let hips = scene.ragdolls[0].bodies[0].unwrap();
        let mut worst: f32 = 0.0;
        for frame in 0..60 * 60 {
            scene.frame(Scene::Stagger, frame, FRAME_DT).unwrap();
            let want = scene.following.as_ref().unwrap().hips(frame, FRAME_DT);
            worst = worst.max((scene.world.body(hips).unwrap().position - want).length());
        }
        eprintln!("{spine:?}: hips within {:.2} cm over 60 s", worst * 100.0);
        assert!(worst < 0.02, "{spine:?}: {worst} m");
    }
}

/// Over both spines under the direct solve, its feet's contacts pinned:
/// the walk tracks its animation within 5 cm (after the ramp), and a 40 N
/// s hit on the chest from every side, standing or walking, is survived
/// and recovered from within a second; a 150 N s hit from the front fells
/// it standing. (Under the paper's iterated solve its 1 kg feet creep
/// forward and it falls standing: `docs/stagger.md`.)
#[test]
fn it_walks_within_5_cm_and_recovers_from_a_40_n_s_hit_from_every_side() {
    let desc = RagdollDesc::anatomical_humanoid();
    let animation = stagger_profile(&desc).unwrap();
    for spine in SPINES {
        let joints = JointSolver::Direct;
        let config = config(spine, joints);
        let sweep = StaggerSweep::run(&config, &animation, 0..1, &[40.0, 150.0]).unwrap();
        let (max, rms) = sweep.tracking();
        eprintln!(
            "{spine:?}, {joints:?}: walking hips within {:.2} cm (rms {:.2} cm)",
            max * 100.0,
            rms * 100.0
        );
        assert!(max < 0.05, "{spine:?} {joints:?}: {max} m");
        for hit in &sweep.hits {
            let what = format!("{spine:?} {joints:?} {hit:?}");
            if hit.size == 40.0 {
                eprintln!(
                    "  {} from the {}: peak {:.1} cm, back in {:?} s",
                    hit.activity.name(),
                    hit.side.name(),
                    hit.peak * 100.0,
                    hit.recovered
                );
                assert!(hit.stays_up, "{what}");
                assert!(hit.recovered.is_some_and(|t| t < 1.0), "{what}");
            } else if (hit.activity, hit.side) == (Activity::Standing, Side::Front) {
                assert!(
                    !hit.stays_up,
                    "held up by drives that should give way: {what}"
                );
            }
        }
    }
}

/// The anatomical humanoid without its feet and ankles: it stands on the
/// round ends of its shins.
fn without_feet() -> RagdollDesc {
    let text = vertebra_ragdoll::ANATOMICAL_HUMANOID;
    let kept: Vec<&str> = (text.split("\n[["))
        .filter(|table| !(table.contains("name = \"foot_") || table.contains("name = \"ankle_")))
        .collect();
    RagdollDesc::from_toml(&kept.join("\n[[")).unwrap()
}

/// On legs with ankles, the walk reaches the ankles, keeps each foot flat
/// and ahead throughout and a planted foot where it was planted (no roll),
/// and still stands at the bind pose before it starts.
#[test]
fn on_feet_the_walk_keeps_them_flat_and_planted() {
    let desc = RagdollDesc::anatomical_humanoid();
    let walk = Walk::new(&desc, Gait::walk(WALK_SPEED), WALK_START).unwrap();
    let g = walk.gait;
    assert_eq!(g.foot_radius, 0.0, "a foot on an ankle does not roll");
    let bind = Pose::bind(&desc);
    let still = walk.pose(&desc, 0.5 * WALK_START).unwrap();
    for (k, (a, b)) in still.bones.iter().zip(&bind.bones).enumerate() {
        assert!((a.0 - b.0).length() < 1e-5, "bone {k} off the bind pose");
    }
    let feet = ["foot_l", "foot_r"].map(|n| desc.body_index(n).unwrap());
    let (mut tipped, mut drift, mut lift) = (0.0f32, 0.0f32, [0.0f32; 2]);
    let full = WALK_START + g.ramp;
    let mut before: Option<Pose> = None;
    for f in 0..(2.0 / FRAME_DT) as usize {
        let t = full + f as f32 * FRAME_DT;
        let pose = walk.pose(&desc, t).unwrap();
        for (side, &k) in feet.iter().enumerate() {
            let (at, turn) = pose.bones[k];
            tipped = tipped.max(turn.angle_between(Quat::IDENTITY));
            lift[side] = lift[side].max(at.y - bind.bones[k].0.y);
            let down = |t: f32| g.foot(side, t - WALK_START).down;
            if let (Some(prev), true, true) = (&before, down(t), down(t - FRAME_DT)) {
                drift = drift.max((at - prev.bones[k].0).length());
            }
        }
        before = Some(pose);
    }
    eprintln!(
        "feet on ankles: turned at most {tipped:.1e} rad, planted ones moved at most {:.4} mm a frame, lifted {:.3?} m",
        drift * 1e3,
        lift
    );
    assert!(tipped < 1e-3, "a foot turned {tipped} rad");
    assert!(drift < 1e-4, "a planted foot moved {drift} m in a frame");
    assert!(lift.iter().all(|&l| l > 0.05), "{lift:?}");
}

/// Without ankles, the legs reach the round ends of the shins and a
/// planted one rolls forward on its round end (at most a few millimetres a
/// frame), never leaving the ground while down.
#[test]
fn without_feet_a_planted_shin_rolls_on_its_round_end() {
    let desc = without_feet();
    let walk = Walk::new(&desc, Gait::walk(WALK_SPEED), WALK_START).unwrap();
    let g = walk.gait;
    assert!(g.foot_radius > 0.0);
    let full = WALK_START + g.ramp;
    let (mut rolled, mut low, mut high) = (0.0f32, f32::MAX, f32::MIN);
    let mut before: Option<Pose> = None;
    for f in 0..(2.0 / FRAME_DT) as usize {
        let t = full + f as f32 * FRAME_DT;
        let pose = walk.pose(&desc, t).unwrap();
        let foot = end(&desc, &pose, "shin_l", 1);
        let down = |t: f32| g.foot(0, t - WALK_START).down;
        if let (Some(prev), true, true) = (&before, down(t), down(t - FRAME_DT)) {
            rolled = rolled.max((foot - end(&desc, prev, "shin_l", 1)).length());
            (low, high) = (low.min(foot.y), high.max(foot.y));
        }
        before = Some(pose);
    }
    eprintln!(
        "without feet: a planted shin end moves at most {:.2} mm a frame, from {low:.4} to {high:.4} m up",
        rolled * 1e3
    );
    assert!(rolled > 1e-4 && rolled < 0.003, "{rolled} m");
    assert!(high - low < 1e-3, "{low} .. {high} m");
}

/// The walk refuses, naming the joint, legs it would bend wrongly: an
/// ankle that does not hang from its leg's shin, a knee that does not hang
/// from its thigh, one ankle without the other.
#[test]
fn the_walk_refuses_legs_that_are_not_one_chain() {
    let shipped = RagdollDesc::anatomical_humanoid();
    let joint = |name: &str| shipped.joint_index(name).unwrap();
    let body = |name: &str| shipped.body_index(name).unwrap();
    // A change to the shipped humanoid, and the words its refusal must name.
    type Change<'a> = &'a dyn Fn(&mut RagdollDesc);
    let cases: [(Change, &[&str]); 3] = [
        (
            &|d| d.joints[joint("ankle_l")].parent = body("thigh_l"),
            &["`ankle_l`", "`shin_l`"],
        ),
        (
            &|d| d.joints[joint("knee_r")].parent = body("hips"),
            &["`knee_r`", "`thigh_r`"],
        ),
        (
            &|d| d.joints[joint("ankle_r")].name = "hock_r".into(),
            &["both ankles"],
        ),
    ];
    for (change, words) in &cases {
        let mut desc = shipped.clone();
        change(&mut desc);
        let message = Walk::new(&desc, Gait::walk(WALK_SPEED), WALK_START)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(words.iter().all(|w| message.contains(w)), "{message}");
    }
    assert!(Walk::new(&shipped, Gait::walk(WALK_SPEED), WALK_START).is_ok());
}
