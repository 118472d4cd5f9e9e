//! Loading descriptions: the reference humanoid, and every kind of
//! malformed file with its own error.

use vertebra_ragdoll::{
    BuildOptions, Pose, REFERENCE_HUMANOID, Ragdoll, RagdollDesc, RagdollError, SpineMode,
};
use vertebra_world::{SolverConfig, World};

#[test]
fn the_reference_humanoid_builds_both_ways_with_the_same_mass() {
    let desc = RagdollDesc::reference_humanoid();
    assert_eq!((desc.bodies.len(), desc.joints.len()), (13, 12));
    assert_eq!(desc.bodies[desc.root].name, "hips");
    for (spine, bodies, sockets, rods) in
        [(SpineMode::Sockets, 13, 12, 0), (SpineMode::Rod, 11, 9, 1)]
    {
        let mut w = World::new(SolverConfig::default()).unwrap();
        let r = Ragdoll::build(
            &mut w,
            &desc,
            BuildOptions::new(spine),
            &Pose::bind(&desc),
            None,
        )
        .unwrap();
        assert_eq!(w.bodies().len(), bodies, "{spine:?}");
        assert_eq!(r.joints.iter().flatten().count(), sockets, "{spine:?}");
        assert_eq!(r.rod.is_some() as usize, rods, "{spine:?}");
        let mass: f32 = r
            .bodies
            .iter()
            .flatten()
            .map(|b| w.bodies().mass[b.index()])
            .sum();
        assert!((mass - 69.0).abs() < 1e-4, "{spine:?}: {mass} kg");
        // The rod's rest length is the straight spine's, hips to chest.
        if let Some(rod) = r.rod {
            assert!((w.rod(rod).unwrap().rest_length - 0.45).abs() < 1e-5);
        }
    }
}

/// The reference file with `from` replaced by `to` (which must occur).
fn edited(from: &str, to: &str) -> String {
    assert!(
        REFERENCE_HUMANOID.contains(from),
        "the reference file has `{from}`"
    );
    REFERENCE_HUMANOID.replacen(from, to, 1)
}

fn error(text: &str) -> RagdollError {
    RagdollDesc::from_toml(text).expect_err("a malformed file")
}

