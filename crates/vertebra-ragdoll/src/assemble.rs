//! From specs to a checked [`RagdollDesc`]: the one path a file's tables
//! and a builder's values both take (names resolved, bodies placed on the
//! skeleton and bound to their bones, masses scaled to a total, the joint
//! tree and the spine chain found), and the checks
//! [`RagdollDesc::validate`] runs on any description.

use std::collections::{HashMap, HashSet};

use vertebra_store::check_coordinate;
use vertebra_world::Spring;

use crate::drive::DriveSettings;
use crate::error::{Problems, RagdollError, finite, first, range};
use crate::joint_def::{JointDef, JointSpec, check_joint, half_turn, resolve};
use crate::model::{BodyDef, BoneBinding, MAX_BODIES, MAX_JOINTS, RagdollDesc, SpineDef};
use crate::profile_def::ProfileSource;
use crate::skeleton::{Skeleton, Transform};
use crate::spec::{BodyShape, BodySpec, SpineSpec};
use crate::text::item;
use vertebra_math::DefaultFloatMode;

/// A value and the line of the file where it is defined (`None` when it
/// was built in code).
pub(crate) struct Item<T> {
    pub(crate) value: T,
    pub(crate) line: Option<usize>,
    /// A stand-in for a table that could not be read (its problem already
    /// found): its name counts, its value is not checked.
    pub(crate) refused: bool,
}

impl<T> Item<T> {
    pub(crate) fn at(value: T, line: usize) -> Self {
        Self {
            value,
            line: Some(line),
            refused: false,
        }
    }

    /// A stand-in at `line` for a table that could not be read.
    pub(crate) fn refused(value: T, line: usize) -> Self {
        Self {
            refused: true,
            ..Self::at(value, line)
        }
    }

    pub(crate) fn unlined(value: T) -> Self {
        Self {
            value,
            line: None,
            refused: false,
        }
    }
}

/// A description as specs: a file's tables or a builder's values.
pub(crate) struct Document {
    pub(crate) name: String,
    pub(crate) total_mass: Option<f32>,
    pub(crate) skeleton: Option<Skeleton>,
    pub(crate) bodies: Vec<Item<BodySpec>>,
    pub(crate) joints: Vec<Item<JointSpec>>,
    pub(crate) spine: Option<Item<SpineSpec>>,
    pub(crate) drive: Option<Item<DriveSettings>>,
    /// `[[profile]]` tables, resolved once the joint tree stands.
    pub(crate) profiles: Vec<Item<ProfileSource>>,
}

/// The lines where a description's items are defined, to name them in
/// errors (none for a description built in code or edited by hand).
#[derive(Default)]
struct At {
    bodies: Vec<Option<usize>>,
    joints: Vec<Option<usize>>,
    spine: Option<usize>,
    drive: Option<usize>,
    profiles: Vec<Option<usize>>,
}

impl At {
    fn body(&self, i: usize, name: &str) -> String {
        item(
            self.bodies.get(i).copied().flatten(),
            &format!("body `{name}`"),
        )
    }

    fn body_line(&self, i: usize) -> Option<usize> {
        self.bodies.get(i).copied().flatten()
    }

    fn joint_line(&self, k: usize) -> Option<usize> {
        self.joints.get(k).copied().flatten()
    }

    fn joint(&self, k: usize, name: &str) -> String {
        item(
            self.joints.get(k).copied().flatten(),
            &format!("joint `{name}`"),
        )
    }
}

/// A skeleton and its bones' bind transforms in its model frame.
type Model<'a> = (&'a Skeleton, Vec<Transform>);

/// Resolves, places, binds, scales and checks a description; refused with
/// the first of [`assemble_all`]'s problems.
pub(crate) fn assemble(doc: Document) -> Result<RagdollDesc, RagdollError> {
    assemble_all(doc, Problems::default()).map_err(first)
}

