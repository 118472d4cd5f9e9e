//! The skeleton's poses: local and model space against closed forms and
//! each other, and every malformed skeleton or pose refused by name.

use core::f32::consts::FRAC_PI_2;

use glam::{Quat, Vec3};
use proptest::prelude::*;
use vertebra_ragdoll::{Bone, LocalPose, ModelPose, RagdollError, Skeleton, Transform};

/// The angle between two rotations (rad), accurate where they are close
/// (glam's `angle_between` takes `acos` of a dot near 1, which loses half
/// the digits: 1e-3 rad for two equal quaternions of length 0.9999999).
fn angle(a: Quat, b: Quat) -> f32 {
    let r = a * b.conjugate();
    2.0 * r.xyz().length().atan2(r.w.abs())
}

fn bone(name: &str, parent: Option<usize>, translation: Vec3, rotation: Quat) -> Bone {
    Bone {
        name: name.to_owned(),
        parent,
        bind: Transform::new(translation, rotation),
    }
}

/// An arm along +Y: shoulder at (0, 1, 0) in the model, upper arm 0.3 m,
/// forearm 0.25 m, each bone turned 90 degrees about +Z from its parent.
fn arm() -> Skeleton {
    let turn = Quat::from_rotation_z(FRAC_PI_2);
    Skeleton::new(vec![
        bone("shoulder", None, Vec3::Y, Quat::IDENTITY),
        bone("upper", Some(0), Vec3::ZERO, turn),
        bone("fore", Some(1), Vec3::new(0.3, 0.0, 0.0), turn),
        bone("hand", Some(2), Vec3::new(0.25, 0.0, 0.0), Quat::IDENTITY),
    ])
    .unwrap()
}

#[test]
fn a_local_pose_composes_down_the_chain_as_the_closed_form_says() {
    let skeleton = arm();
    let model = skeleton.bind_pose().to_model(&skeleton).unwrap();
    // upper turned 90 deg: its +X points along model +Y; the forearm
    // starts 0.3 m up there and is turned 180 deg: its +X points along -X.
    let expected = [
        Vec3::Y,
        Vec3::Y,
        Vec3::new(0.0, 1.3, 0.0),
        Vec3::new(-0.25, 1.3, 0.0),
    ];
    for (t, e) in model.bones.iter().zip(expected) {
        assert!(t.translation.distance(e) < 1e-6, "{t:?} against {e}");
    }
    let hand = model.bones[3].rotation;
    assert!(angle(hand, Quat::from_rotation_z(2.0 * FRAC_PI_2)) < 1e-3);
    // A point 0.1 m along the hand's +Y is 0.1 m along model -Y.
    let p = model.bones[3].transform_point(Vec3::Y * 0.1);
    assert!(p.distance(Vec3::new(-0.25, 1.2, 0.0)) < 1e-6);
}

#[test]
fn placing_a_model_pose_in_the_world_moves_every_bone_rigidly() {
    let skeleton = arm();
    let model = skeleton.bind_pose().to_model(&skeleton).unwrap();
    let place = Transform::new(Vec3::new(5.0, 0.0, -2.0), Quat::from_rotation_y(1.0));
    let world = model.in_world(place);
    for (m, w) in model.bones.iter().zip(&world.bones) {
        assert!(w.translation.distance(place.transform_point(m.translation)) < 1e-5);
        assert!(angle(w.rotation, place.rotation * m.rotation) < 1e-5);
    }
}

fn unit_quat() -> impl Strategy<Value = Quat> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("not near zero", |(x, y, z, w)| {
            x * x + y * y + z * z + w * w > 0.01
        })
        .prop_map(|(x, y, z, w)| Quat::from_xyzw(x, y, z, w).normalize())
}

fn transform() -> impl Strategy<Value = Transform> {
    (prop::array::uniform3(-2.0f32..2.0), unit_quat())
        .prop_map(|(t, q)| Transform::new(Vec3::from(t), q))
}

