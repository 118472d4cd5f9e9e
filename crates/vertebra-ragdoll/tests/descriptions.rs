//! Descriptions attached to a skeleton, built in code, written back to
//! TOML and checked by hand: bodies bound to bones with their bind
//! offsets, bodies placed from bones, a total mass that scales, every
//! inconsistent combination refused by line, body and field, and every
//! description a file or a builder makes read back as itself.

use core::f32::consts::FRAC_PI_2;

use glam::{Quat, Vec3};
use vertebra_ragdoll::{
    ANATOMICAL_HUMANOID, BodySpec, BoneBinding, BuildOptions, DriveSettings, JointFrame, JointSpec,
    Pose, REFERENCE_HUMANOID, REFERENCE_SKELETON, Ragdoll, RagdollDesc, RagdollError, Skeleton,
    SpineMode, SpineSpec, Transform,
};
use vertebra_world::{JointKind, LimitSoftness, SolverConfig, Spring, Swing, SwingTwist, World};

fn model(skeleton: &Skeleton) -> Vec<Transform> {
    skeleton.bind_pose().to_model(skeleton).unwrap().bones
}

#[test]
fn both_humanoids_follow_the_reference_skeleton_by_name() {
    let skeleton = Skeleton::reference();
    let pose = model(&skeleton);
    for text in [REFERENCE_HUMANOID, ANATOMICAL_HUMANOID] {
        let plain = RagdollDesc::from_toml(text).unwrap();
        let desc = RagdollDesc::from_toml_with_skeleton(text, &skeleton).unwrap();
        assert_eq!(desc.skeleton.as_ref(), Some(&skeleton));
        for (body, alone) in desc.bodies.iter().zip(&plain.bodies) {
            // The skeleton changes nothing but the binding.
            assert_eq!((&body.segment, body.mass), (&alone.segment, alone.mass));
            let binding = body.bone.expect("every humanoid body has a bone");
            let bone = skeleton.bone_index(&body.name).unwrap();
            assert_eq!(binding.bone, bone);
            assert_eq!(
                desc.body_on_bone(bone),
                Some(desc.body_index(&body.name).unwrap())
            );
            // The bone's bind transform times the offset is the body's
            // bind frame: its centre, the world's axes.
            let placed = pose[bone] * binding.offset;
            assert!(
                placed.translation.distance(body.centre()) < 1e-6,
                "{}",
                body.name
            );
            assert!(
                placed.rotation.angle_between(Quat::IDENTITY) < 1e-3,
                "{}",
                body.name
            );
        }
        assert_eq!(
            desc.body_on_bone(skeleton.bone_index("index_2_l").unwrap()),
            None
        );
    }
}

/// A two-bone arm inline: shoulder at (0.2, 1.4, 0), elbow 0.3 m below.
const ARM: &str = "\
name = \"arm\"

[[body]]
name = \"upper\"
from = \"shoulder\"
to = \"elbow\"
radius = 0.05
mass = 2.0

[[body]]
name = \"lower\"
segment = [[0.2, 1.05, 0.0], [0.2, 0.85, 0.0]]
radius = 0.04
mass = 1.0
bone = \"elbow\"

[[joint]]
name = \"elbow\"
parent = \"upper\"
child = \"lower\"
anchor = [0.2, 1.1, 0.0]
kind = \"hinge\"
axis = [1.0, 0.0, 0.0]

[[bone]]
name = \"shoulder\"
translation = [0.2, 1.4, 0.0]
rotation = [0.0, 0.0, 1.0, 0.0]

[[bone]]
name = \"elbow\"
parent = \"shoulder\"
translation = [0.0, 0.3, 0.0]
";

