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

use crate::error::{Problems, RagdollError, first};
use crate::skeleton::{Bone, MAX_BONES, Skeleton, Transform};
use crate::text::{Lines, floats, in_file, read_text, same_bits, string, syntax, within_cap};
use vertebra_math::DefaultFloatMode;

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
    /// line of its `[[bone]]`. A text longer than
    /// [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES) is refused before it is
    /// parsed, as a file is.
    pub fn from_toml(text: &str) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        Self::check_toml(text).map_err(first)
    }

    /// [`Skeleton::from_toml`], refused with every problem found rather
    /// than the first (which is what `from_toml` says), in file order: one
    /// for text that does not parse, else one per bad bone.
    pub fn check_toml(text: &str) -> Result<Self, Vec<RagdollError>> {
        let _mode = DefaultFloatMode::enter();
        within_cap(text.len() as u64, "skeleton").map_err(|e| vec![e])?;
        let lines = Lines::new(text);
        let raw: RawSkeleton = toml::from_str(text)
            .map_err(|e| vec![syntax_naming("skeleton", text, &lines, &e, &["bone"])])?;
        bones_all(&raw.bone, &lines)
    }

    /// Reads and checks a skeleton file of at most
    /// [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES); every error names the
    /// file (and the line, where there is one).
    pub fn from_file(path: &Path) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        Self::check_file(path).map_err(first)
    }

    /// [`Skeleton::from_file`], refused with every problem found
    /// ([`Skeleton::check_toml`]), each naming the file: `vertebra check`.
    pub fn check_file(path: &Path) -> Result<Self, Vec<RagdollError>> {
        let _mode = DefaultFloatMode::enter();
        let text = read_text(path, "skeleton").map_err(|e| vec![e])?;
        Self::check_toml(&text)
            .map_err(|problems| problems.into_iter().map(|e| in_file(path, e)).collect())
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
/// file), each checked: every problem names the line, the bone and the
/// field, in file order.
pub(crate) fn bones_all(
    raw: &[Spanned<RawBone>],
    lines: &Lines,
) -> Result<Skeleton, Vec<RagdollError>> {
    if raw.is_empty() || raw.len() > MAX_BONES {
        return Err(vec![RagdollError::OutOfRange {
            context: "skeleton".to_owned(),
            field: "bone",
            reason: format!("has {} bones; must have 1 to {MAX_BONES}", raw.len()),
        }]);
    }
    let mut index: HashMap<&str, usize> = HashMap::new();
    let mut problems = Problems::default();
    let mut out = Vec::with_capacity(raw.len());
    for (i, spanned) in raw.iter().enumerate() {
        let b = spanned.get_ref();
        let line = lines.at(spanned.span().start);
        let bone = problems.note(Some(line), bone(raw, i, &index, lines));
        if index.insert(&b.name, i).is_some() {
            let twice = RagdollError::DuplicateName {
                line: Some(line),
                kind: "bone",
                name: b.name.clone(),
            };
            problems.note(Some(line), Err::<(), _>(twice));
        }
        out.extend(bone);
    }
    problems.done()?;
    Skeleton::new(out).map_err(|e| vec![e])
}

/// Bone `i` of `raw`, its parent found in `index` (the bones before it, by
/// name); the error names its line, the bone and the field.
fn bone(
    raw: &[Spanned<RawBone>],
    i: usize,
    index: &HashMap<&str, usize>,
    lines: &Lines,
) -> Result<Bone, RagdollError> {
    let b = raw[i].get_ref();
    let context = format!("line {}: bone `{}`", lines.at(raw[i].span().start), b.name);
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
            None => return Err(misplaced_parent(raw, i, name, context, lines)),
        },
    };
    let bind = Transform::new(
        Vec3::from(b.translation),
        b.rotation.map_or(Quat::IDENTITY, Quat::from_array),
    );
    bind.validate(&context)?;
    Ok(Bone {
        name: b.name.clone(),
        parent,
        bind,
    })
}

