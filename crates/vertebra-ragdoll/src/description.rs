//! The ragdoll description format (`docs/ragdolls.md`): TOML with bodies as
//! capsules (given by a segment, or from one bone of the skeleton to
//! another), joints (sockets with swing and twist limits, hinges, fixed
//! joints: `joint_def.rs`), an optional `[spine]` chain that the simplified
//! ragdoll replaces by a rod, an optional `[drive]`, named
//! `[[profile]]` tables (`profile_def.rs`), and an optional skeleton (`[[bone]]` tables, or a skeleton file) the bodies follow.
//! Units in the file: metres, kilograms, degrees; here: metres, kilograms,
//! radians.
//!
//! A file is read into specs (what [`RagdollDesc::builder`] takes too) and
//! assembled (`assemble.rs`): one path, one set of checks, whichever way a
//! description is made.

use std::path::Path;

use glam::{Quat, Vec3};
use serde::Deserialize;
use toml::Spanned;

use crate::assemble::{Document, Item, assemble_all};
use crate::drive_def::{RawDrive, drive_settings};
use crate::error::{Problems, RagdollError, first};
use crate::joint_def::{RawJoint, joint_spec};
use crate::model::RagdollDesc;
use crate::profile_def::{ProfileSource, RawProfile};
use crate::skeleton::{Skeleton, Transform};
use crate::skeleton_file::{RawBone, bones_all, syntax_naming};
use crate::spec::{BodyShape, BodySpec, SpineSpec};
use crate::text::{Lines, in_file, item, read_text, within_cap};
use vertebra_math::DefaultFloatMode;

/// The reference humanoid, shipped with the crate: 13 bodies, 12 joints,
/// a 4-body spine.
pub const REFERENCE_HUMANOID: &str = include_str!("../models/humanoid.toml");

/// The anatomical humanoid, shipped with the crate: the reference
/// humanoid's 13 bodies with hinged knees and elbows, elliptical shoulders,
/// hips and spine joints, and a neck, and two feet on pyramid ankles (15
/// bodies, 14 joints; `models/anatomical.toml`).
pub const ANATOMICAL_HUMANOID: &str = include_str!("../models/anatomical.toml");

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    name: String,
    total_mass: Option<f32>,
    skeleton: Option<Spanned<String>>,
    #[serde(default)]
    bone: Vec<Spanned<RawBone>>,
    body: Vec<Spanned<RawBody>>,
    #[serde(default)]
    joint: Vec<Spanned<RawJoint>>,
    spine: Option<Spanned<RawSpine>>,
    drive: Option<Spanned<RawDrive>>,
    #[serde(default)]
    profile: Vec<Spanned<RawProfile>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBody {
    name: String,
    segment: Option<[[f32; 3]; 2]>,
    from: Option<String>,
    to: Option<String>,
    radius: f32,
    mass: f32,
    bone: Option<String>,
    offset: Option<RawTransform>,
}

/// `offset = { translation = [x, y, z], rotation = [x, y, z, w] }`, each
/// part optional (zero, identity).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTransform {
    translation: Option<[f32; 3]>,
    rotation: Option<[f32; 4]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSpine {
    bodies: Vec<String>,
    bend_limit: f32,
    twist_limit: [f32; 2],
    bend_stiffness: f32,
    twist_stiffness: f32,
}

