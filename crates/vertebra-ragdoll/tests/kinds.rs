//! Joint kinds in the description format: the anatomical humanoid's
//! hinges and elliptical cones, read as written and held by the world; and
//! every inconsistent combination refused by joint and field; drive
//! settings read from the file.

use core::f32::consts::PI;

use glam::{Quat, Vec3};
use vertebra_ragdoll::{ANATOMICAL_HUMANOID, BuildOptions, Pose, Ragdoll, RagdollDesc, SpineMode};
use vertebra_world::{
    BodyDesc, JointDesc, JointKind, LimitSoftness, SolverConfig, Spring, Swing, SwingTwist, World,
};

fn joint<'a>(desc: &'a RagdollDesc, name: &str) -> &'a vertebra_ragdoll::JointDef {
    desc.joints.iter().find(|j| j.name == name).unwrap()
}

#[test]
fn the_anatomical_humanoid_has_hinged_knees_and_elliptical_shoulders() {
    let desc = RagdollDesc::anatomical_humanoid();
    let deg = |x: f32| x.to_radians();
    for (name, axis, top) in [
        ("knee_l", Vec3::X, 150.0),
        ("knee_r", Vec3::X, 150.0),
        ("elbow_l", -Vec3::X, 145.0),
        ("elbow_r", -Vec3::X, 145.0),
    ] {
        let j = joint(&desc, name);
        assert_eq!(
            j.kind,
            JointKind::Hinge {
                range: Some([0.0, deg(top)]),
                softness: LimitSoftness::Hard
            },
            "{name}"
        );
        assert!((j.axis() - axis).length() < 1e-6, "{name}: {}", j.axis());
    }
    for (name, y, z) in [("shoulder_l", 90.0, 70.0), ("hip_r", 80.0, 35.0)] {
        let j = joint(&desc, name);
        let JointKind::Socket(limits) = j.kind else {
            panic!("{name} is a socket")
        };
        assert_eq!(
            limits.swing,
            Swing::Ellipse {
                y: deg(y),
                z: deg(z)
            }
        );
        // The frame: twist axis down the limb, Y the body's left.
        assert!((j.frame * Vec3::X - Vec3::NEG_Y).length() < 1e-6);
        assert!((j.frame * Vec3::Y - Vec3::X).length() < 1e-6);
        assert!((j.frame * Vec3::Z - Vec3::Z).length() < 1e-6);
    }
}

#[test]
fn joints_without_a_normal_keep_the_frame_they_always_had() {
    // The reference humanoid's frames are the shortest turn from +X to the
    // axis, bit for bit (its scenes' golden hashes depend on it).
    let desc = RagdollDesc::reference_humanoid();
    for j in &desc.joints {
        let axis = j.axis();
        assert_eq!(
            j.frame,
            Quat::from_rotation_arc(Vec3::X, axis),
            "{}",
            j.name
        );
    }
}

/// The anatomical file with `from` replaced by `to` (which must occur).
fn edited(from: &str, to: &str) -> String {
    assert!(ANATOMICAL_HUMANOID.contains(from), "the file has `{from}`");
    ANATOMICAL_HUMANOID.replacen(from, to, 1)
}

