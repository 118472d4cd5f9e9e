//! The ragdoll description format (`docs/ragdolls.md`): TOML with bodies as
//! capsules, joints (sockets with swing and twist limits, hinges, fixed
//! joints: `joint_def.rs`), and an
//! optional `[spine]` chain that the simplified ragdoll replaces by a rod.
//! Units in the file: metres, kilograms, degrees; here: metres, kilograms,
//! radians.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use glam::Vec3;
use serde::Deserialize;
use toml::Spanned;
use vertebra_world::{Shape, check_coordinate};

use crate::drive::DriveSettings;
use crate::drive_def::{RawDrive, drive_settings};
use crate::error::RagdollError;
use crate::joint_def::{JointDef, RawJoint, joint};

/// The reference humanoid, shipped with the crate: 13 bodies, 12 joints,
/// a 4-body spine.
pub const REFERENCE_HUMANOID: &str = include_str!("../models/humanoid.toml");

/// The anatomical humanoid, shipped with the crate: the reference
/// humanoid's 13 bodies with hinged knees and elbows, elliptical shoulders,
/// hips and spine joints, and a neck (`models/anatomical.toml`).
pub const ANATOMICAL_HUMANOID: &str = include_str!("../models/anatomical.toml");

/// The largest ragdoll file [`RagdollDesc::from_file`] reads (bytes): the
/// reference humanoid is 5 KB and a body or joint about 150 bytes, so
/// 1 MiB holds thousands; a larger file (or `/dev/zero`) is refused before
/// it is read whole.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    name: String,
    total_mass: Option<f32>,
    body: Vec<Spanned<RawBody>>,
    #[serde(default)]
    joint: Vec<Spanned<RawJoint>>,
    spine: Option<Spanned<RawSpine>>,
    drive: Option<Spanned<RawDrive>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBody {
    name: String,
    segment: [[f32; 3]; 2],
    radius: f32,
    mass: f32,
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

/// A body: a capsule in bind pose (world frame, identity orientation, so
/// its centre of mass is the segment's midpoint).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDef {
    /// Unique name; also the animation bone's name.
    pub name: String,
    /// The capsule's core segment, bind pose, world (m).
    pub segment: [Vec3; 2],
    /// Capsule radius (m).
    pub radius: f32,
    /// Mass (kg).
    pub mass: f32,
}

impl BodyDef {
    /// The centre of mass at bind pose (m, world).
    pub fn centre(&self) -> Vec3 {
        (self.segment[0] + self.segment[1]) * 0.5
    }

    /// The capsule in its body frame (centred on the centre of mass).
    pub fn shape(&self) -> Shape {
        let centre = self.centre();
        Shape::capsule(
            self.segment[0] - centre,
            self.segment[1] - centre,
            self.radius,
        )
    }
}

/// The chain a rod replaces in the simplified ragdoll.
#[derive(Clone, Debug, PartialEq)]
pub struct SpineDef {
    /// Body indices from the base (hips) to the top (chest).
    pub bodies: Vec<usize>,
    /// Indices of the chain's joints, in order.
    pub joints: Vec<usize>,
    /// Largest bend (rad).
    pub bend_limit: f32,
    /// Twist range (rad).
    pub twist_limit: [f32; 2],
    /// Kirchhoff bending stiffness (N m^2).
    pub bend_stiffness: f32,
    /// Kirchhoff twisting stiffness (N m^2).
    pub twist_stiffness: f32,
}

/// A validated ragdoll description: names unique, joints a tree over the
/// bodies rooted at body `root`, every number finite and in range.
#[derive(Clone, Debug, PartialEq)]
pub struct RagdollDesc {
    /// The model's name.
    pub name: String,
    /// Bodies (and animation bones), in file order.
    pub bodies: Vec<BodyDef>,
    /// Joints, in file order.
    pub joints: Vec<JointDef>,
    /// The spine chain, if the file has one.
    pub spine: Option<SpineDef>,
    /// The body no joint has as its child.
    pub root: usize,
    /// For each body, the joint whose child it is (`None` for the root).
    pub parent_joint: Vec<Option<usize>>,
    /// How the ragdoll is driven toward an animation pose (the file's
    /// `[drive]` table, with each joint's own strength), if the file says.
    pub drive: Option<DriveSettings>,
}

