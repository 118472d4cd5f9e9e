//! Values a ragdoll accepts give a finite ragdoll; values it cannot use are
//! refused with the item (line, body, joint, option) and field named.

use glam::{Quat, Vec3};
use vertebra_ragdoll::{
    BuildOptions, Pose, REFERENCE_HUMANOID, Ragdoll, RagdollDesc, RagdollError, SpineMode,
};
use vertebra_world::{SolverConfig, World};

/// The reference file with `from` replaced by `to` (which must occur).
fn edited(from: &str, to: &str) -> String {
    assert!(REFERENCE_HUMANOID.contains(from), "the file has `{from}`");
    REFERENCE_HUMANOID.replacen(from, to, 1)
}

/// The line (from 1) of the first `needle` in the reference file.
fn line_of(needle: &str) -> usize {
    let at = REFERENCE_HUMANOID.find(needle).expect("in the file");
    REFERENCE_HUMANOID[..at].matches('\n').count() + 1
}

fn build(
    desc: &RagdollDesc,
    options: BuildOptions,
    pose: &Pose,
) -> (World, Result<Ragdoll, RagdollError>) {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let built = Ragdoll::build(&mut world, desc, options, pose, None);
    (world, built)
}

#[test]
fn stabilisation_ratios_that_are_no_ratio_are_refused() {
    let desc = RagdollDesc::reference_humanoid();
    for ratio in [1e-8, 0.0, f32::NAN, -1.0, 0.5, f32::INFINITY] {
        for spine in [SpineMode::Rod, SpineMode::Sockets] {
            let options = BuildOptions {
                stabilise: Some(ratio),
                ..BuildOptions::new(spine)
            };
            let (world, built) = build(&desc, options, &Pose::bind(&desc));
            let message = built.expect_err("refused").to_string();
            assert!(
                message.starts_with("build options: stabilise is"),
                "{ratio}: {message}"
            );
            assert_eq!(world.bodies().len(), 0);
        }
    }
    // The tightest ratio builds and steps finite.
    let options = BuildOptions {
        stabilise: Some(1.0),
        ..BuildOptions::new(SpineMode::Rod)
    };
    let (mut world, built) = build(&desc, options, &Pose::bind(&desc));
    built.unwrap();
    for _ in 0..60 {
        world.step(1.0 / 60.0).unwrap();
    }
    assert_eq!(world.repaired_bodies(), 0);
}

#[test]
fn an_axis_whose_length_overflows_keeps_its_direction() {
    let text = edited(
        "anchor = [0.10, 0.525, 0.0]\naxis = [0.0, -1.0, 0.0]",
        "anchor = [0.10, 0.525, 0.0]\naxis = [1e38, 1e38, 0.0]",
    );
    let desc = RagdollDesc::from_toml(&text).unwrap();
    let knee = desc.joints.iter().find(|j| j.name == "knee_l").unwrap();
    let expected = Vec3::new(1.0, 1.0, 0.0).normalize();
    assert!((knee.axis() - expected).length() < 1e-6, "{}", knee.axis());
}

#[test]
fn zero_or_non_finite_joint_rotations_are_refused() {
    let desc = RagdollDesc::reference_humanoid();
    let root = (Vec3::new(0.0, 1.0, 0.0), Quat::IDENTITY);
    let mut rotations = vec![Quat::IDENTITY; desc.joints.len()];
    let knee = desc.joints.iter().position(|j| j.name == "knee_l").unwrap();
    for bad in [
        Quat::from_xyzw(0.0, 0.0, 0.0, 0.0),
        Quat::from_xyzw(0.0, 0.0, 0.0, f32::NAN),
        Quat::from_xyzw(0.0, 0.0, 0.0, 3.0),
    ] {
        rotations[knee] = bad;
        let error = Pose::from_joint_rotations(&desc, root, &rotations).expect_err("refused");
        assert!(
            error
                .to_string()
                .contains("joint `knee_l`: rotation is not"),
            "{error}"
        );
    }
    rotations[knee] = Quat::IDENTITY;
    let error = Pose::from_joint_rotations(&desc, (Vec3::NAN, Quat::IDENTITY), &rotations)
        .expect_err("refused");
    assert_eq!(
        error.to_string(),
        "bad pose: bone `hips`: position is not finite"
    );
    let error = Pose::from_joint_rotations(
        &desc,
        (Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)),
        &rotations,
    )
    .expect_err("refused");
    assert_eq!(
        error.to_string(),
        "bad pose: bone `hips`: orientation is not normalised"
    );
}

