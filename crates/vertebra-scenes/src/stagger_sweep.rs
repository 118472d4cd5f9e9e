//! The stagger's sweep: the standing and the walking ragdoll hit on the
//! chest from each side by impulses of rising size, each hit on the
//! ragdoll as it was just before (a snapshot restored: a fresh ragdoll
//! every time), over seeds; and the walk's tracking without hits. What
//! each hit measured: `stagger_hit.rs`.

use core::ops::Range;

use glam::Vec3;
use rayon::prelude::*;
use vertebra_collide::CollisionSnapshot;
use vertebra_math::DefaultFloatMode;
use vertebra_ragdoll::{Profile, RagdollError};
use vertebra_world::Snapshot;

use crate::setup::spine_top;
use crate::stagger::stagger_world;
use crate::{
    Activity, FRAME_DT, MAX_SEEDS, Scene, SceneConfig, SceneWorld, Side, StaggerHit, Tracking,
    UPRIGHT_FRACTION, WALK_START, stagger_walk,
};

/// The impulses of the sweep (N s).
pub const STAGGER_IMPULSES: [f32; 7] = [20.0, 40.0, 60.0, 80.0, 100.0, 120.0, 150.0];

/// The frame whose step a standing hit precedes (2 s).
pub const STANDING_HIT_FRAME: usize = 120;

/// The frame whose step a walking hit precedes (4.5 s: 2 s at full
/// speed).
pub const WALKING_HIT_FRAME: usize = 270;

/// Frames watched after a hit (3 s).
pub const WATCHED_FRAMES: usize = 180;

/// Frames of the walk without hits whose tracking is measured, from the
/// end of the ramp (8 s).
pub const TRACKED_FRAMES: usize = 480;

/// A sweep over seeds: every hit, and each seed's walk.
#[derive(Clone, Debug)]
pub struct StaggerSweep {
    /// The hits, seed by seed, standing then walking, side by side, size
    /// by size.
    pub hits: Vec<StaggerHit>,
    /// Each seed's walk without hits.
    pub walks: Vec<Tracking>,
    /// The hips' standing height (m).
    pub standing_height: f32,
}

impl StaggerSweep {
    /// The sweep of `config` (its spine, solver, backend, threads and
    /// ragdoll; `config.scene` and `config.frames` are not read), the
    /// ragdoll following its animation with `animation`'s drives
    /// ([`crate::stagger_profile`]), from `seeds` (1 to [`MAX_SEEDS`]),
    /// with `sizes` (N s, finite, not negative), seeds spread over rayon's
    /// global pool (each run is deterministic, so the result does not
    /// depend on how many run at once). Refused, naming the field, for
    /// seeds or sizes out of range and whatever [`crate::build`] refuses.
    pub fn run(
        config: &SceneConfig,
        animation: &Profile,
        seeds: Range<u64>,
        sizes: &[f32],
    ) -> Result<Self, RagdollError> {
        config.drive()?;
        let out = |field: &'static str, reason: String| RagdollError::OutOfRange {
            context: "scene stagger".to_owned(),
            field,
            reason,
        };
        let count = seeds.end.saturating_sub(seeds.start);
        if !(1..=MAX_SEEDS).contains(&count) {
            let reason = format!("are {count}; must be 1 to {MAX_SEEDS}");
            return Err(out("seeds", reason));
        }
        if let Some(bad) = sizes.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
            let reason = format!("hold {bad}; each must be finite and not negative (N s)");
            return Err(out("impulses", reason));
        }
        let each = seeds
            .into_par_iter()
            .map(|seed| seeded(config, animation, seed, sizes))
            .collect::<Result<Vec<_>, _>>()?;
        let standing_height = each.first().map_or(0.0, |e| e.2);
        let (mut hits, mut walks) = (Vec::new(), Vec::new());
        for (h, w, _) in each {
            hits.extend(h);
            walks.push(w);
        }
        Ok(Self {
            hits,
            walks,
            standing_height,
        })
    }

    /// The largest size of the sweep that every seed survived from `side`
    /// while `activity`, every smaller size survived too; `None` when the
    /// smallest felled one.
    pub fn largest_survived(&self, activity: Activity, side: Side) -> Option<f32> {
        let mut sizes: Vec<f32> = self.of(activity, side).map(|h| h.size).collect();
        sizes.sort_by(f32::total_cmp);
        sizes.dedup();
        let fell = |size: f32| {
            self.of(activity, side)
                .any(|h| h.size == size && !h.stays_up)
        };
        sizes.into_iter().take_while(|&s| !fell(s)).last()
    }

    /// The slowest recovery (s) over the hits from `side` while `activity`
    /// up to `size`, every seed's; `None` if one never recovered.
    pub fn slowest_recovery(&self, activity: Activity, side: Side, size: f32) -> Option<f32> {
        self.of(activity, side)
            .filter(|h| h.size <= size)
            .map(|h| h.recovered)
            .try_fold(0.0f32, |worst, r| r.map(|r| worst.max(r)))
    }

    /// The walk's largest and root-mean-square tracking error over the
    /// seeds (m): the largest of each.
    pub fn tracking(&self) -> (f32, f32) {
        (self.walks.iter()).fold((0.0, 0.0), |(m, r), w| (m.max(w.max), r.max(w.rms)))
    }

    fn of(&self, activity: Activity, side: Side) -> impl Iterator<Item = &StaggerHit> {
        (self.hits.iter()).filter(move |h| h.activity == activity && h.side == side)
    }
}

