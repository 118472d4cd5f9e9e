//! Each scene, both ways, checked for its physics.

use glam::Vec3;
use vertebra_ragdoll::{RagdollDesc, SpineMode};
use vertebra_scenes::{Comparison, Quantity, Scene, SceneConfig, Seeded, compare, kinematics, run};

const BOTH: [SpineMode; 2] = [SpineMode::Sockets, SpineMode::Rod];

#[test]
fn passive_bending_slumps_to_the_spine_limits() {
    let desc = RagdollDesc::reference_humanoid();
    let (hips, chest) = (desc.root, desc.body_index("chest").unwrap());
    let mut errors = Vec::new();
    for spine in BOTH {
        let r = run(&SceneConfig::new(Scene::PassiveBending, spine), |_, _| {}).unwrap();
        let last = &r.snapshots.last().unwrap()[0];
        // The bend between hips and chest: the sum of the three spine
        // joints' 20 degree cones, and the rod's 60 degree limit.
        let bend = (last.bones[hips].1 * Vec3::Y)
            .angle_between(last.bones[chest].1 * Vec3::Y)
            .to_degrees();
        eprintln!("{spine:?}: bend {bend:.1} degrees");
        assert!(
            bend > 57.0,
            "{spine:?}: the upper body slumps to the limits ({bend} degrees)"
        );
        // The rod holds its limit; the socket chain overshoots by its
        // residual error (about 5 degrees at 20 iterations: figure 8).
        let overshoot = if spine == SpineMode::Rod { 3.0 } else { 8.0 };
        assert!(bend < 60.0 + overshoot, "{spine:?}: {bend} degrees");
        // Forward: the chest ends up ahead of the hips (+Z).
        assert!(last.bones[chest].0.z > last.bones[hips].0.z + 0.2);
        errors.push(r.frames.iter().map(|f| f.eps_lin_cm).sum::<f32>());
    }
    assert!(
        errors[1] < errors[0] / 2.0,
        "the rod's residual error is far lower (figure 8, left): {errors:?}"
    );
}

#[test]
fn nothing_leaves_the_pit_in_the_ragdoll_drop() {
    for spine in BOTH {
        let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
        config.frames = Some(240);
        let r = run(&config, |_, _| {}).unwrap();
        assert_eq!(
            r.final_positions.iter().map(|p| p.0).max(),
            Some(29),
            "30 ragdolls"
        );
        for &(k, p) in &r.final_positions {
            assert!(
                p.x.abs() < 1.5 && p.z.abs() < 1.5,
                "{spine:?}: ragdoll {k} left the pit: {p}"
            );
            assert!(
                p.y > 0.0 && p.y < 2.0,
                "{spine:?}: ragdoll {k} fell through or floats: {p}"
            );
        }
    }
}

#[test]
fn the_driven_ragdoll_returns_after_the_push() {
    let mut settled = Vec::new();
    for spine in BOTH {
        let r = run(&SceneConfig::new(Scene::Controllability, spine), |_, _| {}).unwrap();
        let pushed = r.frames[30..90]
            .iter()
            .map(|f| f.deviation_cm)
            .fold(0.0, f32::max);
        let end = r.frames.last().unwrap().deviation_cm;
        eprintln!("{spine:?}: deviation {pushed:.2} cm while pushed, {end:.3} cm at the end");
        assert!(pushed > 1.0, "{spine:?}: the push moves it");
        assert!(
            end < 0.2 * pushed,
            "{spine:?}: it returns ({end} cm of {pushed} cm)"
        );
        settled.push(r.frames[90..].iter().map(|f| f.deviation_cm).sum::<f32>());
    }
    assert!(
        settled[1] < settled[0],
        "the rod spine holds its pose better (figure 7): {settled:?}"
    );
}

