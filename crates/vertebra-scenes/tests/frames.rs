//! A run's frame count is bounded: no count panics or aborts. Its frames
//! are the scene's own, and the frame's own time is part of the loop's.

use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{FRAME_DT, MAX_FRAMES, Scene, SceneConfig, build, run};

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

/// `run` times the frame alone (`SceneWorld::frame`) and watches it
/// after: its frames are those of `SceneWorld::advance` (frame, then the
/// residuals) measured frame by frame, bit for bit, and `frame_ms` is a
/// part of `ms_per_step`, the whole loop.
#[test]
fn a_run_times_the_frame_alone_and_measures_what_advance_gives() {
    for scene in [Scene::PassiveBending, Scene::RagdollDrop] {
        let mut config = SceneConfig::new(scene, SpineMode::Rod);
        config.frames = Some(20);
        let ran = run(&config, |_, _| {}).expect("the scene runs");
        assert!(
            ran.frame_ms > 0.0 && ran.frame_ms <= ran.ms_per_step,
            "{scene}: frame {} ms of a loop of {} ms",
            ran.frame_ms,
            ran.ms_per_step
        );
        let mut built = build(&config).expect("the scene builds");
        for (frame, measured) in ran.frames.iter().enumerate() {
            built.advance(scene, frame, FRAME_DT).expect("a frame");
            let again = built.measure(&built.world);
            assert_eq!(
                format!("{again:?}"),
                format!("{measured:?}"),
                "{scene}, frame {frame}"
            );
        }
        assert_eq!(built.world.state_hash(), ran.state_hash, "{scene}");
    }
}