#[test]
fn inconsistent_joints_are_refused_by_joint_and_field() {
    let knee = "kind = \"hinge\"\naxis = [1.0, 0.0, 0.0]\nrange = [0.0, 150.0]";
    let shoulder = "normal = [1.0, 0.0, 0.0]\nswing = { y = 90.0, z = 70.0 }";
    let cases = [
        (
            edited(
                knee,
                "axis = [0.0, -1.0, 0.0]\nswing = 70.0\nrange = [0.0, 150.0]",
            ),
            "joint `knee_l`: range is for hinges only; this joint is a socket",
        ),
        (
            edited(knee, &format!("{knee}\nswing = 40.0")),
            "joint `knee_l`: swing is for sockets only; this joint is a hinge",
        ),
        (
            edited(knee, &format!("{knee}\nnormal = [0.0, 1.0, 0.0]")),
            "joint `knee_l`: normal is for sockets only; this joint is a hinge",
        ),
        (
            edited(knee, "kind = \"fixed\"\naxis = [1.0, 0.0, 0.0]"),
            "joint `knee_l`: axis is for sockets and hinges only; this joint is a fixed",
        ),
        (
            edited(knee, "kind = \"hinged\"\naxis = [1.0, 0.0, 0.0]"),
            "joint `knee_l`: kind is `hinged`; must be socket, hinge or fixed",
        ),
        (
            edited(knee, "kind = \"hinge\""),
            "joint `knee_l`: axis is missing",
        ),
        (
            edited(
                knee,
                "kind = \"hinge\"\naxis = [1.0, 0.0, 0.0]\nrange = [10.0, -10.0]",
            ),
            "joint `knee_l`: range must be [min, max] within [-180, 180] degrees",
        ),
        (
            edited(shoulder, "swing = { y = 90.0, z = 70.0 }"),
            "joint `shoulder_l`: normal is missing: an elliptical or pyramid swing needs it",
        ),
        (
            edited(
                shoulder,
                "normal = [1.0, 0.1, 0.0]\nswing = { y = 90.0, z = 70.0 }",
            ),
            "joint `shoulder_l`: normal must be a direction perpendicular to the axis",
        ),
        (
            edited(
                shoulder,
                "normal = [1.0, 0.0, 0.0]\nswing = { y = 190.0, z = 70.0 }",
            ),
            "joint `shoulder_l`: swing.y must be in [0, 180] degrees",
        ),
        (
            edited(
                shoulder,
                "normal = [1.0, 0.0, 0.0]\nswing = { y = [30.0, 20.0], z = [-10.0, 80.0] }",
            ),
            "joint `shoulder_l`: swing.y must be [min, max]",
        ),
        (
            edited(shoulder, &format!("{shoulder}\nsoftness = -1.0")),
            "joint `shoulder_l`: softness is refused: limit compliance must be positive",
        ),
        (
            edited(shoulder, &format!("{shoulder}\nsoftness = nan")),
            "joint `shoulder_l`: softness is not finite",
        ),
    ];
    for (text, expected) in cases {
        let e = RagdollDesc::from_toml(&text).unwrap_err().to_string();
        assert!(e.contains(expected), "expected `{expected}` in `{e}`");
        assert!(e.starts_with("line "), "names the line: {e}");
    }
}

#[test]
fn pyramids_and_soft_limits_are_read_in_radians() {
    let text = edited(
        "normal = [1.0, 0.0, 0.0]\nswing = { y = 90.0, z = 70.0 }",
        "normal = [1.0, 0.0, 0.0]\nswing = { y = [-30.0, 90.0], z = [-10.0, 80.0] }\nsoftness = 0.001",
    );
    let desc = RagdollDesc::from_toml(&text).unwrap();
    let JointKind::Socket(SwingTwist {
        swing, softness, ..
    }) = joint(&desc, "shoulder_l").kind
    else {
        panic!("a socket")
    };
    let r = |x: f32| x.to_radians();
    assert_eq!(
        swing,
        Swing::Pyramid {
            y: [r(-30.0), r(90.0)],
            z: [r(-10.0), r(80.0)]
        }
    );
    assert_eq!(softness, LimitSoftness::compliant(0.001));
}

/// The anatomical humanoid hanging by its hips, a kick (4 m/s) on each shin
/// forwards (the way a knee does not bend) and on each forearm backwards
/// (nor an elbow): no knee or elbow goes past straight by more than 2
/// degrees, with either spine.
#[test]
fn knees_and_elbows_never_bend_backwards() {
    let desc = RagdollDesc::anatomical_humanoid();
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut world = World::new(SolverConfig::default()).unwrap();
        let pose = Pose::bind(&desc);
        let ragdoll =
            Ragdoll::build(&mut world, &desc, BuildOptions::new(spine), &pose, None).unwrap();
        let hips = ragdoll.bodies[desc.root].unwrap();
        let at = world.body(hips).unwrap().position;
        let anchor = world.add_body(BodyDesc::fixed().with_position(at)).unwrap();
        let pin = JointDesc::fixed_at(world.bodies(), anchor, hips, at).unwrap();
        world.add_joint(pin).unwrap();
        let kicks = [
            ("shin_l", Vec3::Z),
            ("shin_r", Vec3::Z),
            ("forearm_l", -Vec3::Z),
            ("forearm_r", -Vec3::Z),
        ];
        for (body, direction) in kicks {
            let b = ragdoll.bodies[desc.body_index(body).unwrap()].unwrap();
            world
                .set_body_velocity(b, direction * 4.0, Vec3::ZERO)
                .unwrap();
        }
        let mut worst = 0.0f32;
        for _ in 0..120 {
            world.step(1.0 / 60.0).unwrap();
            for name in ["knee_l", "knee_r", "elbow_l", "elbow_r"] {
                let j = joint(&desc, name);
                let qa = world
                    .body(ragdoll.bodies[j.parent].unwrap())
                    .unwrap()
                    .orientation;
                let qb = world
                    .body(ragdoll.bodies[j.child].unwrap())
                    .unwrap()
                    .orientation;
                // The hinge angle: b's frame from a's, about the frame's +X.
                let relative = (qa * j.frame).inverse() * (qb * j.frame);
                let angle = 2.0 * relative.x.atan2(relative.w);
                let angle = if angle > PI { angle - 2.0 * PI } else { angle };
                worst = worst.min(angle);
            }
        }
        assert!(
            worst > -2f32.to_radians(),
            "{spine:?}: a hinge went {} degrees past straight",
            -worst.to_degrees()
        );
    }
}