#[test]
fn loader_errors_name_the_line_the_item_and_the_field() {
    let hips = line_of("[[body]]\nname = \"hips\"");
    let knee = line_of("[[joint]]\nname = \"knee_l\"");
    let cases = [
        (
            edited("radius = 0.10\nmass = 11.0", "radius = 1e-30\nmass = 11.0"),
            format!("line {hips}: body `hips`: capsule radius (1e-3 to 1e3 m) is out of range"),
        ),
        (
            edited("mass = 11.0", "mass = 1e30"),
            format!("line {hips}: body `hips`: mass (1e-6 to 1e12 kg) is out of range"),
        ),
        (
            edited(
                "segment = [[-0.06, 1.00, 0.0]",
                "segment = [[-1e30, 1.00, 0.0]",
            ),
            format!("line {hips}: body `hips`: segment end is out of range"),
        ),
        (
            edited("mass = 11.0", "mass = nan"),
            format!("line {hips}: body `hips`: mass is not finite"),
        ),
        (
            edited("anchor = [0.10, 0.525, 0.0]", "anchor = [0.10, 1e30, 0.0]"),
            format!("line {knee}: joint `knee_l`: anchor is out of range"),
        ),
        (
            edited(
                "swing = 70.0\ntwist = [-5.0, 5.0]",
                "swing = 270.0\ntwist = [-5.0, 5.0]",
            ),
            format!("line {knee}: joint `knee_l`: swing must be in [0, 180] degrees"),
        ),
        (
            edited("name = \"knee_r\"", "name = \"knee_l\""),
            format!(
                "line {}: joint name `knee_l` is used twice",
                line_of("[[joint]]\nname = \"knee_r\"")
            ),
        ),
        (
            edited("bend_limit = 60.0", "bend_limit = -1.0"),
            format!(
                "line {}: [spine]: bend_limit must be in [0, 180] degrees",
                line_of("\n[spine]") + 1
            ),
        ),
    ];
    for (text, expected) in cases {
        let error = RagdollDesc::from_toml(&text).expect_err("refused");
        assert_eq!(error.to_string(), expected);
    }
}

#[test]
fn build_errors_name_the_body_or_the_rod() {
    let desc = RagdollDesc::reference_humanoid();
    let far = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::new(2e6, 0.0, 0.0));
    let (world, built) = build(&desc, BuildOptions::new(SpineMode::Sockets), &far);
    assert_eq!(
        built.expect_err("refused").to_string(),
        "bad pose: bone `hips`: position is out of range"
    );
    assert_eq!(world.bodies().len(), 0);
    // Spine bones folded back below the hips bend the rod's arc by more
    // than pi.
    let mut folded = Pose::bind(&desc);
    let spine = desc.spine.as_ref().unwrap();
    let (hips, chest) = (
        folded.bones[spine.bodies[0]].0,
        folded.bones[*spine.bodies.last().unwrap()].0,
    );
    for &b in &spine.bodies[1..spine.bodies.len() - 1] {
        folded.bones[b].0 = hips + (hips - chest) + Vec3::new(0.05, 0.0, 0.0);
    }
    let (world, built) = build(&desc, BuildOptions::new(SpineMode::Rod), &folded);
    let message = built.expect_err("refused").to_string();
    assert!(
        message.starts_with("spine rod `hips`-`chest`: "),
        "{message}"
    );
    assert_eq!(world.bodies().len(), 0);
}

