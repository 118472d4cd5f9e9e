//! Drive settings in a description file: a `[drive]` table (how every
//! joint is driven toward an animation pose by default) and a joint's own
//! `drive = { ... }` strength; see `docs/ragdolls.md`.

use serde::Deserialize;
use vertebra_world::Spring;

use crate::drive::DriveSettings;
use crate::error::{RagdollError, finite, range};

/// A strength as written: `strength = "infinite"`, `frequency` (Hz) with
/// `damping_ratio`, or `compliance` (rad / (N m)) with an optional
/// `damping` (N m s / rad).
#[derive(Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawStrength {
    pub(crate) strength: Option<RawInfinite>,
    pub(crate) frequency: Option<f32>,
    pub(crate) damping_ratio: Option<f32>,
    pub(crate) compliance: Option<f32>,
    pub(crate) damping: Option<f32>,
}

/// The one word `strength` takes.
#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum RawInfinite {
    Infinite,
}

/// The `[drive]` table: a strength, and the torque limit (N m) every joint
/// shares. Its damping is also that of a joint's own compliance that gives
/// none.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDrive {
    pub(crate) strength: Option<RawInfinite>,
    pub(crate) frequency: Option<f32>,
    pub(crate) damping_ratio: Option<f32>,
    pub(crate) compliance: Option<f32>,
    pub(crate) damping: Option<f32>,
    max_torque: Option<f32>,
}

impl RawStrength {
    /// The strength, or why the fields do not make one; a compliance
    /// without its own damping takes `damping`.
    pub(crate) fn read(&self, context: &str, damping: f32) -> Result<Spring, RagdollError> {
        let numbers = [
            self.frequency,
            self.damping_ratio,
            self.compliance,
            self.damping,
        ];
        finite(
            context,
            "drive",
            &numbers.iter().flatten().copied().collect::<Vec<_>>(),
        )?;
        let one_of = |ok: bool| {
            range(
                context,
                "drive",
                ok,
                "takes one of: strength = \"infinite\", frequency with damping_ratio, or compliance",
            )
        };
        let strength = match (
            self.strength,
            self.frequency,
            self.damping_ratio,
            self.compliance,
        ) {
            (Some(RawInfinite::Infinite), None, None, None) => Spring::RIGID,
            (None, Some(frequency), Some(damping_ratio), None) => Spring::Frequency {
                frequency,
                damping_ratio,
            },
            (None, None, None, Some(compliance)) => {
                return Ok(Spring::Compliance {
                    compliance,
                    damping: self.damping.unwrap_or(damping),
                });
            }
            _ => return one_of(false).map(|()| Spring::RIGID),
        };
        range(
            context,
            "damping",
            self.damping.is_none(),
            "is for a compliance strength only (a spring's damping is its ratio)",
        )?;
        Ok(strength)
    }
}

impl RawDrive {
    /// The damping a joint's own compliance takes when it gives none: the
    /// table's (N m s / rad), or none.
    pub(crate) fn damping(&self) -> f32 {
        self.damping.unwrap_or(0.0)
    }

    /// The table's strength fields.
    pub(crate) fn strength_fields(&self) -> RawStrength {
        RawStrength {
            strength: self.strength,
            frequency: self.frequency,
            damping_ratio: self.damping_ratio,
            compliance: self.compliance,
            damping: self.damping,
        }
    }

    /// The torque limit (N m), if the table gives one.
    pub(crate) fn max_torque(&self) -> Option<f32> {
        self.max_torque
    }
}

impl RawStrength {
    /// Whether any strength field is given.
    pub(crate) fn is_given(&self) -> bool {
        self.strength.is_some()
            || self.frequency.is_some()
            || self.damping_ratio.is_some()
            || self.compliance.is_some()
            || self.damping.is_some()
    }
}

/// The `[drive]` table as drive settings without per-joint strengths (the
/// assembly adds the joints' own): one strength (a damping only for a
/// compliance) and a torque limit. Its values are checked with the whole
/// description (`check_drive`).
pub(crate) fn drive_settings(raw: &RawDrive, context: &str) -> Result<DriveSettings, RagdollError> {
    let strength = raw.strength_fields().read(context, 0.0)?;
    let mut settings = DriveSettings::uniform(strength);
    if let Some(t) = raw.max_torque {
        settings = settings.with_max_torque(t);
    }
    Ok(settings)
}