#[test]
fn drive_settings_are_read_from_the_file() {
    let desc = RagdollDesc::anatomical_humanoid();
    let drive = desc
        .drive
        .as_ref()
        .expect("the anatomical humanoid has a [drive] table");
    assert_eq!(
        drive.strength,
        Spring::Frequency {
            frequency: 4.0,
            damping_ratio: 1.0
        }
    );
    assert_eq!(drive.max_torque, 400.0);
    let knee = desc.joints.iter().position(|j| j.name == "knee_l").unwrap();
    let hip = desc.joints.iter().position(|j| j.name == "hip_l").unwrap();
    let six = Spring::Frequency {
        frequency: 6.0,
        damping_ratio: 1.0,
    };
    assert_eq!((drive.joints[knee], drive.joints[hip]), (Some(six), None));
    // The reference humanoid's file says nothing of drives.
    assert_eq!(RagdollDesc::reference_humanoid().drive, None);
}

#[test]
fn drive_settings_that_make_no_drive_are_refused_by_field() {
    let table = "[drive]\nfrequency = 4.0\ndamping_ratio = 1.0\nmax_torque = 400.0";
    let knee = "range = [0.0, 150.0]\ndrive = { frequency = 6.0, damping_ratio = 1.0 }";
    let cases = [
        (
            edited(table, "[drive]\nfrequency = 4.0\ncompliance = 0.1"),
            "[drive]: drive takes one of: strength = \"infinite\", frequency with damping_ratio, or compliance",
        ),
        (
            edited(
                table,
                "[drive]\nfrequency = 4.0\ndamping_ratio = 1.0\ndamping = 2.0",
            ),
            "[drive]: damping is for a compliance strength only",
        ),
        (
            edited(table, "[drive]\nstrength = \"infinite\"\nmax_torque = -1.0"),
            "[drive]: max_torque must be a number, not negative",
        ),
        (
            edited(table, "[drive]\nfrequency = 0.0\ndamping_ratio = 1.0"),
            "[drive]: strength is refused: drive frequency (at least 1e-3 Hz) is out of range",
        ),
        (
            edited(table, "[drive]\nfrequency = inf\ndamping_ratio = nan"),
            "[drive]: drive is not finite",
        ),
        (
            edited(knee, "range = [0.0, 150.0]\ndrive = { frequency = 6.0 }"),
            "joint `knee_l`: drive takes one of",
        ),
        (
            edited(table, "").replace("[drive]", ""),
            "joint `knee_l`: drive needs a [drive] table",
        ),
        (
            edited(
                knee,
                "range = [0.0, 150.0]\ndrive = { frequency = 6.0, damping_ratio = 2e3 }",
            ),
            "joint `knee_l`: drive is refused: drive damping ratio (at most 1e3) is out of range",
        ),
        (
            edited(
                knee,
                "range = [0.0, 150.0]\ndrive = { compliance = 0.001, damping = -1.0 }",
            ),
            "joint `knee_l`: drive is refused: drive damping must be positive",
        ),
        (
            edited(
                knee,
                "range = [0.0, 150.0]\ndrive = { frequency = 6.0, damping_ratio = 1.0, damping = 2.0 }",
            ),
            "joint `knee_l`: damping is for a compliance strength only",
        ),
        (
            edited(table, "[drive]\ncompliance = 1e4\ndamping = 1e3"),
            "[drive]: strength is refused: drive damping (compliance times damping at most 1e6 s) is out of range",
        ),
    ];
    for (text, expected) in cases {
        let e = RagdollDesc::from_toml(&text).unwrap_err().to_string();
        assert!(e.contains(expected), "expected `{expected}` in `{e}`");
    }
    // A fixed joint has nothing to drive.
    let fixed = edited(
        "kind = \"hinge\"\naxis = [1.0, 0.0, 0.0]\nrange = [0.0, 150.0]\ndrive = { frequency = 6.0, damping_ratio = 1.0 }",
        "kind = \"fixed\"\ndrive = { frequency = 6.0, damping_ratio = 1.0 }",
    );
    let e = RagdollDesc::from_toml(&fixed).unwrap_err().to_string();
    assert!(
        e.contains("joint `knee_l`: drive is for sockets and hinges only; this joint is a fixed"),
        "{e}"
    );
}