#[test]
fn malformed_files_each_get_their_own_error() {
    let cases: Vec<(String, &str)> = vec![
        ("this is not [toml".to_owned(), "malformed ragdoll file"),
        (
            edited("radius = 0.10\nmass = 11.0", "mass = 11.0"),
            "missing field `radius`",
        ),
        (
            edited("mass = 11.0", "mass = 11.0\ncolour = \"red\""),
            "unknown field `colour`",
        ),
        (
            edited("name = \"spine_lower\"", "name = \"hips\""),
            "body name `hips` is used twice",
        ),
        (
            edited("name = \"spine_2\"", "name = \"spine_1\""),
            "joint name `spine_1` is used twice",
        ),
        (
            edited("parent = \"thigh_l\"", "parent = \"thigh_x\""),
            "joint `knee_l`: parent `thigh_x` is not a body",
        ),
        (
            edited("child = \"shin_l\"", "child = \"shin_x\""),
            "joint `knee_l`: child `shin_x` is not a body",
        ),
        (
            edited(
                "parent = \"hips\"\nchild = \"spine_lower\"",
                "parent = \"chest\"\nchild = \"spine_lower\"",
            ),
            "a cycle runs through",
        ),
        (
            edited("child = \"shin_l\"", "child = \"shin_r\""),
            "body `shin_r` is the child of both",
        ),
        (
            edited(
                "parent = \"thigh_l\"\nchild = \"shin_l\"",
                "parent = \"shin_l\"\nchild = \"shin_l\"",
            ),
            "joins `shin_l` to itself",
        ),
        (
            edited("mass = 11.0", "mass = nan"),
            "body `hips`: mass is not finite",
        ),
        (
            edited("mass = 11.0", "mass = -11.0"),
            "body `hips`: mass must be positive",
        ),
        (
            edited("radius = 0.10\nmass = 11.0", "radius = 0.0\nmass = 11.0"),
            "body `hips`: radius must be positive",
        ),
        (
            edited(
                "anchor = [0.10, 0.525, 0.0]\naxis = [0.0, -1.0, 0.0]",
                "anchor = [0.10, 0.525, 0.0]\naxis = [0.0, 0.0, 0.0]",
            ),
            "joint `knee_l`: axis has zero length",
        ),
        (
            edited("anchor = [0.0, 1.08, 0.0]", "anchor = [0.0, inf, 0.0]"),
            "joint `spine_1`: anchor is not finite",
        ),
        (
            edited(
                "swing = 70.0\ntwist = [-5.0, 5.0]",
                "swing = 270.0\ntwist = [-5.0, 5.0]",
            ),
            "joint `knee_l`: swing must be in [0, 180]",
        ),
        (
            edited("twist = [-5.0, 5.0]", "twist = [5.0, -5.0]"),
            "joint `knee_l`: twist must be [min, max]",
        ),
        (
            edited("total_mass = 69.0", "total_mass = -69.0"),
            "ragdoll: total_mass must be positive",
        ),
        (
            edited(
                "bodies = [\"hips\", \"spine_lower\", \"spine_upper\", \"chest\"]",
                "bodies = [\"hips\", \"spine_lower\", \"spine_mid\", \"chest\"]",
            ),
            "[spine]: bodies `spine_mid` is not a body",
        ),
        (
            edited(
                "bodies = [\"hips\", \"spine_lower\", \"spine_upper\", \"chest\"]",
                "bodies = [\"hips\", \"spine_upper\", \"chest\"]",
            ),
            "no joint has parent `hips` and child `spine_upper`",
        ),
        (
            edited(
                "bodies = [\"hips\", \"spine_lower\", \"spine_upper\", \"chest\"]",
                "bodies = [\"hips\"]",
            ),
            "needs at least two bodies",
        ),
        (
            edited(
                "bodies = [\"hips\", \"spine_lower\", \"spine_upper\", \"chest\"]",
                "bodies = [\"spine_upper\", \"chest\", \"head\"]",
            ),
            "joint `shoulder_l` hangs from an interior spine body",
        ),
        (
            edited("bend_limit = 60.0", "bend_limit = -1.0"),
            "[spine]: bend_limit must be in [0, 180]",
        ),
        (
            edited("bend_stiffness = 2.0", "bend_stiffness = -2.0"),
            "[spine]: bend_stiffness must not be negative",
        ),
    ];
    let mut seen = std::collections::HashSet::new();
    for (text, expected) in &cases {
        let message = error(text).to_string();
        assert!(
            message.contains(expected),
            "expected `{expected}`, got `{message}`"
        );
        assert!(
            seen.insert(message.clone()),
            "two cases gave the same message: {message}"
        );
    }
}

#[test]
fn several_roots_are_refused() {
    // Drop the hip joint: the left leg becomes a second tree.
    let start = REFERENCE_HUMANOID.find("name = \"hip_l\"").unwrap();
    let joint_start = REFERENCE_HUMANOID[..start].rfind("[[joint]]").unwrap();
    let joint_end = start + REFERENCE_HUMANOID[start..].find("[[joint]]").unwrap();
    let text = format!(
        "{}{}",
        &REFERENCE_HUMANOID[..joint_start],
        &REFERENCE_HUMANOID[joint_end..]
    );
    let message = error(&text).to_string();
    assert!(
        message.contains("2 bodies have no parent (`hips`, `thigh_l`)"),
        "{message}"
    );
}

/// A pipe named as a ragdoll or skeleton file is refused without waiting
/// for a writer (opening one for reading blocks until a writer comes:
/// before, `from_file` and `vertebra check` hung for ever). Run on a
/// thread with a deadline, so that a hang fails the test.
#[cfg(unix)]
#[test]
fn a_pipe_is_refused_not_waited_on() {
    use std::sync::mpsc;
    use std::time::Duration;
    let dir = std::env::temp_dir().join(format!("vertebra-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("fifo.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("no mkfifo on this machine: the pipe case is not run");
        return;
    }
    let (send, receive) = mpsc::channel();
    let path = fifo.clone();
    std::thread::spawn(move || {
        let ragdoll = RagdollDesc::from_file(&path).map(|_| ()).unwrap_err();
        let skeleton = vertebra_ragdoll::Skeleton::from_file(&path)
            .map(|_| ())
            .unwrap_err();
        send.send((ragdoll.to_string(), skeleton.to_string()))
            .unwrap();
    });
    let (ragdoll, skeleton) = receive
        .recv_timeout(Duration::from_secs(20))
        .expect("refused at once, not blocked on the pipe");
    for message in [ragdoll, skeleton] {
        assert!(message.contains("not a regular file"), "{message}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
