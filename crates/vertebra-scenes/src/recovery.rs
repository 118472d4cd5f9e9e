//! The hit reaction's summary: each hit's peak deviation from the target
//! pose and the frames the drive takes to bring the body back.

use crate::{HIT_FRAMES, Scene, SceneRun};

/// The fraction of a hit's rise in deviation still left when the body
/// counts as recovered.
pub const RECOVERED: f32 = 0.1;

/// How the body took one hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Recovery {
    /// The frame whose step the hit preceded.
    pub hit: usize,
    /// The largest summed deviation from the target pose (cm) from the hit
    /// to the next hit (or the end of the run).
    pub peak_cm: f32,
    /// Frames from the hit until the deviation is back within
    /// [`RECOVERED`] of its rise above the frame before the hit: the first
    /// frame `f` after the peak with `d(f) - d0 < 0.1 (peak - d0)`, where
    /// `d0` is the deviation the frame before the hit; `f - hit`. `None`
    /// when that does not happen before the next hit (or the end).
    pub frames: Option<usize>,
}

impl SceneRun {
    /// Each hit's [`Recovery`] (the hit reaction; nothing for the other
    /// scenes, or a run ended before a hit).
    pub fn recoveries(&self) -> Vec<Recovery> {
        if self.scene != Scene::HitReaction {
            return Vec::new();
        }
        let d: Vec<f32> = self.frames.iter().map(|f| f.deviation_cm).collect();
        let ends = HIT_FRAMES.iter().skip(1).copied().chain([d.len()]);
        HIT_FRAMES
            .iter()
            .zip(ends)
            .filter(|&(&hit, end)| hit < end.min(d.len()))
            .map(|(&hit, end)| recovery(&d, hit, end.min(d.len())))
            .collect()
    }
}

/// The recovery from a hit before frame `hit`'s step, within `d[hit..end]`.
fn recovery(d: &[f32], hit: usize, end: usize) -> Recovery {
    let before = if hit > 0 { d[hit - 1] } else { 0.0 };
    let (peak_at, peak_cm) =
        (hit..end).map(|f| (f, d[f])).fold(
            (hit, f32::MIN),
            |best, x| if x.1 > best.1 { x } else { best },
        );
    let back = before + RECOVERED * (peak_cm - before);
    let frames = (peak_at..end).find(|&f| d[f] < back).map(|f| f - hit);
    Recovery {
        hit,
        peak_cm,
        frames,
    }
}