/// A joint's own compliance takes the `[drive]` table's damping unless it
/// gives its own (as every compliance took the one damping before a
/// strength carried its own); either reads back from the written file.
#[test]
fn a_joints_compliance_takes_the_tables_damping_unless_it_gives_one() {
    let table = "[drive]\nfrequency = 4.0\ndamping_ratio = 1.0\nmax_torque = 400.0";
    let knee = "range = [0.0, 150.0]\ndrive = { frequency = 6.0, damping_ratio = 1.0 }";
    let compliant = edited(table, "[drive]\ncompliance = 0.01\ndamping = 4.0");
    let knee_drive = |desc: &RagdollDesc| {
        let k = desc.joints.iter().position(|j| j.name == "knee_l").unwrap();
        desc.joints[k].drive
    };
    let cases = [
        ("drive = { compliance = 0.002 }", 4.0),
        ("drive = { compliance = 0.002, damping = 1.5 }", 1.5),
        ("drive = { compliance = 0.002, damping = 0.0 }", 0.0),
    ];
    for (own, damping) in cases {
        let text = compliant.replacen(knee, &format!("range = [0.0, 150.0]\n{own}"), 1);
        let desc = RagdollDesc::from_toml(&text).unwrap();
        let expected = Spring::Compliance {
            compliance: 0.002,
            damping,
        };
        assert_eq!(knee_drive(&desc), Some(expected), "{own}");
        let drive = desc.drive.as_ref().unwrap();
        let table = Spring::Compliance {
            compliance: 0.01,
            damping: 4.0,
        };
        assert_eq!(drive.strength, table);
        let again = RagdollDesc::from_toml(&desc.to_toml()).unwrap();
        assert_eq!(again, desc, "{own} reads back");
    }
    // `strength = "infinite"` is the rigid spring, whatever the table's
    // damping.
    let text = compliant.replacen(
        knee,
        "range = [0.0, 150.0]\ndrive = { strength = \"infinite\" }",
        1,
    );
    let desc = RagdollDesc::from_toml(&text).unwrap();
    assert_eq!(knee_drive(&desc), Some(Spring::RIGID));
}

/// The file's drive settings drive the ragdoll: hanging by its hips under
/// gravity, held to its bind pose, the anatomical humanoid stays within a
/// few centimetres of it (limp, its arms and legs would hang and swing).
#[test]
fn the_files_drive_holds_the_pose() {
    let desc = RagdollDesc::anatomical_humanoid();
    let drive = desc.drive.clone().unwrap();
    let mut world = World::new(SolverConfig::default()).unwrap();
    let pose = Pose::bind(&desc);
    let ragdoll = Ragdoll::build(
        &mut world,
        &desc,
        BuildOptions::new(SpineMode::Rod),
        &pose,
        None,
    )
    .unwrap();
    let hips = ragdoll.bodies[desc.root].unwrap();
    let at = world.body(hips).unwrap().position;
    let anchor = world.add_body(BodyDesc::fixed().with_position(at)).unwrap();
    let pin = JointDesc::fixed_at(world.bodies(), anchor, hips, at).unwrap();
    world.add_joint(pin).unwrap();
    ragdoll.drive_to(&mut world, &pose, &drive).unwrap();
    let head = ragdoll.bodies[desc.body_index("head").unwrap()].unwrap();
    let start = world.body(head).unwrap().position;
    for _ in 0..120 {
        world.step(1.0 / 60.0).unwrap();
    }
    let sag = (world.body(head).unwrap().position - start).length();
    assert!(sag < 0.05, "the head sagged {sag} m");
}