/// A random skeleton (each bone's parent any earlier bone, or none: a
/// forest is a skeleton too) and a
/// random local pose of it.
fn skeleton_and_pose() -> impl Strategy<Value = (Skeleton, LocalPose)> {
    (1usize..40).prop_flat_map(|n| {
        let parents: Vec<_> = (0..n)
            .map(|i| (0..=i).prop_map(move |k| (k < i).then_some(k)))
            .collect();
        (
            parents,
            prop::collection::vec(transform(), n),
            prop::collection::vec(transform(), n),
        )
            .prop_map(|(parents, binds, pose)| {
                let bones = parents
                    .iter()
                    .zip(binds)
                    .enumerate()
                    .map(|(i, (&parent, bind))| Bone {
                        name: format!("b{i}"),
                        parent,
                        bind,
                    })
                    .collect();
                (Skeleton::new(bones).unwrap(), LocalPose { bones: pose })
            })
    })
}

proptest! {
    /// Local to model and back gives the local pose again, and each
    /// model transform is its parent's times its local one.
    #[test]
    fn local_and_model_space_convert_both_ways((skeleton, local) in skeleton_and_pose()) {
        let model = local.to_model(&skeleton).unwrap();
        for (i, bone) in skeleton.bones().iter().enumerate() {
            let parent = bone.parent.map_or(Transform::IDENTITY, |p| model.bones[p]);
            let expected = parent.transform_point(local.bones[i].translation);
            prop_assert!(model.bones[i].translation.distance(expected) < 1e-4);
        }
        let back = model.to_local(&skeleton).unwrap();
        for (a, b) in back.bones.iter().zip(&local.bones) {
            prop_assert!(a.translation.distance(b.translation) < 1e-3, "{a:?} {b:?}");
            prop_assert!(angle(a.rotation, b.rotation) < 1e-3, "{a:?} {b:?}");
        }
    }
}

fn refused(bones: Vec<Bone>) -> String {
    Skeleton::new(bones).unwrap_err().to_string()
}

#[test]
fn a_malformed_skeleton_is_refused_naming_the_bone_and_field() {
    let ok = |name: &str, parent| bone(name, parent, Vec3::ZERO, Quat::IDENTITY);
    let e = refused(vec![ok("a", None), ok("b", Some(2)), ok("c", Some(0))]);
    assert!(e.contains("bone 1 `b`") && e.contains("parent"), "{e}");
    let e = refused(vec![ok("a", None), ok("a", Some(0))]);
    assert!(e.contains("bone 1 `a`") && e.contains("name"), "{e}");
    let e = refused(vec![ok("", None)]);
    assert!(e.contains("bone 0") && e.contains("name"), "{e}");
    let e = refused(vec![bone(
        "a",
        None,
        Vec3::new(f32::NAN, 0.0, 0.0),
        Quat::IDENTITY,
    )]);
    assert!(e.contains("bone 0 `a`") && e.contains("translation"), "{e}");
    let e = refused(vec![bone(
        "a",
        None,
        Vec3::ZERO,
        Quat::from_xyzw(0.0, 0.0, 0.0, 2.0),
    )]);
    assert!(e.contains("bone 0 `a`") && e.contains("rotation"), "{e}");
    let e = refused(vec![]);
    assert!(e.contains("bones"), "{e}");
}

#[test]
fn a_pose_that_does_not_fit_is_refused_naming_the_bone() {
    let skeleton = arm();
    let short = LocalPose {
        bones: vec![Transform::IDENTITY; 3],
    };
    assert!(matches!(
        short.to_model(&skeleton),
        Err(RagdollError::BadPose(_))
    ));
    let mut bad = skeleton.bind_pose();
    bad.bones[2].translation.y = f32::INFINITY;
    let e = bad.to_model(&skeleton).unwrap_err().to_string();
    assert!(e.contains("`fore`") && e.contains("translation"), "{e}");
    let bad = ModelPose {
        bones: vec![Transform::new(Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)); 4],
    };
    let e = bad.to_local(&skeleton).unwrap_err().to_string();
    assert!(e.contains("`shoulder`") && e.contains("rotation"), "{e}");
}