/// [`assemble`], refused with every problem it finds, after `problems`
/// (those of a file's tables that could not be read: their items are
/// stand-ins, [`Item::refused`], whose names count but whose values are
/// not checked). Every body and joint is checked on its own; the joint
/// tree once every joint resolves; the spine's chain once the tree stands;
/// the whole description ([`RagdollDesc::validate`]'s checks) once every
/// part passed.
pub(crate) fn assemble_all(
    doc: Document,
    mut problems: Problems,
) -> Result<RagdollDesc, Vec<RagdollError>> {
    // The counts first, before any item is read: a description beyond them
    // is refused with that problem alone, whatever its items hold.
    counts(&doc.name, doc.bodies.len(), doc.joints.len()).map_err(|e| vec![e])?;
    let at = At {
        bodies: doc.bodies.iter().map(|b| b.line).collect(),
        joints: doc.joints.iter().map(|j| j.line).collect(),
        spine: doc.spine.as_ref().and_then(|s| s.line),
        drive: doc.drive.as_ref().and_then(|d| d.line),
        profiles: doc.profiles.iter().map(|p| p.line).collect(),
    };
    let index = names(
        doc.bodies.iter().map(|b| (b.value.name.as_str(), b.line)),
        "body",
        &mut problems,
    );
    names(
        doc.joints.iter().map(|j| (j.value.name.as_str(), j.line)),
        "joint",
        &mut problems,
    );
    let model = doc
        .skeleton
        .as_ref()
        .map(|s| s.bind_pose().to_model(s).map(|pose| (s, pose.bones)))
        .transpose()
        .map_err(|e| vec![e])?;
    let mut bodies: Vec<BodyDef> = doc
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| !b.refused)
        .filter_map(|(i, b)| {
            let context = at.body(i, &b.value.name);
            problems.note(b.line, body_def(&b.value, &context, model.as_ref()))
        })
        .collect();
    if let (Some(total), true) = (doc.total_mass, problems.is_empty()) {
        problems.note(None, scale(&mut bodies, total, &at));
    }
    let joints: Vec<JointDef> = doc
        .joints
        .iter()
        .enumerate()
        .filter_map(|(k, j)| {
            let context = at.joint(k, &j.value.name);
            problems.note(j.line, resolve(&j.value, &context, &index))
        })
        .collect();
    let names: Vec<&str> = doc.bodies.iter().map(|b| b.value.name.as_str()).collect();
    let tree = (joints.len() == doc.joints.len())
        .then(|| problems.note(None, tree(&names, &joints)))
        .flatten();
    let spine = doc.spine.as_ref().and_then(|s| {
        let context = item(s.line, "[spine]");
        let v = &s.value;
        let limits = [v.bend_limit, v.bend_stiffness, v.twist_stiffness];
        problems.note(s.line, rod_limits(&context, limits, v.twist_limit));
        let (_, parent_joint) = tree.as_ref()?;
        problems.note(s.line, spine(v, &context, &index, &joints, parent_joint))
    });
    let drive = doc.drive.and_then(|d| {
        let context = item(d.line, "[drive]");
        let empty = d.value.joints.is_empty();
        let reason = "must be empty: a joint's own strength is its spec's";
        problems.note(d.line, range(&context, "joints", empty, reason))?;
        Some(DriveSettings {
            joints: own_strengths(&joints),
            ..d.value
        })
    });
    let (Some((root, parent_joint)), true) = (tree, problems.is_empty()) else {
        return Err(problems
            .done()
            .expect_err("a part of the description failed"));
    };
    let mut desc = RagdollDesc {
        name: doc.name,
        bodies,
        joints,
        spine,
        root,
        parent_joint,
        drive,
        profiles: Vec::new(),
        skeleton: doc.skeleton,
    };
    for p in &doc.profiles {
        let context = item(p.line, &format!("profile `{}`", p.value.name()));
        let resolved = problems.note(p.line, p.value.resolve(&desc, &context));
        desc.profiles.extend(resolved);
    }
    if !problems.is_empty() {
        return Err(problems.done().expect_err("a profile failed"));
    }
    check(&desc, &at, &mut problems);
    problems.done()?;
    Ok(desc)
}

