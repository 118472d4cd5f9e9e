//! The C and C++ examples, compiled with the system's compilers against
//! the static library this test was built with, and run: their output is
//! the Rust API's on the same scene, bit for bit; and the C one runs clean
//! under the address and undefined-behaviour sanitizers.
//!
//! Where no C (or C++) compiler exists, or it cannot build with the
//! sanitizers, the test prints why and passes: there is nothing to run.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use glam::Vec3;
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{BuildOptions, Pose, RagdollDesc, SpineMode};
use vertebra_world::{BodyDesc, SolverConfig, World};

fn crate_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn humanoid() -> PathBuf {
    crate_dir().join("../vertebra-ragdoll/models/humanoid.toml")
}

/// The static library cargo built beside this test.
fn static_library() -> PathBuf {
    let exe = std::env::current_exe().expect("the test's path");
    exe.parent().expect("deps").join("libvertebra_capi.a")
}

/// The libraries a Rust static library needs on this system (as `rustc
/// --print native-static-libs` lists them).
const SYSTEM_LIBRARIES: [&str; 7] = [
    "-lgcc_s",
    "-lutil",
    "-lrt",
    "-lpthread",
    "-lm",
    "-ldl",
    "-lc",
];

/// The compiler named by `variable` (`CC`, `CXX`) or the first of `names`
/// that runs.
fn compiler(variable: &str, names: &[&str]) -> Option<String> {
    let named = std::env::var(variable).ok();
    named
        .into_iter()
        .chain(names.iter().map(|s| s.to_string()))
        .find(|c| {
            Command::new(c)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        })
}

