//! The `vertebra` command as a user runs it.

use std::process::Command;

fn vertebra(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_vertebra"))
        .args(args)
        .output()
        .expect("the binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Unless told, the paper's scenes run the paper's solver and the others
/// the world's default; `--joints iterative` starts from the paper's
/// settings anywhere, and each flag given replaces its setting.
#[test]
fn a_scene_runs_the_papers_settings_or_the_worlds_default_unless_told() {
    let settings = |args: &[&str]| {
        let mut all = vec!["scene", "--frames", "2", "--json"];
        all.extend_from_slice(args);
        let (code, stdout, stderr) = vertebra(&all);
        assert_eq!(code, 0, "{args:?}: {stderr}");
        let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
        (
            v["joints"].as_str().unwrap().to_owned(),
            v["substeps"].as_u64().unwrap(),
            v["iterations"].as_u64().unwrap(),
            v["relax_contacts"].as_bool().unwrap(),
            v["pin_contacts"].as_str().unwrap().to_owned(),
        )
    };
    let [never, driven, always] = ["never", "driven", "always"].map(str::to_owned);
    let paper = ("iterative".to_owned(), 1, 20, false, never.clone());
    let default = ("direct".to_owned(), 1, 8, true, never.clone());
    assert_eq!(settings(&["passive-bending", "--spine", "rod"]), paper);
    assert_eq!(settings(&["heavy-chain", "--spine", "sockets"]), default);
    let iterated = ["heavy-chain", "--spine", "sockets", "--joints", "iterative"];
    assert_eq!(settings(&iterated), paper);
    let direct = ["ragdoll-drop", "--spine", "rod", "--joints", "direct"];
    assert_eq!(
        settings(&direct),
        ("direct".to_owned(), 1, 20, false, never.clone())
    );
    let told = [
        "heavy-chain",
        "--spine",
        "sockets",
        "--iterations",
        "3",
        "--substeps",
        "2",
        "--relax-contacts",
        "false",
        "--pin-contacts",
        "never",
    ];
    assert_eq!(
        settings(&told),
        ("direct".to_owned(), 2, 3, false, never.clone())
    );
    let relaxed = ["passive-bending", "--spine", "rod", "--relax-contacts"];
    assert_eq!(
        settings(&relaxed),
        ("iterative".to_owned(), 1, 20, true, never.clone())
    );
    // The stagger's driven ragdoll stands on pinned feet under the direct
    // solve unless told.
    let stagger = ["stagger", "--spine", "rod"];
    assert_eq!(
        settings(&stagger),
        ("direct".to_owned(), 1, 8, true, driven)
    );
    let unpinned = ["stagger", "--spine", "rod", "--pin-contacts", "never"];
    assert_eq!(
        settings(&unpinned),
        ("direct".to_owned(), 1, 8, true, never)
    );
    let pinned = ["heavy-chain", "--spine", "sockets", "--pin-contacts"];
    assert_eq!(settings(&pinned), ("direct".to_owned(), 1, 8, true, always));
    // Pinning every ragdoll needs the direct solve: asked of the iterated
    // one, refused.
    let iterated = [
        "scene",
        "stagger",
        "--spine",
        "rod",
        "--frames",
        "2",
        "--joints",
        "iterative",
        "--pin-contacts",
    ];
    let (code, _, stderr) = vertebra(&iterated);
    assert_ne!(code, 0);
    assert!(stderr.contains("pin_contacts"), "{stderr}");
}

#[test]
fn scene_json_has_every_field() {
    let (code, stdout, stderr) = vertebra(&[
        "scene",
        "passive-bending",
        "--spine",
        "rod",
        "--frames",
        "12",
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
    for field in [
        "scene",
        "spine",
        "iterations",
        "substeps",
        "backend",
        "threads",
        "sleep",
        "relax_contacts",
        "pin_contacts",
        "seed",
        "frames",
        "summary",
        "state_hash",
    ] {
        assert!(v.get(field).is_some(), "missing `{field}` in {v}");
    }
    assert_eq!(v["scene"], "passive-bending");
    assert_eq!(v["spine"], "rod");
    assert_eq!(v["iterations"], 20);
    assert_eq!(v["sleep"], false, "the paper's scenes do not sleep");
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 12);
    assert!(
        frames
            .iter()
            .all(|f| f["eps_lin_cm"].is_number() && f["eps_ang_rad"].is_number())
    );
    for field in [
        "mean_eps_lin_cm",
        "max_eps_lin_cm",
        "mean_eps_ang_rad",
        "max_eps_ang_rad",
        "ms_per_step",
        "frame_ms",
    ] {
        assert!(v["summary"][field].is_number(), "summary.{field}");
    }
    assert_eq!(v["state_hash"].as_str().unwrap().len(), 16);
    // The same run gives the same hash.
    let (_, again, _) = vertebra(&[
        "scene",
        "passive-bending",
        "--spine",
        "rod",
        "--frames",
        "12",
        "--json",
        "--backend",
        "scalar",
    ]);
    let again: serde_json::Value = serde_json::from_str(again.trim()).unwrap();
    assert_eq!(
        again["state_hash"], v["state_hash"],
        "every backend gives the same bits"
    );
    // Another start: another state, named in the output.
    let (_, seeded, _) = vertebra(&[
        "scene",
        "passive-bending",
        "--spine",
        "rod",
        "--frames",
        "12",
        "--json",
        "--seed",
        "3",
    ]);
    let seeded: serde_json::Value = serde_json::from_str(seeded.trim()).unwrap();
    assert_eq!((&v["seed"], &seeded["seed"]), (&0.into(), &3.into()));
    assert_ne!(seeded["state_hash"], v["state_hash"]);
}

/// A failing run: non-zero status, one line on stderr naming the problem,
/// no panic or backtrace.
fn fails_with(args: &[&str], expected: &str) {
    let (code, _, stderr) = vertebra(args);
    assert_ne!(code, 0, "{args:?} should fail");
    assert_eq!(stderr.trim().lines().count(), 1, "one line: {stderr}");
    assert!(
        stderr.contains(expected),
        "{args:?}: expected `{expected}` in `{stderr}`"
    );
    assert!(!stderr.contains("panicked") && !stderr.contains("backtrace"));
}

#[test]
fn bad_arguments_end_with_one_clear_line() {
    fails_with(
        &["scene", "somersault", "--spine", "rod"],
        "unknown scene `somersault`",
    );
    fails_with(&["scene", "passive-bending", "--spine", "noodle"], "noodle");
    fails_with(&["scene", "passive-bending"], "--spine");
    fails_with(
        &[
            "scene",
            "passive-bending",
            "--spine",
            "rod",
            "--backend",
            "avx512",
        ],
        "unknown backend `avx512`",
    );
    fails_with(
        &[
            "scene",
            "passive-bending",
            "--spine",
            "rod",
            "--frames",
            "0",
        ],
        "--frames must be at least 1",
    );
    fails_with(
        &[
            "scene",
            "passive-bending",
            "--spine",
            "rod",
            "--iterations",
            "0",
        ],
        "iterations must be at least 1",
    );
    fails_with(
        &[
            "scene",
            "passive-bending",
            "--spine",
            "rod",
            "--threads",
            "zero",
        ],
        "zero",
    );
    fails_with(&["dance"], "dance");
}

#[test]
fn malformed_ragdoll_files_end_with_one_clear_line() {
    let dir = std::env::temp_dir().join(format!("vertebra-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let missing = dir.join("missing.toml");
    fails_with(
        &[
            "scene",
            "passive-bending",
            "--spine",
            "rod",
            "--ragdoll",
            missing.to_str().unwrap(),
        ],
        "cannot read",
    );
    let bad = dir.join("bad.toml");
    let text = vertebra_ragdoll::REFERENCE_HUMANOID.replacen("mass = 11.0", "mass = -11.0", 1);
    std::fs::write(&bad, text).unwrap();
    fails_with(
        &[
            "scene",
            "passive-bending",
            "--spine",
            "rod",
            "--ragdoll",
            bad.to_str().unwrap(),
        ],
        "body `hips`: mass must be positive",
    );
    let garbage = dir.join("garbage.toml");
    std::fs::write(&garbage, "[[body]\nname = ").unwrap();
    fails_with(
        &[
            "scene",
            "passive-bending",
            "--spine",
            "rod",
            "--ragdoll",
            garbage.to_str().unwrap(),
        ],
        "malformed ragdoll file",
    );
}

#[test]
fn no_arguments_print_the_usage() {
    let (code, stdout, stderr) = vertebra(&[]);
    assert_eq!(code, 2, "a usage error, as clap gives");
    assert!(stdout.is_empty());
    for expected in ["Usage: vertebra", "reproduce", "scene"] {
        assert!(stderr.contains(expected), "`{expected}` in {stderr}");
    }
}

/// `scene passive-bending --spine rod` with `extra` arguments.
fn scene_with(extra: &[&str]) -> Vec<String> {
    ["scene", "passive-bending", "--spine", "rod"]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .collect()
}

#[test]
fn extreme_counts_end_with_one_clear_line() {
    let cases: [(&[&str], &str); 11] = [
        (
            &["--frames", "18446744073709551615"],
            "--frames must be at most 1000000",
        ),
        (
            &["--frames", "1000000000000"],
            "--frames must be at most 1000000",
        ),
        (&["--frames", "1e12"], "invalid value '1e12' for '--frames"),
        (&["--frames", "-5"], "-5"),
        (&["--frames", "NaN"], "invalid value 'NaN' for '--frames"),
        (
            &["--frames", "18446744073709551616"],
            "invalid value '18446744073709551616'",
        ),
        (
            &["--threads", "18446744073709551615"],
            "threads must be at most 256",
        ),
        (&["--threads", "257"], "threads must be at most 256"),
        (
            &["--iterations", "4294967295"],
            "substeps x iterations must be at most 10000",
        ),
        (
            &["--substeps", "4294967295"],
            "substeps x iterations must be at most 10000",
        ),
        (&["--iterations", "-1"], "-1"),
    ];
    for (extra, expected) in cases {
        let args = scene_with(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        fails_with(&args, expected);
    }
}

#[test]
fn an_output_directory_that_cannot_be_made_is_named() {
    fails_with(
        &["reproduce", "--out", "/proc/vertebra-none/out"],
        "cannot write the results: /proc/vertebra-none/out: ",
    );
}

#[test]
fn ragdoll_files_are_read_bounded_and_named_in_every_error() {
    let dir = std::env::temp_dir().join(format!("vertebra-cli-bounded-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let with_ragdoll = |path: &str| scene_with(&["--ragdoll", path]);
    let run = |path: &str, expected: &str| {
        let args = with_ragdoll(path);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        fails_with(&args, expected);
    };
    run(
        "/dev/zero",
        "/dev/zero: cannot read the ragdoll file: not a regular file (a directory, a device or a pipe)",
    );
    let dir_name = dir.to_str().unwrap();
    run(
        dir_name,
        &format!("{dir_name}: cannot read the ragdoll file"),
    );
    let binary = dir.join("binary.toml");
    std::fs::write(&binary, [b'n', b'a', 0xff, 0xfe]).unwrap();
    let binary = binary.to_str().unwrap();
    run(
        binary,
        &format!("{binary}: cannot read the ragdoll file: not UTF-8 text (at byte 2)"),
    );
    let tiny = dir.join("tiny.toml");
    let text = vertebra_ragdoll::REFERENCE_HUMANOID.replacen("radius = 0.10", "radius = 1e-30", 1);
    std::fs::write(&tiny, &text).unwrap();
    let line = text[..text.find("[[body]]\nname = \"hips\"").unwrap()]
        .matches('\n')
        .count()
        + 1;
    let tiny = tiny.to_str().unwrap();
    run(
        tiny,
        &format!(
            "{tiny}: line {line}: body `hips`: capsule radius (1e-3 to 1e3 m) is out of range"
        ),
    );
}

#[test]
fn seeds_give_every_figure_with_its_spread() {
    let (code, stdout, stderr) = vertebra(&[
        "scene",
        "passive-bending",
        "--spine",
        "sockets",
        "--frames",
        "10",
        "--seed",
        "2",
        "--seeds",
        "3",
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
    assert_eq!(v["seeds"]["first"], 2);
    assert_eq!(v["seeds"]["count"], 3);
    assert_eq!(v["seeds"]["band"], "min-max");
    let runs = v["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 3);
    // Each seed's figures, and their spread: the median of three is the
    // middle one, the band the smallest and largest.
    let mut means: Vec<f64> = runs
        .iter()
        .map(|r| r["summary"]["mean_eps_lin_cm"].as_f64().unwrap())
        .collect();
    means.sort_by(f64::total_cmp);
    let spread = &v["spread"]["mean_eps_lin_cm"];
    assert_eq!(spread["median"].as_f64().unwrap(), means[1]);
    assert_eq!(spread["min"].as_f64().unwrap(), means[0]);
    assert_eq!(spread["max"].as_f64().unwrap(), means[2]);
    // The seeded runs are the single runs of their seeds.
    let (_, single, _) = vertebra(&[
        "scene",
        "passive-bending",
        "--spine",
        "sockets",
        "--frames",
        "10",
        "--seed",
        "3",
        "--json",
    ]);
    let single: serde_json::Value = serde_json::from_str(single.trim()).unwrap();
    assert_eq!(runs[1]["seed"], 3);
    assert_eq!(runs[1]["state_hash"], single["state_hash"]);
    assert_eq!(v["frames"].as_array().unwrap().len(), 10);
    assert!(v["frames"][9]["eps_lin_cm"]["median"].is_number());
    // Without --json: one line per figure, median [band].
    let (code, text, _) = vertebra(&[
        "scene",
        "passive-bending",
        "--spine",
        "rod",
        "--frames",
        "5",
        "--seeds",
        "2",
    ]);
    assert_eq!(code, 0);
    assert!(
        text.contains("seeds 0..1: median [min-max] over 2 runs"),
        "{text}"
    );
    assert!(text.contains("mean_eps_lin_cm"), "{text}");
    fails_with(
        &scene_with(&["--seeds", "0"])
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
        "seeds",
    );
}

fn hit_with(extra: &[&str]) -> Vec<String> {
    ["scene", "hit-reaction", "--spine", "rod", "--frames", "40"]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .collect()
}

#[test]
fn bad_drive_settings_end_with_one_clear_line() {
    for (flag, value, field) in [
        ("--drive-frequency", "0", "drive_frequency is 0"),
        ("--drive-frequency", "inf", "drive_frequency is inf"),
        ("--drive-frequency", "NaN", "drive_frequency is NaN"),
        ("--damping-ratio", "-1", "drive_damping_ratio is -1"),
        ("--max-torque", "-5", "max_torque is -5"),
        ("--max-torque", "NaN", "max_torque is NaN"),
        ("--max-torque", "strong", "strong"),
    ] {
        let args = hit_with(&[flag, value]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        fails_with(&args, field);
    }
    // Refused whichever scene runs: a bad setting is never silently
    // ignored.
    let args = scene_with(&["--drive-frequency", "-2"]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    fails_with(&args, "drive_frequency is -2");
}

#[test]
fn the_new_scenes_run_by_name_and_report_their_figures() {
    let (code, stdout, stderr) = vertebra(&[
        "scene",
        "hit-reaction",
        "--spine",
        "sockets",
        "--drive-frequency",
        "8",
        "--damping-ratio",
        "0.5",
        "--max-torque",
        "50",
        "--json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
    assert_eq!(v["scene"], "hit-reaction");
    assert_eq!(v["frames"].as_array().unwrap().len(), 240);
    assert!(v["frames"][0]["max_violation_rad"].is_number());
    for field in [
        "max_max_violation_rad",
        "peak_deviation_cm_chest",
        "peak_deviation_cm_head",
        "recovery_frames_chest",
        "recovery_frames_head",
    ] {
        assert!(v["summary"].get(field).is_some(), "missing `{field}`");
    }
    let (code, stdout, stderr) = vertebra(&[
        "scene",
        "anatomical-drop",
        "--spine",
        "rod",
        "--frames",
        "5",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("largest limit violation"), "{stdout}");
}

/// `scene stagger` sweeps chest hits over seeds and prints a row per hit
/// and what every seed survived; JSON gives the same; with `--frames` it
/// is one run like any scene's.
#[test]
fn the_stagger_prints_its_sweep_of_hits() {
    let stagger = ["scene", "stagger", "--spine", "rod", "--seeds", "1"];
    let (code, stdout, stderr) = vertebra(&stagger);
    assert_eq!(code, 0, "{stderr}");
    let rows = stdout
        .lines()
        .filter(|l| l.starts_with("standing ") || l.starts_with("walking  "));
    assert_eq!(rows.count(), 2 * 4 * 7, "{stdout}");
    assert!(
        stdout.contains("stagger (rod, direct joints), seeds 0..0"),
        "{stdout}"
    );
    assert!(
        stdout.contains("largest impulse every seed survived"),
        "{stdout}"
    );
    let mut json = stagger.to_vec();
    json.push("--json");
    let (code, stdout, stderr) = vertebra(&json);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
    assert_eq!(v["scene"], "stagger");
    assert_eq!(v["hits"].as_array().unwrap().len(), 2 * 4 * 7);
    let first = &v["hits"][0];
    for field in [
        "activity",
        "from",
        "impulse_ns",
        "seed",
        "stays_up",
        "lowest_hips_m",
        "peak_m",
    ] {
        assert!(first.get(field).is_some(), "missing `{field}`");
    }
    assert!(v["tracking"]["max_m"].as_f64().unwrap() < 0.05);
    let front = &v["largest_survived"]["standing"]["front"];
    assert!(front["impulse_ns"].as_f64().unwrap() >= 40.0, "{front}");
    let (code, stdout, stderr) = vertebra(&["scene", "stagger", "--spine", "rod", "--frames", "5"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.starts_with("stagger (rod, direct joints):"),
        "{stdout}"
    );
}

/// A shipped model file.
fn model(name: &str) -> String {
    format!(
        "{}/../vertebra-ragdoll/models/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn check_prints_what_a_ragdoll_file_holds() {
    let (code, stdout, stderr) = vertebra(&["check", &model("anatomical.toml")]);
    assert_eq!(code, 0, "{stderr}");
    // The file's own numbers: 15 bodies and 14 joints, 69 kg, the hips
    // 11 kg, knees hinged 0 to 150 degrees, shoulders elliptical 90 by 70,
    // ankles pyramids,
    // the spine's rod limits, the [drive] table, the profiles, no skeleton.
    for expected in [
        "ragdoll `anatomical-humanoid`: 15 bodies, 14 joints, 69 kg",
        "hips ",
        "11 kg  radius 0.1 m\n",
        "hinge   thigh_l -> shin_l  range 0 .. 150 deg",
        "socket  shin_l -> foot_l  swing pyramid y -40 .. 40 z -20 .. 20 deg, twist -15 .. 15 deg",
        "socket  chest -> upper_arm_l  swing ellipse y 90 z 70 deg, twist -60 .. 60 deg",
        "spine: hips, spine_lower, spine_upper, chest (one rod in the simplified ragdoll): bend 60 deg, twist -30 .. 30 deg, stiffness 2 / 2 N m^2",
        "drive: spring 4 Hz, damping ratio 1, max torque 400 N m",
        "profiles:\n  standing: 14 of 14 joints driven, 15 of 15 bodies held in the world, 2 upright\n",
        "  limp: 0 of 14 joints driven, 0 of 15 bodies held in the world, 0 upright\n",
        "skeleton: none",
    ] {
        assert!(stdout.contains(expected), "`{expected}` in\n{stdout}");
    }
}

#[test]
fn check_prints_what_a_skeleton_file_holds_and_a_ragdoll_its_bones() {
    let (code, stdout, stderr) = vertebra(&["check", &model("skeleton.toml")]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("skeleton: 63 bones, 1 root\n"), "{stdout}");
    // The hips 1 m up, the chest 1.36 m (the spine_3 pivot), the left toes at (0.1, 0.04, 0.08)
    // (the foot turned so it points forward and down, 3-4-5).
    for expected in ["(0, 1, 0)", "(0, 1.36, 0)", "toes_l", "(0.1, 0.04, 0.08)"] {
        assert!(stdout.contains(expected), "`{expected}` in\n{stdout}");
    }
    // A ragdoll file naming a skeleton file next to it.
    let dir = std::env::temp_dir().join(format!("vertebra-cli-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(model("skeleton.toml"), dir.join("skeleton.toml")).unwrap();
    let text = vertebra_ragdoll::REFERENCE_HUMANOID.replacen(
        "total_mass = 69.0",
        "total_mass = 69.0\nskeleton = \"skeleton.toml\"",
        1,
    );
    let ragdoll = dir.join("humanoid.toml");
    std::fs::write(&ragdoll, text).unwrap();
    let (code, stdout, stderr) = vertebra(&["check", ragdoll.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    for expected in [
        "bone forearm_l",
        "skeleton: 63 bones, 13 followed by a body",
        "socket  hips -> spine_lower  swing 20 deg, twist -10 .. 10 deg",
    ] {
        assert!(stdout.contains(expected), "`{expected}` in\n{stdout}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn check_names_the_file_and_line_of_a_problem() {
    let dir = std::env::temp_dir().join(format!("vertebra-cli-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_owned()
    };
    let humanoid = vertebra_ragdoll::REFERENCE_HUMANOID;
    let line = humanoid[..humanoid.find("[[body]]\nname = \"hips\"").unwrap()]
        .matches('\n')
        .count()
        + 1;
    let ragdoll = write(
        "bad.toml",
        &humanoid.replacen("mass = 11.0", "mass = nan", 1),
    );
    fails_with(
        &["check", &ragdoll],
        &format!("vertebra: {ragdoll}: line {line}: body `hips`: mass is not finite"),
    );
    let skeleton = write(
        "bones.toml",
        "[[bone]]\nname = \"root\"\ntranslation = [0.0, 0.0, 0.0]\n\n[[bone]]\nname = \"hips\"\nparent = \"pelvis\"\ntranslation = [0.0, 1.0, 0.0]\n",
    );
    fails_with(
        &["check", &skeleton],
        &format!("{skeleton}: line 5: bone `hips`: parent `pelvis` is not a bone of the skeleton"),
    );
    let broken = write(
        "broken.toml",
        "[[bone]]\nname = \"root\"\ntranslation = [0.0, 0.0\n",
    );
    fails_with(
        &["check", &broken],
        &format!("{broken}: malformed skeleton file: line 3"),
    );
    let neither = write("neither.toml", "name = \"x\"\n");
    fails_with(
        &["check", &neither],
        &format!(
            "{neither}: neither a ragdoll file ([[body]] tables) nor a skeleton file ([[bone]] tables)"
        ),
    );
    fails_with(
        &["check", "/dev/zero"],
        "/dev/zero: cannot read the ragdoll file: not a regular file (a directory, a device or a pipe)",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// One row per frame, ragdoll and reference-skeleton bone, parsed.
fn skeleton_rows(path: &std::path::Path) -> Vec<(usize, usize, String, [f32; 7])> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("frame,ragdoll,bone,x,y,z,qx,qy,qz,qw"));
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), 10, "{line}");
            let v: Vec<f32> = f[3..].iter().map(|x| x.parse().unwrap()).collect();
            (
                f[0].parse().unwrap(),
                f[1].parse().unwrap(),
                f[2].to_owned(),
                v.try_into().unwrap(),
            )
        })
        .collect()
}

#[test]
fn scenes_write_the_reference_skeleton_frame_by_frame() {
    let dir = std::env::temp_dir().join(format!("vertebra-skeleton-out-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Passive bending: one ragdoll, its hips held at the bind pose turned
    // 30 degrees about +X through (0, 1, 0).
    for spine in ["rod", "sockets"] {
        let path = dir.join(format!("bending-{spine}.csv"));
        let (code, _, stderr) = vertebra(&[
            "scene",
            "passive-bending",
            "--spine",
            spine,
            "--frames",
            "3",
            "--skeleton-out",
            path.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stderr}");
        let rows = skeleton_rows(&path);
        assert_eq!(rows.len(), 3 * 63);
        assert!(rows.iter().all(|r| r.3.iter().all(|x| x.is_finite())));
        for (k, r) in rows.iter().enumerate() {
            assert_eq!((r.0, r.1), (k / 63, 0));
        }
        let bone = |frame: usize, name: &str| {
            let r = rows.iter().find(|r| r.0 == frame && r.2 == name).unwrap();
            let [x, y, z, qx, qy, qz, qw] = r.3;
            (
                glam::Vec3::new(x, y, z),
                glam::Quat::from_xyzw(qx, qy, qz, qw),
            )
        };
        // The hips bone is the held hips body's frame (its offset is the
        // identity: the bone sits at the body's centre, unrotated).
        let turn = glam::Quat::from_rotation_x(30f32.to_radians());
        let (p, q) = bone(0, "hips");
        assert!(p.distance(glam::Vec3::Y) < 1e-3, "{spine}: hips at {p}");
        assert!(q.angle_between(turn) < 1e-3, "{spine}: hips turned {q}");
        // The root rides on the hips as at bind (1 m below it); a hand
        // keeps its bind place below its forearm (it has no body).
        let (root, _) = bone(0, "root");
        assert!(root.distance(p + q * glam::Vec3::new(0.0, -1.0, 0.0)) < 1e-5);
        let skeleton = vertebra_ragdoll::Skeleton::reference();
        let hand = &skeleton.bones()[skeleton.bone_index("hand_l").unwrap()];
        for frame in 0..3 {
            let (fp, fq) = bone(frame, "forearm_l");
            let (hp, hq) = bone(frame, "hand_l");
            assert!(hp.distance(fp + fq * hand.bind.translation) < 1e-5);
            assert!(hq.angle_between(fq * hand.bind.rotation) < 1e-4);
        }
    }
    // The hit reaction (the anatomical humanoid binds by name too).
    let path = dir.join("hit.csv");
    let (code, _, stderr) = vertebra(&[
        "scene",
        "hit-reaction",
        "--spine",
        "rod",
        "--frames",
        "2",
        "--skeleton-out",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let rows = skeleton_rows(&path);
    assert_eq!(rows.len(), 2 * 63);
    assert!(rows.iter().all(|r| r.3.iter().all(|x| x.is_finite())));
    std::fs::remove_dir_all(&dir).unwrap();
    fails_with(
        &scene_with(&[
            "--frames",
            "1",
            "--skeleton-out",
            "/proc/vertebra-none/bones.csv",
        ])
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>(),
        "cannot write the skeleton poses to `/proc/vertebra-none/bones.csv`: ",
    );
    fails_with(
        &[
            "scene",
            "passive-bending",
            "--spine",
            "rod",
            "--seeds",
            "2",
            "--skeleton-out",
            "x.csv",
        ],
        "--skeleton-out writes one run; not with --seeds",
    );
}

/// A `--ragdoll` whose bodies are not bones of the reference skeleton is
/// refused saying that `--skeleton-out` maps onto that skeleton, and
/// leaves no file behind.
#[test]
fn skeleton_out_refuses_a_ragdoll_off_the_reference_skeleton_without_a_file() {
    let dir = std::env::temp_dir().join(format!("vertebra-skeleton-off-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ragdoll = dir.join("pendulum.toml");
    std::fs::write(
        &ragdoll,
        "name = \"pendulum\"\n\n[[body]]\nname = \"a\"\nsegment = [[0.0, 1.0, 0.0], [0.0, 0.8, 0.0]]\nradius = 0.05\nmass = 1.0\n\n[[body]]\nname = \"b\"\nsegment = [[0.0, 0.7, 0.0], [0.0, 0.5, 0.0]]\nradius = 0.05\nmass = 1.0\n\n[[joint]]\nname = \"j\"\nparent = \"a\"\nchild = \"b\"\nanchor = [0.0, 0.75, 0.0]\naxis = [0.0, -1.0, 0.0]\n",
    )
    .unwrap();
    let out = dir.join("bones.csv");
    fails_with(
        &[
            "scene",
            "passive-bending",
            "--spine",
            "sockets",
            "--frames",
            "2",
            "--ragdoll",
            ragdoll.to_str().unwrap(),
            "--skeleton-out",
            out.to_str().unwrap(),
        ],
        "vertebra: --skeleton-out maps each ragdoll onto the reference skeleton (63 bones) by body name: body `a`: bone is missing",
    );
    assert!(!out.exists(), "a file was left behind");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Fails with exactly the `expected` lines on stderr.
fn fails_with_lines(args: &[&str], expected: &[String]) {
    let (code, _, stderr) = vertebra(args);
    assert_eq!(code, 1, "{args:?} should fail: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines, expected, "{args:?}");
}

/// The line (from 1) of the first `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("`{needle}` in the text"));
    text[..at].matches('\n').count() + 1
}

#[test]
fn check_lists_every_problem_of_a_ragdoll_file_in_file_order() {
    let dir = std::env::temp_dir().join(format!("vertebra-cli-all-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(model("skeleton.toml"), dir.join("skeleton.toml")).unwrap();
    // Four independent problems: a NaN segment (hips), an unknown bone
    // (forearm_l), a joint name used twice (elbow_l renamed shoulder_l), a
    // twist limit with its ends swapped (knee_l).
    let text = vertebra_ragdoll::REFERENCE_HUMANOID
        .replacen(
            "total_mass = 69.0",
            "total_mass = 69.0\nskeleton = \"skeleton.toml\"",
            1,
        )
        .replacen("[[-0.06, 1.00, 0.0]", "[[nan, 1.00, 0.0]", 1)
        .replacen("mass = 1.5", "mass = 1.5\nbone = \"nope\"", 1)
        .replacen("name = \"elbow_l\"", "name = \"shoulder_l\"", 1)
        .replacen(
            "child = \"shin_l\"\nanchor = [0.10, 0.525, 0.0]\naxis = [0.0, -1.0, 0.0]\nswing = 70.0\ntwist = [-5.0, 5.0]",
            "child = \"shin_l\"\nanchor = [0.10, 0.525, 0.0]\naxis = [0.0, -1.0, 0.0]\nswing = 70.0\ntwist = [5.0, -5.0]",
            1,
        );
    let table = |name: &str| line_of(&text, &format!("name = \"{name}\"")) - 1;
    let second_shoulder = {
        let first = text.find("name = \"shoulder_l\"").unwrap() + 1;
        line_of(&text[first..], "name = \"shoulder_l\"") + text[..first].matches('\n').count() - 1
    };
    let path = dir.join("bad.toml");
    std::fs::write(&path, &text).unwrap();
    let path = path.to_str().unwrap();
    fails_with_lines(
        &["check", path],
        &[
            format!(
                "vertebra: {path}: line {}: body `hips`: segment is not finite",
                table("hips")
            ),
            format!(
                "vertebra: {path}: line {}: body `forearm_l`: bone `nope` is not a bone of the skeleton",
                table("forearm_l")
            ),
            format!(
                "vertebra: {path}: line {second_shoulder}: joint name `shoulder_l` is used twice"
            ),
            format!(
                "vertebra: {path}: line {}: joint `knee_l`: twist must be [min, max] within [-180, 180] degrees",
                table("knee_l")
            ),
        ],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A generator for three bones of the reference skeleton.
const GENERATOR: &str = "\
name = \"small\"

[[body]]
bone = \"hips\"
radius = 0.1
mass = 11.0
end = \"spine_lower\"

[[body]]
bone = \"chest\"
radius = 0.12
mass = 12.0
end = \"neck_1\"

[[body]]
bone = \"head\"
radius = 0.1
mass = 5.0
length = 0.12
";

#[test]
fn check_prints_what_a_generator_file_generates_or_its_problems() {
    let dir = std::env::temp_dir().join(format!("vertebra-cli-gen-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_owned()
    };
    let generator = write("generator.toml", GENERATOR);
    let (code, stdout, stderr) = vertebra(&["check", &generator]);
    assert_eq!(code, 0, "{stderr}");
    for expected in [
        "ragdoll generator, on the reference skeleton (63 bones): generates\n",
        "ragdoll `small`: 3 bodies, 2 joints, 28 kg",
        "socket  hips -> chest  swing free, twist free",
        "socket  chest -> head  swing free, twist free",
        "skeleton: 63 bones, 3 followed by a body",
    ] {
        assert!(stdout.contains(expected), "`{expected}` in\n{stdout}");
    }
    // The same on a skeleton file given.
    let skeleton = write(
        "skeleton.toml",
        &std::fs::read_to_string(model("skeleton.toml")).unwrap(),
    );
    let (code, stdout, stderr) = vertebra(&["check", &generator, "--skeleton", &skeleton]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains(&format!("on {skeleton} (63 bones): generates")),
        "{stdout}"
    );
    // Every table's problem of form, in file order.
    let bad = GENERATOR
        .replacen("mass = 11.0", "mass = 11.0\ndensity = 1000.0", 1)
        .replacen("length = 0.12", "length = 0.12\nend = \"neck_2\"", 1);
    let head = line_of(&bad, "bone = \"head\"") - 1;
    let bad = write("bad.toml", &bad);
    fails_with_lines(
        &["check", &bad],
        &[
            format!(
                "vertebra: {bad}: line 3: bone `hips`: mass and density both give the mass; give one"
            ),
            format!(
                "vertebra: {bad}: line {head}: bone `head`: end is given twice: give one of end, length and point"
            ),
        ],
    );
    // --skeleton is for generator files only.
    let (code, _, stderr) =
        vertebra(&["check", &model("anatomical.toml"), "--skeleton", &skeleton]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("--skeleton is for a generator file"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--sleep` reaches the world: the anatomical drop (one ragdoll on the
/// ground) stepped with sleeping on ends in another state than without,
/// and says so in its JSON.
#[test]
fn sleep_turns_sleeping_on() {
    let run = |extra: &[&str]| {
        let mut args = vec![
            "scene",
            "anatomical-drop",
            "--spine",
            "rod",
            "--frames",
            "90",
            "--json",
        ];
        args.extend_from_slice(extra);
        let (code, stdout, stderr) = vertebra(&args);
        assert_eq!(code, 0, "{stderr}");
        serde_json::from_str::<serde_json::Value>(stdout.trim()).expect("one JSON object")
    };
    let (asleep, awake) = (run(&["--sleep"]), run(&[]));
    assert_eq!(asleep["sleep"], true);
    assert_eq!(awake["sleep"], false);
    assert_ne!(asleep["state_hash"], awake["state_hash"]);
}

/// `--joints` reaches the scene and is reported: in the JSON, in the
/// one-line summary and over seeds; for the heavy chain (not one of the
/// paper's scenes), direct unless told.
#[test]
fn joints_choose_the_solver_and_are_reported() {
    let scene = |extra: &[&str]| {
        let mut args = vec![
            "scene",
            "heavy-chain",
            "--spine",
            "sockets",
            "--frames",
            "3",
        ];
        args.extend_from_slice(extra);
        let (code, stdout, stderr) = vertebra(&args);
        assert_eq!(code, 0, "{stderr}");
        stdout
    };
    let json = |extra: &[&str]| {
        let stdout = scene(&[extra, &["--json"]].concat());
        serde_json::from_str::<serde_json::Value>(stdout.trim()).expect("one JSON object")
    };
    assert_eq!(json(&[])["joints"], "direct");
    assert_eq!(json(&["--joints", "iterative"])["joints"], "iterative");
    assert_eq!(json(&["--joints", "direct"])["joints"], "direct");
    assert_eq!(
        json(&["--joints", "direct", "--seeds", "2"])["joints"],
        "direct"
    );
    let line = scene(&["--joints", "direct"]);
    assert!(
        line.starts_with("heavy-chain (sockets, direct joints):"),
        "{line}"
    );
    let seeded = scene(&["--joints", "iterative", "--seeds", "2"]);
    assert!(
        seeded.starts_with("heavy-chain (sockets, iterative joints), seeds 0..1"),
        "{seeded}"
    );
}

/// A `--joints` that is neither value is refused, naming the flag and the
/// values it takes, by both commands.
#[test]
fn a_bad_joints_value_names_the_flag_and_its_values() {
    let scene = [
        "scene",
        "heavy-chain",
        "--spine",
        "rod",
        "--joints",
        "exact",
    ];
    let reproduce = ["reproduce", "--joints", "Direct"];
    for args in [&scene[..], &reproduce[..]] {
        for expected in ["--joints", "iterative", "direct"] {
            fails_with(args, expected);
        }
    }
}

/// `reproduce --joints direct` writes to `out-direct` unless told, beside
/// the iterative run's `out`: here a file in its way is named.
#[test]
fn reproduce_with_direct_joints_writes_beside_the_iterative_run() {
    let dir = std::env::temp_dir().join(format!("vertebra-cli-direct-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["out", "out-direct"] {
        std::fs::write(dir.join(name), "in the way").unwrap();
    }
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_vertebra"))
            .args(args)
            .current_dir(&dir)
            .output()
            .expect("the binary runs");
        assert_ne!(out.status.code(), Some(0), "{args:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let direct = run(&["reproduce", "--joints", "direct"]);
    assert!(
        direct.contains("cannot write the results: out-direct: "),
        "{direct}"
    );
    let iterative = run(&["reproduce"]);
    assert!(
        iterative.contains("cannot write the results: out: "),
        "{iterative}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `reproduce`'s progress is drawn only on a terminal: run with stderr
/// into a pipe (a log file, CI), it writes no carriage returns and no bar
/// (the hand-written bar it replaced wrote one `\r` line per seed). The
/// same run writes figure 1 for both spines, and side views of every
/// ragdoll: the drop's 30 in 30 colours.
#[test]
fn reproduce_writes_figure_1_and_every_ragdoll_and_no_progress_into_a_pipe() {
    let out = std::env::temp_dir().join(format!("vertebra-progress-{}", std::process::id()));
    let (code, _, stderr) =
        vertebra(&["reproduce", "--seeds", "1", "--out", out.to_str().unwrap()]);
    let read = |name: &str| std::fs::read(out.join(name));
    let figures = ["figure1-rod.png", "figure1-sockets.png"].map(read);
    let poses = ["ragdoll-drop-poses.svg", "passive-bending-poses.svg"].map(read);
    std::fs::remove_dir_all(&out).ok();
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains('\r'), "{stderr:?}");
    assert!(!stderr.contains("seeds"), "{stderr:?}");
    for figure in figures {
        let png = resvg::tiny_skia::Pixmap::decode_png(&figure.expect("figure 1 written"))
            .expect("a PNG");
        assert_eq!((png.width(), png.height()), (1200, 800));
        let colours: std::collections::HashSet<_> = png
            .pixels()
            .iter()
            .map(|p| (p.red(), p.green(), p.blue()))
            .collect();
        assert!(
            colours.len() > 1000,
            "shaded, in many colours: {}",
            colours.len()
        );
    }
    let strokes = |svg: &[u8]| {
        let svg = String::from_utf8_lossy(svg);
        let colours: std::collections::HashSet<String> = svg
            .split("stroke=\"")
            .skip(1)
            .map(|s| s[..s.find('"').unwrap()].to_owned())
            .collect();
        colours
    };
    let [drop, bending] = poses.map(|p| strokes(&p.expect("side views written")));
    assert_eq!(drop.len(), 30, "{drop:?}");
    assert_eq!(bending, ["blue", "red"].map(String::from).into());
}

/// `vertebra ARGS` with a guard: a run still going after `limit` is
/// killed and reported as `None` (a hang fails the test instead of
/// hanging it); otherwise its exit code and stderr.
fn vertebra_guarded(args: &[&str], limit: std::time::Duration) -> Option<(i32, String)> {
    use std::io::Read as _;
    let mut child = Command::new(env!("CARGO_BIN_EXE_vertebra"))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("waits") {
            let mut stderr = String::new();
            child
                .stderr
                .take()
                .expect("piped")
                .read_to_string(&mut stderr)
                .unwrap();
            return Some((status.code().unwrap_or(-1), stderr));
        }
        if start.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// Every path of the command that reads a file (`check FILE`, `check
/// --skeleton FILE`, `scene --ragdoll FILE`) goes through the one reader,
/// which refuses anything but a regular file without opening it: opening
/// a FIFO (to tell a ragdoll from a skeleton file, say) would wait for a
/// writer for ever.
#[test]
fn every_file_the_command_reads_is_refused_when_it_is_a_fifo() {
    let dir = std::env::temp_dir().join(format!("vertebra-cli-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("f.toml");
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success(), "mkfifo {}", fifo.display());
    let fifo = fifo.to_str().unwrap().to_owned();
    let generator = dir.join("generator.toml");
    std::fs::write(
        &generator,
        "name = \"g\"\n[[body]]\nbone = \"hips\"\nradius = 0.1\nmass = 10.0\nlength = 0.2\n",
    )
    .unwrap();
    let generator = generator.to_str().unwrap().to_owned();
    let scene = scene_with(&["--ragdoll", &fifo]);
    let cases: [(Vec<&str>, &str); 3] = [
        (vec!["check", &fifo], "ragdoll"),
        (vec!["check", &generator, "--skeleton", &fifo], "skeleton"),
        (scene.iter().map(String::as_str).collect(), "ragdoll"),
    ];
    for (args, file) in &cases {
        let ran = vertebra_guarded(args, std::time::Duration::from_secs(60));
        let Some((code, stderr)) = ran else {
            std::fs::remove_dir_all(&dir).ok();
            panic!("{args:?} still ran after a minute: it opened the FIFO");
        };
        assert_eq!(code, 1, "{args:?}: {stderr}");
        let expected = format!(
            "vertebra: {fifo}: cannot read the {file} file: not a regular file (a directory, a device or a pipe)"
        );
        assert_eq!(stderr.trim(), expected, "{args:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--spine rod` on a ragdoll without a `[spine]` is refused naming the
/// file, the description and the missing table, rather than running the
/// standard ragdoll without a word. A scene whose own ragdoll has
/// no spine (the heavy chain) is refused the same way, by name.
#[test]
fn a_rod_spine_of_a_ragdoll_without_a_spine_is_refused_by_name() {
    let dir = std::env::temp_dir().join(format!("vertebra-cli-nospine-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let reference = include_str!("../../vertebra-ragdoll/models/humanoid.toml");
    let at = reference.find("\n[spine]").expect("a [spine] table");
    let file = dir.join("no-spine.toml");
    std::fs::write(&file, &reference[..at]).unwrap();
    let name = file.to_str().unwrap();
    let args = scene_with(&["--ragdoll", name, "--frames", "2"]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    fails_with(
        &args,
        &format!(
            "{name}: ragdoll `reference-humanoid`: spine is a rod (SpineMode::Rod), but the \
             description has no [spine] for one to replace; build it with SpineMode::Sockets, \
             or give it a [spine]"
        ),
    );
    let sockets = [
        "scene",
        "passive-bending",
        "--spine",
        "sockets",
        "--ragdoll",
        name,
        "--frames",
        "2",
    ];
    let (code, _, stderr) = vertebra(&sockets);
    assert_eq!(code, 0, "{stderr}");
    fails_with(
        &["scene", "heavy-chain", "--spine", "rod", "--frames", "2"],
        "ragdoll `heavy chain`: spine is a rod (SpineMode::Rod), but the description has no \
         [spine] for one to replace",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A refused `reproduce` (`--seeds 0`, or more than a run may take)
/// leaves no empty output directory behind: everything the command is
/// given is checked before anything is written.
#[test]
fn a_refused_reproduce_leaves_no_output_directory() {
    let dir = std::env::temp_dir().join(format!("vertebra-cli-refused-{}", std::process::id()));
    for seeds in ["0", "10001"] {
        let out = dir.join(format!("seeds-{seeds}"));
        let out_name = out.to_str().unwrap();
        fails_with(
            &["reproduce", "--seeds", seeds, "--out", out_name],
            &format!("seeds is {seeds} from seed 0; must be 1 to 10000"),
        );
        assert!(!out.exists(), "--seeds {seeds} made {out_name}");
    }
    assert!(!dir.exists(), "{}", dir.display());
}