/// Where a file's skeleton may come from besides its own `[[bone]]`
/// tables.
enum Given<'a> {
    /// Nothing: a `skeleton = "file"` cannot be found.
    Nothing,
    /// The ragdoll file's directory, where `skeleton = "file"` is found.
    Dir(&'a Path),
    /// A skeleton from the caller.
    Skeleton(&'a Skeleton),
}

impl RagdollDesc {
    /// The reference humanoid (`models/humanoid.toml`).
    pub fn reference_humanoid() -> Self {
        Self::from_toml(REFERENCE_HUMANOID).expect("the shipped reference humanoid is valid")
    }

    /// The anatomical humanoid (`models/anatomical.toml`).
    pub fn anatomical_humanoid() -> Self {
        Self::from_toml(ANATOMICAL_HUMANOID).expect("the shipped anatomical humanoid is valid")
    }

    /// Reads, parses and validates a description file of at most
    /// [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES), with the skeleton file
    /// it names (`skeleton = "skeleton.toml"`, relative to the ragdoll
    /// file's directory); every error names the file (and the line, where
    /// there is one).
    pub fn from_file(path: &Path) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        Self::check_file(path).map_err(first)
    }

    /// [`RagdollDesc::from_file`], refused with every problem found rather
    /// than the first (which is what `from_file` says), in file order by
    /// line, each naming the file: `vertebra check`. A file that cannot be
    /// read or parsed as TOML has one problem; so has a skeleton that
    /// cannot be used (its file's problems, or its `[[bone]]` tables'),
    /// since the bodies are placed on it. Otherwise every body, joint,
    /// `[spine]` and `[drive]` table is checked on its own, the joint tree
    /// once every joint resolves, the spine's chain once the tree stands,
    /// and the whole description once every part passed.
    pub fn check_file(path: &Path) -> Result<Self, Vec<RagdollError>> {
        let _mode = DefaultFloatMode::enter();
        let text = read_text(path, "ragdoll").map_err(|e| vec![e])?;
        let dir = path.parent().unwrap_or(Path::new(""));
        Self::parse(&text, Given::Dir(dir))
            .map_err(|problems| problems.into_iter().map(|e| in_file(path, e)).collect())
    }

    /// Parses and validates a description of at most
    /// [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES) (a longer one is refused
    /// before it is parsed, as a file is). Errors about a body, joint,
    /// bone or the spine start with the line where it is defined. A file
    /// that names a skeleton file is refused: only
    /// [`RagdollDesc::from_file`] knows where to look for it.
    pub fn from_toml(text: &str) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        Self::check_toml(text).map_err(first)
    }

    /// [`RagdollDesc::from_toml`], refused with every problem found, in
    /// file order ([`RagdollDesc::check_file`] says what is checked when).
    pub fn check_toml(text: &str) -> Result<Self, Vec<RagdollError>> {
        let _mode = DefaultFloatMode::enter();
        Self::parse(text, Given::Nothing)
    }

    /// Parses and validates a description whose bodies follow the bones of
    /// `skeleton` (its model frame the file's world frame at bind pose):
    /// each body the bone of its name unless it says `bone = "..."`, and
    /// bodies may be defined `from` one bone `to` another. A file that
    /// carries its own skeleton is refused.
    pub fn from_toml_with_skeleton(text: &str, skeleton: &Skeleton) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        Self::parse(text, Given::Skeleton(skeleton)).map_err(first)
    }

    /// The description in `text`, or every problem found in it; a text
    /// longer than [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES) is refused
    /// before it is parsed.
    fn parse(text: &str, given: Given<'_>) -> Result<Self, Vec<RagdollError>> {
        within_cap(text.len() as u64, "ragdoll").map_err(|e| vec![e])?;
        let lines = Lines::new(text);
        let raw: RawFile = toml::from_str(text).map_err(|e| {
            vec![syntax_naming(
                "ragdoll",
                text,
                &lines,
                &e,
                &["bone", "body", "joint"],
            )]
        })?;
        let at = |span: core::ops::Range<usize>| lines.at(span.start);
        let skeleton = skeleton(&raw, given, &lines)?;
        let mut problems = Problems::default();
        let bodies = raw
            .body
            .iter()
            .map(|b| {
                let (line, r) = (at(b.span()), b.get_ref());
                let context = item(Some(line), &format!("body `{}`", r.name));
                match problems.note(Some(line), body_spec(r, &context)) {
                    Some(value) => Item::at(value, line),
                    None => Item::refused(r.stand_in(), line),
                }
            })
            .collect();
        // A joint's own compliance without a damping takes the table's.
        let damping = raw.drive.as_ref().map_or(0.0, |d| d.get_ref().damping());
        let joints = raw
            .joint
            .iter()
            .map(|j| {
                let (line, r) = (at(j.span()), j.get_ref());
                let context = item(Some(line), &format!("joint `{}`", r.name));
                match problems.note(Some(line), joint_spec(r, &context, damping)) {
                    Some(value) => Item::at(value, line),
                    None => Item::refused(r.stand_in(), line),
                }
            })
            .collect();
        let spine = raw.spine.as_ref().map(|s| {
            let r = s.get_ref();
            let value = SpineSpec {
                bodies: r.bodies.clone(),
                bend_limit: r.bend_limit.to_radians(),
                twist_limit: r.twist_limit.map(f32::to_radians),
                bend_stiffness: r.bend_stiffness,
                twist_stiffness: r.twist_stiffness,
            };
            Item::at(value, at(s.span()))
        });
        let drive = raw.drive.as_ref().and_then(|d| {
            let line = at(d.span());
            let read = drive_settings(d.get_ref(), &item(Some(line), "[drive]"));
            problems
                .note(Some(line), read)
                .map(|value| Item::at(value, line))
        });
        let doc = Document {
            name: raw.name,
            total_mass: raw.total_mass,
            skeleton,
            bodies,
            joints,
            spine,
            drive,
            profiles: (raw.profile.into_iter())
                .map(|p| {
                    let line = at(p.span());
                    Item::at(ProfileSource::File(p.into_inner()), line)
                })
                .collect(),
        };
        assemble_all(doc, problems)
    }
}

