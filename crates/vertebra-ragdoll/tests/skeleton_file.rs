//! Skeleton files: the shipped reference skeleton against the humanoids'
//! bodies and its own conventions, every file written back read as the same
//! skeleton bit for bit, and every malformed file refused by line, bone and
//! field.

use glam::{Quat, Vec3};
use proptest::prelude::*;
use vertebra_ragdoll::{
    Bone, MAX_FILE_BYTES, REFERENCE_SKELETON, RagdollDesc, Skeleton, Transform,
};

fn model(skeleton: &Skeleton) -> Vec<Transform> {
    skeleton.bind_pose().to_model(skeleton).unwrap().bones
}

/// The point of segment `[a, b]` nearest `p`.
fn nearest_on_segment(p: Vec3, [a, b]: [Vec3; 2]) -> Vec3 {
    let ab = b - a;
    a + ab * ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
}

/// The distance from `p` to the polyline through `points`.
fn distance_to_polyline(p: Vec3, points: &[Vec3]) -> f32 {
    points
        .windows(2)
        .map(|w| p.distance(nearest_on_segment(p, [w[0], w[1]])))
        .fold(f32::INFINITY, f32::min)
}

#[test]
fn the_reference_skeleton_has_the_bones_an_engine_exports() {
    let s = Skeleton::reference();
    assert!(s.len() >= 60, "{} bones", s.len());
    let parent = |name: &str| {
        let bone = &s.bones()[s.bone_index(name).unwrap_or_else(|| panic!("no `{name}`"))];
        bone.parent.map(|p| s.bones()[p].name.as_str())
    };
    assert_eq!(parent("root"), None);
    assert_eq!(parent("hips"), Some("root"));
    // Five spine bones from the hips to the chest, three neck bones, the head.
    let chain = [
        "hips",
        "spine_lower",
        "spine_middle",
        "spine_upper",
        "spine_top",
        "chest",
        "neck_1",
        "neck_2",
        "neck_3",
        "head",
    ];
    for pair in chain.windows(2) {
        assert_eq!(parent(pair[1]), Some(pair[0]));
    }
    for side in ["l", "r"] {
        let b = |name: &str| format!("{name}_{side}");
        assert_eq!(parent(&b("clavicle")), Some("chest"));
        assert_eq!(parent(&b("upper_arm")), Some(b("clavicle").as_str()));
        assert_eq!(parent(&b("forearm")), Some(b("upper_arm").as_str()));
        assert_eq!(parent(&b("hand")), Some(b("forearm").as_str()));
        assert_eq!(parent(&b("upper_arm_twist")), Some(b("upper_arm").as_str()));
        assert_eq!(parent(&b("forearm_twist")), Some(b("forearm").as_str()));
        for finger in ["thumb", "index", "middle", "ring", "pinky"] {
            assert_eq!(
                parent(&format!("{finger}_1_{side}")),
                Some(b("hand").as_str())
            );
            assert_eq!(
                parent(&format!("{finger}_2_{side}")),
                Some(format!("{finger}_1_{side}").as_str())
            );
            assert_eq!(
                parent(&format!("{finger}_3_{side}")),
                Some(format!("{finger}_2_{side}").as_str())
            );
        }
        assert_eq!(parent(&b("thigh")), Some("hips"));
        assert_eq!(parent(&b("thigh_twist")), Some(b("thigh").as_str()));
        assert_eq!(parent(&b("shin")), Some(b("thigh").as_str()));
        assert_eq!(parent(&b("foot")), Some(b("shin").as_str()));
        assert_eq!(parent(&b("toes")), Some(b("foot").as_str()));
    }
}

/// Each body of both humanoids has a bone of its name at the pivot of the
/// joint to its parent body (the root, the hips, at its centre), so a bone
/// turned about its origin turns its body about its joint; and the five
/// spine bones lie on the spine's polyline (the hips' centre, the spine
/// joints' pivots).
#[test]
fn the_reference_skeleton_fits_both_humanoids_bind_poses() {
    let s = Skeleton::reference();
    let pose = model(&s);
    let origin = |name: &str| pose[s.bone_index(name).unwrap()].translation;
    for desc in [
        RagdollDesc::reference_humanoid(),
        RagdollDesc::anatomical_humanoid(),
    ] {
        for (i, body) in desc.bodies.iter().enumerate() {
            let expected = match desc.parent_joint[i] {
                None => body.centre(),
                Some(k) => desc.joints[k].anchor,
            };
            let miss = origin(&body.name).distance(expected);
            assert!(miss < 1e-6, "{}: {}: {miss} m", desc.name, body.name);
        }
        let pivot = |name: &str| desc.joints.iter().find(|j| j.name == name).unwrap().anchor;
        let hips = desc.bodies[desc.body_index("hips").unwrap()].centre();
        let polyline = [hips, pivot("spine_1"), pivot("spine_2"), pivot("spine_3")];
        for bone in [
            "spine_lower",
            "spine_middle",
            "spine_upper",
            "spine_top",
            "chest",
        ] {
            let miss = distance_to_polyline(origin(bone), &polyline);
            assert!(miss < 1e-6, "{}: {bone}: {miss} m", desc.name);
        }
    }
}

