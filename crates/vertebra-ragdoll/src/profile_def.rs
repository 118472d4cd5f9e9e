//! Profiles in a description file: `[[profile]]` tables, each a name, an
//! optional `base` (an earlier profile it starts from), the joints' drive, the bodies' world drive, uprights, and `[[profile.bone]]`
//! tables that change a body (and, with `below = true`, every body below
//! it) in file order, resolved into a [`Profile`] once the joint tree
//! stands; and profiles fitted to a description (made limp, scaled per
//! subtree, checked); see `docs/ragdolls.md`, "Profiles".

use serde::Deserialize;
use vertebra_world::{Spring, SpringField};

use crate::drive_def::{RawDrive, RawInfinite, RawStrength};
use crate::error::{RagdollError, check_spring, finite, range};
use crate::model::RagdollDesc;
use crate::profile::{
    BodyDriveSetting, JointDriveSetting, Profile, UprightSetting, check_multiplier,
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
    base: Option<String>,
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
    let mut profile = match &raw.base {
        Some(base) => {
            let found = desc.profile(base).ok_or_else(|| RagdollError::OutOfRange {
                context: context.to_owned(),
                field: "base",
                reason: format!("names `{base}`, which is no profile above this one"),
            })?;
            Profile {
                name: raw.name.clone(),
                ..found.clone()
            }
        }
        None => Profile {
            name: raw.name.clone(),
            joints: vec![JointDriveSetting::NONE; desc.joints.len()],
            bodies: vec![BodyDriveSetting::NONE; desc.bodies.len()],
        },
    };
    if let Some(d) = &raw.joints {
        let context = format!("{context} joints");
        for j in &mut profile.joints {
            *j = joint_setting(d, *j, &context)?;
        }
    }
    if let Some(w) = &raw.world {
        let context = format!("{context} world");
        for b in &mut profile.bodies {
            *b = world_setting(w, *b, &context)?;
        }
    }
    // A based profile's uprights may be given again; one table gives a
    // body at most one.
    let named: Vec<&str> = raw.upright.iter().map(|u| u.body.as_str()).collect();
    let mut multipliers = vec![1.0_f32; desc.bodies.len()];
    for (k, bone) in raw.bone.iter().enumerate() {
        let context = format!("{context} bone {k}");
        let b = body_named(desc, &bone.body, &context)?;
        if let Some(m) = bone.strength_multiplier {
            check_multiplier(&context, m)?;
        }
        let below = bone.below.unwrap_or(false);
        let no_joint = bone.joints.is_some() && !below && desc.parent_joint[b].is_none();
        range(
            &context,
            "joints",
            !no_joint,
            "is for the joint above the body, and the root has none (below = true reaches the joints below it)",
        )?;
        for c in covered(desc, b, below) {
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
        let once = !named[..k].contains(&u.body.as_str());
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

impl Profile {
    /// Nothing driven: the ragdoll limp.
    pub fn limp(name: &str, desc: &RagdollDesc) -> Self {
        Self {
            name: name.to_owned(),
            joints: vec![JointDriveSetting::NONE; desc.joints.len()],
            bodies: vec![BodyDriveSetting::NONE; desc.bodies.len()],
        }
    }

    /// The profile with the drives of `body` (its world and upright drives
    /// and the drive of the joint above it) and, if `below`, of every body
    /// below it in the joint tree, scaled by `multiplier` (0..1: 0 turns
    /// them off, 1 leaves them). Refused, naming the field, for a body out
    /// of range or a multiplier outside 0..1.
    pub fn scaled(
        &self,
        desc: &RagdollDesc,
        body: usize,
        below: bool,
        multiplier: f32,
    ) -> Result<Self, RagdollError> {
        let context = format!("profile `{}`", self.name);
        self.validate_counts(desc, &context)?;
        check_multiplier(&context, multiplier)?;
        let n = desc.bodies.len();
        range(&context, "body", body < n, &format!("must be below {n}"))?;
        let mut out = self.clone();
        for b in covered(desc, body, below) {
            out.bodies[b] = out.bodies[b].scaled(multiplier);
            if let Some(k) = desc.parent_joint[b] {
                out.joints[k] = out.joints[k].scaled(multiplier);
            }
        }
        Ok(out)
    }

    /// Checks the profile for `desc`: one entry per joint and per body,
    /// every strength one the world takes, every cap a number not
    /// negative. Errors name the profile and the joint or body.
    pub fn validate(&self, desc: &RagdollDesc) -> Result<(), RagdollError> {
        self.check(desc, &format!("profile `{}`", self.name))
    }

    /// [`Profile::validate`], errors naming `context` (the profile, with
    /// the line of its table in a file).
    pub(crate) fn check(&self, desc: &RagdollDesc, context: &str) -> Result<(), RagdollError> {
        self.validate_counts(desc, context)?;
        for (j, s) in desc.joints.iter().zip(&self.joints) {
            let context = format!("{context} joint `{}`", j.name);
            if let Some(strength) = s.strength {
                strength_in_range(&context, "drive", strength, SpringField::Drive)?;
            }
            check_cap(&context, "max_torque", s.max_torque)?;
        }
        for (b, s) in desc.bodies.iter().zip(&self.bodies) {
            let context = format!("{context} body `{}`", b.name);
            if let Some(strength) = s.linear {
                strength_in_range(&context, "linear", strength, SpringField::WorldPosition)?;
            }
            if let Some(strength) = s.angular {
                strength_in_range(&context, "angular", strength, SpringField::WorldOrientation)?;
            }
            check_cap(&context, "max_acceleration", s.max_acceleration)?;
            check_cap(&context, "max_torque", s.max_torque)?;
            if let Some(u) = s.upright {
                strength_in_range(&context, "upright", u.strength, SpringField::Upright)?;
                check_cap(&context, "upright max_torque", u.max_torque)?;
            }
        }
        Ok(())
    }

    fn validate_counts(&self, desc: &RagdollDesc, context: &str) -> Result<(), RagdollError> {
        let (joints, bodies) = (desc.joints.len(), desc.bodies.len());
        range(
            context,
            "joints",
            self.joints.len() == joints,
            &format!("needs {joints} entries, one per joint"),
        )?;
        range(
            context,
            "bodies",
            self.bodies.len() == bodies,
            &format!("needs {bodies} entries, one per body"),
        )
    }
}

/// The bodies `body` covers: itself and, if `below`, every body whose
/// chain of joints toward the root passes it.
fn covered(desc: &RagdollDesc, body: usize, below: bool) -> Vec<usize> {
    (0..desc.bodies.len())
        .filter(|&b| b == body || (below && is_below(desc, b, body)))
        .collect()
}

/// Whether `b` lies below `above` in the joint tree.
fn is_below(desc: &RagdollDesc, mut b: usize, above: usize) -> bool {
    // A tree: at most one joint per body toward the root.
    for _ in 0..desc.bodies.len() {
        let Some(k) = desc.parent_joint.get(b).copied().flatten() else {
            return false;
        };
        b = desc.joints[k].parent;
        if b == above {
            return true;
        }
    }
    false
}

/// A profile's strength as the world checks it, and finite: a rigid one is
/// a zero compliance (`strength = "infinite"` in a file), which a file
/// writes and reads back, where an infinite frequency does not.
fn strength_in_range(
    context: &str,
    field: &'static str,
    strength: Spring,
    of: SpringField,
) -> Result<(), RagdollError> {
    check_spring(context, field, strength, of)?;
    let finite = match strength {
        Spring::Frequency { frequency, .. } => frequency.is_finite(),
        Spring::Compliance { .. } => true,
    };
    range(
        context,
        field,
        finite,
        "has an infinite frequency; a rigid drive in a profile is a zero compliance",
    )
}

fn check_cap(context: &str, field: &'static str, cap: f32) -> Result<(), RagdollError> {
    range(
        context,
        field,
        !(cap.is_nan() || cap < 0.0),
        "must be a number, not negative",
    )
}
