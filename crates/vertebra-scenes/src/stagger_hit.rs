//! What the stagger's sweep measures of one hit: where it came from, how
//! big it was, whether the ragdoll stayed up, how far it was pushed from
//! its animation and how soon it was back; and of the walk without hits.

use glam::Vec3;

/// A hit counts as survived while the hips stay above this fraction of
/// their standing height.
pub const UPRIGHT_FRACTION: f32 = 0.6;

/// What the ragdoll is doing when hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Activity {
    /// Following the standing (bind) pose.
    Standing,
    /// Walking at full speed.
    Walking,
}

/// Where a hit comes from: the ragdoll faces +Z, its left is +X.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// From ahead: pushed back (-Z).
    Front,
    /// From behind: pushed forward (+Z).
    Back,
    /// From its left: pushed right (-X).
    Left,
    /// From its right: pushed left (+X).
    Right,
}

impl Side {
    /// Every side, in the sweep's order.
    pub const ALL: [Side; 4] = [Side::Front, Side::Back, Side::Left, Side::Right];

    /// The impulse (N s, world) of a hit of `size` from this side.
    pub fn impulse(self, size: f32) -> Vec3 {
        match self {
            Side::Front => Vec3::new(0.0, 0.0, -size),
            Side::Back => Vec3::new(0.0, 0.0, size),
            Side::Left => Vec3::new(-size, 0.0, 0.0),
            Side::Right => Vec3::new(size, 0.0, 0.0),
        }
    }

    /// Its name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Side::Front => "front",
            Side::Back => "back",
            Side::Left => "left",
            Side::Right => "right",
        }
    }
}

impl Activity {
    /// Both, in the sweep's order.
    pub const ALL: [Activity; 2] = [Activity::Standing, Activity::Walking];

    /// Its name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Activity::Standing => "standing",
            Activity::Walking => "walking",
        }
    }

    /// How near the animation's hips the hips must come back, and stay, to
    /// count as recovered (m): 2 cm standing, 5 cm walking (as near as
    /// the walk tracks its animation without hits).
    pub fn recovered_within(self) -> f32 {
        match self {
            Activity::Standing => 0.02,
            Activity::Walking => 0.05,
        }
    }
}

/// How the ragdoll took one hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaggerHit {
    /// Standing or walking.
    pub activity: Activity,
    /// Where it came from.
    pub side: Side,
    /// Its size (N s).
    pub size: f32,
    /// The seed of the start.
    pub seed: u64,
    /// Whether the hips stayed above [`UPRIGHT_FRACTION`] of their
    /// standing height from the hit to the end of the watch.
    pub stays_up: bool,
    /// The hips' lowest height after the hit (m).
    pub lowest: f32,
    /// The hips' largest distance from the animation's after the hit (m).
    pub peak: f32,
    /// Seconds from the hit until the hips are back within
    /// [`Activity::recovered_within`] of the animation's and stay there to the end
    /// of the watch (0 if they never left); `None` if they never are.
    pub recovered: Option<f32>,
}

/// The walk without hits: the hips' distance from the animation's over
/// [`crate::TRACKED_FRAMES`] after the ramp (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tracking {
    /// The seed of the start.
    pub seed: u64,
    /// The largest distance.
    pub max: f32,
    /// The root mean square.
    pub rms: f32,
}
