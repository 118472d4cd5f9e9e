//! A generator file (`docs/ragdolls.md`, "Generating a ragdoll from a
//! skeleton"): a [`RagdollGenerator`]'s choices as TOML, read against a
//! skeleton the caller gives. `[[body]]` tables name a `bone` with its
//! `radius` (m) and `mass` (kg) or `density` (kg/m^3), optionally its end
//! (`end = "bone"`, `length` (m) along the bone's +Y, or `point = [x, y,
//! z]` (m, the bone's frame)) and its `joint = { ... }` (a `[[joint]]`
//! table's `kind`, limits in degrees and `softness`, its `axis` and
//! `normal` in the bone's frame); an optional `[spine]` names its `from`
//! and `to` bones with the rod's limits (degrees) and stiffness.

use std::path::Path;

use glam::Vec3;
use serde::Deserialize;
use toml::Spanned;

use crate::error::{Problems, RagdollError, first};
use crate::generate::{BodyMass, BoneBody, RagdollGenerator, RodSpine, SegmentEnd};
use crate::joint_def::RawBoneJoint;
use crate::model::RagdollDesc;
use crate::skeleton::Skeleton;
use crate::text::{Lines, in_file, item, read_text, syntax, within_cap};
use vertebra_math::DefaultFloatMode;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGenerator {
    name: String,
    total_mass: Option<f32>,
    body: Vec<Spanned<RawBoneBody>>,
    spine: Option<Spanned<RawRodSpine>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBoneBody {
    bone: String,
    radius: f32,
    mass: Option<f32>,
    density: Option<f32>,
    end: Option<String>,
    length: Option<f32>,
    point: Option<[f32; 3]>,
    joint: Option<RawBoneJoint>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRodSpine {
    from: String,
    to: String,
    bend_limit: f32,
    twist_limit: [f32; 2],
    bend_stiffness: f32,
    twist_stiffness: f32,
}

impl RagdollGenerator {
    /// Parses a generator file's text into a generator over `skeleton`:
    /// its choices as written, checked for form here (one of `mass` and
    /// `density`, at most one of `end`, `length` and `point`, the joint's
    /// fields those of its kind: errors start with the line of the body's
    /// table) and for sense by [`RagdollGenerator::generate`] (errors
    /// name the bone). A text longer than
    /// [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES) is refused before it is
    /// parsed, as a file is, and more `[[body]]` tables than the skeleton
    /// has bones before any is read.
    pub fn from_toml(text: &str, skeleton: &Skeleton) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        Self::read(text, skeleton).map_err(first)
    }

    /// [`RagdollGenerator::from_toml`], refused with every table's problem
    /// of form, in file order.
    fn read(text: &str, skeleton: &Skeleton) -> Result<Self, Vec<RagdollError>> {
        within_cap(text.len() as u64, "generator").map_err(|e| vec![e])?;
        let lines = Lines::new(text);
        let raw: RawGenerator =
            toml::from_str(text).map_err(|e| vec![syntax("generator", &lines, &e)])?;
        // A bone has at most one body: counted before any table is read.
        if raw.body.len() > skeleton.len() {
            return Err(vec![RagdollError::OutOfRange {
                context: format!("generator `{}`", raw.name),
                field: "body",
                reason: format!(
                    "has {} tables; at most one per bone of the skeleton ({})",
                    raw.body.len(),
                    skeleton.len()
                ),
            }]);
        }
        let mut generator = crate::RagdollDesc::generator(&raw.name, skeleton);
        let mut problems = Problems::default();
        for b in &raw.body {
            let line = lines.at(b.span().start);
            let context = item(Some(line), &format!("bone `{}`", b.get_ref().bone));
            if let Some(body) = problems.note(Some(line), bone_body(b.get_ref(), &context)) {
                generator = generator.body(body);
            }
        }
        problems.done()?;
        if let Some(s) = &raw.spine {
            let s = s.get_ref();
            generator = generator.spine(RodSpine {
                from: s.from.clone(),
                to: s.to.clone(),
                bend_limit: s.bend_limit.to_radians(),
                twist_limit: s.twist_limit.map(f32::to_radians),
                bend_stiffness: s.bend_stiffness,
                twist_stiffness: s.twist_stiffness,
            });
        }
        Ok(match raw.total_mass {
            Some(kg) => generator.total_mass(kg),
            None => generator,
        })
    }

    /// Reads a generator file of at most
    /// [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES) into a generator over
    /// `skeleton` ([`RagdollGenerator::from_toml`]); errors name the file.
    pub fn from_file(path: &Path, skeleton: &Skeleton) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let text = read_text(path, "generator")?;
        Self::from_toml(&text, skeleton).map_err(|e| in_file(path, e))
    }

    /// Reads a generator file over `skeleton` and generates its
    /// description (`vertebra check`): refused with every `[[body]]`
    /// table's problem of form (by line), else with what
    /// [`RagdollGenerator::generate`] refuses; each names the file.
    pub fn check_file(path: &Path, skeleton: &Skeleton) -> Result<RagdollDesc, Vec<RagdollError>> {
        let _mode = DefaultFloatMode::enter();
        let text = read_text(path, "generator").map_err(|e| vec![e])?;
        Self::read(&text, skeleton)
            .and_then(|generator| generator.generate().map_err(|e| vec![e]))
            .map_err(|problems| problems.into_iter().map(|e| in_file(path, e)).collect())
    }
}

/// A `[[body]]` table as a [`BoneBody`].
fn bone_body(b: &RawBoneBody, context: &str) -> Result<BoneBody, RagdollError> {
    let refuse = |field, reason: &str| RagdollError::OutOfRange {
        context: context.to_owned(),
        field,
        reason: reason.to_owned(),
    };
    let mass = match (b.mass, b.density) {
        (Some(kg), None) => BodyMass::Mass(kg),
        (None, Some(density)) => BodyMass::Density(density),
        (Some(_), Some(_)) => {
            return Err(refuse("mass", "and density both give the mass; give one"));
        }
        (None, None) => return Err(refuse("mass", "is missing: give mass or density")),
    };
    let end = match (&b.end, b.length, b.point) {
        (None, None, None) => SegmentEnd::Next,
        (Some(bone), None, None) => SegmentEnd::Bone(bone.clone()),
        (None, Some(length), None) => SegmentEnd::Length(length),
        (None, None, Some(point)) => SegmentEnd::Point(Vec3::from(point)),
        _ => {
            return Err(refuse(
                "end",
                "is given twice: give one of end, length and point",
            ));
        }
    };
    let mut body = BoneBody::new(&b.bone, b.radius, mass);
    body.end = end;
    if let Some(joint) = &b.joint {
        (body.joint, body.axis, body.normal) = joint.read(&format!("{context}: joint"))?;
    }
    Ok(body)
}