/// The skeleton of a file `raw`: its own `[[bone]]` tables, the skeleton
/// file it names (found through `given`), or the one `given`; refused with
/// the skeleton's problems, or with the one of having two.
fn skeleton(
    raw: &RawFile,
    given: Given<'_>,
    lines: &Lines,
) -> Result<Option<Skeleton>, Vec<RagdollError>> {
    let inline = if raw.bone.is_empty() {
        None
    } else {
        Some(bones_all(&raw.bone, lines)?)
    };
    let refuse = |line: Option<usize>, reason: &str| {
        vec![RagdollError::OutOfRange {
            context: item(line, "ragdoll"),
            field: "skeleton",
            reason: reason.to_owned(),
        }]
    };
    let named = raw
        .skeleton
        .as_ref()
        .map(|s| (s.get_ref(), lines.at(s.span().start)));
    match (inline, named, given) {
        (Some(_), Some((_, line)), _) => Err(refuse(
            Some(line),
            "names a file, and the file has [[bone]] tables too; give one skeleton",
        )),
        (Some(_), None, Given::Skeleton(_)) | (None, Some(_), Given::Skeleton(_)) => Err(refuse(
            None,
            "is given twice: the file has its own, and from_toml_with_skeleton gives one",
        )),
        (None, Some((_, line)), Given::Nothing) => Err(refuse(
            Some(line),
            "names a file, which only RagdollDesc::from_file finds (relative to the ragdoll file)",
        )),
        (None, Some((file, _)), Given::Dir(dir)) => Skeleton::check_file(&dir.join(file)).map(Some),
        (None, None, Given::Skeleton(given)) => Ok(Some(given.clone())),
        (inline, None, _) => Ok(inline),
    }
}

impl RawBody {
    /// A capsule of the table's radius and mass on a zero segment: what a
    /// table that could not be read stands for, so that its name still
    /// counts while its problem is reported.
    fn stand_in(&self) -> BodySpec {
        BodySpec::capsule(&self.name, [Vec3::ZERO; 2], self.radius, self.mass)
    }
}

/// A `[[body]]` table as a spec: placed by `segment` or `from` and `to`
/// bones (one or the other), with an optional bone and offset.
fn body_spec(b: &RawBody, context: &str) -> Result<BodySpec, RagdollError> {
    let missing = |field, reason: &str| RagdollError::OutOfRange {
        context: context.to_owned(),
        field,
        reason: reason.to_owned(),
    };
    let shape = match (b.segment, &b.from, &b.to) {
        (Some(segment), None, None) => BodyShape::Segment(segment.map(Vec3::from)),
        (Some(_), _, _) => {
            return Err(missing(
                "segment",
                "and from/to both place the body; give one or the other",
            ));
        }
        (None, Some(from), Some(to)) => BodyShape::Bones {
            from: from.clone(),
            to: to.clone(),
        },
        (None, Some(_), None) => return Err(missing("to", "is missing: from needs it")),
        (None, None, Some(_)) => return Err(missing("from", "is missing: to needs it")),
        (None, None, None) => {
            return Err(missing(
                "segment",
                "is missing: give segment, or from and to (bones)",
            ));
        }
    };
    Ok(BodySpec {
        name: b.name.clone(),
        shape,
        radius: b.radius,
        mass: b.mass,
        bone: b.bone.clone(),
        offset: b.offset.as_ref().map(|o| {
            Transform::new(
                o.translation.map_or(Vec3::ZERO, Vec3::from),
                o.rotation.map_or(Quat::IDENTITY, Quat::from_array),
            )
        }),
    })
}