/// A bone's +Y points at its first child, its +Z as near the character's
/// front (+Z) as that allows; a bone without children has its parent's
/// orientation.
#[test]
fn the_reference_skeleton_keeps_its_axis_convention() {
    let s = Skeleton::reference();
    let pose = model(&s);
    for (i, bone) in s.bones().iter().enumerate() {
        match s.bones().iter().position(|b| b.parent == Some(i)) {
            Some(child) => {
                let along = (pose[child].translation - pose[i].translation).normalize();
                let y = pose[i].rotation * Vec3::Y;
                assert!(
                    y.distance(along) < 1e-6,
                    "{}: +Y {y}, to child {along}",
                    bone.name
                );
                let front = (Vec3::Z - along * along.z).normalize();
                let z = pose[i].rotation * Vec3::Z;
                assert!(
                    z.distance(front) < 1e-6,
                    "{}: +Z {z}, front {front}",
                    bone.name
                );
            }
            None => assert_eq!(bone.bind.rotation, Quat::IDENTITY, "{}", bone.name),
        }
    }
}

#[test]
fn the_reference_skeleton_file_reads_back_as_itself() {
    let s = Skeleton::reference();
    assert_eq!(Skeleton::from_toml(&s.to_toml()).unwrap(), s);
    assert_eq!(Skeleton::from_toml(REFERENCE_SKELETON).unwrap(), s);
}

/// Names with everything a TOML string must escape.
fn name() -> impl Strategy<Value = String> {
    prop::collection::vec(
        prop::sample::select(vec![
            'a', 'Z', '_', ' ', '"', '\\', '\n', '\t', '\u{1}', '\u{7f}', 'é', '骨', '🦴',
        ]),
        0..6,
    )
    .prop_map(|chars| chars.into_iter().collect())
}

/// Any `f32` a bone's translation may hold: within 1e6 m, signed zeros and
/// subnormals included.
fn coordinate() -> impl Strategy<Value = f32> {
    prop_oneof![
        -1.0e6f32..1.0e6,
        -1.0f32..1.0,
        Just(0.0),
        Just(-0.0),
        Just(f32::MIN_POSITIVE / 3.0),
        Just(1.0e6),
        Just(0.1),
    ]
}

