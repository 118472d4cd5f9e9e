//! Physical-animation profiles: a named set of drive settings for a whole
//! ragdoll, every joint's drive and every body's world and upright drive
//! given one by one (a description's `[[profile]]` tables resolve to one:
//! `profile_def.rs`), scaled per body by a 0..1 strength multiplier and
//! blended from one profile to another over time ([`ProfileBlend`]).
//!
//! A multiplier `s` scales a drive's force: its stiffness and damping and
//! its caps, all by `s` (a spring given by frequency `f` and ratio `z`
//! becomes `f sqrt(s)`, `z sqrt(s)`; a compliance `c` with damping `d`
//! becomes `c / s`, `d s`). A blend at `a` in 0..1 interpolates the
//! stiffnesses, the dampings and the caps linearly, so the force a blended
//! drive exerts is the interpolation of the two profiles' forces (below the
//! caps). `docs/ragdolls.md`, "Profiles", says what blends smoothly and
//! what does not (a rigid strength, an unlimited cap, two kinds of
//! strength).

use vertebra_world::Spring;

use crate::error::{RagdollError, range};

/// One joint's drive in a profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointDriveSetting {
    /// The drive's strength (`None`: the joint is not driven).
    pub strength: Option<Spring>,
    /// The largest torque (N m; infinity is unlimited).
    pub max_torque: f32,
}

/// One body's upright drive in a profile: the axis up in the animation's
/// pose held near world up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UprightSetting {
    /// Stiffness and damping across the axis.
    pub strength: Spring,
    /// The largest torque (N m; infinity is unlimited).
    pub max_torque: f32,
}

/// One body's drives in the world in a profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyDriveSetting {
    /// The position part's strength (`None`: position free).
    pub linear: Option<Spring>,
    /// The orientation part's strength (`None`: orientation free).
    pub angular: Option<Spring>,
    /// The force cap per kilogram of the body's mass (N/kg; infinity is
    /// unlimited).
    pub max_acceleration: f32,
    /// The torque cap (N m; infinity is unlimited).
    pub max_torque: f32,
    /// The upright drive, if the body has one.
    pub upright: Option<UprightSetting>,
}

/// A named set of drive settings: one entry per described joint and one
/// per described body. A simplified ragdoll's rod takes the entry of the
/// spine's first joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    /// The profile's name, unique in its description.
    pub name: String,
    /// Per described joint, its drive.
    pub joints: Vec<JointDriveSetting>,
    /// Per described body, its world and upright drives.
    pub bodies: Vec<BodyDriveSetting>,
}

impl JointDriveSetting {
    /// Not driven.
    pub const NONE: Self = Self {
        strength: None,
        max_torque: f32::INFINITY,
    };

    pub(crate) fn scaled(self, s: f32) -> Self {
        Self::blended(Self::NONE, self, s)
    }

    fn blended(x: Self, y: Self, a: f32) -> Self {
        Self {
            strength: blended(x.strength, y.strength, a),
            max_torque: caps(x.max_torque, x.strength, y.max_torque, y.strength, a),
        }
    }
}

impl BodyDriveSetting {
    /// No drive in the world.
    pub const NONE: Self = Self {
        linear: None,
        angular: None,
        max_acceleration: f32::INFINITY,
        max_torque: f32::INFINITY,
        upright: None,
    };

    /// Whether the body has any drive.
    pub fn is_driven(&self) -> bool {
        self.linear.is_some() || self.angular.is_some() || self.upright.is_some()
    }

    pub(crate) fn scaled(self, s: f32) -> Self {
        Self::blended(Self::NONE, self, s)
    }

    fn blended(x: Self, y: Self, a: f32) -> Self {
        let upright = |u: Option<UprightSetting>| JointDriveSetting {
            strength: u.map(|u| u.strength),
            max_torque: u.map_or(f32::INFINITY, |u| u.max_torque),
        };
        let up = JointDriveSetting::blended(upright(x.upright), upright(y.upright), a);
        // The force cap belongs to the position part, the torque cap to
        // the orientation part: each fades with its own part.
        Self {
            linear: blended(x.linear, y.linear, a),
            angular: blended(x.angular, y.angular, a),
            max_acceleration: caps(
                x.max_acceleration,
                x.linear,
                y.max_acceleration,
                y.linear,
                a,
            ),
            max_torque: caps(x.max_torque, x.angular, y.max_torque, y.angular, a),
            upright: up.strength.map(|strength| UprightSetting {
                strength,
                max_torque: up.max_torque,
            }),
        }
    }
}

