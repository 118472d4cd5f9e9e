//! Golden state hashes: fixed scenes, a fixed number of frames, every
//! backend this CPU has and one and two threads, against hashes committed
//! here, the same on x86-64, AArch64 and WebAssembly. The cross-backend tests compare backends with each other inside
//! one build; these catch a change that moves every backend the same way.
//!
//! When a golden hash may change: only when a change is meant to change
//! what the solver computes (a new rounding, a reordered sum, a different
//! part order), never as a side effect of a refactor, and never to make a
//! failing test pass without knowing why. The update goes in a commit of
//! its own whose message says which change moved the bits and why that is
//! intended; the scenes' figures (`docs/reproduction.md`) are rechecked in
//! the same commit.

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

// The anatomical drop's, set by the commit that introduced them: its
// elliptical sockets, hinges and rod through both solves.
const GOLDEN_ANATOMICAL_SOCKETS: u64 = 0x8956_dae4_0c5d_c4bb;
const GOLDEN_ANATOMICAL_ROD: u64 = 0xe17f_cac9_f0a4_ed67;
const GOLDEN_ANATOMICAL_SOCKETS_DIRECT: u64 = 0x5fff_c5e6_5fb8_46f4;
const GOLDEN_ANATOMICAL_ROD_DIRECT: u64 = 0xb36d_d5f6_47c9_e263;

// The direct solve's, as the current direct solve steps the paper's
// scenes. Each time one moved, the commit that moved it, alone, says why
// and what it was (`git log -G "GOLDEN_.*_DIRECT: u64"`).
const GOLDEN_BENDING_SOCKETS_DIRECT: u64 = 0x2636_906e_671c_b1e1;
const GOLDEN_BENDING_ROD_DIRECT: u64 = 0x7bb4_b6ec_3042_0e2d;
const GOLDEN_DROP_SOCKETS_DIRECT: u64 = 0x3070_1f12_587a_75ea;
const GOLDEN_DROP_ROD_DIRECT: u64 = 0x8072_15bf_128f_98ab;

// Set 2026-11-29 by the commit that introduced them (issue 13), on the
// state the whole issue left: displacement rows, double-precision
// coordinates, the rod's wrapped twist, the lineage-free state hash.
// Passive bending's two updated 2026 by the drives (issue 15): the hips'
// pin is a drive, and the hashed socket description gained the drive's
// target velocity, strength and torque limit. Every body's state is the
// same bits as before: hashing the old description's fields instead gave
// the old values. The two rod hashes updated by the rod drives (issue 15):
// the hashed rod description gained `max_torque` (and the stiffness two
// variants). The bodies' bits are unchanged: with `max_torque` left out of
// the serialisation the old hashes came back on every backend and thread
// count (undriven rods take the old correction bit for bit).
const GOLDEN_BENDING_SOCKETS: u64 = 0x8d73_20b5_ddd0_c4c2;
const GOLDEN_BENDING_ROD: u64 = 0xd84b_b822_c089_a836;
const GOLDEN_DROP_SOCKETS: u64 = 0x5dea_866b_e280_42f8;
const GOLDEN_DROP_ROD: u64 = 0x3acc_fc06_e929_3ed0;
// The drop's two updated 2026-11-30 by the contact fix (issue 17): a
// contact's corrections act through the step's first lever arms, not the
// turned ones (a capsule lying on the ground spun up about its axis);
// they were 0x3ba1_35df_40d4_a94e (sockets) and 0x347d_fa1b_5a96_7063
// (rod) with that fix alone. Then all four by islands (issue 17): the
// state hash covers every body's island, stillness and anchor and every
// island's flags. Passive bending's bodies are the same bits: with the
// islands left out of the hash its old values came back, on every
// backend and thread count; so did the drop's contact-fix values.
// Then all four by issue 17's cheaper kernels (merged after): a
// correction's weight and turn now come from one rotation of its axis into
// the body (`body::Response`), the turn is applied in the body frame
// (`q + 1/2 q (S u dlambda, 0)`, the same turn as before in other
// roundings), the socket's swing and twist are measured in the bodies'
// frames, frames' axes are matrix columns, the fixed joint's lock is solved
// in a's frame, and the rod's twist takes an unnormalised half-way
// quaternion. Every backend and thread count still gives one hash (with
// the contact fix and the islands: checked by this test at the merge).
// Then three by issue 17's frames (kernels17c, 2026-11-30): the rod's
// bend, twist, limits and length are measured in a's body frame (other
// roundings of the same angles), and the angular drive is solved in a's
// body frame, its start error and multiplier held there (the damping no
// longer sees a rigid turn of the pair as a rate). The drop with sockets
// has no drive and no rod: its hash is unchanged. They were
// 0xba45_2624_d2f6_d6b3 (bending, sockets: the hips' pin is a drive),
// 0xe98b_653e_d246_c735 (bending, rod) and 0x0f2e_e7c8_ad79_1507 (drop,
// rod). Then all four by the stillness in double precision (2026-11-30:
// in single precision a long sleep time was reached late or never): the
// hash covers every body's stillness, now eight bytes wide. The scenes do
// not sleep, so no stillness is ever added to and every body's motion is
// the same bits; they were 0xd058_d104_f861_b247 (bending, sockets),
// 0x026b_981b_3467_eb81 (bending, rod), 0xb16f_5ecf_f1ec_b012 (drop,
// sockets) and 0x2876_b9bc_0f6f_67fd (drop, rod).
