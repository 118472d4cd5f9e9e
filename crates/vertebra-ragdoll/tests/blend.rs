//! Per-bone blending between an animation pose and the simulated pose, and
//! the blend back from ragdoll to animation: each bone lands its weight's
//! share of the way (metres and radians), the ends are exact, no bone moves
//! more per frame than the closed form allows, and bad weights are refused
//! by name.

mod common;

use common::{angle, walking};
use glam::{Quat, Vec3};
use vertebra_ragdoll::{
    BlendBack, Bone, BuildOptions, LocalPose, Pose, Ragdoll, RagdollDesc, RagdollError, Skeleton,
    SpineMapping, SpineMode, Transform,
};
use vertebra_world::{SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

/// A bone blended at weight `w` between `a` and `b` is `w` of the way from
/// `a` and `1 - w` from `b`, in metres and in radians; 0 and 1 give the
/// ends bit for bit.
fn assert_share((pa, qa): (Vec3, Quat), (pb, qb): (Vec3, Quat), (po, qo): (Vec3, Quat), w: f32) {
    if w == 0.0 {
        assert_eq!((po, qo), (pa, qa));
    } else if w == 1.0 {
        assert_eq!((po, qo), (pb, qb));
    }
    let (distance, turn) = ((pb - pa).length(), angle(qa, qb));
    assert!(((po - pa).length() - w * distance).abs() < 1e-5);
    assert!(((po - pb).length() - (1.0 - w) * distance).abs() < 1e-5);
    assert!(
        (angle(qo, qa) - w * turn).abs() < 2e-5,
        "{} vs {}",
        angle(qo, qa),
        w * turn
    );
    assert!((angle(qo, qb) - (1.0 - w) * turn).abs() < 2e-5);
}

#[test]
fn a_pose_blend_puts_each_bone_its_weights_share_of_the_way() {
    let desc = RagdollDesc::reference_humanoid();
    let animation = walking(&desc, 0.1);
    let simulated = walking(&desc, 0.6).moved(Vec3::Y, Quat::from_rotation_x(1.2), Vec3::X);
    let weights: Vec<f32> = (0..desc.bodies.len()).map(|k| k as f32 / 12.0).collect();
    let out = animation.blend(&desc, &simulated, &weights).unwrap();
    for (k, &w) in weights.iter().enumerate() {
        assert_share(animation.bones[k], simulated.bones[k], out.bones[k], w);
    }
}

/// An arm of four bones.
fn arm() -> Skeleton {
    let bone = |name: &str, parent, x: f32| Bone {
        name: name.to_owned(),
        parent,
        bind: Transform::new(Vec3::new(x, 0.0, 0.0), Quat::IDENTITY),
    };
    Skeleton::new(vec![
        bone("shoulder", None, 0.0),
        bone("upper", Some(0), 0.1),
        bone("fore", Some(1), 0.3),
        bone("hand", Some(2), 0.25),
    ])
    .unwrap()
}

#[test]
fn a_local_pose_blend_puts_each_bone_its_weights_share_of_the_way() {
    let skeleton = arm();
    let animation = skeleton.bind_pose();
    let mut simulated = skeleton.bind_pose();
    for (k, t) in simulated.bones.iter_mut().enumerate() {
        t.rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.3 * k as f32, -0.5, 2.5);
        t.translation += Vec3::new(0.0, 0.05 * k as f32, -0.02);
    }
    let weights = [0.0, 0.25, 0.5, 1.0];
    let out = animation.blend(&skeleton, &simulated, &weights).unwrap();
    let pair = |t: &Transform| (t.translation, t.rotation);
    for (k, &w) in weights.iter().enumerate() {
        let (a, b) = (pair(&animation.bones[k]), pair(&simulated.bones[k]));
        assert_share(a, b, pair(&out.bones[k]), w);
    }
}

