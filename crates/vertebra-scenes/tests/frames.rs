//! A run's frame count is bounded: no count panics or aborts.

use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{MAX_FRAMES, Scene, SceneConfig, run};

#[test]
fn frame_counts_out_of_range_are_refused_before_anything_runs() {
    for frames in [0, MAX_FRAMES + 1, 1_000_000_000_000, usize::MAX] {
        let mut config = SceneConfig::new(Scene::PassiveBending, SpineMode::Rod);
        config.frames = Some(frames);
        let error = run(&config, |_, _| {}).expect_err("refused");
        assert_eq!(
            error.to_string(),
            format!("scene: frames is {frames}; must be 1 to {MAX_FRAMES}")
        );
    }
}