/// Why bone `i`'s parent `name` is not a bone before it: it is the bone
/// itself, an ancestor of it (a cycle: the chain of parents named), a bone
/// defined later, or no bone at all.
fn misplaced_parent(
    raw: &[Spanned<RawBone>],
    i: usize,
    name: &str,
    context: String,
    lines: &Lines,
) -> RagdollError {
    let find = |name: &str| raw.iter().position(|b| b.get_ref().name == name);
    let out_of_range = |reason: String| RagdollError::OutOfRange {
        context: context.clone(),
        field: "parent",
        reason,
    };
    let Some(later) = find(name) else {
        return RagdollError::UnknownBone {
            context: context.clone(),
            field: "parent",
            name: name.to_owned(),
        };
    };
    if later == i {
        return out_of_range("is the bone itself".to_owned());
    }
    // Up the parents from `name`: back to this bone is a cycle.
    let mut chain = vec![raw[i].get_ref().name.as_str(), name];
    let mut at = later;
    while let Some(up) = raw[at].get_ref().parent.as_deref() {
        chain.push(up);
        match find(up) {
            Some(next) if next == i => {
                let chain: Vec<String> = chain.iter().map(|n| format!("`{n}`")).collect();
                return out_of_range(format!(
                    "makes the bone its own ancestor: {}",
                    chain.join(" -> ")
                ));
            }
            Some(next) if chain.len() <= raw.len() => at = next,
            _ => break,
        }
    }
    out_of_range(format!(
        "`{name}` is defined at line {}, not before this bone; a parent comes before its children",
        lines.at(raw[later].span().start)
    ))
}

/// A parse error of a `file` file (ragdoll or skeleton) as [`syntax`]
/// gives it, naming the table it is in when that is one of the file's
/// `kinds` (`bone`, `body`, `joint`) and has a name: `line 3: bone `hips`:
/// missing field `translation``.
pub(crate) fn syntax_naming(
    file: &'static str,
    text: &str,
    lines: &Lines,
    e: &toml::de::Error,
    kinds: &[&str],
) -> RagdollError {
    let named = e.span().and_then(|span| table_at(text, span.start, kinds));
    match (syntax(file, lines, e), named) {
        (RagdollError::Syntax { file, message }, Some(table)) => {
            let message = match message.split_once(": ") {
                Some((line, rest)) if line.starts_with("line ") => {
                    format!("{line}: {table}: {rest}")
                }
                _ => format!("{table}: {message}"),
            };
            RagdollError::Syntax { file, message }
        }
        (error, _) => error,
    }
}

/// A table with a name, read leniently to name it in a parse error.
#[derive(Deserialize)]
struct Named {
    name: Option<toml::Value>,
}

/// A file's named tables, read leniently.
#[derive(Deserialize)]
struct NamedTables {
    #[serde(default)]
    bone: Vec<Spanned<Named>>,
    #[serde(default)]
    body: Vec<Spanned<Named>>,
    #[serde(default)]
    joint: Vec<Spanned<Named>>,
}

/// The `[[bone]]`, `[[body]]` or `[[joint]]` table (one of `kinds`) around
/// byte `offset` of `text`, as `bone `name``, when the text parses
/// leniently and the table has a string name.
fn table_at(text: &str, offset: usize, kinds: &[&str]) -> Option<String> {
    let tables: NamedTables = toml::from_str(text).ok()?;
    [
        ("bone", &tables.bone),
        ("body", &tables.body),
        ("joint", &tables.joint),
    ]
    .into_iter()
    .filter(|(kind, _)| kinds.contains(kind))
    .flat_map(|(kind, all)| all.iter().map(move |t| (kind, t)))
    .find(|(_, t)| t.span().contains(&offset))
    .and_then(|(kind, t)| match &t.get_ref().name {
        Some(toml::Value::String(name)) => Some(format!("{kind} `{name}`")),
        _ => None,
    })
}