/// The ragdoll's last simulated pose: the reference humanoid held by its
/// hips (kinematic) with everything else limp for a second.
fn held_ragdoll_pose(desc: &RagdollDesc, spine: SpineMode) -> Pose {
    let mut w = World::new(SolverConfig::default()).unwrap();
    let bind = Pose::bind(desc);
    let ragdoll = Ragdoll::build(&mut w, desc, BuildOptions::new(spine), &bind, None).unwrap();
    ragdoll.set_body_kinematic(&mut w, "hips", true).unwrap();
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    ragdoll.skeleton_pose(&w, SpineMapping::Arc).unwrap()
}

/// Each frame of a blend back from `simulated` to `animation(t)` over
/// `duration`: (output, animation, weight), until it is done.
fn blend_back(
    desc: &RagdollDesc,
    simulated: &Pose,
    duration: f32,
    animation: impl Fn(f32) -> Pose,
) -> Vec<(Pose, Pose, f32)> {
    let mut blend = BlendBack::new(desc, simulated.clone(), duration).unwrap();
    let mut frames = Vec::new();
    loop {
        let target = animation(frames.len() as f32 * DT);
        frames.push((blend.pose(desc, &target).unwrap(), target, blend.weight()));
        if blend.is_done() {
            return frames;
        }
        blend.advance(DT).unwrap();
    }
}

/// Faded back into a still animation pose, every bone moves per frame by
/// exactly `|w' - w|` times its distance from the held pose (metres and
/// radians), and the weight follows smoothstep: 1, then 0 after the
/// duration, never changing faster than `1.5 dt / duration` per frame.
#[test]
fn blending_back_to_a_still_pose_moves_each_bone_by_the_fades_share() {
    let desc = RagdollDesc::reference_humanoid();
    let duration = 0.5;
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let simulated = held_ragdoll_pose(&desc, spine);
        let still = walking(&desc, 0.25);
        let frames = blend_back(&desc, &simulated, duration, |_| still.clone());
        let (mut worst, mut fastest_fade) = (0.0f32, 0.0f32);
        for pair in frames.windows(2) {
            let ((out0, _, w0), (out1, _, w1)) = (&pair[0], &pair[1]);
            let fade = (w1 - w0).abs();
            fastest_fade = fastest_fade.max(fade);
            for k in 0..desc.bodies.len() {
                let (s, a) = (simulated.bones[k], still.bones[k]);
                let (o0, o1) = (out0.bones[k], out1.bones[k]);
                worst = worst
                    .max(((o1.0 - o0.0).length() - fade * (s.0 - a.0).length()).abs())
                    .max((angle(o1.1, o0.1) - fade * angle(s.1, a.1)).abs());
            }
        }
        let middle = frames[frames.len() / 2].2;
        eprintln!(
            "{spine:?}: {} frames, weight {middle:.3} halfway; fastest fade {fastest_fade:.4} \
             per frame (1.5 dt / duration = {:.4}); each step off the fade's share by at \
             most {worst:.1e}",
            frames.len(),
            1.5 * DT / duration
        );
        assert!(worst < 3e-6, "{worst}");
        assert!(fastest_fade <= 1.5 * DT / duration + 1e-6);
        assert!((middle - 0.5).abs() < 0.06, "{middle}");
    }
}

