//! The substepped pile comes to rest (issue 14; docs/contacts.md, "The
//! jammed pile").

use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneConfig, run};

#[test]
fn a_substepped_pile_comes_to_rest_in_its_pit() {
    // 20 substeps x 5 iterations from seed 1. When an overlap found at
    // detection was removed in the first substep, bodies came out at
    // overlap / h (20 times faster than at one substep): the pile boiled
    // at up to 57 m/s for all 600 frames, ragdolls were thrown out of the
    // pit, and ragdoll 3's left forearm was fired into the wall, past its
    // middle, where the wall pushed it out the far side while its upper
    // arm was pushed back in: 4.85 cm of elbow separation, frame after
    // frame.
    let mut config = SceneConfig::new(Scene::RagdollDrop, SpineMode::Sockets);
    config.substeps = 20;
    config.iterations = 5;
    config.seed = 1;
    let r = run(&config, |_, _| {}).unwrap();
    for &(k, p) in &r.final_positions {
        assert!(
            p.x.abs() < 1.5 && p.z.abs() < 1.5 && p.y > 0.0 && p.y < 2.0,
            "ragdoll {k} left the pit: {p}"
        );
    }
    let last: Vec<f32> = r
        .frames
        .iter()
        .rev()
        .take(100)
        .map(|f| f.eps_lin_cm)
        .collect();
    let at_rest = last.iter().sum::<f32>() / last.len() as f32;
    eprintln!("summed joint separation over the last 100 frames: {at_rest:.3} cm");
    assert!(
        at_rest < 1.0,
        "the pile holds {at_rest} cm of joint separation"
    );
}