/// A body's spec placed (its segment from its bones, in `model`'s bind
/// pose), checked and bound to its bone (`context` names it).
fn body_def(
    spec: &BodySpec,
    context: &str,
    model: Option<&Model<'_>>,
) -> Result<BodyDef, RagdollError> {
    let bone = |field: &'static str, name: &str| -> Result<usize, RagdollError> {
        let unknown = || RagdollError::UnknownBone {
            context: context.to_owned(),
            field,
            name: name.to_owned(),
        };
        match model {
            Some((skeleton, _)) => skeleton.bone_index(name).ok_or_else(unknown),
            None => Err(RagdollError::OutOfRange {
                context: context.to_owned(),
                field,
                reason: format!(
                    "names bone `{name}`, but the ragdoll has no skeleton ([[bone]] tables, skeleton = \"file\", or one given to the loader)"
                ),
            }),
        }
    };
    let segment = match &spec.shape {
        BodyShape::Segment(segment) => *segment,
        BodyShape::Bones { from, to } => {
            let (a, b) = (bone("from", from)?, bone("to", to)?);
            range(
                context,
                "to",
                a != b,
                "is the from bone; a body runs from one bone to another",
            )?;
            let pose = &model.expect("a bone was found").1;
            [pose[a].translation, pose[b].translation]
        }
    };
    let mut def = BodyDef {
        name: spec.name.clone(),
        segment,
        radius: spec.radius,
        mass: spec.mass,
        bone: None,
    };
    check_body(&def, context)?;
    let chosen = match (&spec.bone, &spec.shape, model) {
        (Some(name), _, _) => Some(bone("bone", name)?),
        (None, _, None) => None,
        (None, shape, Some((skeleton, _))) => skeleton.bone_index(&spec.name).or(match shape {
            BodyShape::Bones { from, .. } => skeleton.bone_index(from),
            BodyShape::Segment(_) => None,
        }),
    };
    if let Some(offset) = spec.offset {
        range(
            context,
            "offset",
            chosen.is_some(),
            "places the body on its bone, but it has none",
        )?;
        offset.validate(&format!("{context}: offset"))?;
    }
    def.bone = match (chosen, model) {
        (Some(bone), Some((_, pose))) => Some(BoneBinding {
            bone,
            offset: spec
                .offset
                .unwrap_or_else(|| pose[bone].inverse() * def.bind_frame()),
        }),
        _ => None,
    };
    Ok(def)
}

/// Scales the bodies' masses to `total` (kg) in all, their ratios kept.
fn scale(bodies: &mut [BodyDef], total: f32, at: &At) -> Result<(), RagdollError> {
    finite("ragdoll", "total_mass", &[total])?;
    range("ragdoll", "total_mass", total > 0.0, "must be positive")?;
    let factor = total / bodies.iter().map(|b| b.mass).sum::<f32>();
    for (i, b) in bodies.iter_mut().enumerate() {
        b.mass *= factor;
        b.shape().mass_properties_with_mass(b.mass).map_err(|e| {
            let context = format!("{} (its mass scaled to total_mass)", at.body(i, &b.name));
            RagdollError::world(&context, e)
        })?;
    }
    Ok(())
}

impl RagdollDesc {
    /// Checks a description as the file loader checks a file: names
    /// unique; every body a capsule the world takes (finite, in range);
    /// every bone binding on a bone of [`RagdollDesc::skeleton`], at most
    /// one body per bone, its offset finite with a unit rotation; every
    /// joint's bodies, anchor, frame, limits and softness in range; the
    /// joints one tree whose root and parent joints are `root` and
    /// `parent_joint`; the spine a chain of joints with nothing but the
    /// chain hanging from its interior bodies, its limits in range; the
    /// drive settings ones the world takes, their per-joint list the
    /// joints' own strengths. For a description edited by hand; errors
    /// name the item and the field.
    pub fn validate(&self) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.problems().into_iter().next().map_or(Ok(()), Err)
    }

    /// Every problem [`RagdollDesc::validate`] finds, in order (its first
    /// is the one `validate` returns): each body, binding and joint on its
    /// own, then the joint tree (once every joint passed), the spine (once
    /// the tree stands) and the drive settings.
    pub fn problems(&self) -> Vec<RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let mut problems = Problems::default();
        check(self, &At::default(), &mut problems);
        problems.done().err().unwrap_or_default()
    }
}

/// At most [`MAX_BODIES`] bodies and [`MAX_JOINTS`] joints in the
/// description called `name`: checked before any body or joint is, so
/// that the work every other check does is bounded.
fn counts(name: &str, bodies: usize, joints: usize) -> Result<(), RagdollError> {
    let context = format!("ragdoll `{name}`");
    range(
        &context,
        "body",
        bodies <= MAX_BODIES,
        &format!(
            "has {bodies} bodies; a ragdoll has at most MAX_BODIES ({MAX_BODIES}), one per bone of the largest skeleton"
        ),
    )?;
    range(
        &context,
        "joint",
        joints <= MAX_JOINTS,
        &format!(
            "has {joints} joints; a ragdoll has at most MAX_JOINTS ({MAX_JOINTS}), one fewer than its bodies at most"
        ),
    )
}

