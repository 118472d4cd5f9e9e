//! Running a scene in rapier and measuring it with vertebra's metric.

use std::time::Instant;

use vertebra_scenes::{Frame, SceneConfig, build};

use crate::{PeerError, RapierScene, RapierSettings};

/// A finished rapier run of a scene.
#[derive(Clone, Debug)]
pub struct PeerRun {
    /// Rapier's settings.
    pub settings: RapierSettings,
    /// Per frame, measured by vertebra's metric on rapier's poses.
    pub frames: Vec<Frame>,
    /// Mean wall time per rapier step, its collision detection included
    /// (ms); the mirroring and measuring are not timed.
    pub ms_per_step: f64,
}

/// Runs `config`'s scene (standard ragdolls: `config.spine` must be
/// sockets) in rapier with `settings` at 60 Hz, measuring every frame.
pub fn run(
    config: &SceneConfig,
    settings: RapierSettings,
) -> Result<PeerRun, Box<dyn std::error::Error>> {
    let mut scene = build(config)?;
    if scene.push.is_some() {
        return Err(PeerError::Unsupported("the controllability scene's drives").into());
    }
    let dt = 1.0 / 60.0;
    let mut rapier = RapierScene::from_scene(&scene, settings, dt)?;
    let frames = config.frames.unwrap_or(config.scene.default_frames());
    let mut out = Vec::with_capacity(frames);
    let mut stepping = std::time::Duration::ZERO;
    for _ in 0..frames {
        let start = Instant::now();
        rapier.step();
        stepping += start.elapsed();
        rapier.mirror(&mut scene.world)?;
        out.push(scene.measure(&scene.world));
    }
    Ok(PeerRun {
        settings,
        frames: out,
        ms_per_step: stepping.as_secs_f64() * 1e3 / frames.max(1) as f64,
    })
}