pub(crate) fn finite(
    context: &str,
    field: &'static str,
    values: &[f32],
) -> Result<(), RagdollError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(RagdollError::NonFinite {
            context: context.to_owned(),
            field,
        })
    }
}

pub(crate) fn range(
    context: &str,
    field: &'static str,
    ok: bool,
    reason: &str,
) -> Result<(), RagdollError> {
    if ok {
        Ok(())
    } else {
        Err(RagdollError::OutOfRange {
            context: context.to_owned(),
            field,
            reason: reason.to_owned(),
        })
    }
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
    /// [`MAX_FILE_BYTES`]; every error names the file (and the line, where
    /// there is one).
    pub fn from_file(path: &Path) -> Result<Self, RagdollError> {
        let in_file = |error| RagdollError::File {
            path: path.display().to_string(),
            error: Box::new(error),
        };
        let unreadable = |reason: String| in_file(RagdollError::Unreadable(reason));
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .and_then(|file| file.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes))
            .map_err(|e| unreadable(e.to_string()))?;
        if bytes.len() as u64 > MAX_FILE_BYTES {
            return Err(unreadable(format!(
                "larger than {MAX_FILE_BYTES} bytes; a ragdoll file is a few KB"
            )));
        }
        let text = String::from_utf8(bytes).map_err(|e| {
            unreadable(format!(
                "not UTF-8 text (at byte {})",
                e.utf8_error().valid_up_to()
            ))
        })?;
        Self::from_toml(&text).map_err(in_file)
    }

    /// Parses and validates a description. Errors about a body, joint or
    /// the spine start with the line where it is defined.
    pub fn from_toml(text: &str) -> Result<Self, RagdollError> {
        let lines = Lines::new(text);
        let raw: RawFile = toml::from_str(text).map_err(|e| syntax(&lines, &e))?;
        let at = |span: core::ops::Range<usize>| lines.at(span.start);
        let bodies = raw
            .body
            .iter()
            .map(|b| body(b.get_ref(), at(b.span())))
            .collect::<Result<Vec<_>, _>>()?;
        let index = names(
            &raw.body
                .iter()
                .map(|b| (b.get_ref().name.as_str(), at(b.span())))
                .collect::<Vec<_>>(),
            "body",
        )?;
        names(
            &raw.joint
                .iter()
                .map(|j| (j.get_ref().name.as_str(), at(j.span())))
                .collect::<Vec<_>>(),
            "joint",
        )?;
        let joints = raw
            .joint
            .iter()
            .map(|j| joint(j.get_ref(), at(j.span()), &index))
            .collect::<Result<Vec<_>, _>>()?;
        let (root, parent_joint) = tree(&bodies, &joints)?;
        let spine = raw
            .spine
            .as_ref()
            .map(|s| spine(s.get_ref(), at(s.span()), &index, &joints, &parent_joint))
            .transpose()?;
        if let Some(total) = raw.total_mass {
            finite("ragdoll", "total_mass", &[total])?;
            let sum: f32 = bodies.iter().map(|b| b.mass).sum();
            range(
                "ragdoll",
                "total_mass",
                (sum - total).abs() <= 1e-3 * total.abs().max(1.0),
                &format!("is {total} but the bodies weigh {sum}"),
            )?;
        }
        let drive = drive(raw.drive.as_ref(), &joints, at)?;
        Ok(Self {
            name: raw.name,
            bodies,
            joints,
            spine,
            root,
            parent_joint,
            drive,
        })
    }

    /// The body index of `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f32 {
        self.bodies.iter().map(|b| b.mass).sum()
    }
}