/// `validate`'s checks of `desc`, each problem kept in `problems`.
fn check(desc: &RagdollDesc, at: &At, problems: &mut Problems) {
    if let Err(e) = counts(&desc.name, desc.bodies.len(), desc.joints.len()) {
        problems.note(None, Err::<(), _>(e));
        return;
    }
    names(
        desc.bodies
            .iter()
            .enumerate()
            .map(|(i, b)| (b.name.as_str(), at.body_line(i))),
        "body",
        problems,
    );
    names(
        desc.joints
            .iter()
            .enumerate()
            .map(|(k, j)| (j.name.as_str(), at.joint_line(k))),
        "joint",
        problems,
    );
    for (i, b) in desc.bodies.iter().enumerate() {
        problems.note(at.body_line(i), check_body(b, &at.body(i, &b.name)));
    }
    check_bindings(desc, at, problems);
    let bodies = desc.bodies.len();
    let failed = desc
        .joints
        .iter()
        .enumerate()
        .filter(|&(k, j)| {
            let checked = check_joint(j, bodies, &at.joint(k, &j.name));
            problems.note(at.joint_line(k), checked).is_none()
        })
        .count();
    let names: Vec<&str> = desc.bodies.iter().map(|b| b.name.as_str()).collect();
    let tree = (failed == 0)
        .then(|| problems.note(None, tree(&names, &desc.joints)))
        .flatten();
    let stands = tree.is_some_and(|(root, parent_joint)| {
        let same = (root, &parent_joint) == (desc.root, &desc.parent_joint);
        let wrong =
            || RagdollError::NotATree("root and parent_joint are not the joints' tree".to_owned());
        problems
            .note(None, same.then_some(()).ok_or_else(wrong))
            .is_some()
    });
    if let (true, Some(spine)) = (stands, &desc.spine) {
        let checked = check_spine(spine, desc, &item(at.spine, "[spine]"));
        problems.note(at.spine, checked);
    }
    let drive = check_drive(
        desc.drive.as_ref(),
        &desc.joints,
        &item(at.drive, "[drive]"),
        |k| at.joint(k, &desc.joints[k].name),
    );
    problems.note(at.drive, drive);
    if stands {
        check_profiles(desc, at, problems);
    }
}

/// Every profile checked for the description (its joint tree standing),
/// names unique.
fn check_profiles(desc: &RagdollDesc, at: &At, problems: &mut Problems) {
    let line = |k: usize| at.profiles.get(k).copied().flatten();
    names(
        (desc.profiles.iter().enumerate()).map(|(k, p)| (p.name.as_str(), line(k))),
        "profile",
        problems,
    );
    for (k, p) in desc.profiles.iter().enumerate() {
        let context = item(line(k), &format!("profile `{}`", p.name));
        problems.note(line(k), p.check(desc, &context));
    }
}

/// Indexes `(name, line)` pairs by name; a name used twice is a problem
/// at its second use.
fn names<'a>(
    names: impl Iterator<Item = (&'a str, Option<usize>)>,
    kind: &'static str,
    problems: &mut Problems,
) -> HashMap<String, usize> {
    let mut index = HashMap::new();
    for (i, (n, line)) in names.enumerate() {
        if index.insert(n.to_owned(), i).is_some() {
            let twice = RagdollError::DuplicateName {
                line,
                kind,
                name: n.to_owned(),
            };
            problems.note(line, Err::<(), _>(twice));
        }
    }
    index
}

/// A body's segment within the world's coordinate range, and a capsule the
/// world accepts at its mass (size within `SIZE_RANGE`, mass within
/// `MASS_RANGE`, invertible inertia), so building it cannot fail on them.
fn check_body(b: &BodyDef, context: &str) -> Result<(), RagdollError> {
    finite(
        context,
        "segment",
        b.segment.map(|e| e.to_array()).as_flattened(),
    )?;
    finite(context, "radius", &[b.radius])?;
    finite(context, "mass", &[b.mass])?;
    range(context, "mass", b.mass > 0.0, "must be positive")?;
    range(context, "radius", b.radius > 0.0, "must be positive")?;
    for end in b.segment {
        check_coordinate("segment end", end).map_err(|e| RagdollError::world(context, e))?;
    }
    b.shape()
        .mass_properties_with_mass(b.mass)
        .map_err(|e| RagdollError::world(context, e))?;
    Ok(())
}

/// Every binding on a bone of the skeleton, at most one body per bone,
/// each offset finite with a unit rotation: a problem per body.
fn check_bindings(desc: &RagdollDesc, at: &At, problems: &mut Problems) {
    let mut owner: HashMap<usize, usize> = HashMap::new();
    for (i, b) in desc.bodies.iter().enumerate() {
        if let Some(binding) = b.bone {
            let checked = check_binding(desc, i, binding, &at.body(i, &b.name), &mut owner);
            problems.note(at.body_line(i), checked);
        }
    }
}