#[test]
fn a_body_from_bones_runs_from_one_bone_origin_to_the_other() {
    let desc = RagdollDesc::from_toml(ARM).unwrap();
    let upper = &desc.bodies[0];
    // The shoulder is turned half a turn about Z, so the elbow's 0.3 m
    // along its +Y is 0.3 m down.
    assert!(upper.segment[0].distance(Vec3::new(0.2, 1.4, 0.0)) < 1e-6);
    assert!(upper.segment[1].distance(Vec3::new(0.2, 1.1, 0.0)) < 1e-6);
    // No bone is called `upper`: it follows its `from` bone, and its
    // centre is 0.15 m along the shoulder's +Y.
    let binding = upper.bone.unwrap();
    assert_eq!(binding.bone, 0);
    assert!(
        binding
            .offset
            .translation
            .distance(Vec3::new(0.0, 0.15, 0.0))
            < 1e-6
    );
    // `lower` names its bone; its centre is 0.15 m below the elbow.
    let lower = desc.bodies[1].bone.unwrap();
    assert_eq!(lower.bone, 1);
    assert!(lower.offset.translation.distance(Vec3::new(0.0, 0.15, 0.0)) < 1e-6);
}

#[test]
fn an_explicit_offset_is_kept_as_written() {
    let text = ARM.replace(
        "bone = \"elbow\"",
        "bone = \"elbow\"\noffset = { translation = [0.0, 0.1, 0.0], rotation = [0.0, 1.0, 0.0, 0.0] }",
    );
    let desc = RagdollDesc::from_toml(&text).unwrap();
    assert_eq!(
        desc.bodies[1].bone,
        Some(BoneBinding {
            bone: 1,
            offset: Transform::new(
                Vec3::new(0.0, 0.1, 0.0),
                Quat::from_xyzw(0.0, 1.0, 0.0, 0.0)
            ),
        })
    );
}