/// Velocities from two poses are motion over the time between them: a
/// subnormal time made them infinite (the world then refused a body's
/// velocity, naming nothing about the time), or 1e38 m/s.
#[test]
fn the_time_between_two_poses_is_at_least_the_shortest_step() {
    let desc = RagdollDesc::reference_humanoid();
    let previous = Pose::bind(&desc);
    let current = previous.moved(Vec3::ZERO, Quat::IDENTITY, Vec3::new(0.0, 0.0, 0.01));
    for dt in [1e-40, 1e-7, 0.0, -1.0, f32::NAN] {
        let mut world = World::new(SolverConfig::default()).unwrap();
        let options = BuildOptions::new(SpineMode::Rod);
        let built = Ragdoll::build(&mut world, &desc, options, &current, Some((&previous, dt)));
        let message = built.expect_err("refused").to_string();
        assert!(
            message.starts_with("bad pose: the time between the two poses is")
                && message.ends_with("it must be at least 0.000001 s"),
            "{dt}: {message}"
        );
        assert_eq!(world.bodies().len(), 0);
    }
}

/// The reference humanoid's file without its `[spine]` table (the last
/// table of the file).
fn without_spine() -> String {
    let at = REFERENCE_HUMANOID
        .find("\n[spine]")
        .expect("a [spine] table");
    REFERENCE_HUMANOID[..at].to_owned()
}

/// A rod spine asked of a description without a `[spine]` is refused,
/// naming the description and the missing table, rather than building the
/// standard ragdoll (no rod) without a word: by the build (with nothing
/// added to the world) and by the mapper, which would map a rod that is
/// not there.
#[test]
fn a_rod_spine_of_a_description_without_a_spine_is_refused_by_name() {
    let desc = RagdollDesc::from_toml(&without_spine()).unwrap();
    assert_eq!(desc.spine, None);
    let expected = "ragdoll `reference-humanoid`: spine is a rod (SpineMode::Rod), but the \
                    description has no [spine] for one to replace; build it with \
                    SpineMode::Sockets, or give it a [spine]";
    let fresh = World::new(SolverConfig::default()).unwrap().state_hash();
    for options in [
        BuildOptions::new(SpineMode::Rod),
        BuildOptions::at_switch(SpineMode::Rod),
    ] {
        let (world, built) = build(&desc, options, &Pose::bind(&desc));
        assert_eq!(built.unwrap_err().to_string(), expected);
        assert_eq!(world.state_hash(), fresh, "nothing was added");
    }
    let skeleton = vertebra_ragdoll::Skeleton::reference();
    let mapper = vertebra_ragdoll::SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod);
    assert_eq!(mapper.unwrap_err().to_string(), expected);
    // The sockets build it, and the reference humanoid (with its spine)
    // builds both ways.
    assert!(
        build(
            &desc,
            BuildOptions::new(SpineMode::Sockets),
            &Pose::bind(&desc)
        )
        .1
        .is_ok()
    );
    let reference = RagdollDesc::reference_humanoid();
    let (_, rod) = build(
        &reference,
        BuildOptions::new(SpineMode::Rod),
        &Pose::bind(&reference),
    );
    assert!(rod.unwrap().rod.is_some());
}

/// A string whose first bytes are no TOML, `len` bytes long in all.
fn long_text(len: usize) -> String {
    let mut text = String::from("[[[ not toml\n");
    text.push_str(&"#".repeat(len - text.len()));
    text
}

/// The string entry points are capped at `MAX_FILE_BYTES`, as files are
/// (parsing a description megabytes long takes seconds). Every one refuses a
/// longer text before parsing it: the text starts with a syntax error
/// that a parser would name, and the refusal is the size, not that.
#[test]
fn a_text_longer_than_a_file_may_be_is_refused_before_it_is_parsed() {
    use vertebra_ragdoll::{MAX_FILE_BYTES, RagdollGenerator, Skeleton};
    let cap = MAX_FILE_BYTES as usize;
    let refusal = |file: &str| {
        format!(
            "the {file} text is larger than MAX_FILE_BYTES (1048576 bytes) and is refused \
             before it is parsed; a {file} file is a few KB"
        )
    };
    let skeleton = Skeleton::reference();
    let long = long_text(cap + 1);
    let refused: [(&str, Result<(), RagdollError>); 6] = [
        ("ragdoll", RagdollDesc::from_toml(&long).map(drop)),
        (
            "ragdoll",
            RagdollDesc::check_toml(&long)
                .map(drop)
                .map_err(|mut p| p.remove(0)),
        ),
        (
            "ragdoll",
            RagdollDesc::from_toml_with_skeleton(&long, &skeleton).map(drop),
        ),
        ("skeleton", Skeleton::from_toml(&long).map(drop)),
        (
            "skeleton",
            Skeleton::check_toml(&long)
                .map(drop)
                .map_err(|mut p| p.remove(0)),
        ),
        (
            "generator",
            RagdollGenerator::from_toml(&long, &skeleton).map(drop),
        ),
    ];
    for (file, result) in refused {
        assert_eq!(result.unwrap_err().to_string(), refusal(file));
    }
    // One byte less is parsed: its syntax error is named.
    let fits = long_text(cap);
    for text in [
        RagdollDesc::from_toml(&fits).unwrap_err().to_string(),
        Skeleton::from_toml(&fits).unwrap_err().to_string(),
        RagdollGenerator::from_toml(&fits, &skeleton)
            .unwrap_err()
            .to_string(),
    ] {
        assert!(text.contains("line 1"), "{text}");
    }
}

