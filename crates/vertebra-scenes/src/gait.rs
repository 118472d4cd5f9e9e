//! A walk's timing: how fast the root moves, where each foot is planted
//! and when it swings, how the hips rise, sway and turn. Pure functions of
//! time, as offsets from the bind pose (walking along +Z); [`crate::Walk`]
//! turns them into a pose.
//!
//! The walk starts from standing: the speed rises from 0 along a
//! smoothstep over [`Gait::ramp`], so the root's position, velocity and
//! acceleration are continuous, and the hips' bob and turn and the arms'
//! swing grow with the speed; the feet's lift and the hips' sway grow
//! faster, over [`Gait::onset`]. Each foot is planted where the root will
//! be halfway through its stance, so the leg sweeps as far back as
//! forward; while it is down it only rolls on its round end.

use vertebra_math::trig;

/// The walk's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gait {
    /// Speed once the ramp is over (m/s).
    pub speed: f32,
    /// Strides per second: each foot steps once a stride.
    pub cadence: f32,
    /// The fraction of a stride each foot is down (above one half: both
    /// feet are down as the weight passes from one to the other).
    pub stance: f32,
    /// Seconds from standing to full speed.
    pub ramp: f32,
    /// Seconds over which the feet's lift and the hips' sway grow to
    /// full (a smoothstep from the start): the weight must leave a foot
    /// before it can swing, however slowly the walk begins.
    pub onset: f32,
    /// How high a swinging foot lifts (m).
    pub clearance: f32,
    /// How far the hips are lowered at full speed (m).
    pub drop: f32,
    /// The hips' rise and fall about that (m), twice a stride: highest
    /// over each foot, lowest when both are down.
    pub bob: f32,
    /// The hips' sway toward the foot that is down (m).
    pub sway: f32,
    /// The hips' turn about +Y toward the leg stepping forward (rad).
    pub turn: f32,
    /// The trunk's forward lean (rad).
    pub lean: f32,
    /// The arms' swing forward and back, against the legs (rad).
    pub arm_swing: f32,
    /// The elbows' bend (rad).
    pub elbow: f32,
    /// The radius of the round end a foot stands on (m): a planted foot
    /// rolls forward on it as the leg sweeps back, as it would without
    /// slipping (0: a point foot that stays put).
    pub foot_radius: f32,
    /// The hips' height above a planted foot's centre (m), for the leg's
    /// angle that sets how far the foot rolls.
    pub leg: f32,
}

/// One foot at one instant: where it is (m, the walk's frame) and whether
/// it is down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Foot {
    /// Along +Z from the bind pose (m).
    pub forward: f32,
    /// Above where it stands (m).
    pub lift: f32,
    /// Whether it is planted.
    pub down: bool,
}

impl Gait {
    /// A walk at `speed` (m/s) for a humanoid with legs of about 0.8 m (the
    /// anatomical humanoid's): 1.25 strides a second (150 steps a minute),
    /// each foot down 52% of a stride, full speed 1.5 s after the start;
    /// at 1.5 m/s the hips 5 cm lower than standing, rising and falling
    /// 1.5 cm about that, low enough that a planted foot stays on the
    /// ground through its whole stance.
    pub fn walk(speed: f32) -> Self {
        Self {
            speed,
            cadence: 1.25,
            stance: 0.52,
            ramp: 1.5,
            onset: 0.3,
            clearance: 0.06,
            drop: 0.05,
            bob: 0.015,
            sway: 0.02,
            turn: 0.08,
            lean: 0.06,
            arm_swing: 0.35,
            elbow: 0.3,
            foot_radius: 0.055,
            leg: 0.73,
        }
    }

    /// The fraction of full speed at `t` (s since the start): 0 before it,
    /// a smoothstep over the ramp, then 1.
    pub fn speed_fraction(&self, t: f32) -> f32 {
        let u = self.ramp_fraction(t);
        u * u * (3.0 - 2.0 * u)
    }

    /// How far the root has gone along +Z at `t` (m): the smoothstep's
    /// integral over the ramp, then `speed` a second.
    pub fn distance(&self, t: f32) -> f32 {
        let u = self.ramp_fraction(t);
        let ramped = self.speed * self.ramp * (u * u * u - 0.5 * u * u * u * u);
        ramped + self.speed * (t - self.ramp).max(0.0)
    }

