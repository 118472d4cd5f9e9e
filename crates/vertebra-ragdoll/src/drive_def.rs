//! Drive settings in a description file: a `[drive]` table (how every
//! joint is driven toward an animation pose by default) and a joint's own
//! `drive = { ... }` strength; see `docs/ragdolls.md`.

use serde::Deserialize;

use crate::description::{finite, range};
use crate::drive::{DriveSettings, Strength};
use crate::error::RagdollError;

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

/// The ragdoll's drive settings from its `[drive]` table (at `line`) and
/// each joint's own strength (`None` where it has none), checked as the
/// world will check them.
pub(crate) fn drive_settings(
    raw: &RawDrive,
    line: usize,
    joints: Vec<Option<Strength>>,
) -> Result<DriveSettings, RagdollError> {
    let context = format!("line {line}: [drive]");
    let strength = RawStrength {
        strength: raw.strength,
        frequency: raw.frequency,
        damping_ratio: raw.damping_ratio,
        compliance: raw.compliance,
    }
    .read(&context)?;
    let mut settings = DriveSettings::uniform(strength);
    if let Some(d) = raw.damping {
        range(
            &context,
            "damping",
            strength_is_compliance(strength),
            "is for a compliance strength only (a spring's damping is its ratio)",
        )?;
        settings = settings.with_damping(d);
    }
    if let Some(t) = raw.max_torque {
        settings = settings.with_max_torque(t);
    }
    if joints.iter().any(Option::is_some) {
        settings.joints = joints;
    }
    let count = settings.joints.len();
    settings
        .validate(count)
        .map_err(|e| in_context(&context, e))?;
    Ok(settings)
}

fn strength_is_compliance(s: Strength) -> bool {
    matches!(s, Strength::Compliance(_))
}

/// `e`, said of the `[drive]` table at its line.
fn in_context(context: &str, e: RagdollError) -> RagdollError {
    match e {
        RagdollError::OutOfRange { field, reason, .. } => RagdollError::OutOfRange {
            context: context.to_owned(),
            field,
            reason,
        },
        other => other,
    }
}
