//! Drive settings in a description file: a `[drive]` table (how every
//! joint is driven toward an animation pose by default) and a joint's own
//! `drive = { ... }` strength; see `docs/ragdolls.md`.

use serde::Deserialize;

use crate::drive::{DriveSettings, Strength};
use crate::error::{RagdollError, finite, range};

/// A strength as written: `strength = "infinite"`, `frequency` (Hz) with
/// `damping_ratio`, or `compliance` (rad / (N m)).
#[derive(Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawStrength {
    strength: Option<RawInfinite>,
    frequency: Option<f32>,
    damping_ratio: Option<f32>,
    compliance: Option<f32>,
}

/// The one word `strength` takes.
#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
enum RawInfinite {
    Infinite,
}

/// The `[drive]` table: a strength, and the damping (N m s / rad, for a
/// compliance) and torque limit (N m) every joint shares.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawDrive {
    strength: Option<RawInfinite>,
    frequency: Option<f32>,
    damping_ratio: Option<f32>,
    compliance: Option<f32>,
    damping: Option<f32>,
    max_torque: Option<f32>,
}

impl RawStrength {
    /// The strength, or why the fields do not make one.
    pub(crate) fn read(&self, context: &str) -> Result<Strength, RagdollError> {
        let numbers = [self.frequency, self.damping_ratio, self.compliance];
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
        match (
            self.strength,
            self.frequency,
            self.damping_ratio,
            self.compliance,
        ) {
            (Some(RawInfinite::Infinite), None, None, None) => Ok(Strength::Infinite),
            (None, Some(frequency), Some(damping_ratio), None) => Ok(Strength::Spring {
                frequency,
                damping_ratio,
            }),
            (None, None, None, Some(c)) => Ok(Strength::Compliance(c)),
            _ => one_of(false).map(|()| Strength::Infinite),
        }
    }
}

/// The `[drive]` table as drive settings without per-joint strengths (the
/// assembly adds the joints' own): one strength, a damping only for a
/// compliance, a torque limit. Its values are checked with the whole
/// description (`check_drive`).
pub(crate) fn drive_settings(raw: &RawDrive, context: &str) -> Result<DriveSettings, RagdollError> {
    let strength = RawStrength {
        strength: raw.strength,
        frequency: raw.frequency,
        damping_ratio: raw.damping_ratio,
        compliance: raw.compliance,
    }
    .read(context)?;
    let mut settings = DriveSettings::uniform(strength);
    if let Some(d) = raw.damping {
        damping_for_compliance(context, strength, true)?;
        settings = settings.with_damping(d);
    }
    if let Some(t) = raw.max_torque {
        settings = settings.with_max_torque(t);
    }
    Ok(settings)
}

/// A damping (`given`) is for a compliance strength only.
pub(crate) fn damping_for_compliance(
    context: &str,
    strength: Strength,
    given: bool,
) -> Result<(), RagdollError> {
    range(
        context,
        "damping",
        !given || matches!(strength, Strength::Compliance(_)),
        "is for a compliance strength only (a spring's damping is its ratio)",
    )
}
