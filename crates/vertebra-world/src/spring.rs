//! The one damped spring every soft part of a joint is: a drive's strength
//! and a soft limit (as Jolt's `SpringSettings`, used by its motors and
//! limits alike), its ranges, its one validation and its one conversion
//! to the numbers the kernels read (`vertebra_kernels::parts::drive` and
//! `parts::limit` derive them).

use core::f32::consts::TAU;

use vertebra_store::Error;

/// The lowest spring frequency (Hz): a period of about 17 minutes. Lower
/// ones are no spring at all, and `1 / omega^2` would leave `f32`.
pub const MIN_DRIVE_FREQUENCY: f32 = 1e-3;

/// The largest spring damping ratio: far past critical (1), and small
/// enough that `2 zeta / omega` stays a number.
pub const MAX_DRIVE_DAMPING_RATIO: f32 = 1e3;

/// The largest damping time `compliance * damping` (s) of a spring given
/// by compliance (a damping ratio of ~1e6 at 1 Hz).
pub const MAX_DRIVE_DAMPING_TIME: f32 = 1e6;

/// A damped spring: how hard a drive pulls toward its target
/// ([`AngularDrive::strength`](crate::AngularDrive)) or a soft limit
/// holds ([`LimitSoftness::Soft`](crate::LimitSoftness)). It acts on an
/// error rotation `C` (rad): the drive's from its target, the limit's
/// excess beyond it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Spring {
    /// XPBD compliance and damping coefficient: the torque is
    /// `-C / compliance - damping dC/dt`. Independent of the time step and
    /// iteration count; how fast it moves a body depends on the body's
    /// inertia.
    Compliance {
        /// Compliance (rad / (N m), finite, not negative), the inverse of
        /// stiffness; 0 is infinitely stiff (and then damping does
        /// nothing).
        compliance: f32,
        /// Damping coefficient (N m s / rad, finite, not negative), with
        /// `compliance * damping` at most [`MAX_DRIVE_DAMPING_TIME`] s.
        damping: f32,
    },
    /// An oscillator at `frequency` with `damping_ratio` whatever the
    /// bodies' inertia (as Jolt's `SpringSettings` and Box2D's soft
    /// constraints): stiffness and damping are scaled by the part's
    /// effective inertia, per substep and lane. (Encoded under the name it
    /// had before, `Spring`, for formats that write names.)
    #[serde(rename = "Spring")]
    Frequency {
        /// Natural frequency (Hz), at least [`MIN_DRIVE_FREQUENCY`];
        /// infinity is infinitely stiff.
        frequency: f32,
        /// Damping ratio (dimensionless) in [0, [`MAX_DRIVE_DAMPING_RATIO`]]:
        /// 1 is critical (no overshoot: a limb comes to rest against a
        /// limit without rebounding), below it oscillates.
        damping_ratio: f32,
    },
}

/// Which field a spring is, as its refusals name it
/// ([`Spring::check`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpringField {
    /// A drive's strength: `drive compliance`, `drive damping ratio`, ...
    Drive,
    /// A limit's softness: `limit compliance`, `limit damping ratio`, ...
    Limit,
    /// A world drive's position part: `world drive position frequency`, ...
    WorldPosition,
    /// A world drive's orientation part: `world drive orientation
    /// frequency`, ...
    WorldOrientation,
    /// An upright drive's strength: `upright drive frequency`, ...
    Upright,
}

/// The names a check gives a spring's numbers and ranges.
struct Names {
    compliance: &'static str,
    damping: &'static str,
    damping_time: &'static str,
    frequency: &'static str,
    min_frequency: &'static str,
    damping_ratio: &'static str,
    max_damping_ratio: &'static str,
}

/// The names of the field `$field` (`Error` carries static text, so they
/// are put together as the program is compiled).
macro_rules! names {
    ($field:literal) => {
        Names {
            compliance: concat!($field, " compliance"),
            damping: concat!($field, " damping"),
            damping_time: concat!($field, " damping (compliance times damping at most 1e6 s)"),
            frequency: concat!($field, " frequency"),
            min_frequency: concat!($field, " frequency (at least 1e-3 Hz)"),
            damping_ratio: concat!($field, " damping ratio"),
            max_damping_ratio: concat!($field, " damping ratio (at most 1e3)"),
        }
    };
}

impl SpringField {
    fn names(self) -> Names {
        match self {
            Self::Drive => names!("drive"),
            Self::Limit => names!("limit"),
            Self::WorldPosition => names!("world drive position"),
            Self::WorldOrientation => names!("world drive orientation"),
            Self::Upright => names!("upright drive"),
        }
    }
}

/// A spring as the kernels read it: `alpha = compliance + period2 W` (with
/// `W` the part's effective inverse inertia) and `gamma h = damping_time`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SpringLane {
    /// Compliance (rad / (N m)).
    pub compliance: f32,
    /// `1 / omega^2` (s^2), for a spring given by frequency.
    pub period2: f32,
    /// `gamma h` (s): compliance times damping, or `2 zeta / omega`.
    pub damping_time: f32,
}

impl Spring {
    /// Infinitely stiff: zero compliance (the target or limit is a hard
    /// constraint; the paper's figure 7 drives "with infinite strength").
    pub const RIGID: Self = Self::compliant(0.0);

    /// A spring of compliance `c` (rad / (N m)) without damping.
    pub const fn compliant(c: f32) -> Self {
        Self::Compliance {
            compliance: c,
            damping: 0.0,
        }
    }

    /// Checks the spring's numbers against their ranges (see each
    /// variant); the error names `field` and the number, e.g.
    /// `drive damping ratio (at most 1e3)`.
    pub fn check(&self, field: SpringField) -> Result<(), Error> {
        let names = field.names();
        match *self {
            Self::Compliance {
                compliance,
                damping,
            } => {
                finite_not_negative(names.compliance, compliance)?;
                finite_not_negative(names.damping, damping)?;
                if compliance * damping > MAX_DRIVE_DAMPING_TIME {
                    return Err(Error::OutOfRange(names.damping_time));
                }
            }
            Self::Frequency {
                frequency,
                damping_ratio,
            } => {
                if frequency.is_nan() {
                    return Err(Error::NonFinite(names.frequency));
                }
                if frequency < MIN_DRIVE_FREQUENCY {
                    return Err(Error::OutOfRange(names.min_frequency));
                }
                finite_not_negative(names.damping_ratio, damping_ratio)?;
                if damping_ratio > MAX_DRIVE_DAMPING_RATIO {
                    return Err(Error::OutOfRange(names.max_damping_ratio));
                }
            }
        }
        Ok(())
    }

    /// The kernels' numbers (`parts::drive`, `parts::limit`); all 0 when
    /// rigid (and for an infinite frequency).
    pub(crate) fn lane(&self) -> SpringLane {
        match *self {
            Self::Compliance {
                compliance,
                damping,
            } => SpringLane {
                compliance,
                period2: 0.0,
                damping_time: compliance * damping,
            },
            Self::Frequency {
                frequency,
                damping_ratio,
            } => {
                let omega = TAU * frequency;
                SpringLane {
                    compliance: 0.0,
                    period2: 1.0 / (omega * omega),
                    damping_time: 2.0 * damping_ratio / omega,
                }
            }
        }
    }
}

/// Finite and not negative, else the error naming `what`.
fn finite_not_negative(what: &'static str, x: f32) -> Result<(), Error> {
    if !x.is_finite() {
        return Err(Error::NonFinite(what));
    }
    if x < 0.0 {
        return Err(Error::NonPositive(what));
    }
    Ok(())
}
