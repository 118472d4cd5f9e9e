//! Golden state hashes: fixed scenes, a fixed number of frames, every
//! backend this CPU has and one and two threads, against hashes committed
//! here, the same on x86-64, AArch64 and WebAssembly. The cross-backend
//! tests compare backends with each other inside one build; these catch a
//! change that moves every backend the same way.
//!
//! A golden hash moves only in a commit of its own that says why: only
//! when a change is meant to change what the solver computes (a new
//! rounding, a reordered sum, a different part order, a new piece of
//! hashed state), never as a side effect of a refactor, and never to make
//! a failing test pass without knowing why. The scenes' figures
//! (`docs/reproduction.md`) are rechecked in the same commit. Why each
//! hash is what it is stays in those commits:
//! `git log -G GOLDEN_ -- crates/vertebra-scenes/tests/golden.rs`.

use vertebra_math::Backend;
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneConfig, run};
use vertebra_world::{BackendChoice, JointSolver};

/// Frames each scene runs for its hash: two seconds at 60 Hz.
const FRAMES: usize = 120;

/// Worker threads each hash is checked at: one and two on x86-64, one
/// elsewhere. The same hashes hold on every architecture: CI runs this
/// test under qemu-aarch64 and Node's WASI too (`.ci/run`), where the
/// second thread count would double the emulated time (wasm32-wasip1 has
/// no threads at all); results across thread counts are the scheduler's
/// and task systems' property, checked here on x86-64.
const THREADS: &[usize] = if cfg!(target_arch = "x86_64") {
    &[1, 2]
} else {
    &[1]
};

fn check(scene: Scene, spine: SpineMode, golden: u64) {
    check_solved(scene, spine, JointSolver::Iterative, golden);
}

fn check_solved(scene: Scene, spine: SpineMode, joints: JointSolver, golden: u64) {
    for backend in Backend::available() {
        for &threads in THREADS {
            let mut config = SceneConfig::new(scene, spine);
            config.joints = joints;
            config.frames = Some(FRAMES);
            config.backend = BackendChoice::Forced(backend);
            config.threads = threads;
            let hash = run(&config, |_, _| {}).expect("the scene runs").state_hash;
            assert_eq!(
                hash, golden,
                "{scene} ({spine:?}, {joints:?}) on {backend} with {threads} threads: {hash:#018x}"
            );
        }
    }
}

#[test]
fn passive_bending_sockets() {
    check(
        Scene::PassiveBending,
        SpineMode::Sockets,
        GOLDEN_BENDING_SOCKETS,
    );
}

#[test]
fn passive_bending_rod() {
    check(Scene::PassiveBending, SpineMode::Rod, GOLDEN_BENDING_ROD);
}

#[test]
fn ragdoll_drop_sockets() {
    check(Scene::RagdollDrop, SpineMode::Sockets, GOLDEN_DROP_SOCKETS);
}

#[test]
fn ragdoll_drop_rod() {
    check(Scene::RagdollDrop, SpineMode::Rod, GOLDEN_DROP_ROD);
}

#[test]
fn passive_bending_direct() {
    let (scene, direct) = (Scene::PassiveBending, JointSolver::Direct);
    check_solved(
        scene,
        SpineMode::Sockets,
        direct,
        GOLDEN_BENDING_SOCKETS_DIRECT,
    );
    check_solved(scene, SpineMode::Rod, direct, GOLDEN_BENDING_ROD_DIRECT);
}

#[test]
fn ragdoll_drop_sockets_direct() {
    let (scene, direct) = (Scene::RagdollDrop, JointSolver::Direct);
    check_solved(
        scene,
        SpineMode::Sockets,
        direct,
        GOLDEN_DROP_SOCKETS_DIRECT,
    );
}

#[test]
fn ragdoll_drop_rod_direct() {
    let (scene, direct) = (Scene::RagdollDrop, JointSolver::Direct);
    check_solved(scene, SpineMode::Rod, direct, GOLDEN_DROP_ROD_DIRECT);
}

#[test]
fn anatomical_drop_iterative() {
    let scene = Scene::AnatomicalDrop;
    check(scene, SpineMode::Sockets, GOLDEN_ANATOMICAL_SOCKETS);
    check(scene, SpineMode::Rod, GOLDEN_ANATOMICAL_ROD);
}

#[test]
fn anatomical_drop_direct() {
    let (scene, direct) = (Scene::AnatomicalDrop, JointSolver::Direct);
    check_solved(
        scene,
        SpineMode::Sockets,
        direct,
        GOLDEN_ANATOMICAL_SOCKETS_DIRECT,
    );
    check_solved(scene, SpineMode::Rod, direct, GOLDEN_ANATOMICAL_ROD_DIRECT);
}

// The anatomical drop: its elliptical sockets, hinges and rod through
// both solves.
const GOLDEN_ANATOMICAL_SOCKETS: u64 = 0x3e10_c32f_ff19_9d3d;
const GOLDEN_ANATOMICAL_ROD: u64 = 0x3d39_b9c2_d1c5_37eb;
const GOLDEN_ANATOMICAL_SOCKETS_DIRECT: u64 = 0x7716_ebb1_2518_1336;
const GOLDEN_ANATOMICAL_ROD_DIRECT: u64 = 0x513c_985b_4246_c33f;

// The paper's scenes, passive bending and the 30-ragdoll drop, each
// spine, solved directly.
const GOLDEN_BENDING_SOCKETS_DIRECT: u64 = 0x412e_010b_667f_27f3;
const GOLDEN_BENDING_ROD_DIRECT: u64 = 0x5943_886e_d66d_2748;
const GOLDEN_DROP_SOCKETS_DIRECT: u64 = 0x3070_1f12_587a_75ea;
const GOLDEN_DROP_ROD_DIRECT: u64 = 0x8072_15bf_128f_98ab;

// The same scenes solved iteratively.
const GOLDEN_BENDING_SOCKETS: u64 = 0x8d73_20b5_ddd0_c4c2;
const GOLDEN_BENDING_ROD: u64 = 0xd84b_b822_c089_a836;
const GOLDEN_DROP_SOCKETS: u64 = 0x5dea_866b_e280_42f8;
const GOLDEN_DROP_ROD: u64 = 0x3acc_fc06_e929_3ed0;