/// Body `i`'s `binding` (`context` names the body), its bone taken in
/// `owner` (bone to body).
fn check_binding(
    desc: &RagdollDesc,
    i: usize,
    binding: BoneBinding,
    context: &str,
    owner: &mut HashMap<usize, usize>,
) -> Result<(), RagdollError> {
    let reason = match &desc.skeleton {
        Some(s) => format!(
            "is bone {}; the ragdoll's skeleton has {}",
            binding.bone,
            s.len()
        ),
        None => format!("is bone {}, but the ragdoll has no skeleton", binding.bone),
    };
    let bones = desc.skeleton.as_ref().map_or(0, Skeleton::len);
    range(context, "bone", binding.bone < bones, &reason)?;
    if let Some(&other) = owner.get(&binding.bone) {
        let skeleton = desc.skeleton.as_ref().expect("the bone is in it");
        return Err(RagdollError::OutOfRange {
            context: context.to_owned(),
            field: "bone",
            reason: format!(
                "`{}` is body `{}`'s bone too; a bone has at most one body",
                skeleton.bones()[binding.bone].name,
                desc.bodies[other].name
            ),
        });
    }
    owner.insert(binding.bone, i);
    binding.offset.validate(&format!("{context}: offset"))
}

/// Checks the joints form one tree over all bodies (their names); returns the root and
/// each body's parent joint.
fn tree(bodies: &[&str], joints: &[JointDef]) -> Result<(usize, Vec<Option<usize>>), RagdollError> {
    let mut parent_joint = vec![None; bodies.len()];
    for (k, j) in joints.iter().enumerate() {
        if j.parent == j.child {
            return Err(RagdollError::NotATree(format!(
                "joint `{}` joins `{}` to itself",
                j.name, bodies[j.child]
            )));
        }
        if let Some(other) = parent_joint[j.child].replace(k) {
            return Err(RagdollError::NotATree(format!(
                "body `{}` is the child of both `{}` and `{}`",
                bodies[j.child], joints[other].name, j.name
            )));
        }
    }
    // Every body must reach the root by parent links, without a cycle:
    // each walk up stops at a body an earlier walk reached the root from,
    // so every body is walked through once (linear, however deep).
    let mut reaches_root = vec![false; bodies.len()];
    let mut walk = Vec::new();
    for start in 0..bodies.len() {
        let mut body = start;
        walk.clear();
        while !reaches_root[body] {
            walk.push(body);
            match parent_joint[body] {
                Some(k) => body = joints[k].parent,
                None => break,
            }
            if walk.len() > bodies.len() {
                return Err(RagdollError::NotATree(format!(
                    "a cycle runs through body `{}`",
                    bodies[start]
                )));
            }
        }
        for &b in &walk {
            reaches_root[b] = true;
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
                .map(|&b| format!("`{}`", bodies[b]))
                .collect::<Vec<_>>()
                .join(", ")
        ))),
    }
}

/// The spine's bodies by name and the chain of joints between them.
fn spine(
    s: &SpineSpec,
    context: &str,
    index: &HashMap<String, usize>,
    joints: &[JointDef],
    parent_joint: &[Option<usize>],
) -> Result<SpineDef, RagdollError> {
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
    let mut chain = Vec::new();
    for (k, pair) in bodies.windows(2).enumerate() {
        let joint = parent_joint[pair[1]]
            .filter(|&j| joints[j].parent == pair[0])
            .ok_or_else(|| {
                RagdollError::SpineNotChain(format!(
                    "no joint has parent `{}` and child `{}`",
                    s.bodies[k],
                    s.bodies[k + 1]
                ))
            })?;
        chain.push(joint);
    }
    Ok(SpineDef {
        bodies,
        joints: chain,
        bend_limit: s.bend_limit,
        twist_limit: s.twist_limit,
        bend_stiffness: s.bend_stiffness,
        twist_stiffness: s.twist_stiffness,
    })
}