/// Where a text's lines end, to name the line of a byte offset.
struct Lines(Vec<usize>);

impl Lines {
    fn new(text: &str) -> Self {
        Self(text.match_indices('\n').map(|(at, _)| at).collect())
    }

    /// The line (from 1) of byte `offset`.
    fn at(&self, offset: usize) -> usize {
        self.0.partition_point(|&end| end < offset) + 1
    }
}

/// A parse error on one line: where, and what (without the source excerpt).
fn syntax(lines: &Lines, e: &toml::de::Error) -> RagdollError {
    let message = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
    match e.span() {
        Some(span) => RagdollError::Syntax(format!("line {}: {message}", lines.at(span.start))),
        None => RagdollError::Syntax(message),
    }
}

/// Indexes `(name, line)` pairs by name; a name used twice is refused at
/// its second line.
fn names(
    names: &[(&str, usize)],
    kind: &'static str,
) -> Result<HashMap<String, usize>, RagdollError> {
    let mut index = HashMap::new();
    for (i, &(n, line)) in names.iter().enumerate() {
        if index.insert(n.to_owned(), i).is_some() {
            return Err(RagdollError::DuplicateName {
                line,
                kind,
                name: n.to_owned(),
            });
        }
    }
    Ok(index)
}

/// A body's segment within the world's coordinate range, and a capsule the
/// world accepts at its mass (size within `SIZE_RANGE`, mass within
/// `MASS_RANGE`, invertible inertia), so building it cannot fail on them.
fn body(b: &RawBody, line: usize) -> Result<BodyDef, RagdollError> {
    let context = format!("line {line}: body `{}`", b.name);
    finite(&context, "segment", b.segment.as_flattened())?;
    finite(&context, "radius", &[b.radius])?;
    finite(&context, "mass", &[b.mass])?;
    range(&context, "mass", b.mass > 0.0, "must be positive")?;
    range(&context, "radius", b.radius > 0.0, "must be positive")?;
    let def = BodyDef {
        name: b.name.clone(),
        segment: b.segment.map(Vec3::from),
        radius: b.radius,
        mass: b.mass,
    };
    for end in def.segment {
        check_coordinate("segment end", end).map_err(|e| RagdollError::world(&context, e))?;
    }
    def.shape()
        .mass_properties_with_mass(def.mass)
        .map_err(|e| RagdollError::world(&context, e))?;
    Ok(def)
}

/// Checks the joints form one tree over all bodies; returns the root and
/// each body's parent joint.
fn tree(
    bodies: &[BodyDef],
    joints: &[JointDef],
) -> Result<(usize, Vec<Option<usize>>), RagdollError> {
    let mut parent_joint = vec![None; bodies.len()];
    for (k, j) in joints.iter().enumerate() {
        if j.parent == j.child {
            return Err(RagdollError::NotATree(format!(
                "joint `{}` joins `{}` to itself",
                j.name, bodies[j.child].name
            )));
        }
        if let Some(other) = parent_joint[j.child].replace(k) {
            return Err(RagdollError::NotATree(format!(
                "body `{}` is the child of both `{}` and `{}`",
                bodies[j.child].name, joints[other].name, j.name
            )));
        }
    }
    // Every body must reach the root by parent links, without a cycle.
    for start in 0..bodies.len() {
        let (mut body, mut steps) = (start, 0);
        while let Some(k) = parent_joint[body] {
            body = joints[k].parent;
            steps += 1;
            if steps > bodies.len() {
                return Err(RagdollError::NotATree(format!(
                    "a cycle runs through body `{}`",
                    bodies[start].name
                )));
            }
        }
    }
    let roots: Vec<usize> = (0..bodies.len())
        .filter(|&b| parent_joint[b].is_none())
        .collect();
    match roots.as_slice() {
        [root] => Ok((*root, parent_joint)),
        [] => Err(RagdollError::NotATree("no root body".to_owned())),
        many => Err(RagdollError::NotATree(format!(
            "{} bodies have no parent ({}); one root is needed",
            many.len(),
            many.iter()
                .map(|&b| format!("`{}`", bodies[b].name))
                .collect::<Vec<_>>()
                .join(", ")
        ))),
    }
}