    /// Strides since the start (negative before it).
    pub fn phase(&self, t: f32) -> f32 {
        self.cadence * t
    }

    /// Foot `side`'s place at `t` (0: the left, which is down as the walk
    /// starts and swings second; 1: the right, half a stride later).
    pub fn foot(&self, side: usize, t: f32) -> Foot {
        if t <= 0.0 {
            return Foot {
                forward: 0.0,
                lift: 0.0,
                down: true,
            };
        }
        let offset = 0.5 * side as f32;
        let step = self.phase(t) - offset;
        let k = step.floor();
        let within = step - k;
        if within < self.stance {
            return Foot {
                forward: self.rolled(k, offset, t),
                lift: 0.0,
                down: true,
            };
        }
        // Swinging to the next stance: a cycloid forward (still as it lifts
        // and as it lands) and a cosine bump up.
        let s = (within - self.stance) / (1.0 - self.stance);
        let tau = core::f32::consts::TAU;
        let along = s - trig::sin(tau * s) / tau;
        let lifted = (k + offset + self.stance) / self.cadence;
        let (from, to) = (self.rolled(k, offset, lifted), self.plant(k + 1.0, offset));
        Foot {
            forward: from + (to - from) * along,
            lift: self.clearance * self.onset_fraction(t) * 0.5 * (1.0 - trig::cos(tau * s)),
            down: false,
        }
    }

    /// The hips' offset from standing at `t` (m: sideways toward +X, up)
    /// and their turn about +Y (rad).
    pub fn hips(&self, t: f32) -> (f32, f32, f32) {
        if t <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        let (grown, shifted) = (self.speed_fraction(t), self.onset_fraction(t));
        let tau = core::f32::consts::TAU;
        // The left foot is down from phase 0 to `stance`, the right half a
        // stride later: over each at the middle of its stance.
        let over = self.phase(t) - 0.5 * self.stance;
        let side = self.sway * trig::cos(tau * over);
        let up = -self.drop + self.bob * trig::cos(2.0 * tau * over);
        // The left leg leads as it lands (phase 0): the left hip forward,
        // a turn by -turn about +Y.
        let turn = -self.turn * trig::cos(tau * self.phase(t));
        (shifted * side, grown * up, grown * turn)
    }

    /// The left arm's swing forward at `t` (rad; the right's is its
    /// opposite): forward as the right foot lands, half a stride in.
    pub fn arms(&self, t: f32) -> f32 {
        if t <= 0.0 {
            return 0.0;
        }
        let tau = core::f32::consts::TAU;
        -self.speed_fraction(t) * self.arm_swing * trig::cos(tau * self.phase(t))
    }

    /// Where stance `k` of the foot `offset` strides behind the left plants
    /// it: where the root is halfway through that stance, or where it stood
    /// for a stance under way at the start.
    fn plant(&self, k: f32, offset: f32) -> f32 {
        let begins = k + offset;
        if begins <= 0.0 {
            return 0.0;
        }
        self.distance((begins + 0.5 * self.stance) / self.cadence)
    }

    /// Where the foot planted for stance `k` is at `t` during it: rolled
    /// forward by its radius times the leg's turn since the stance began.
    fn rolled(&self, k: f32, offset: f32, t: f32) -> f32 {
        let plant = self.plant(k, offset);
        let began = ((k + offset) / self.cadence).max(0.0);
        let angle = |t: f32| trig::atan2(self.distance(t) - plant, self.leg);
        plant + self.foot_radius * (angle(t) - angle(began))
    }

    /// How far the feet's lift and the hips' sway have grown at `t`: a
    /// smoothstep over [`Gait::onset`].
    pub fn onset_fraction(&self, t: f32) -> f32 {
        let u = fraction(t, self.onset);
        u * u * (3.0 - 2.0 * u)
    }

    fn ramp_fraction(&self, t: f32) -> f32 {
        fraction(t, self.ramp)
    }
}

/// How far `t` is through `span` seconds from 0, in [0, 1].
fn fraction(t: f32, span: f32) -> f32 {
    if span > 0.0 {
        (t / span).clamp(0.0, 1.0)
    } else if t > 0.0 {
        1.0
    } else {
        0.0
    }
}