/// One seed's hits, walk, and the hips' standing height.
fn seeded(
    config: &SceneConfig,
    animation: &Profile,
    seed: u64,
    sizes: &[f32],
) -> Result<(Vec<StaggerHit>, Tracking, f32), RagdollError> {
    let _mode = DefaultFloatMode::enter();
    let desc = crate::builder::description(config)?;
    let mut hits = Vec::new();
    let mut standing_height = 0.0;
    let mut tracked = Tracked::default();
    for activity in Activity::ALL {
        let (start, hit) = match activity {
            Activity::Standing => (f32::INFINITY, STANDING_HIT_FRAME),
            Activity::Walking => (WALK_START, WALKING_HIT_FRAME),
        };
        let walk = stagger_walk(&desc, seed, start)?;
        standing_height = walk.hips(0.0).y;
        // The walk's tracking counts from the end of its ramp.
        let first = ((start + walk.gait.ramp) / FRAME_DT).round();
        let first = if first.is_finite() {
            first as usize
        } else {
            usize::MAX
        };
        let world = config.world()?;
        let mut scene = stagger_world(world, &desc, config, walk, animation.clone())?;
        let chest = scene.ragdolls[0].bodies[spine_top(&desc)].ok_or_else(|| {
            RagdollError::UnknownBody {
                context: "scene stagger (the body hit)".to_owned(),
                field: "body",
                name: "chest".to_owned(),
            }
        })?;
        for frame in 0..hit {
            let error = step(&mut scene, frame)?;
            tracked.add(frame >= first, error);
        }
        let saved = save(&scene)?;
        let within = activity.recovered_within();
        for side in Side::ALL {
            for &size in sizes {
                load(&mut scene, &saved)?;
                scene.world.apply_impulse(chest, side.impulse(size))?;
                let (lowest, peak, recovered) = watch(&mut scene, hit, within)?;
                hits.push(StaggerHit {
                    activity,
                    side,
                    size,
                    seed,
                    stays_up: lowest > UPRIGHT_FRACTION * standing_height,
                    lowest,
                    peak,
                    recovered,
                });
            }
        }
        if activity == Activity::Walking {
            // On without hits to the end of the tracked frames.
            load(&mut scene, &saved)?;
            for frame in hit..first + TRACKED_FRAMES {
                let error = step(&mut scene, frame)?;
                tracked.add(frame >= first, error);
            }
        }
    }
    Ok((hits, tracked.of(seed), standing_height))
}

/// The walk's tracking as it is measured.
#[derive(Default)]
struct Tracked {
    max: f32,
    squares: f32,
    frames: usize,
}

impl Tracked {
    fn add(&mut self, counted: bool, error: f32) {
        if counted {
            self.max = self.max.max(error);
            self.squares += error * error;
            self.frames += 1;
        }
    }

    fn of(&self, seed: u64) -> Tracking {
        Tracking {
            seed,
            max: self.max,
            rms: (self.squares / self.frames.max(1) as f32).sqrt(),
        }
    }
}

/// [`WATCHED_FRAMES`] from frame `hit`: the hips' lowest height, their
/// largest distance from the animation's, and when they came back within
/// `within` of it for good.
fn watch(
    scene: &mut SceneWorld,
    hit: usize,
    within: f32,
) -> Result<(f32, f32, Option<f32>), RagdollError> {
    let (mut lowest, mut peak, mut back) = (f32::MAX, 0.0f32, Some(0.0));
    for k in 0..WATCHED_FRAMES {
        let error = step(scene, hit + k)?;
        lowest = lowest.min(hips(scene)?.y);
        peak = peak.max(error);
        back = match (error < within, back) {
            (false, _) => None,
            (true, None) => Some((k + 1) as f32 * FRAME_DT),
            (true, kept) => kept,
        };
    }
    Ok((lowest, peak, back))
}

/// Frame `frame` of the scene; then the hips' distance from the
/// animation's (m).
fn step(scene: &mut SceneWorld, frame: usize) -> Result<f32, RagdollError> {
    scene.frame(Scene::Stagger, frame, FRAME_DT)?;
    let want = (scene.following.as_ref()).map_or(Vec3::ZERO, |f| f.hips(frame, FRAME_DT));
    Ok((hips(scene)? - want).length())
}

/// The hips' centre (m, world).
fn hips(scene: &SceneWorld) -> Result<Vec3, RagdollError> {
    let root = scene.following.as_ref().map_or(0, |f| f.desc.root);
    let root = scene.ragdolls[0].bodies[root].ok_or_else(|| RagdollError::UnknownBody {
        context: "scene stagger (the hips)".to_owned(),
        field: "body",
        name: "root".to_owned(),
    })?;
    Ok(scene.world.body(root)?.position)
}

/// The world and its collision set, saved together.
fn save(scene: &SceneWorld) -> Result<(Snapshot, Option<CollisionSnapshot>), RagdollError> {
    let set = (scene.collisions.as_ref())
        .map(|c| c.snapshot(&scene.world))
        .transpose()?;
    Ok((scene.world.snapshot(), set))
}

/// Both put back: the world first, then its set.
fn load(
    scene: &mut SceneWorld,
    (world, set): &(Snapshot, Option<CollisionSnapshot>),
) -> Result<(), RagdollError> {
    scene.world.restore(world)?;
    if let (Some(c), Some(set)) = (scene.collisions.as_mut(), set) {
        c.restore(set, &scene.world)?;
    }
    Ok(())
}