impl Profile {
    /// The profile between `self` (at `a = 0`) and `to` (at `a = 1`):
    /// every stiffness, damping and cap interpolated (module
    /// documentation). Named as `to`.
    pub fn blended(&self, to: &Profile, a: f32) -> Result<Self, RagdollError> {
        let context = format!("profile `{}`", to.name);
        let same = self.joints.len() == to.joints.len() && self.bodies.len() == to.bodies.len();
        range(
            &context,
            "joints",
            same,
            "must have as many joints and bodies as the profile it blends from",
        )?;
        range(
            &context,
            "blend",
            (0.0..=1.0).contains(&a),
            "must be in 0..1",
        )?;
        let pair = |x: &[JointDriveSetting], y: &[JointDriveSetting]| {
            (x.iter().zip(y))
                .map(|(&x, &y)| JointDriveSetting::blended(x, y, a))
                .collect()
        };
        Ok(Self {
            name: to.name.clone(),
            joints: pair(&self.joints, &to.joints),
            bodies: (self.bodies.iter().zip(&to.bodies))
                .map(|(&x, &y)| BodyDriveSetting::blended(x, y, a))
                .collect(),
        })
    }
}

/// A profile blended into another over time: what a game holds per
/// ragdoll and hands to [`crate::Ragdoll::follow_profile`] each frame.
/// [`ProfileBlend::switch_to`] starts a blend from wherever the last one
/// stands, so a hit may fade the drives out before a recovery has faded
/// them back in.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileBlend {
    from: Profile,
    to: Profile,
    /// The blend's length (s); zero: switched.
    duration: f32,
    /// Time since the blend began (s).
    elapsed: f32,
}

impl ProfileBlend {
    /// At `profile`, not blending.
    pub fn new(profile: Profile) -> Self {
        Self {
            from: profile.clone(),
            to: profile,
            duration: 0.0,
            elapsed: 0.0,
        }
    }

    /// Starts a blend of `duration` seconds (zero: at once) from the
    /// profile as it stands now to `to`. Refused, unchanged, for a
    /// duration that is negative or not finite, or a profile of another
    /// shape.
    pub fn switch_to(&mut self, to: Profile, duration: f32) -> Result<(), RagdollError> {
        range(
            &format!("profile `{}`", to.name),
            "duration",
            duration.is_finite() && duration >= 0.0,
            "must be a time (s), not negative",
        )?;
        let from = self.current()?.blended(&to, 0.0)?;
        *self = Self {
            from,
            to,
            duration,
            elapsed: 0.0,
        };
        Ok(())
    }

    /// Moves the blend on by `dt` seconds (a step's time).
    pub fn advance(&mut self, dt: f32) {
        if dt.is_finite() && dt > 0.0 {
            self.elapsed = (self.elapsed + dt).min(self.duration);
        }
    }

    /// How far the blend is, 0..1 (1: at the target).
    pub fn progress(&self) -> f32 {
        if self.elapsed >= self.duration {
            1.0
        } else {
            self.elapsed / self.duration
        }
    }

    /// The profile the blend is heading for.
    pub fn target(&self) -> &Profile {
        &self.to
    }

    /// The profile as the blend stands now.
    pub fn current(&self) -> Result<Profile, RagdollError> {
        self.from.blended(&self.to, self.progress())
    }
}

pub(crate) fn check_multiplier(context: &str, multiplier: f32) -> Result<(), RagdollError> {
    range(
        context,
        "strength_multiplier",
        (0.0..=1.0).contains(&multiplier),
        "must be in 0..1",
    )
}

/// `s` with its force scaled by `w` in (0, 1): stiffness and damping both
/// (`f sqrt(w)`, `z sqrt(w)` for a frequency, so nothing is squared and
/// nothing overflows; `c / w`, `d w` for a compliance); `None` once too
/// weak for the world (a frequency below its least, a compliance past
/// `f32`).
fn scaled(s: Spring, w: f32) -> Option<Spring> {
    if w >= 1.0 {
        return Some(s);
    }
    if w <= 0.0 {
        return None;
    }
    match s {
        Spring::Frequency {
            frequency,
            damping_ratio,
        } => {
            let root = w.sqrt();
            let frequency = frequency * root;
            (frequency >= vertebra_world::MIN_DRIVE_FREQUENCY).then_some(Spring::Frequency {
                frequency,
                damping_ratio: damping_ratio * root,
            })
        }
        Spring::Compliance {
            compliance,
            damping,
        } => {
            let compliance = compliance / w;
            compliance.is_finite().then_some(Spring::Compliance {
                compliance,
                damping: damping * w,
            })
        }
    }
}