fn spine(
    s: &RawSpine,
    line: usize,
    index: &HashMap<String, usize>,
    joints: &[JointDef],
    parent_joint: &[Option<usize>],
) -> Result<SpineDef, RagdollError> {
    let context = &format!("line {line}: [spine]");
    let bodies = s
        .bodies
        .iter()
        .map(|n| {
            index
                .get(n)
                .copied()
                .ok_or_else(|| RagdollError::UnknownBody {
                    context: context.to_owned(),
                    field: "bodies",
                    name: n.clone(),
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    if bodies.len() < 2 {
        return Err(RagdollError::SpineNotChain(
            "needs at least two bodies".to_owned(),
        ));
    }
    let mut chain = Vec::new();
    for pair in bodies.windows(2) {
        let joint = parent_joint[pair[1]]
            .filter(|&k| joints[k].parent == pair[0])
            .ok_or_else(|| {
                RagdollError::SpineNotChain(format!(
                    "no joint has parent `{}` and child `{}`",
                    s.bodies[chain.len()],
                    s.bodies[chain.len() + 1]
                ))
            })?;
        chain.push(joint);
    }
    // The interior bodies disappear in the simplified ragdoll: nothing but
    // the chain may hang from them.
    for &interior in &bodies[1..bodies.len() - 1] {
        if let Some(j) = joints
            .iter()
            .find(|j| j.parent == interior && !chain.iter().any(|&k| joints[k].name == j.name))
        {
            return Err(RagdollError::SpineNotChain(format!(
                "joint `{}` hangs from an interior spine body; only the chain may",
                j.name
            )));
        }
    }
    for (field, v) in [
        ("bend_limit", s.bend_limit),
        ("bend_stiffness", s.bend_stiffness),
        ("twist_stiffness", s.twist_stiffness),
    ] {
        finite(context, field, &[v])?;
    }
    finite(context, "twist_limit", &s.twist_limit)?;
    range(
        context,
        "bend_limit",
        (0.0..=180.0).contains(&s.bend_limit),
        "must be in [0, 180] degrees",
    )?;
    let [lo, hi] = s.twist_limit;
    range(
        context,
        "twist_limit",
        -180.0 <= lo && lo <= hi && hi <= 180.0,
        "must be [min, max] within [-180, 180] degrees",
    )?;
    range(
        context,
        "bend_stiffness",
        s.bend_stiffness >= 0.0,
        "must not be negative",
    )?;
    range(
        context,
        "twist_stiffness",
        s.twist_stiffness >= 0.0,
        "must not be negative",
    )?;
    Ok(SpineDef {
        bodies,
        joints: chain,
        bend_limit: s.bend_limit.to_radians(),
        twist_limit: [lo.to_radians(), hi.to_radians()],
        bend_stiffness: s.bend_stiffness,
        twist_stiffness: s.twist_stiffness,
    })
}

/// The `[drive]` table with the joints' own strengths; a joint's strength
/// without a table to fall back on is refused at the joint.
fn drive(
    raw: Option<&Spanned<RawDrive>>,
    joints: &[JointDef],
    at: impl Fn(core::ops::Range<usize>) -> usize,
) -> Result<Option<DriveSettings>, RagdollError> {
    let own: Vec<_> = joints.iter().map(|j| j.drive).collect();
    match raw {
        Some(table) => drive_settings(table.get_ref(), at(table.span()), own).map(Some),
        None => match joints.iter().find(|j| j.drive.is_some()) {
            Some(j) => Err(RagdollError::OutOfRange {
                context: format!("joint `{}`", j.name),
                field: "drive",
                reason: "needs a [drive] table for the ragdoll's other joints".to_owned(),
            }),
            None => Ok(None),
        },
    }
}
