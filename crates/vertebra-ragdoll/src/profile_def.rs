//! Profiles in a description file: `[[profile]]` tables, each a name, the
//! joints' drive, the bodies' world drive, uprights, and `[[profile.bone]]`
//! tables that change a body (and, with `below = true`, every body below
//! it) in file order, resolved into a [`Profile`] once the joint tree
//! stands; see `docs/ragdolls.md`, "Profiles".

use serde::Deserialize;
use vertebra_world::Spring;

use crate::drive_def::{RawDrive, RawInfinite, RawStrength};
use crate::error::{RagdollError, finite, range};
use crate::model::RagdollDesc;
use crate::profile::{
    BodyDriveSetting, JointDriveSetting, Profile, UprightSetting, check_multiplier, covered,
};

/// A profile as a description gives it: a file's table, resolved once the
/// joint tree stands, or one a builder was given whole.
pub(crate) enum ProfileSource {
    File(RawProfile),
    Built(Profile),
}

impl ProfileSource {
    pub(crate) fn name(&self) -> &str {
        match self {
            Self::File(raw) => &raw.name,
            Self::Built(p) => &p.name,
        }
    }

    /// The profile for `desc`; errors name `context`.
    pub(crate) fn resolve(
        &self,
        desc: &RagdollDesc,
        context: &str,
    ) -> Result<Profile, RagdollError> {
        match self {
            Self::File(raw) => resolve(raw, desc, context),
            Self::Built(p) => Ok(p.clone()),
        }
    }
}

/// A `[[profile]]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawProfile {
    name: String,
    joints: Option<RawDrive>,
    world: Option<RawWorld>,
    #[serde(default)]
    upright: Vec<RawUpright>,
    #[serde(default)]
    bone: Vec<RawProfileBone>,
}

/// `world = { linear = { ... }, angular = { ... }, max_acceleration, max_torque }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWorld {
    linear: Option<RawStrength>,
    angular: Option<RawStrength>,
    max_acceleration: Option<f32>,
    max_torque: Option<f32>,
}

/// `upright = [{ body = "hips", frequency = 2.0, damping_ratio = 1.0,
/// max_torque = 100.0 }, ...]`: the strength fields of a drive.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawUpright {
    body: String,
    strength: Option<RawInfinite>,
    frequency: Option<f32>,
    damping_ratio: Option<f32>,
    compliance: Option<f32>,
    damping: Option<f32>,
    max_torque: Option<f32>,
}

/// A `[[profile.bone]]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawProfileBone {
    body: String,
    below: Option<bool>,
    strength_multiplier: Option<f32>,
    joints: Option<RawDrive>,
    world: Option<RawWorld>,
}

/// The profile `raw` gives `desc` (its joint tree standing); errors name
/// `context` (the profile), an upright or a bone table by its index.
fn resolve(raw: &RawProfile, desc: &RagdollDesc, context: &str) -> Result<Profile, RagdollError> {
    let joint = match &raw.joints {
        Some(d) => joint_setting(d, JointDriveSetting::NONE, &format!("{context} joints"))?,
        None => JointDriveSetting::NONE,
    };
    let body = match &raw.world {
        Some(w) => world_setting(w, BodyDriveSetting::NONE, &format!("{context} world"))?,
        None => BodyDriveSetting::NONE,
    };
    let mut profile = Profile {
        name: raw.name.clone(),
        joints: vec![joint; desc.joints.len()],
        bodies: vec![body; desc.bodies.len()],
    };
    let mut multipliers = vec![1.0_f32; desc.bodies.len()];
    for (k, bone) in raw.bone.iter().enumerate() {
        let context = format!("{context} bone {k}");
        let b = body_named(desc, &bone.body, &context)?;
        if let Some(m) = bone.strength_multiplier {
            check_multiplier(&context, m)?;
        }
        for c in covered(desc, b, bone.below.unwrap_or(false)) {
            if let (Some(d), Some(j)) = (&bone.joints, desc.parent_joint[c]) {
                profile.joints[j] = joint_setting(d, profile.joints[j], &context)?;
            }
            if let Some(w) = &bone.world {
                profile.bodies[c] = world_setting(w, profile.bodies[c], &context)?;
            }
            if let Some(m) = bone.strength_multiplier {
                multipliers[c] = m;
            }
        }
    }
    for (k, u) in raw.upright.iter().enumerate() {
        let context = format!("{context} upright {k}");
        let b = body_named(desc, &u.body, &context)?;
        let once = profile.bodies[b].upright.is_none();
        range(
            &context,
            "body",
            once,
            "names a body an earlier upright names",
        )?;
        let fields = RawStrength {
            strength: u.strength,
            frequency: u.frequency,
            damping_ratio: u.damping_ratio,
            compliance: u.compliance,
            damping: u.damping,
        };
        let strength = fields.read(&context, 0.0)?;
        let max_torque = u.max_torque.unwrap_or(f32::INFINITY);
        finite_or_unlimited(&context, "max_torque", max_torque)?;
        profile.bodies[b].upright = Some(UprightSetting {
            strength,
            max_torque,
        });
    }
    for (b, &m) in multipliers.iter().enumerate() {
        if m != 1.0 {
            profile = profile.scaled(desc, b, false, m)?;
        }
    }
    Ok(profile)
}

fn body_named(desc: &RagdollDesc, name: &str, context: &str) -> Result<usize, RagdollError> {
    desc.body_index(name)
        .ok_or_else(|| RagdollError::OutOfRange {
            context: context.to_owned(),
            field: "body",
            reason: format!("names `{name}`, which is no body of the ragdoll"),
        })
}

/// A joint's setting from a `joints` table over `base`: the table's
/// strength if it gives one, its torque limit if it gives one.
fn joint_setting(
    raw: &RawDrive,
    base: JointDriveSetting,
    context: &str,
) -> Result<JointDriveSetting, RagdollError> {
    let fields = raw.strength_fields();
    let strength = match fields.is_given() {
        true => Some(fields.read(context, 0.0)?),
        false => base.strength,
    };
    let max_torque = raw.max_torque().unwrap_or(base.max_torque);
    finite_or_unlimited(context, "max_torque", max_torque)?;
    Ok(JointDriveSetting {
        strength,
        max_torque,
    })
}

/// A body's world drive from a `world` table over `base`, part by part.
fn world_setting(
    raw: &RawWorld,
    base: BodyDriveSetting,
    context: &str,
) -> Result<BodyDriveSetting, RagdollError> {
    let part = |s: &Option<RawStrength>, base: Option<Spring>| match s {
        Some(s) => s.read(context, 0.0).map(Some),
        None => Ok(base),
    };
    let out = BodyDriveSetting {
        linear: part(&raw.linear, base.linear)?,
        angular: part(&raw.angular, base.angular)?,
        max_acceleration: raw.max_acceleration.unwrap_or(base.max_acceleration),
        max_torque: raw.max_torque.unwrap_or(base.max_torque),
        upright: base.upright,
    };
    finite_or_unlimited(context, "max_acceleration", out.max_acceleration)?;
    finite_or_unlimited(context, "max_torque", out.max_torque)?;
    Ok(out)
}

/// A cap as a file gives it: a finite number (no cap is written as no
/// field).
fn finite_or_unlimited(context: &str, field: &'static str, cap: f32) -> Result<(), RagdollError> {
    if cap.is_infinite() && cap > 0.0 {
        return Ok(());
    }
    finite(context, field, &[cap])?;
    range(context, field, cap >= 0.0, "must not be negative")
}