/// Compiles `source` with `flags` into an executable in a fresh directory.
fn build(compiler: &str, source: &str, flags: &[&str], name: &str) -> Result<PathBuf, String> {
    let dir = std::env::temp_dir().join(format!("vertebra-capi-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let exe = dir.join(name);
    let output = Command::new(compiler)
        .args(flags)
        .arg("-I")
        .arg(crate_dir().join("include"))
        .arg(crate_dir().join("examples").join(source))
        .arg(static_library())
        .args(SYSTEM_LIBRARIES)
        .arg("-o")
        .arg(&exe)
        .output()
        .map_err(|e| e.to_string())?;
    match output.status.success() {
        true => Ok(exe),
        false => Err(String::from_utf8_lossy(&output.stderr).into_owned()),
    }
}

/// Runs an example on the humanoid's file: its standard output. The
/// example's directory is removed after the run (each executable holds the
/// whole static library, about 100 MB: left in the temporary directory,
/// every run of these tests filled the disk by half a gigabyte).
fn run(exe: &Path) -> String {
    let output = Command::new(exe)
        .arg(humanoid())
        .output()
        .expect("run the example");
    if let Some(dir) = exe.parent() {
        // A directory left behind costs disk, not a result.
        let _ = std::fs::remove_dir_all(dir);
    }
    assert!(
        output.status.success(),
        "{} failed: {}",
        exe.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).expect("UTF-8")
}

/// The examples' program through the Rust API: what they must print.
fn rust_twin() -> String {
    let dt = 1.0 / 60.0;
    let desc = RagdollDesc::from_file(&humanoid()).expect("the humanoid");
    let mut world = World::new(SolverConfig::default()).expect("a world");
    let mut collisions = Collisions::new();
    let ground = world.add_body(BodyDesc::fixed()).expect("ground");
    let mut plane = Collider::new(ground, ColliderShape::Plane(Vec3::Y));
    plane.friction = 0.6;
    collisions.add(plane).expect("the plane");
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, glam::Quat::IDENTITY, Vec3::Y * 0.5);
    let options = BuildOptions::new(SpineMode::Rod);
    let ragdoll = collisions
        .build_ragdoll(&mut world, &desc, options, &pose, None)
        .expect("the ragdoll");
    ragdoll
        .set_velocity(
            &mut world,
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(2.0, 0.0, 0.0),
        )
        .expect("a velocity");
    let hips = ragdoll.bodies[desc.body_index("hips").expect("hips")].expect("a body");
    let mut contacts = Vec::new();
    let mut text = String::new();
    for frame in 1..=4 * 60 {
        collisions
            .find_contacts_into(&world, dt, &mut contacts)
            .expect("contacts");
        world.swap_contacts(&mut contacts).expect("contacts");
        world.step(dt).expect("a step");
        if frame % 60 == 0 {
            let p = world.body(hips).expect("hips").position;
            let [x, y, z] = [p.x, p.y, p.z];
            let (bx, by, bz) = (x.to_bits(), y.to_bits(), z.to_bits());
            writeln!(
                text,
                "t={} s hips {x:.6} {y:.6} {z:.6} [{bx:08x} {by:08x} {bz:08x}]",
                frame / 60
            )
            .expect("a line");
        }
    }
    writeln!(text, "state hash {:016x}", world.state_hash()).expect("a line");
    text
}

#[test]
fn the_twin_moves_the_hips() {
    // The comparison below means something only if the hips move: they
    // fall from about 1.5 m and come to rest on the ground.
    let twin = rust_twin();
    let heights: Vec<f32> = twin
        .lines()
        .filter(|l| l.starts_with("t="))
        .map(|l| {
            l.split_whitespace()
                .nth(4)
                .expect("y")
                .parse()
                .expect("a number")
        })
        .collect();
    assert_eq!(heights.len(), 4);
    assert!(heights.iter().all(|&y| (0.0..0.5).contains(&y)), "{twin}");
}

#[test]
fn the_c_example_prints_what_the_rust_api_computes() {
    let Some(cc) = compiler("CC", &["cc", "gcc", "clang"]) else {
        println!("skipped: no C compiler (cc, gcc, clang or $CC) on this machine");
        return;
    };
    let flags = ["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic"];
    let exe = build(&cc, "drop.c", &flags, "drop").expect("the C example builds");
    assert_eq!(run(&exe), rust_twin());
}

#[test]
fn the_cpp_example_prints_what_the_rust_api_computes() {
    let Some(cxx) = compiler("CXX", &["c++", "g++", "clang++"]) else {
        println!("skipped: no C++ compiler (c++, g++, clang++ or $CXX) on this machine");
        return;
    };
    let flags = ["-std=c++17", "-Wall", "-Wextra", "-Werror", "-pedantic"];
    let exe = build(&cxx, "drop.cpp", &flags, "drop_cpp").expect("the C++ example builds");
    assert_eq!(run(&exe), rust_twin());
}

/// Flags for a build under the address and undefined sanitizers.
const SANITIZED: [&str; 5] = [
    "-std=c11",
    "-g",
    "-fsanitize=address,undefined",
    "-fno-sanitize-recover=all",
    "-fno-omit-frame-pointer",
];

/// The C example `source` built under the sanitizers, or `None` (with
/// the reason printed) where no C compiler or no sanitizer runtime exists.
fn sanitized(source: &str, name: &str) -> Option<PathBuf> {
    let Some(cc) = compiler("CC", &["cc", "gcc", "clang"]) else {
        println!("skipped: no C compiler on this machine");
        return None;
    };
    match build(&cc, source, &SANITIZED, name) {
        Ok(exe) => Some(exe),
        Err(why) if why.contains("asan") || why.contains("ubsan") || why.contains("sanitize") => {
            println!("skipped: {cc} cannot build with the sanitizers here: {why}");
            None
        }
        Err(why) => panic!("{source} does not build under the sanitizers: {why}"),
    }
}

#[test]
fn the_c_example_runs_clean_under_the_sanitizers() {
    if let Some(exe) = sanitized("drop.c", "drop_sanitized") {
        assert_eq!(run(&exe), rust_twin());
    }
}

/// What the error-paths example prints last: every check passed.
fn all_refusals_passed(output: &str) -> bool {
    output
        .lines()
        .last()
        .is_some_and(|l| l.starts_with("all ") && l.ends_with(" refusals as documented"))
}

#[test]
fn the_c_error_paths_are_refused_as_documented() {
    let Some(cc) = compiler("CC", &["cc", "gcc", "clang"]) else {
        println!("skipped: no C compiler (cc, gcc, clang or $CC) on this machine");
        return;
    };
    let flags = ["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic"];
    let exe = build(&cc, "errors.c", &flags, "errors").expect("the C error example builds");
    let output = run(&exe);
    assert!(all_refusals_passed(&output), "{output}");
}

#[test]
fn the_c_error_paths_run_clean_and_free_everything_under_the_sanitizers() {
    let Some(exe) = sanitized("errors.c", "errors_sanitized") else {
        return;
    };
    // The leak checker is on by default with the address sanitizer; a
    // leak makes the run fail.
    let output = run(&exe);
    assert!(all_refusals_passed(&output), "{output}");
}
