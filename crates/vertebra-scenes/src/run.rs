//! Running a scene and measuring it frame by frame.

use std::time::{Duration, Instant};

use vertebra_math::Backend;
use vertebra_ragdoll::{Pose, RagdollError, SpineMapping};

use crate::frame::Frame;
use crate::{Scene, SceneConfig, SceneWorld, build};
use vertebra_math::DefaultFloatMode;

/// The most frames a run takes: 4.6 hours at 60 Hz. A run keeps a record
/// per frame (20 bytes), reserved up front from the count, so the bound
/// keeps it (and the CLI's JSON, about 60 bytes a frame) under 100 MB;
/// without it a count near `usize::MAX` overflowed the reservation and
/// 1e12 frames aborted allocating 16 TB.
pub const MAX_FRAMES: usize = 1_000_000;

/// One frame's time step (s): every scene runs at 60 Hz.
pub const FRAME_DT: f32 = 1.0 / 60.0;

/// A finished run.
#[derive(Clone, Debug)]
pub struct SceneRun {
    /// What ran.
    pub scene: Scene,
    /// The backend it ran on.
    pub backend: Backend,
    /// Per frame.
    pub frames: Vec<Frame>,
    /// Mean wall time per frame of the whole frame loop (ms): the frame's
    /// own cost, the residual metric, the pose snapshots and the
    /// bookkeeping.
    pub ms_per_step: f64,
    /// Mean wall time per frame of the frame's own cost alone (ms):
    /// collision detection and `World::step`, nothing the scene does to
    /// watch it ([`SceneWorld::frame`]). What a game pays, and what is set
    /// against other engines' step.
    pub frame_ms: f64,
    /// The final world state's hash.
    pub state_hash: u64,
    /// Every ragdoll's skeleton (arc mapping) at the first, middle
    /// (controllability: frame 60, mid-push) and last frame, for pictures:
    /// `snapshots[k][r]` is ragdoll `r` at the `k`-th of those frames.
    pub snapshots: Vec<Vec<Pose>>,
    /// Every body's final position (m): (ragdoll index, position).
    pub final_positions: Vec<(usize, glam::Vec3)>,
}

/// Runs `config` (1 to [`MAX_FRAMES`] frames), calling
/// `progress(frame, frames)` after each frame.
pub fn run(
    config: &SceneConfig,
    progress: impl FnMut(usize, usize),
) -> Result<SceneRun, RagdollError> {
    let _mode = DefaultFloatMode::enter();
    run_observed(config, progress, |_, _| Ok(()))
}

/// As [`run`], calling `observe(frame, &scene)` after each frame's step
/// (frame 0 first), before `progress`; its error ends the run.
pub fn run_observed<E: From<RagdollError>>(
    config: &SceneConfig,
    mut progress: impl FnMut(usize, usize),
    mut observe: impl FnMut(usize, &SceneWorld) -> Result<(), E>,
) -> Result<SceneRun, E> {
    let _mode = DefaultFloatMode::enter();
    let frames = config.frames.unwrap_or(config.scene.default_frames());
    if !(1..=MAX_FRAMES).contains(&frames) {
        return Err(RagdollError::OutOfRange {
            context: "scene".to_owned(),
            field: "frames",
            reason: format!("is {frames}; must be 1 to {MAX_FRAMES}"),
        }
        .into());
    }
    let mut built = build(config)?;
    let dt = FRAME_DT;
    let mut out = Vec::with_capacity(frames);
    let mut snapshots = Vec::new();
    let start = Instant::now();
    let mut framing = Duration::ZERO;
    for frame in 0..frames {
        let frame_start = Instant::now();
        built.frame(config.scene, frame, dt)?;
        framing += frame_start.elapsed();
        built.watch();
        out.push(built.measure(&built.world));
        // First, middle (mid-push for controllability: figure 7), last.
        let middle = if config.scene == Scene::Controllability {
            60.min(frames / 2)
        } else {
            frames / 2
        };
        if frame == 0 || frame == middle || frame + 1 == frames {
            let poses = built
                .ragdolls
                .iter()
                .map(|r| r.skeleton_pose(&built.world, SpineMapping::Arc));
            snapshots.push(poses.collect::<Result<Vec<_>, _>>()?);
        }
        observe(frame, &built)?;
        progress(frame + 1, frames);
    }
    let per_frame = |d: Duration| d.as_secs_f64() * 1e3 / frames.max(1) as f64;
    let ms_per_step = per_frame(start.elapsed());
    let final_positions = built
        .ragdolls
        .iter()
        .enumerate()
        .flat_map(|(k, r)| r.bodies.iter().flatten().map(move |b| (k, *b)))
        .map(|(k, b)| built.world.body(b).map(|s| (k, s.position)))
        .collect::<Result<Vec<_>, _>>()
        .map_err(RagdollError::from)?;
    Ok(SceneRun {
        scene: config.scene,
        backend: built.world.backend(),
        frames: out,
        ms_per_step,
        frame_ms: per_frame(framing),
        state_hash: built.world.state_hash(),
        snapshots,
        final_positions,
    })
}
