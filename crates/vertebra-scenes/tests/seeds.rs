//! Scenes over seeded starts: the same runs as one at a time, their spread
//! and comparisons computed from the runs' own frames.

use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{
    Comparison, Frame, MAX_SEEDS, Quantity, Scene, SceneConfig, Seeded, Spread, compare, run,
};

fn config(scene: Scene, spine: SpineMode, frames: usize) -> SceneConfig {
    let mut config = SceneConfig::new(scene, spine);
    config.frames = Some(frames);
    config
}

#[test]
fn seeded_runs_are_the_runs_of_each_seed() {
    // Run in parallel, collected in seed order: each is bit for bit the
    // run of its own seed, from `config.seed` on.
    let mut c = config(Scene::PassiveBending, SpineMode::Rod, 30);
    c.seed = 5;
    let seeded = Seeded::run(&c, 4, |_, _| {}).unwrap();
    assert_eq!((seeded.first, seeded.runs.len()), (5, 4));
    for (k, r) in seeded.runs.iter().enumerate() {
        c.seed = 5 + k as u64;
        let alone = run(&c, |_, _| {}).unwrap();
        assert_eq!((r.state_hash, &r.frames), (alone.state_hash, &alone.frames));
    }
}

#[test]
fn bands_are_the_spread_of_each_frame() {
    let seeded = Seeded::run(
        &config(Scene::PassiveBending, SpineMode::Sockets, 20),
        3,
        |_, _| {},
    )
    .unwrap();
    let band = seeded.band(Quantity::EpsLin);
    assert_eq!(band.len(), 20);
    for (k, s) in band.iter().enumerate() {
        let mut x: Vec<f32> = seeded.runs.iter().map(|r| r.frames[k].eps_lin_cm).collect();
        x.sort_by(f32::total_cmp);
        // Three samples: the median is the middle one, the band the ends.
        assert_eq!(
            (s.median, s.range()),
            (f64::from(x[1]), (f64::from(x[0]), f64::from(x[2])))
        );
    }
    let means = seeded.spread(|r| r.stats(Quantity::EpsLin).mean);
    assert_eq!(means.count, 3);
    assert!(means.min <= means.median && means.median <= means.max);
}

#[test]
fn seed_counts_out_of_range_are_refused_by_name() {
    let c = config(Scene::PassiveBending, SpineMode::Rod, 10);
    for count in [0, MAX_SEEDS + 1] {
        let e = Seeded::run(&c, count, |_, _| {}).unwrap_err().to_string();
        assert!(e.contains("seeds"), "{e}");
    }
    // Seeds past u64::MAX, and more frames in all than the bound.
    let mut late = c.clone();
    late.seed = u64::MAX;
    assert!(Seeded::run(&late, 2, |_, _| {}).is_err());
    let mut long = c;
    long.frames = Some(vertebra_scenes::MAX_FRAMES);
    assert!(Seeded::run(&long, 11, |_, _| {}).is_err());
}

fn run_of(values: &[f32]) -> vertebra_scenes::SceneRun {
    let mut r = run(&config(Scene::PassiveBending, SpineMode::Rod, 1), |_, _| {}).unwrap();
    r.frames = values
        .iter()
        .map(|&eps_lin_cm| Frame {
            eps_lin_cm,
            ..Frame::default()
        })
        .collect();
    r
}

#[test]
fn a_comparison_counts_frames_and_divides_means() {
    // b is lower in frames 0 and 2 of four; a's mean 4, b's 2.
    let a = run_of(&[4.0, 1.0, 6.0, 5.0]);
    let b = run_of(&[1.0, 2.0, 0.0, 5.0]);
    assert_eq!(
        Comparison::of(&a, &b, Quantity::EpsLin),
        Comparison {
            ratio: 2.0,
            lower: 0.5
        }
    );
    // Seed by seed: two seeds' comparisons, spread.
    let two = |runs| Seeded { first: 0, runs };
    let (ratio, lower) = compare(
        &two(vec![a.clone(), a.clone()]),
        &two(vec![b, run_of(&[4.0, 1.0, 6.0, 5.0])]),
        Quantity::EpsLin,
    );
    assert_eq!(ratio, Spread::of([2.0, 1.0]));
    assert_eq!(lower, Spread::of([0.5, 0.0]));
}