#[test]
fn kinematics_loci_approach_the_rod() {
    let locus = kinematics(0.45, 60f32.to_radians(), 31);
    let gaps: Vec<f32> = locus.chains.iter().map(|c| c.2).collect();
    assert!(
        gaps[0] > gaps[1] && gaps[1] > gaps[2] && gaps[2] > gaps[3],
        "{gaps:?}"
    );
    assert!(gaps[4] > 10.0 * gaps[2], "unequal angles: {gaps:?}");
    // Straight, every chain ends where the rod does: 0.45 m up.
    assert!((locus.rod[0][1] - 0.45).abs() < 1e-6);
}

#[test]
fn runs_are_deterministic_and_backend_independent() {
    let mut config = SceneConfig::new(Scene::PassiveBending, SpineMode::Rod);
    config.frames = Some(60);
    let reference = run(&config, |_, _| {}).unwrap().state_hash;
    for backend in vertebra_math::Backend::available() {
        config.backend = vertebra_world::BackendChoice::Forced(backend);
        assert_eq!(
            run(&config, |_, _| {}).unwrap().state_hash,
            reference,
            "{backend}"
        );
    }
}

/// Figure 8, right: smaller than passive bending, but consistent. The pile
/// is chaotic, so the claim is checked over eight seeded starts, seed by
/// seed: the rod's mean errors are lower in at least seven, and by 5% or
/// more at the median (`docs/reproduction.md` gives the spread over 16).
#[test]
fn the_rod_ragdolls_drop_with_less_joint_error() {
    let seeded =
        |spine| Seeded::run(&SceneConfig::new(Scene::RagdollDrop, spine), 8, |_, _| {}).unwrap();
    let (sockets, rod) = (seeded(SpineMode::Sockets), seeded(SpineMode::Rod));
    for quantity in [Quantity::EpsLin, Quantity::EpsAng] {
        let each: Vec<f32> = sockets
            .runs
            .iter()
            .zip(&rod.runs)
            .map(|(s, r)| Comparison::of(s, r, quantity).ratio)
            .collect();
        eprintln!("drop, sockets over rod, {quantity}: {each:?}");
        assert!(
            each.iter().filter(|&&x| x > 1.0).count() >= 7,
            "{quantity}: {each:?}"
        );
        assert!(
            compare(&sockets, &rod, quantity).0.median > 1.05,
            "{quantity}: {each:?}"
        );
    }
}

/// A seeded start is another start (every scene, each spine it takes), the same on
/// every backend and at two threads; seed 0 is the paper's scene, whose
/// bits the golden hashes hold.
#[test]
fn seeds_give_other_starts_the_same_everywhere() {
    for scene in Scene::ALL {
        for &spine in scene.spines() {
            let hash = |seed: u64, backend, threads| {
                let mut config = SceneConfig::new(scene, spine);
                config.frames = Some(20);
                config.seed = seed;
                config.backend = backend;
                config.threads = threads;
                run(&config, |_, _| {}).unwrap().state_hash
            };
            let auto = vertebra_world::BackendChoice::Auto;
            let seeded = hash(1, auto, 1);
            assert_ne!(seeded, hash(0, auto, 1), "{scene} {spine:?}");
            assert_ne!(seeded, hash(2, auto, 1), "{scene} {spine:?}");
            for backend in vertebra_math::Backend::available() {
                let forced = vertebra_world::BackendChoice::Forced(backend);
                assert_eq!(hash(1, forced, 2), seeded, "{scene} {spine:?} {backend}");
            }
        }
    }
}

/// Every seeded placement stays within 1 mm and 0.1 degree.
#[test]
fn seeded_starts_are_small() {
    use vertebra_scenes::seed::{MAX_OFFSET, MAX_TURN, perturbation};
    for seed in 1..200u64 {
        for index in 0..30 {
            let (offset, turn) = perturbation(seed, index);
            assert!(offset.y == 0.0 && offset.abs().max_element() <= MAX_OFFSET);
            let (axis, angle) = turn.to_axis_angle();
            assert!(angle <= MAX_TURN * 1.001 && (angle == 0.0 || axis.y.abs() > 0.999));
        }
    }
    assert_eq!(perturbation(0, 7), (glam::Vec3::ZERO, glam::Quat::IDENTITY));
}
