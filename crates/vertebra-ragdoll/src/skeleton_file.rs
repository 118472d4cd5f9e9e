//! Skeleton files (`docs/ragdolls.md`, "Skeletons"): `[[bone]]` tables
//! with a name, an optional parent (a bone defined earlier), a
//! parent-local `translation` (m) and an optional `rotation` (`[x, y, z,
//! w]`, identity by default). The same tables carry a skeleton inside a
//! ragdoll file.

use std::collections::HashMap;
use std::path::Path;

use glam::{Quat, Vec3};
use serde::Deserialize;
use toml::Spanned;

use crate::error::RagdollError;
use crate::skeleton::{Bone, MAX_BONES, Skeleton, Transform};
use crate::text::{Lines, floats, in_file, read_text, same_bits, string, syntax};

/// The reference animation skeleton, shipped with the crate
/// (`models/skeleton.toml`): 63 bones (a root, the hips, five spine bones,
/// three neck bones and the head, arms with clavicles, twist bones and
/// five three-bone fingers, legs with twist bones, feet and toes), bound
/// to both humanoids in their bind pose.
pub const REFERENCE_SKELETON: &str = include_str!("../models/skeleton.toml");

/// A `[[bone]]` table as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawBone {
    name: String,
    parent: Option<String>,
    translation: [f32; 3],
    rotation: Option<[f32; 4]>,
}

/// A skeleton file: bones only.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSkeleton {
    bone: Vec<Spanned<RawBone>>,
}

impl Skeleton {
    /// The reference animation skeleton ([`REFERENCE_SKELETON`]).
    pub fn reference() -> Self {
        Self::from_toml(REFERENCE_SKELETON).expect("the shipped reference skeleton is valid")
    }

    /// Parses and checks a skeleton file's text: `[[bone]]` tables, each
    /// with `name`, optional `parent` (the name of a bone defined earlier),
    /// `translation = [x, y, z]` (m, in the parent's frame) and optional
    /// `rotation = [x, y, z, w]` (a unit quaternion, within 1e-3; identity
    /// when left out), kept as written. Errors about a bone start with the
    /// line of its `[[bone]]`.
    pub fn from_toml(text: &str) -> Result<Self, RagdollError> {
        let lines = Lines::new(text);
        let raw: RawSkeleton = toml::from_str(text).map_err(|e| syntax("skeleton", &lines, &e))?;
        bones(&raw.bone, &lines)
    }

    /// Reads and checks a skeleton file of at most
    /// [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES); every error names the
    /// file (and the line, where there is one).
    pub fn from_file(path: &Path) -> Result<Self, RagdollError> {
        let text = read_text(path, "skeleton")?;
        Self::from_toml(&text).map_err(|e| in_file(path, e))
    }

    /// The skeleton as a skeleton file: [`Skeleton::from_toml`] of it
    /// gives this skeleton back, bit for bit.
    pub fn to_toml(&self) -> String {
        let mut out = String::new();
        write_bones(self, &mut out);
        out
    }
}

/// The `[[bone]]` tables of `skeleton`, appended to `out`.
pub(crate) fn write_bones(skeleton: &Skeleton, out: &mut String) {
    for bone in skeleton.bones() {
        out.push_str("[[bone]]\n");
        out.push_str(&format!("name = {}\n", string(&bone.name)));
        if let Some(p) = bone.parent {
            let parent = &skeleton.bones()[p].name;
            out.push_str(&format!("parent = {}\n", string(parent)));
        }
        let t = bone.bind.translation.to_array();
        out.push_str(&format!("translation = {}\n", floats(&t)));
        let r = bone.bind.rotation.to_array();
        if !same_bits(&r, &Quat::IDENTITY.to_array()) {
            out.push_str(&format!("rotation = {}\n", floats(&r)));
        }
        out.push('\n');
    }
}

/// The skeleton of `raw` bones (`[[bone]]` tables of a skeleton or ragdoll
/// file), each checked: errors name the line, the bone and the field.
pub(crate) fn bones(raw: &[Spanned<RawBone>], lines: &Lines) -> Result<Skeleton, RagdollError> {
    if raw.is_empty() || raw.len() > MAX_BONES {
        return Err(RagdollError::OutOfRange {
            context: "skeleton".to_owned(),
            field: "bone",
            reason: format!("has {} bones; must have 1 to {MAX_BONES}", raw.len()),
        });
    }
    let defined: HashMap<&str, usize> = raw
        .iter()
        .enumerate()
        .rev()
        .map(|(i, b)| (b.get_ref().name.as_str(), i))
        .collect();
    let mut index: HashMap<&str, usize> = HashMap::new();
    let mut out = Vec::with_capacity(raw.len());
    for (i, spanned) in raw.iter().enumerate() {
        let b = spanned.get_ref();
        let line = lines.at(spanned.span().start);
        let context = format!("line {line}: bone `{}`", b.name);
        if b.name.is_empty() {
            return Err(RagdollError::OutOfRange {
                context,
                field: "name",
                reason: "is empty".to_owned(),
            });
        }
        let parent = match &b.parent {
            None => None,
            Some(name) => match index.get(name.as_str()) {
                Some(&p) => Some(p),
                None => {
                    return Err(match defined.get(name.as_str()) {
                        Some(&me) if me == i => RagdollError::OutOfRange {
                            context,
                            field: "parent",
                            reason: "is the bone itself".to_owned(),
                        },
                        Some(&later) => RagdollError::OutOfRange {
                            context,
                            field: "parent",
                            reason: format!(
                                "`{name}` is defined at line {}, not before this bone; a parent comes before its children",
                                lines.at(raw[later].span().start)
                            ),
                        },
                        None => RagdollError::UnknownBone {
                            context,
                            field: "parent",
                            name: name.clone(),
                        },
                    });
                }
            },
        };
        if index.insert(&b.name, i).is_some() {
            return Err(RagdollError::DuplicateName {
                line: Some(line),
                kind: "bone",
                name: b.name.clone(),
            });
        }
        let bind = Transform::new(
            Vec3::from(b.translation),
            b.rotation.map_or(Quat::IDENTITY, Quat::from_array),
        );
        bind.validate(&context)?;
        out.push(Bone {
            name: b.name.clone(),
            parent,
            bind,
        });
    }
    Skeleton::new(out)
}