fn rotation() -> impl Strategy<Value = Quat> {
    prop_oneof![
        Just(Quat::IDENTITY),
        Just(Quat::from_xyzw(-0.0, 0.0, -0.0, 1.0)),
        (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
            .prop_filter("not near zero", |(x, y, z, w)| x * x
                + y * y
                + z * z
                + w * w
                > 0.01)
            .prop_map(|(x, y, z, w)| Quat::from_xyzw(x, y, z, w).normalize()),
    ]
}

fn skeleton() -> impl Strategy<Value = Skeleton> {
    (1usize..30).prop_flat_map(|n| {
        let parents: Vec<_> = (0..n)
            .map(|i| (0..=i).prop_map(move |k| (k < i).then_some(k)))
            .collect();
        (
            parents,
            prop::collection::vec((name(), prop::array::uniform3(coordinate()), rotation()), n),
        )
            .prop_map(|(parents, bones)| {
                let bones = parents
                    .into_iter()
                    .zip(bones)
                    .enumerate()
                    .map(|(i, (parent, (name, t, r)))| Bone {
                        // Unique and non-empty: the index ends every name.
                        name: format!("{name}{i}"),
                        parent,
                        bind: Transform::new(Vec3::from(t), r),
                    })
                    .collect();
                Skeleton::new(bones).unwrap()
            })
    })
}

fn bits(s: &Skeleton) -> Vec<(String, Option<usize>, [u32; 7])> {
    s.bones()
        .iter()
        .map(|b| {
            let t = b.bind.translation.to_array();
            let r = b.bind.rotation.to_array();
            let mut all = [0; 7];
            for (slot, v) in all.iter_mut().zip(t.iter().chain(&r)) {
                *slot = v.to_bits();
            }
            (b.name.clone(), b.parent, all)
        })
        .collect()
}

proptest! {
    /// Any skeleton written and read back is the same skeleton, bit for bit
    /// (signed zeros and subnormals included).
    #[test]
    fn any_skeleton_reads_back_bit_for_bit(s in skeleton()) {
        let back = Skeleton::from_toml(&s.to_toml()).unwrap();
        prop_assert_eq!(bits(&back), bits(&s));
    }
}

const TWO_BONES: &str = "\
[[bone]]
name = \"root\"
translation = [0.0, 0.0, 0.0]

[[bone]]
name = \"hips\"
parent = \"root\"
translation = [0.0, 1.0, 0.0]
rotation = [0.0, 0.0, 0.0, 1.0]
";

#[test]
fn a_small_file_reads_as_written() {
    let s = Skeleton::from_toml(TWO_BONES).unwrap();
    assert_eq!(s.len(), 2);
    assert_eq!(s.bones()[1].parent, Some(0));
    assert_eq!(s.bones()[1].bind, Transform::new(Vec3::Y, Quat::IDENTITY));
    assert_eq!(model(&s)[1].translation, Vec3::Y);
}

#[test]
fn malformed_skeleton_files_are_refused_by_line_bone_and_field() {
    let edited = |from: &str, to: &str| {
        assert!(TWO_BONES.contains(from), "`{from}`");
        TWO_BONES.replacen(from, to, 1)
    };
    let cases = [
        (
            "name = \"hips\"",
            "name = \"hips\"\nlength = 2.0",
            "line 7: unknown field `length`",
        ),
        (
            "parent = \"root\"",
            "parent = \"pelvis\"",
            "line 5: bone `hips`: parent `pelvis` is not a bone of the skeleton",
        ),
        (
            "parent = \"root\"",
            "parent = \"hips\"",
            "line 5: bone `hips`: parent is the bone itself",
        ),
        (
            "name = \"root\"",
            "name = \"root\"\nparent = \"hips\"",
            "line 1: bone `root`: parent makes the bone its own ancestor: `root` -> `hips` -> `root`",
        ),
        (
            "name = \"hips\"",
            "name = \"root\"",
            "line 5: bone name `root` is used twice",
        ),
        (
            "name = \"hips\"",
            "name = \"\"",
            "line 5: bone ``: name is empty",
        ),
        (
            "[0.0, 1.0, 0.0]",
            "[0.0, nan, 0.0]",
            "line 5: bone `hips`: translation is not finite",
        ),
        (
            "[0.0, 1.0, 0.0]",
            "[0.0, 2e6, 0.0]",
            "line 5: bone `hips`: translation is [0, 2000000, 0]; each coordinate must be within 1000000 m",
        ),
        (
            "[0.0, 0.0, 0.0, 1.0]",
            "[0.0, 0.0, 0.0, 2.0]",
            "line 5: bone `hips`: rotation has length 2; must be a unit quaternion (within 1e-3)",
        ),
        (
            "[0.0, 0.0, 0.0, 1.0]",
            "[0.0, 0.0, inf, 1.0]",
            "line 5: bone `hips`: rotation is not finite",
        ),
        (
            "translation = [0.0, 1.0, 0.0]\n",
            "",
            "malformed skeleton file: line 5: bone `hips`: missing field `translation`",
        ),
    ];
    for (from, to, expected) in cases {
        let e = Skeleton::from_toml(&edited(from, to))
            .unwrap_err()
            .to_string();
        assert!(e.contains(expected), "expected `{expected}` in `{e}`");
    }
    // A parent defined after its child, without a cycle.
    let later = TWO_BONES
        .replacen("name = \"root\"", "name = \"root\"\nparent = \"hips\"", 1)
        .replacen("parent = \"root\"\n", "", 1);
    let e = Skeleton::from_toml(&later).unwrap_err().to_string();
    assert!(
        e.ends_with("line 1: bone `root`: parent `hips` is defined at line 6, not before this bone; a parent comes before its children"),
        "{e}"
    );
    let e = Skeleton::from_toml("bone = []").unwrap_err().to_string();
    assert_eq!(e, "skeleton: bone has 0 bones; must have 1 to 4096");
    let e = Skeleton::from_toml("[[body]]\nname = \"x\"")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("malformed skeleton file: line 1: unknown field `body`"),
        "{e}"
    );
}

#[test]
fn skeleton_files_are_read_within_the_size_cap_and_named_in_errors() {
    let dir = std::env::temp_dir().join(format!("vertebra-skeleton-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("skeleton.toml");
    std::fs::write(&good, REFERENCE_SKELETON).unwrap();
    assert_eq!(Skeleton::from_file(&good).unwrap(), Skeleton::reference());
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        TWO_BONES.replace("[0.0, 1.0, 0.0]", "[0.0, nan, 0.0]"),
    )
    .unwrap();
    let e = Skeleton::from_file(&bad).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{}: line 5: bone `hips`: translation is not finite",
            bad.display()
        )
    );
    let big = dir.join("big.toml");
    std::fs::write(&big, vec![b'#'; MAX_FILE_BYTES as usize + 1]).unwrap();
    let e = Skeleton::from_file(&big).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{}: the skeleton text is larger than MAX_FILE_BYTES (1048576 bytes) and is refused \
             before it is parsed; a skeleton file is a few KB",
            big.display()
        )
    );
    let e = Skeleton::from_file(&dir.join("absent.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!(
            "{}: cannot read the skeleton file",
            dir.join("absent.toml").display()
        )),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
