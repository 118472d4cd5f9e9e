//! Getting up: the clip that fits a lying ragdoll, placed where it lies,
//! and the blend back to it starting without a slide.

use glam::{Quat, Vec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_ragdoll::{BlendBack, GetUp, Pose, RagdollDesc};

/// The reference humanoid lying on its back or its front: the bind pose
/// (standing, +Y up) laid down by a quarter turn about +X one way or the
/// other, its root body 0.1 m above the origin.
fn laid(desc: &RagdollDesc, quarter: f32) -> Pose {
    let bind = Pose::bind(desc);
    let root = bind.bones[desc.root].0;
    let turn = Quat::from_rotation_x(quarter * core::f32::consts::FRAC_PI_2);
    bind.moved(root, turn, Vec3::new(0.0, 0.1, 0.0) - root)
}

/// A lying pose like `clip`, turned about +Y by `heading`, moved on the
/// ground, and tipped by up to `tip` rad about a random horizontal axis
/// (a body does not settle exactly as a clip starts).
fn lying_like(clip: &Pose, root: usize, heading: f32, tip: f32, r: &mut StdRng) -> Pose {
    let at = clip.bones[root].0;
    let axis = Vec3::new(r.random_range(-1.0..1.0), 0.0, r.random_range(-1.0..1.0)).normalize();
    let turn =
        Quat::from_axis_angle(axis, r.random_range(0.0..=tip)) * Quat::from_rotation_y(heading);
    let moved = Vec3::new(r.random_range(-5.0..5.0), 0.05, r.random_range(-5.0..5.0));
    clip.moved(at, turn, moved)
}

/// Whichever way it lies and faces, the clip of its lie is chosen (face
/// up from face down: half a turn of swing apart), turned to its heading
/// (the turn about up equals the heading it was given, to 1e-4 rad when
/// it lies exactly as the clip starts) and put with its root on the
/// ragdoll's; the misfit is the tip it was given, at most.
#[test]
fn the_clip_of_the_ragdolls_lie_is_chosen_and_placed_on_it() {
    let desc = RagdollDesc::reference_humanoid();
    let clips = [laid(&desc, 1.0), laid(&desc, -1.0)];
    let mut r = StdRng::seed_from_u64(3);
    for trial in 0..200 {
        let which = trial % 2;
        let heading = r.random_range(-3.1..3.1);
        let tip = if trial < 20 { 0.0 } else { 0.4 };
        let lying = lying_like(&clips[which], desc.root, heading, tip, &mut r);
        let get_up = GetUp::choose(&desc, &lying, &clips, Vec3::Y).unwrap();
        assert_eq!(get_up.clip, which, "trial {trial}");
        assert!(get_up.misfit <= tip + 1e-3, "trial {trial}: {get_up:?}");
        let placed = get_up.placed(&clips[which]);
        let (at, facing) = lying.bones[desc.root];
        assert!(
            placed.bones[desc.root].0.distance(at) < 1e-4,
            "trial {trial}"
        );
        let left = placed.bones[desc.root].1.angle_between(facing);
        assert!(left <= get_up.misfit + 1e-3, "trial {trial}: {left}");
        // The turn is about up alone.
        let axis = Vec3::new(get_up.turn.x, get_up.turn.y, get_up.turn.z);
        assert!(
            axis.x.abs() < 1e-6 && axis.z.abs() < 1e-6,
            "{:?}",
            get_up.turn
        );
        if tip == 0.0 {
            let off = get_up.turn.angle_between(Quat::from_rotation_y(heading));
            assert!(off < 1e-4, "trial {trial}: {off} rad off the heading");
        }
    }
}

/// Blended back to the placed clip, held at its first frame: the output
/// starts at the lying pose exactly, ends on the clip exactly, and the
/// root body never moves (the clip's root is put on the ragdoll's).
#[test]
fn the_blend_back_to_the_placed_clip_does_not_slide_the_root() {
    let desc = RagdollDesc::reference_humanoid();
    let clips = [laid(&desc, 1.0), laid(&desc, -1.0)];
    let mut r = StdRng::seed_from_u64(9);
    let lying = lying_like(&clips[1], desc.root, 2.0, 0.0, &mut r);
    let get_up = GetUp::choose(&desc, &lying, &clips, Vec3::Y).unwrap();
    let clip = get_up.placed(&clips[get_up.clip]);
    let mut blend = BlendBack::new(&desc, lying.clone(), 0.5).unwrap();
    assert_eq!(blend.pose(&desc, &clip).unwrap(), lying);
    let root = lying.bones[desc.root].0;
    while !blend.is_done() {
        let output = blend.pose(&desc, &clip).unwrap();
        assert!(output.bones[desc.root].0.distance(root) < 1e-4);
        blend.advance(1.0 / 60.0).unwrap();
    }
    assert_eq!(blend.pose(&desc, &clip).unwrap(), clip);
}

#[test]
fn get_up_refuses_what_it_cannot_use() {
    let desc = RagdollDesc::reference_humanoid();
    let clips = [laid(&desc, 1.0)];
    let lying = clips[0].clone();
    let message = |e: vertebra_ragdoll::RagdollError| e.to_string();
    let none = GetUp::choose(&desc, &lying, &[], Vec3::Y).unwrap_err();
    assert!(message(none).contains("first_frames"));
    for up in [Vec3::ZERO, Vec3::new(0.0, 2.0, 0.0), Vec3::NAN] {
        let bad = GetUp::choose(&desc, &lying, &clips, up).unwrap_err();
        assert!(message(bad).contains("up"), "{up}");
    }
    let mut short = lying.clone();
    short.bones.pop();
    let bad = GetUp::choose(&desc, &short, &clips, Vec3::Y).unwrap_err();
    assert!(message(bad).contains("the lying pose"));
    let mut broken = clips[0].clone();
    broken.bones[2].1 = Quat::from_xyzw(0.0, 0.0, 0.0, 2.0);
    let bad = GetUp::choose(&desc, &lying, &[clips[0].clone(), broken], Vec3::Y).unwrap_err();
    let text = message(bad);
    assert!(
        text.contains("clip 1's first frame") && text.contains("bone `"),
        "{text}"
    );
}