/// Faded back into a walk over half a second: the first frame is the
/// simulated pose and the last the walk's, exactly, and every bone moves
/// per frame by at most the larger of the two poses' own motion (the held
/// pose has none: the walk's) plus the fade's share, `|w' - w|` times its
/// distance from the held pose: the closed form of a blend toward a held
/// pose, with nothing left for a pop.
#[test]
fn blending_back_to_a_walk_starts_on_the_ragdoll_ends_on_the_walk_and_never_pops() {
    let desc = RagdollDesc::reference_humanoid();
    let duration = 0.5;
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let simulated = held_ragdoll_pose(&desc, spine);
        let frames = blend_back(&desc, &simulated, duration, |t| walking(&desc, t));
        let (first, last) = (&frames[0], frames.last().unwrap());
        assert_eq!(first.0, simulated, "the first frame is the ragdoll's");
        assert_eq!(first.2, 1.0);
        assert_eq!(last.0, last.1, "the last frame is the animation's");
        assert_eq!(last.2, 0.0);
        assert!((30..=31).contains(&frames.len()), "{} frames", frames.len());
        let mut largest_step = 0.0f32;
        for pair in frames.windows(2) {
            let ((out0, anim0, w0), (out1, anim1, w1)) = (&pair[0], &pair[1]);
            let fade = (w1 - w0).abs();
            for k in 0..desc.bodies.len() {
                let (s, a0, a1) = (simulated.bones[k], anim0.bones[k], anim1.bones[k]);
                let (o0, o1) = (out0.bones[k], out1.bones[k]);
                let moved = (o1.0 - o0.0).length();
                let bound = (a1.0 - a0.0).length() + fade * (s.0 - a0.0).length();
                assert!(moved <= bound + 1e-6, "bone {k}: {moved} m > {bound} m");
                let turned = angle(o1.1, o0.1);
                let turn_bound = angle(a1.1, a0.1) + fade * angle(s.1, a0.1);
                assert!(
                    turned <= turn_bound + 3e-6,
                    "bone {k}: {turned} rad > {turn_bound} rad"
                );
                largest_step = largest_step.max(moved);
            }
        }
        eprintln!(
            "{spine:?}: {} frames from the ragdoll to the walk; largest bone step {:.1} mm",
            frames.len(),
            largest_step * 1e3
        );
    }
}

#[test]
fn bad_weights_durations_and_poses_are_refused_by_name() {
    let desc = RagdollDesc::reference_humanoid();
    let pose = Pose::bind(&desc);
    let ones = vec![1.0; desc.bodies.len()];
    let with = |k: usize, w: f32| {
        let mut weights = ones.clone();
        weights[k] = w;
        weights
    };
    let message = |e: RagdollError| e.to_string();
    let cases = [
        (
            pose.blend(&desc, &pose, &[0.5; 3]).map(drop),
            "blend: weights has 3 entries for 13 bones",
        ),
        (
            pose.blend(&desc, &pose, &with(3, f32::NAN)).map(drop),
            "bone `chest`: weight is not finite",
        ),
        (
            pose.blend(&desc, &pose, &with(4, 1.5)).map(drop),
            "bone `head`: weight is 1.5; must be within [0, 1]",
        ),
        (
            pose.blend(&desc, &Pose { bones: vec![] }, &ones).map(drop),
            "bad pose: 0 bones for 13 bodies",
        ),
        (
            arm()
                .bind_pose()
                .blend(&arm(), &arm().bind_pose(), &[0.0, 0.0, -0.1, 0.0])
                .map(drop),
            "bone 2 `fore`: weight is -0.1; must be within [0, 1]",
        ),
        (
            arm()
                .bind_pose()
                .blend(
                    &arm(),
                    &LocalPose {
                        bones: vec![Transform::IDENTITY],
                    },
                    &[0.0; 4],
                )
                .map(drop),
            "bad pose: 1 transforms for 4 bones",
        ),
        (
            BlendBack::new(&desc, pose.clone(), 0.0).map(drop),
            "blend back: duration is 0 s; must be finite and positive",
        ),
        (
            BlendBack::new(&desc, Pose { bones: vec![] }, 1.0).map(drop),
            "bad pose: 0 bones for 13 bodies",
        ),
        (
            BlendBack::new(&desc, pose.clone(), 1.0)
                .unwrap()
                .advance(f32::NAN),
            "blend back: dt is NaN s; must be finite and not negative",
        ),
    ];
    for (result, expected) in cases {
        assert_eq!(result.map_err(message), Err(expected.to_owned()));
    }
}