#[test]
fn a_skeleton_file_is_found_next_to_the_ragdoll_file() {
    let dir = std::env::temp_dir().join(format!("vertebra-attach-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("skeleton.toml"), REFERENCE_SKELETON).unwrap();
    let text = REFERENCE_HUMANOID.replacen(
        "total_mass = 69.0",
        "total_mass = 69.0\nskeleton = \"skeleton.toml\"",
        1,
    );
    let ragdoll = dir.join("humanoid.toml");
    std::fs::write(&ragdoll, &text).unwrap();
    let desc = RagdollDesc::from_file(&ragdoll).unwrap();
    let expected =
        RagdollDesc::from_toml_with_skeleton(REFERENCE_HUMANOID, &Skeleton::reference()).unwrap();
    assert_eq!(desc, expected);
    // Without a path there is nowhere to look.
    let e = RagdollDesc::from_toml(&text).unwrap_err().to_string();
    assert!(
        e.contains("ragdoll: skeleton names a file, which only RagdollDesc::from_file finds"),
        "{e}"
    );
    // A broken skeleton file is named with its own line.
    std::fs::write(
        dir.join("skeleton.toml"),
        "[[bone]]\nname = \"root\"\ntranslation = [0.0, nan, 0.0]\n",
    )
    .unwrap();
    let e = RagdollDesc::from_file(&ragdoll).unwrap_err().to_string();
    assert!(
        e.ends_with(&format!(
            "{}: line 1: bone `root`: translation is not finite",
            dir.join("skeleton.toml").display()
        )),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

fn refused(text: &str) -> String {
    RagdollDesc::from_toml(text).unwrap_err().to_string()
}

#[test]
fn inconsistent_bindings_are_refused_by_line_body_and_field() {
    let edited = |from: &str, to: &str| {
        assert!(ARM.contains(from), "`{from}`");
        ARM.replacen(from, to, 1)
    };
    let cases = [
        (
            edited(
                "to = \"elbow\"",
                "to = \"elbow\"\nsegment = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]",
            ),
            "line 3: body `upper`: segment and from/to both place the body",
        ),
        (
            edited("to = \"elbow\"\n", ""),
            "line 3: body `upper`: to is missing",
        ),
        (
            edited("from = \"shoulder\"\nto = \"elbow\"\n", ""),
            "line 3: body `upper`: segment is missing: give segment, or from and to (bones)",
        ),
        (
            edited("from = \"shoulder\"", "from = \"clavicle\""),
            "line 3: body `upper`: from `clavicle` is not a bone of the skeleton",
        ),
        (
            edited("to = \"elbow\"", "to = \"shoulder\""),
            "line 3: body `upper`: to is the from bone",
        ),
        (
            edited("bone = \"elbow\"", "bone = \"wrist\""),
            "line 10: body `lower`: bone `wrist` is not a bone of the skeleton",
        ),
        (
            edited("bone = \"elbow\"", "bone = \"shoulder\""),
            "line 10: body `lower`: bone `shoulder` is body `upper`'s bone too; a bone has at most one body",
        ),
        (
            edited(
                "bone = \"elbow\"",
                "bone = \"elbow\"\noffset = { translation = [0.0, inf, 0.0] }",
            ),
            "line 10: body `lower`: offset: translation is not finite",
        ),
        (
            edited(
                "bone = \"elbow\"",
                "bone = \"elbow\"\noffset = { rotation = [0.0, 0.0, 0.0, 0.5] }",
            ),
            "line 10: body `lower`: offset: rotation has length 0.5",
        ),
        (
            edited(
                "bone = \"elbow\"",
                "bone = \"elbow\"\noffset = { scale = 2.0 }",
            ),
            "unknown field `scale`",
        ),
        (
            edited(
                "name = \"arm\"",
                "name = \"arm\"\nskeleton = \"skeleton.toml\"",
            ),
            "line 2: ragdoll: skeleton names a file, and the file has [[bone]] tables too",
        ),
    ];
    for (text, expected) in &cases {
        let e = refused(text);
        assert!(e.contains(expected), "expected `{expected}` in `{e}`");
    }
    // Without a skeleton, a bone or from/to has nothing to name.
    let bare = ARM[..ARM.find("[[bone]]").unwrap()].to_owned();
    assert!(refused(&bare).contains(
        "line 3: body `upper`: from names bone `shoulder`, but the ragdoll has no skeleton"
    ));
    let e = RagdollDesc::from_toml_with_skeleton(ARM, &Skeleton::reference())
        .unwrap_err()
        .to_string();
    assert!(e.contains("ragdoll: skeleton is given twice"), "{e}");
    // An offset on a body without a bone.
    let e = RagdollDesc::from_toml(&REFERENCE_HUMANOID.replacen(
        "mass = 11.0",
        "mass = 11.0\noffset = { translation = [0.0, 0.0, 0.0] }",
        1,
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("body `hips`: offset places the body on its bone, but it has none"),
        "{e}"
    );
}

/// A file's `total_mass` scales the bodies to it: masses 11 .. 4 kg
/// summing to 69 become 138 kg in all, each doubled.
#[test]
fn a_total_mass_scales_the_bodies_and_adding_one_keeps_the_total() {
    let plain = RagdollDesc::reference_humanoid();
    let doubled = RagdollDesc::from_toml(&REFERENCE_HUMANOID.replacen(
        "total_mass = 69.0",
        "total_mass = 138.0",
        1,
    ))
    .unwrap();
    for (a, b) in doubled.bodies.iter().zip(&plain.bodies) {
        assert_eq!(a.mass, 2.0 * b.mass, "{}", a.name);
    }
    assert_eq!(doubled.total_mass(), 138.0);
    // A new 3 kg body hanging from the right forearm: the total stays 69 kg,
    // every body is scaled by 69 / 72.
    let sword = "[[body]]\nname = \"sword\"\nsegment = [[-0.22, 0.9, 0.0], [-0.22, 0.5, 0.0]]\nradius = 0.02\nmass = 3.0\n\n[[joint]]\nname = \"grip\"\nparent = \"forearm_r\"\nchild = \"sword\"\nanchor = [-0.22, 0.95, 0.0]\nkind = \"fixed\"\n\n";
    let armed = RagdollDesc::from_toml(&REFERENCE_HUMANOID.replacen(
        "[[joint]]",
        &format!("{sword}[[joint]]"),
        1,
    ))
    .unwrap();
    assert!(
        (armed.total_mass() - 69.0).abs() < 1e-4,
        "{}",
        armed.total_mass()
    );
    let hips = armed.bodies[armed.body_index("hips").unwrap()].mass;
    let sword = armed.bodies[armed.body_index("sword").unwrap()].mass;
    assert!((hips - 11.0 * 69.0 / 72.0).abs() < 1e-5, "{hips}");
    assert!((sword - 3.0 * 69.0 / 72.0).abs() < 1e-5, "{sword}");
    for (total, expected) in [
        ("0.0", "ragdoll: total_mass must be positive"),
        ("nan", "ragdoll: total_mass is not finite"),
        (
            "1e-9",
            "body `hips` (its mass scaled to total_mass): mass (1e-6 to 1e12 kg) is out of range",
        ),
    ] {
        let e = refused(&REFERENCE_HUMANOID.replacen(
            "total_mass = 69.0",
            &format!("total_mass = {total}"),
            1,
        ));
        assert!(e.contains(expected), "expected `{expected}` in `{e}`");
    }
    // The scaled mass is refused at the body's line.
    let hips = REFERENCE_HUMANOID[..REFERENCE_HUMANOID
        .find("[[body]]\nname = \"hips\"")
        .unwrap()]
        .lines()
        .count()
        + 1;
    let e = refused(&REFERENCE_HUMANOID.replacen("total_mass = 69.0", "total_mass = 1e-9", 1));
    assert!(e.starts_with(&format!("line {hips}: body `hips`")), "{e}");
}

/// The anatomical humanoid, built in code, as its file describes it.
fn built() -> RagdollDesc {
    let file = RagdollDesc::anatomical_humanoid();
    let mut builder = RagdollDesc::builder(&file.name)
        .drive(DriveSettings {
            joints: Vec::new(),
            ..file.drive.clone().unwrap()
        })
        .skeleton(Skeleton::reference());
    for p in &file.profiles {
        builder = builder.profile(p.clone());
    }
    for b in &file.bodies {
        builder = builder.body(BodySpec::capsule(&b.name, b.segment, b.radius, b.mass));
    }
    for j in &file.joints {
        let mut spec = JointSpec {
            name: j.name.clone(),
            parent: file.bodies[j.parent].name.clone(),
            child: file.bodies[j.child].name.clone(),
            anchor: j.anchor,
            frame: JointFrame::Rotation(j.frame),
            kind: j.kind,
            drive: None,
            breaking: j.breaking,
        };
        if let Some(s) = j.drive {
            spec = spec.with_drive(s);
        }
        builder = builder.joint(spec);
    }
    let spine = file.spine.as_ref().unwrap();
    builder
        .spine(SpineSpec {
            bodies: spine
                .bodies
                .iter()
                .map(|&b| file.bodies[b].name.clone())
                .collect(),
            bend_limit: spine.bend_limit,
            twist_limit: spine.twist_limit,
            bend_stiffness: spine.bend_stiffness,
            twist_stiffness: spine.twist_stiffness,
        })
        .total_mass(69.0)
        .build()
        .unwrap()
}

#[test]
fn a_builder_makes_what_the_file_makes() {
    let file =
        RagdollDesc::from_toml_with_skeleton(ANATOMICAL_HUMANOID, &Skeleton::reference()).unwrap();
    assert_eq!(built(), file);
}

/// A small ragdoll with one of every kind of joint, softness and drive,
/// frames by axis, by axis and normal, and by quaternion, a body from
/// bones with an offset, and a spine.
fn assorted() -> RagdollDesc {
    let y = |x: f32| Vec3::new(0.0, x, 0.0);
    let cone = SwingTwist {
        swing: Swing::Cone(0.7),
        twist: Some([-0.3, 0.2]),
        softness: LimitSoftness::compliant(1e-3),
    };
    let ellipse = SwingTwist {
        swing: Swing::Ellipse { y: 1.1, z: 0.4 },
        twist: None,
        softness: LimitSoftness::Soft(Spring::Compliance {
            compliance: 2e-3,
            damping: 5.0,
        }),
    };
    let pyramid = SwingTwist {
        swing: Swing::Pyramid {
            y: [-0.5, 1.2],
            z: [-0.1, 0.9],
        },
        twist: Some([-1.0, 1.0]),
        softness: LimitSoftness::Soft(Spring::Frequency {
            frequency: 8.0,
            damping_ratio: 0.7,
        }),
    };
    let skeleton = Skeleton::from_toml(
        "[[bone]]\nname = \"base\"\ntranslation = [0.0, 1.0, 0.0]\n\n\
         [[bone]]\nname = \"tip\"\nparent = \"base\"\ntranslation = [0.0, 0.3, 0.0]\nrotation = [0.0, 0.0, 0.38268343, 0.9238795]\n",
    )
    .unwrap();
    RagdollDesc::builder("assorted \"bits\"")
        .skeleton(skeleton)
        .body(BodySpec::capsule("a", [y(0.0), y(0.2)], 0.05, 1.0))
        .body(BodySpec::capsule("b", [y(0.3), y(0.5)], 0.05, 0.7))
        .body(BodySpec::capsule("c", [y(0.6), y(0.8)], 0.05, 0.3))
        .body(
            BodySpec::from_bones("d", "base", "tip", 0.04, 2.0)
                .with_offset(Transform::new(Vec3::new(0.0, 0.15, 0.01), Quat::IDENTITY)),
        )
        .body(BodySpec::capsule(
            "e",
            [Vec3::new(0.3, 1.0, 0.0), Vec3::new(0.5, 1.0, 0.0)],
            0.03,
            0.4,
        ))
        .body(BodySpec::capsule(
            "f",
            [Vec3::new(0.6, 1.0, 0.0), Vec3::new(0.7, 1.0, 0.0)],
            0.03,
            0.1,
        ))
        .joint(
            JointSpec::socket("ab", "a", "b", y(0.25), Vec3::new(0.1, 1.0, 0.0), cone)
                .with_drive(Spring::RIGID),
        )
        .joint(
            JointSpec::socket("bc", "b", "c", y(0.55), Vec3::Y, ellipse)
                .with_normal(Vec3::new(1.0, 0.0, 1.0)),
        )
        .joint(
            JointSpec::socket("cd", "c", "d", y(0.9), Vec3::Y, pyramid)
                .with_normal(Vec3::Z)
                .with_drive(Spring::compliant(0.01)),
        )
        .joint(JointSpec {
            frame: JointFrame::Rotation(
                Quat::from_rotation_z(FRAC_PI_2) * Quat::from_rotation_x(0.3),
            ),
            ..JointSpec::hinge(
                "de",
                "d",
                "e",
                Vec3::new(0.3, 1.0, 0.0),
                Vec3::X,
                Some([-0.2, 2.0]),
            )
            .with_drive(Spring::Frequency {
                frequency: 3.0,
                damping_ratio: 1.0,
            })
        })
        .joint(JointSpec::fixed("ef", "e", "f", Vec3::new(0.55, 1.0, 0.0)))
        .spine(SpineSpec {
            bodies: vec!["a".into(), "b".into(), "c".into()],
            bend_limit: 1.0,
            twist_limit: [-0.5, 0.5],
            bend_stiffness: 2.0,
            twist_stiffness: 0.0,
        })
        .drive(
            DriveSettings::uniform(Spring::Compliance {
                compliance: 0.02,
                damping: 3.0,
            })
            .with_max_torque(50.0),
        )
        .build()
        .unwrap()
}

#[test]
fn every_description_reads_back_from_its_toml_as_itself() {
    let skeleton = Skeleton::reference();
    let descs = [
        RagdollDesc::reference_humanoid(),
        RagdollDesc::anatomical_humanoid(),
        RagdollDesc::from_toml_with_skeleton(REFERENCE_HUMANOID, &skeleton).unwrap(),
        built(),
        assorted(),
    ];
    for desc in descs {
        let text = desc.to_toml();
        let back =
            RagdollDesc::from_toml(&text).unwrap_or_else(|e| panic!("{}: {e}\n{text}", desc.name));
        assert_eq!(back, desc, "{text}");
        // Bit for bit: written again, the same text.
        assert_eq!(back.to_toml(), text);
    }
}

#[test]
fn frames_are_written_as_axes_where_an_axis_rebuilds_them() {
    let text = RagdollDesc::anatomical_humanoid().to_toml();
    // Every shipped joint's frame came from a short axis and normal.
    assert!(!text.contains("frame ="), "{text}");
    assert!(
        text.contains("axis = [0.0, -1.0, 0.0]\nnormal = [1.0, 0.0, 0.0]"),
        "{text}"
    );
    // Angles as the file wrote them: 30 and 60 degrees, not the nearest
    // conversions back (30.000002, 60.000004).
    assert!(
        text.contains("swing = { y = 40.0, z = 30.0 }\ntwist = [-60.0, 60.0]"),
        "{text}"
    );
    // The assorted hinge's frame is no shortest turn from +X: written whole.
    let text = assorted().to_toml();
    assert!(text.contains("frame = ["), "{text}");
}

#[test]
fn a_builder_refuses_what_the_file_refuses_naming_the_item() {
    let y = |x: f32| Vec3::new(0.0, x, 0.0);
    let two = || {
        RagdollDesc::builder("two")
            .body(BodySpec::capsule("a", [y(0.0), y(0.2)], 0.05, 1.0))
            .body(BodySpec::capsule("b", [y(0.3), y(0.5)], 0.05, 1.0))
    };
    let socket = |swing| {
        JointSpec::socket(
            "ab",
            "a",
            "b",
            y(0.25),
            Vec3::Y,
            SwingTwist {
                swing,
                ..SwingTwist::FREE
            },
        )
    };
    let cases = [
        (
            two()
                .body(BodySpec::capsule("a", [y(0.0), y(0.2)], 0.05, 1.0))
                .build(),
            "body name `a` is used twice",
        ),
        (
            two().joint(socket(Swing::Cone(4.0))).build(),
            "joint `ab`: swing must be in [0, 180] degrees",
        ),
        (
            two()
                .joint(socket(Swing::Ellipse { y: 0.5, z: 0.5 }))
                .build(),
            "joint `ab`: normal is missing",
        ),
        (
            two()
                .joint(
                    JointSpec::hinge("ab", "a", "b", y(0.25), Vec3::X, None).with_normal(Vec3::Y),
                )
                .build(),
            "joint `ab`: normal is for sockets only; this joint is a hinge",
        ),
        (
            two()
                .joint(socket(Swing::Free))
                .body(BodySpec::from_bones("c", "x", "y", 0.1, 1.0))
                .build(),
            "body `c`: from names bone `x`, but the ragdoll has no skeleton",
        ),
        (
            two()
                .joint(socket(Swing::Free))
                .drive(DriveSettings {
                    joints: vec![None],
                    ..DriveSettings::uniform(Spring::RIGID)
                })
                .build(),
            "[drive]: joints must be empty",
        ),
        (two().build(), "2 bodies have no parent"),
        (
            two().joint(socket(Swing::Free)).total_mass(-1.0).build(),
            "ragdoll: total_mass must be positive",
        ),
    ];
    for (result, expected) in cases {
        let e = result.unwrap_err().to_string();
        assert!(e.contains(expected), "expected `{expected}` in `{e}`");
        assert!(!e.starts_with("line"), "{e}");
    }
}

/// A change made by hand.
type Edit = fn(&mut RagdollDesc);

#[test]
fn validate_refuses_a_hand_edited_description_naming_the_item() {
    let good =
        RagdollDesc::from_toml_with_skeleton(REFERENCE_HUMANOID, &Skeleton::reference()).unwrap();
    assert_eq!(good.validate(), Ok(()));
    assert_eq!(assorted().validate(), Ok(()));
    let edits: [(Edit, &str); 12] = [
        (
            |d| d.bodies[0].mass = f32::NAN,
            "body `hips`: mass is not finite",
        ),
        (
            |d| d.bodies[1].name = "hips".into(),
            "body name `hips` is used twice",
        ),
        (
            |d| d.bodies[2].radius = 0.0,
            "body `spine_upper`: radius must be positive",
        ),
        (
            |d| d.joints[3].child = 40,
            "joint `neck`: child is body 40; there are 13",
        ),
        (
            |d| d.joints[3].frame = Quat::from_xyzw(0.0, 0.0, 0.0, 3.0),
            "joint `neck`: frame is not normalised",
        ),
        (
            |d| {
                d.joints[3].kind = JointKind::Hinge {
                    range: Some([1.0, 0.0]),
                    softness: LimitSoftness::Hard,
                }
            },
            "joint `neck`: range must be [min, max]",
        ),
        (
            |d| d.root = 4,
            "root and parent_joint are not the joints' tree",
        ),
        (
            |d| d.spine.as_mut().unwrap().joints.swap(0, 1),
            "[spine]: its joint 1 does not join `hips` to `spine_lower`",
        ),
        (
            |d| d.spine.as_mut().unwrap().bend_limit = 4.0,
            "[spine]: bend_limit must be in [0, 180] degrees",
        ),
        (
            |d| d.bodies[0].bone.as_mut().unwrap().bone = 1000,
            "body `hips`: bone is bone 1000; the ragdoll's skeleton has 63",
        ),
        (
            |d| d.bodies[0].bone = d.bodies[1].bone,
            "body `spine_lower`: bone `spine_lower` is body `hips`'s bone too",
        ),
        (
            |d| d.joints[0].drive = Some(Spring::RIGID),
            "joint `spine_1`: drive needs a [drive] table",
        ),
    ];
    for (edit, expected) in edits {
        let mut d = good.clone();
        edit(&mut d);
        let e = d.validate().unwrap_err().to_string();
        assert!(e.contains(expected), "expected `{expected}` in `{e}`");
    }
    let mut d = good.clone();
    d.skeleton = None;
    assert!(
        d.validate().unwrap_err().to_string()
            == "body `hips`: bone is bone 1, but the ragdoll has no skeleton"
    );
    let mut d = RagdollDesc::anatomical_humanoid();
    d.drive.as_mut().unwrap().joints = vec![Some(Spring::RIGID); d.joints.len()];
    let e = d.validate().unwrap_err().to_string();
    assert!(
        e.contains("[drive]: joints must be each joint's own strength"),
        "{e}"
    );
    assert!(matches!(d.validate(), Err(RagdollError::OutOfRange { .. })));
}

/// A hand-edited description is refused by the build (which indexed the
/// spine's first body and would have panicked), the world untouched.
#[test]
fn a_build_refuses_a_description_that_does_not_validate() {
    let mut desc = RagdollDesc::reference_humanoid();
    desc.spine.as_mut().unwrap().bodies.clear();
    let mut world = World::new(SolverConfig::default()).unwrap();
    let pose = Pose::bind(&RagdollDesc::reference_humanoid());
    let e = Ragdoll::build(
        &mut world,
        &desc,
        BuildOptions::new(SpineMode::Rod),
        &pose,
        None,
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "[spine]: needs at least two bodies");
    assert_eq!(world.bodies().len(), 0);
}