/// A chain of at least two bodies joined in order by its joints, nothing
/// but the chain hanging from its interior bodies, limits and stiffness in
/// range.
fn check_spine(s: &SpineDef, desc: &RagdollDesc, context: &str) -> Result<(), RagdollError> {
    if s.bodies.len() < 2 {
        return Err(RagdollError::SpineNotChain(
            "needs at least two bodies".to_owned(),
        ));
    }
    let (bodies, joints) = (&desc.bodies, &desc.joints);
    for &b in &s.bodies {
        range(
            context,
            "bodies",
            b < bodies.len(),
            &format!("has body {b}; there are {}", bodies.len()),
        )?;
    }
    range(
        context,
        "joints",
        s.joints.len() + 1 == s.bodies.len(),
        "must be one fewer than the bodies: the joints between them",
    )?;
    for (&k, pair) in s.joints.iter().zip(s.bodies.windows(2)) {
        if joints
            .get(k)
            .is_none_or(|j| (j.parent, j.child) != (pair[0], pair[1]))
        {
            return Err(RagdollError::SpineNotChain(format!(
                "its joint {k} does not join `{}` to `{}`",
                bodies[pair[0]].name, bodies[pair[1]].name
            )));
        }
    }
    // The interior bodies disappear in the simplified ragdoll: nothing but
    // the chain may hang from them. Per body, the first joint off the
    // chain that hangs from it (one pass over the joints, not one per
    // interior body).
    let chain: HashSet<usize> = s.joints.iter().copied().collect();
    let mut hanging: Vec<Option<usize>> = vec![None; bodies.len()];
    for (k, j) in joints.iter().enumerate() {
        if !chain.contains(&k) && j.parent < bodies.len() {
            hanging[j.parent].get_or_insert(k);
        }
    }
    if let Some(k) = s.bodies[1..s.bodies.len() - 1]
        .iter()
        .find_map(|&interior| hanging[interior])
    {
        return Err(RagdollError::SpineNotChain(format!(
            "joint `{}` hangs from an interior spine body; only the chain may",
            joints[k].name
        )));
    }
    let limits = [s.bend_limit, s.bend_stiffness, s.twist_stiffness];
    rod_limits(context, limits, s.twist_limit)
}

/// The rod's `[bend_limit, bend_stiffness, twist_stiffness]` and
/// `twist_limit` in range (`context` names the spine).
fn rod_limits(
    context: &str,
    [bend_limit, bend_stiffness, twist_stiffness]: [f32; 3],
    twist_limit: [f32; 2],
) -> Result<(), RagdollError> {
    for (field, v) in [
        ("bend_limit", bend_limit),
        ("bend_stiffness", bend_stiffness),
        ("twist_stiffness", twist_stiffness),
    ] {
        finite(context, field, &[v])?;
    }
    finite(context, "twist_limit", &twist_limit)?;
    range(
        context,
        "bend_limit",
        (0.0..=half_turn()).contains(&bend_limit),
        "must be in [0, 180] degrees",
    )?;
    let [lo, hi] = twist_limit;
    range(
        context,
        "twist_limit",
        -half_turn() <= lo && lo <= hi && hi <= half_turn(),
        "must be [min, max] within [-180, 180] degrees",
    )?;
    range(
        context,
        "bend_stiffness",
        bend_stiffness >= 0.0,
        "must not be negative",
    )?;
    range(
        context,
        "twist_stiffness",
        twist_stiffness >= 0.0,
        "must not be negative",
    )
}

/// The joints' own strengths as the settings' per-joint list: each
/// joint's, or none when no joint has its own.
pub(crate) fn own_strengths(joints: &[JointDef]) -> Vec<Option<Spring>> {
    if joints.iter().any(|j| j.drive.is_some()) {
        joints.iter().map(|j| j.drive).collect()
    } else {
        Vec::new()
    }
}

/// Checks a description's drive settings as the loader does: a joint's own
/// strength needs settings to fall back on, the settings' per-joint list
/// is the joints' own strengths, and every value is one the world takes.
/// `context` names the `[drive]` table, `joint` a joint.
pub(crate) fn check_drive(
    drive: Option<&DriveSettings>,
    joints: &[JointDef],
    context: &str,
    joint: impl Fn(usize) -> String,
) -> Result<(), RagdollError> {
    let Some(settings) = drive else {
        return match joints.iter().position(|j| j.drive.is_some()) {
            Some(k) => Err(RagdollError::OutOfRange {
                context: joint(k),
                field: "drive",
                reason: "needs a [drive] table for the ragdoll's other joints".to_owned(),
            }),
            None => Ok(()),
        };
    };
    settings.validate(context, joints.len(), joint)?;
    range(
        context,
        "joints",
        settings.joints == own_strengths(joints),
        "must be each joint's own strength (`JointDef::drive`), or empty when no joint has one",
    )
}