/// The counts are checked before any body or joint is, so a description of
/// tens of thousands of bodies costs no time to refuse: a description with
/// more bodies (or joints) than a ragdoll may have is refused with that one
/// problem, however many others its items have.
#[test]
fn more_bodies_or_joints_than_a_ragdoll_may_have_are_refused_before_any_is_read() {
    use vertebra_ragdoll::{BodySpec, JointSpec, MAX_BONES};
    use vertebra_world::SwingTwist;
    let count = MAX_BONES + 1;
    // Bodies placed on bones of a skeleton the description does not have:
    // each is a problem, but the count is found first.
    let mut builder = RagdollDesc::builder("big");
    for i in 0..count {
        builder = builder.body(BodySpec::from_bones(&format!("b{i}"), "x", "y", 0.05, 1.0));
    }
    for i in 1..count {
        builder = builder.joint(JointSpec::socket(
            &format!("j{i}"),
            &format!("b{}", i - 1),
            &format!("b{i}"),
            Vec3::ZERO,
            Vec3::Y,
            SwingTwist::FREE,
        ));
    }
    assert_eq!(
        builder.build().unwrap_err().to_string(),
        "ragdoll `big`: body has 4097 bodies; a ragdoll has at most MAX_BODIES (4096), \
         one per bone of the largest skeleton"
    );
    // The same as a file (well within MAX_FILE_BYTES): one problem.
    let mut text = String::from("name = \"big\"\n");
    for i in 0..count {
        text.push_str(&format!(
            "[[body]]\nname = \"b{i}\"\nfrom = \"x\"\nto = \"y\"\nradius = 0.05\nmass = 1.0\n"
        ));
    }
    let problems = RagdollDesc::check_toml(&text).unwrap_err();
    assert_eq!(
        problems.iter().map(ToString::to_string).collect::<Vec<_>>(),
        [
            "ragdoll `big`: body has 4097 bodies; a ragdoll has at most MAX_BODIES (4096), \
          one per bone of the largest skeleton"
        ]
    );
    // More joints than bodies can take in a tree, before any is resolved.
    let mut builder = RagdollDesc::builder("knotted").body(BodySpec::capsule(
        "only",
        [Vec3::ZERO, Vec3::Y],
        0.05,
        1.0,
    ));
    for i in 0..MAX_BONES {
        builder = builder.joint(JointSpec::socket(
            &format!("j{i}"),
            "nowhere",
            "only",
            Vec3::ZERO,
            Vec3::Y,
            SwingTwist::FREE,
        ));
    }
    assert_eq!(
        builder.build().unwrap_err().to_string(),
        "ragdoll `knotted`: joint has 4096 joints; a ragdoll has at most MAX_JOINTS (4095), \
         one fewer than its bodies at most"
    );
    // A generator choosing more bodies than its skeleton has bones.
    let skeleton = vertebra_ragdoll::Skeleton::reference();
    let mut text = String::from("name = \"many\"\n");
    for _ in 0..=skeleton.len() {
        text.push_str("[[body]]\nbone = \"nowhere\"\nradius = 0.05\nmass = 1.0\n");
    }
    let refused = vertebra_ragdoll::RagdollGenerator::from_toml(&text, &skeleton);
    assert_eq!(
        refused.unwrap_err().to_string(),
        "generator `many`: body has 64 tables; at most one per bone of the skeleton (63)"
    );
}
