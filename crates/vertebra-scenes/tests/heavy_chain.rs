//! The heavy chain (8 links of 1 kg, a 1000 kg body at the end, hanging
//! from a fixed anchor): under the iterative joint solve the mass ratio
//! across the last joint stretches the chain by metres; the direct solve
//! holds it together, at the same 1 substep.

use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{HEAVY_MASS, LINK_MASS, LINKS, Quantity, Scene, SceneConfig, build, run};
use vertebra_world::JointSolver;

/// The heavy body's centre at rest, the chain unstretched (m): the anchor
/// at 3 m, eight links of 0.25 m, half the heavy body's 0.3 m core.
const REST_HEIGHT: f32 = 3.0 - 8.0 * 0.25 - 0.15;

#[test]
fn the_iterative_solve_lets_the_heavy_chain_stretch() {
    assert_eq!((LINKS, HEAVY_MASS / LINK_MASS), (8, 1000.0));
    let config = SceneConfig::new(Scene::HeavyChain, SpineMode::Sockets);
    assert_eq!(config.joints, JointSolver::Iterative);
    let r = run(&config, |_, _| {}).unwrap();
    let lin = r.stats(Quantity::EpsLin);
    eprintln!(
        "heavy chain, iterative 1x20: separation mean {} cm, max {} cm, final {} cm",
        lin.mean, lin.max, lin.last
    );
    // Measured 106 cm (max 210 cm): a clear failure, far above the 1 cm
    // the direct solve must reach.
    assert!(lin.mean > 50.0, "mean separation {} cm", lin.mean);
    // The separation is the chain stretching: the heavy body hangs lower
    // than the unstretched chain holds it, by about the final separation.
    let heavy = r.final_positions.last().unwrap().1;
    let sag_cm = (REST_HEIGHT - heavy.y) * 100.0;
    assert!(
        (sag_cm - lin.last).abs() < 0.1 * lin.last,
        "sag {sag_cm} cm, separation {} cm",
        lin.last
    );
}

#[test]
fn the_direct_solve_holds_the_heavy_chain_together() {
    let mut config = SceneConfig::new(Scene::HeavyChain, SpineMode::Sockets);
    config.joints = JointSolver::Direct;
    let r = run(&config, |_, _| {}).unwrap();
    let lin = r.stats(Quantity::EpsLin);
    // The target is 1 cm at 1 substep; measured under 1e-4 cm.
    assert!(lin.max < 0.01, "max separation {} cm", lin.max);
    // The heavy body hangs where the unstretched chain holds it.
    let heavy = r.final_positions.last().unwrap().1;
    assert!((REST_HEIGHT - heavy.y).abs() < 1e-3, "at {}", heavy.y);
}

#[test]
fn the_heavy_chain_counts_every_joint_and_refuses_another_ragdoll() {
    // No spine: a rod spine is refused by the chain's name.
    let rod = SceneConfig::new(Scene::HeavyChain, SpineMode::Rod);
    let refused = build(&rod).err().unwrap().to_string();
    assert!(
        refused.starts_with("ragdoll `heavy chain`: spine is a rod"),
        "{refused}"
    );
    assert_eq!(Scene::HeavyChain.spines(), [SpineMode::Sockets]);
    let mut config = SceneConfig::new(Scene::HeavyChain, SpineMode::Sockets);
    let mut scene = build(&config).unwrap();
    assert_eq!(scene.ragdolls[0].rod, None);
    let r = scene.world.measure_residuals();
    assert_eq!(
        r.joints.len(),
        LINKS + 1,
        "the hanging socket and the chain's"
    );
    config.ragdoll = Some(vertebra_ragdoll::RagdollDesc::reference_humanoid());
    let refused = build(&config).err().unwrap().to_string();
    assert!(refused.contains("ragdoll"), "{refused}");
}