/// Two springs of one kind between `x` (at `a = 0`) and `y` (at `a = 1`),
/// `a` strictly between: their stiffnesses and dampings interpolated, in
/// `f64` (a frequency's stiffness is its square). A rigid one (an infinite
/// frequency, a zero compliance) stays rigid while it has any weight.
fn interpolated(x: Spring, y: Spring, a: f32) -> Option<Spring> {
    let a = f64::from(a);
    let lerp = |p: f64, q: f64| p + (q - p) * a;
    match (x, y) {
        (
            Spring::Frequency {
                frequency: fx,
                damping_ratio: zx,
            },
            Spring::Frequency {
                frequency: fy,
                damping_ratio: zy,
            },
        ) => {
            if fx.is_infinite() || fy.is_infinite() {
                let z = if fx.is_infinite() { zx } else { zy };
                return Some(Spring::Frequency {
                    frequency: f32::INFINITY,
                    damping_ratio: z,
                });
            }
            let (fx, fy) = (f64::from(fx), f64::from(fy));
            let stiffness = lerp(fx * fx, fy * fy);
            let damping = lerp(f64::from(zx) * fx, f64::from(zy) * fy);
            let frequency = stiffness.sqrt();
            Some(Spring::Frequency {
                frequency: frequency as f32,
                damping_ratio: (damping / frequency) as f32,
            })
        }
        (
            Spring::Compliance {
                compliance: cx,
                damping: dx,
            },
            Spring::Compliance {
                compliance: cy,
                damping: dy,
            },
        ) => {
            let damping = lerp(f64::from(dx), f64::from(dy)) as f32;
            if cx == 0.0 || cy == 0.0 {
                return Some(Spring::Compliance {
                    compliance: 0.0,
                    damping,
                });
            }
            let stiffness = lerp(1.0 / f64::from(cx), 1.0 / f64::from(cy));
            Some(Spring::Compliance {
                compliance: (1.0 / stiffness) as f32,
                damping,
            })
        }
        _ => None,
    }
}

/// A strength between `x` (at `a = 0`) and `y` (at `a = 1`): the force
/// laws interpolated when both are of one kind, one scaled by its weight
/// when the other is none, and when their kinds differ, `x` faded out
/// over the first half and `y` in over the second.
fn blended(x: Option<Spring>, y: Option<Spring>, a: f32) -> Option<Spring> {
    if a <= 0.0 {
        return x;
    }
    if a >= 1.0 {
        return y;
    }
    match (x, y) {
        (None, None) => None,
        (Some(x), None) => scaled(x, 1.0 - a),
        (None, Some(y)) => scaled(y, a),
        (Some(x), Some(y)) if core::mem::discriminant(&x) == core::mem::discriminant(&y) => {
            interpolated(x, y, a)
        }
        (Some(x), Some(y)) => {
            if a < 0.5 {
                scaled(x, 1.0 - 2.0 * a)
            } else {
                scaled(y, 2.0 * a - 1.0)
            }
        }
    }
}

/// A cap between `x` and `y` as their strengths blend: a part that is
/// absent on one side takes the other side's cap scaled by its weight,
/// so a drive fading in starts from no force at all.
fn caps(x: f32, sx: Option<Spring>, y: f32, sy: Option<Spring>, a: f32) -> f32 {
    if a <= 0.0 {
        return x;
    }
    if a >= 1.0 {
        return y;
    }
    match (sx, sy) {
        (None, None) => f32::INFINITY,
        (Some(_), None) => scale_cap(x, 1.0 - a),
        (None, Some(_)) => scale_cap(y, a),
        // An unlimited cap stays unlimited while it has any weight.
        (Some(_), Some(_)) if x.is_infinite() || y.is_infinite() => f32::INFINITY,
        (Some(_), Some(_)) => x + (y - x) * a,
    }
}

/// A cap scaled by a weight; an unlimited one stays unlimited while the
/// weight is above zero.
fn scale_cap(cap: f32, w: f32) -> f32 {
    if w >= 1.0 {
        cap
    } else if cap.is_infinite() {
        if w > 0.0 { cap } else { 0.0 }
    } else {
        cap * w.max(0.0)
    }
}
