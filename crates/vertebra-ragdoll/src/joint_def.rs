//! A described joint: its kind (socket, hinge, fixed), its frame at bind
//! pose, and its limits. A `[[joint]]` table is read into a [`JointSpec`]
//! (what a builder takes too), resolved into a [`JointDef`], and checked
//! field by field (`docs/ragdolls.md` gives the format).

use std::collections::HashMap;
use vertebra_math::PortableQuat;

use glam::{DVec3, Mat3, Quat, Vec3};
use serde::Deserialize;
use vertebra_store::{check_coordinate, check_unit_quat};
use vertebra_world::{
    JointBreaking, JointKind, LimitSoftness, Spring, SpringField, Swing, SwingTwist,
};

use crate::drive_def::RawStrength;
use crate::error::{RagdollError, check_spring, finite, range};

/// A joint between a parent and a child body.
#[derive(Clone, Debug, PartialEq)]
pub struct JointDef {
    /// Unique name.
    pub name: String,
    /// Index of the parent body.
    pub parent: usize,
    /// Index of the child body.
    pub child: usize,
    /// The pivot at bind pose (m, world).
    pub anchor: Vec3,
    /// The joint frame at bind pose (world): its +X is a socket's twist
    /// axis (from parent to child) or a hinge's rotation axis, its +Y the
    /// file's `normal` (when given). Both bodies' joint frames are this
    /// one at bind pose, so every joint starts at zero swing, twist and
    /// hinge angle.
    pub frame: Quat,
    /// The kind and its limits (rad), as the world takes them.
    pub kind: JointKind,
    /// The joint's own drive strength (the file's `drive = { ... }`), over
    /// the ragdoll's `[drive]` one; `None` takes the ragdoll's.
    pub drive: Option<Spring>,
    /// When it breaks (the file's `break_force`, N, and `break_torque`,
    /// N m; either alone leaves the other infinite): see
    /// `vertebra_world::JointBreaking`. `None`: never.
    pub breaking: Option<JointBreaking>,
}

impl JointDef {
    /// The joint frame's +X at bind pose (unit, world): a socket's twist
    /// axis, a hinge's rotation axis.
    pub fn axis(&self) -> Vec3 {
        self.frame * Vec3::X
    }
}

/// A `[[joint]]` table as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawJoint {
    pub name: String,
    parent: String,
    child: String,
    anchor: [f32; 3],
    kind: Option<String>,
    frame: Option<[f32; 4]>,
    axis: Option<[f32; 3]>,
    normal: Option<[f32; 3]>,
    swing: Option<RawSwing>,
    twist: Option<[f32; 2]>,
    range: Option<[f32; 2]>,
    softness: Option<RawSoftness>,
    drive: Option<RawStrength>,
    break_force: Option<f32>,
    break_torque: Option<f32>,
}

/// `softness = 0.001` (a compliance), `softness = { compliance = 0.001,
/// damping = 20 }` or `softness = { frequency = 8, damping_ratio = 1 }`.
#[derive(Deserialize)]
#[serde(untagged)]
#[serde(
    expecting = "softness: a compliance, { compliance, damping } or { frequency, damping_ratio }"
)]
enum RawSoftness {
    Compliance(f32),
    Table(RawSoftTable),
}

/// The table form of `softness`, its combinations checked by `softness`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSoftTable {
    compliance: Option<f32>,
    damping: Option<f32>,
    frequency: Option<f32>,
    damping_ratio: Option<f32>,
}

/// `swing = 40` (a cone), `swing = { y = 80, z = 35 }` (an ellipse) or
/// `swing = { y = [-30, 90], z = [-10, 80] }` (a pyramid), in degrees.
#[derive(Clone, Copy, Deserialize)]
#[serde(untagged)]
enum RawSwing {
    Cone(f32),
    Ellipse { y: f32, z: f32 },
    Pyramid { y: [f32; 2], z: [f32; 2] },
}

/// A joint as a builder gives it (and as a `[[joint]]` table reads): its
/// bodies by name, its frame by an axis (and normal) or as a rotation,
/// and its limits in radians. [`RagdollDesc::builder`] resolves and checks
/// it as the file loader does.
///
/// [`RagdollDesc::builder`]: crate::RagdollDesc::builder
#[derive(Clone, Debug, PartialEq)]
pub struct JointSpec {
    /// Unique name.
    pub name: String,
    /// The parent body's name.
    pub parent: String,
    /// The child body's name.
    pub child: String,
    /// The pivot at bind pose (m, world: the skeleton's model frame).
    pub anchor: Vec3,
    /// The joint frame at bind pose.
    pub frame: JointFrame,
    /// The kind and its limits (rad), as the world takes them.
    pub kind: JointKind,
    /// The joint's own drive strength, over the ragdoll's `[drive]` one.
    pub drive: Option<Spring>,
    /// When it breaks; `None`: never.
    pub breaking: Option<JointBreaking>,
}

/// How a [`JointSpec`] gives its frame at bind pose (world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointFrame {
    /// +X along `axis` (longer than 1e-6; normalised), +Y along `normal`
    /// made exactly perpendicular (it must be within 0.06 degrees of
    /// perpendicular; sockets only), or without a normal the shortest turn
    /// from +X to the axis. A socket with an elliptical or pyramid swing
    /// needs the normal.
    Axis {
        /// A socket's twist axis (parent to child) or a hinge's rotation
        /// axis.
        axis: Vec3,
        /// The frame's +Y.
        normal: Option<Vec3>,
    },
    /// The frame itself: a unit quaternion (within 1e-3), kept as given
    /// (the file's `frame = [x, y, z, w]`).
    Rotation(Quat),
}

impl JointSpec {
    /// A socket of `limits` (rad) whose twist axis (parent to child) is
    /// `axis`; `anchor` in metres, world at bind pose.
    pub fn socket(
        name: &str,
        parent: &str,
        child: &str,
        anchor: Vec3,
        axis: Vec3,
        limits: SwingTwist,
    ) -> Self {
        Self::new(name, parent, child, anchor, axis, JointKind::Socket(limits))
    }

    /// A hinge turning about `axis`, within `range` (rad, `None`:
    /// unlimited), with hard limits.
    pub fn hinge(
        name: &str,
        parent: &str,
        child: &str,
        anchor: Vec3,
        axis: Vec3,
        range: Option<[f32; 2]>,
    ) -> Self {
        let kind = JointKind::Hinge {
            range,
            softness: LimitSoftness::Hard,
        };
        Self::new(name, parent, child, anchor, axis, kind)
    }

    /// A fixed joint at `anchor` (m, world at bind pose), its frame the
    /// world's axes.
    pub fn fixed(name: &str, parent: &str, child: &str, anchor: Vec3) -> Self {
        Self {
            frame: JointFrame::Rotation(Quat::IDENTITY),
            ..Self::new(name, parent, child, anchor, Vec3::X, JointKind::Fixed)
        }
    }

    fn new(
        name: &str,
        parent: &str,
        child: &str,
        anchor: Vec3,
        axis: Vec3,
        kind: JointKind,
    ) -> Self {
        Self {
            name: name.to_owned(),
            parent: parent.to_owned(),
            child: child.to_owned(),
            anchor,
            frame: JointFrame::Axis { axis, normal: None },
            kind,
            drive: None,
            breaking: None,
        }
    }

    /// With the frame's +Y along `normal` (a socket's; an elliptical or
    /// pyramid swing needs it). A frame given as a rotation becomes its
    /// +X axis with this normal.
    pub fn with_normal(mut self, normal: Vec3) -> Self {
        let axis = match self.frame {
            JointFrame::Axis { axis, .. } => axis,
            JointFrame::Rotation(q) => q * Vec3::X,
        };
        self.frame = JointFrame::Axis {
            axis,
            normal: Some(normal),
        };
        self
    }

    /// With its own drive strength.
    pub fn with_drive(mut self, strength: Spring) -> Self {
        self.drive = Some(strength);
        self
    }

    /// Breaking past `force` (N) or `torque` (N m; infinity: never by
    /// it): a limb that tears off (`vertebra_world::JointBreaking`).
    pub fn with_breaking(mut self, force: f32, torque: f32) -> Self {
        self.breaking = Some(JointBreaking { force, torque });
        self
    }
}

/// Fields each kind takes besides name, parent, child, anchor and frame.
const SOCKET_FIELDS: [&str; 6] = ["axis", "normal", "swing", "twist", "softness", "drive"];
const HINGE_FIELDS: [&str; 4] = ["axis", "range", "softness", "drive"];

impl RawJoint {
    /// The optional fields this joint has, by name.
    fn present(&self) -> [(&'static str, bool); 7] {
        [
            ("axis", self.axis.is_some()),
            ("normal", self.normal.is_some()),
            ("swing", self.swing.is_some()),
            ("twist", self.twist.is_some()),
            ("range", self.range.is_some()),
            ("softness", self.softness.is_some()),
            ("drive", self.drive.is_some()),
        ]
    }
}

impl RawJoint {
    /// A fixed joint between the table's bodies at its anchor: what a
    /// table that could not be read stands for, so that its names still
    /// count while its problem is reported.
    pub(crate) fn stand_in(&self) -> JointSpec {
        JointSpec::fixed(
            &self.name,
            &self.parent,
            &self.child,
            Vec3::from(self.anchor),
        )
    }
}

/// Reads one `[[joint]]` table (`context` names its line and the joint):
/// its kind and the fields that kind takes, its softness and drive as one
/// of their forms (a drive's compliance without its own damping taking
/// `damping`, the `[drive]` table's), its angles in radians. The values
/// are checked when the joint is resolved.
pub(crate) fn joint_spec(
    j: &RawJoint,
    context: &str,
    damping: f32,
) -> Result<JointSpec, RagdollError> {
    let named = j.kind.as_deref().unwrap_or("socket");
    let kind = joint_kind(
        context,
        named,
        &j.present(),
        j.swing,
        [j.twist, j.range],
        j.softness.as_ref(),
    )?;
    let drive = j.drive.map(|d| d.read(context, damping)).transpose()?;
    let breaking = (j.break_force.is_some() || j.break_torque.is_some()).then(|| JointBreaking {
        force: j.break_force.unwrap_or(f32::INFINITY),
        torque: j.break_torque.unwrap_or(f32::INFINITY),
    });
    let frame = match (j.frame, j.axis, j.normal) {
        (Some(q), None, None) => JointFrame::Rotation(Quat::from_array(q)),
        (Some(_), _, _) => {
            return Err(RagdollError::OutOfRange {
                context: context.to_owned(),
                field: "frame",
                reason: "takes the place of axis and normal; give one or the other".to_owned(),
            });
        }
        (None, None, _) if named == "fixed" => JointFrame::Rotation(Quat::IDENTITY),
        (None, axis, normal) => JointFrame::Axis {
            axis: Vec3::from(required(context, "axis", axis)?),
            normal: normal.map(Vec3::from),
        },
    };
    Ok(JointSpec {
        name: j.name.clone(),
        parent: j.parent.clone(),
        child: j.child.clone(),
        anchor: Vec3::from(j.anchor),
        frame,
        kind,
        drive,
        breaking,
    })
}

/// The kind a table names (`named`: socket, hinge or fixed) with its
/// limits in radians (the table's `swing`, `[twist, range]` and
/// `softness`, in degrees), refusing a field among `present` that the
/// kind does not take (`context` names the table).
fn joint_kind(
    context: &str,
    named: &str,
    present: &[(&'static str, bool)],
    swing: Option<RawSwing>,
    [twist, hinge_range]: [Option<[f32; 2]>; 2],
    softness_table: Option<&RawSoftness>,
) -> Result<JointKind, RagdollError> {
    let allowed: &[&str] = match named {
        "socket" => &SOCKET_FIELDS,
        "hinge" => &HINGE_FIELDS,
        "fixed" => &[],
        other => {
            return Err(RagdollError::OutOfRange {
                context: context.to_owned(),
                field: "kind",
                reason: format!("is `{other}`; must be socket, hinge or fixed"),
            });
        }
    };
    for &(field, present) in present {
        let owners = match field {
            "range" => "hinges",
            "normal" | "swing" | "twist" => "sockets",
            _ => "sockets and hinges",
        };
        range(
            context,
            field,
            !present || allowed.contains(&field),
            &format!("is for {owners} only; this joint is a {named}"),
        )?;
    }
    let softness = softness(context, softness_table)?;
    Ok(match named {
        "socket" => JointKind::Socket(SwingTwist {
            swing: match swing {
                None => Swing::Free,
                Some(RawSwing::Cone(x)) => Swing::Cone(x.to_radians()),
                Some(RawSwing::Ellipse { y, z }) => Swing::Ellipse {
                    y: y.to_radians(),
                    z: z.to_radians(),
                },
                Some(RawSwing::Pyramid { y, z }) => Swing::Pyramid {
                    y: y.map(f32::to_radians),
                    z: z.map(f32::to_radians),
                },
            },
            twist: twist.map(|t| t.map(f32::to_radians)),
            softness,
        }),
        "hinge" => JointKind::Hinge {
            range: hinge_range.map(|r| r.map(f32::to_radians)),
            softness,
        },
        _ => JointKind::Fixed,
    })
}

/// A generated body's `joint = { ... }` table: a `[[joint]]` table's kind,
/// limits and softness, with its axis and normal in the bone's frame and
/// both optional (`docs/ragdolls.md`, "Generating a ragdoll from a
/// skeleton").
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawBoneJoint {
    kind: Option<String>,
    axis: Option<[f32; 3]>,
    normal: Option<[f32; 3]>,
    swing: Option<RawSwing>,
    twist: Option<[f32; 2]>,
    range: Option<[f32; 2]>,
    softness: Option<RawSoftness>,
}

impl RawBoneJoint {
    /// The kind and limits (rad), the axis and the normal (the bone's
    /// frame), checked as a `[[joint]]` table's fields are read
    /// (`context` names the body's table).
    pub(crate) fn read(
        &self,
        context: &str,
    ) -> Result<(JointKind, Option<Vec3>, Option<Vec3>), RagdollError> {
        let present = [
            ("axis", self.axis.is_some()),
            ("normal", self.normal.is_some()),
            ("swing", self.swing.is_some()),
            ("twist", self.twist.is_some()),
            ("range", self.range.is_some()),
            ("softness", self.softness.is_some()),
        ];
        let kind = joint_kind(
            context,
            self.kind.as_deref().unwrap_or("socket"),
            &present,
            self.swing,
            [self.twist, self.range],
            self.softness.as_ref(),
        )?;
        Ok((kind, self.axis.map(Vec3::from), self.normal.map(Vec3::from)))
    }
}

/// Resolves a joint's body names through `index` and builds its frame,
/// then checks every value (`context` names the joint, and its line in a
/// file).
pub(crate) fn resolve(
    j: &JointSpec,
    context: &str,
    index: &HashMap<String, usize>,
) -> Result<JointDef, RagdollError> {
    let lookup = |field: &'static str, name: &str| {
        index
            .get(name)
            .copied()
            .ok_or_else(|| RagdollError::UnknownBody {
                context: context.to_owned(),
                field,
                name: name.to_owned(),
            })
    };
    let (parent, child) = (lookup("parent", &j.parent)?, lookup("child", &j.child)?);
    let shaped = matches!(
        j.kind,
        JointKind::Socket(SwingTwist {
            swing: Swing::Ellipse { .. } | Swing::Pyramid { .. },
            ..
        })
    );
    let frame = match j.frame {
        JointFrame::Rotation(q) => q,
        JointFrame::Axis { axis, normal } => {
            if let (Some(_), JointKind::Hinge { .. } | JointKind::Fixed) = (normal, j.kind) {
                let kind = kind_name(&j.kind);
                range(
                    context,
                    "normal",
                    false,
                    &format!("is for sockets only; this joint is a {kind}"),
                )?;
            }
            range(
                context,
                "normal",
                !shaped || normal.is_some(),
                "is missing: an elliptical or pyramid swing needs it to place its axes",
            )?;
            frame(
                context,
                &j.name,
                axis.to_array(),
                normal.map(|n| n.to_array()),
            )?
        }
    };
    let def = JointDef {
        name: j.name.clone(),
        parent,
        child,
        anchor: j.anchor,
        frame,
        kind: j.kind,
        drive: j.drive,
        breaking: j.breaking,
    };
    check_joint(&def, index.len(), context)?;
    Ok(def)
}

/// `socket`, `hinge` or `fixed`, as a file names the kind.
pub(crate) fn kind_name(kind: &JointKind) -> &'static str {
    match kind {
        JointKind::Socket(_) => "socket",
        JointKind::Hinge { .. } => "hinge",
        JointKind::Fixed => "fixed",
    }
}

/// Checks a joint's values as the file loader does, among `bodies` bodies:
/// its bodies exist, its anchor is within the world's range, its frame a
/// unit quaternion, its limits and softness in range.
pub(crate) fn check_joint(j: &JointDef, bodies: usize, context: &str) -> Result<(), RagdollError> {
    for (field, body) in [("parent", j.parent), ("child", j.child)] {
        range(
            context,
            field,
            body < bodies,
            &format!("is body {body}; there are {bodies}"),
        )?;
    }
    finite(context, "anchor", &j.anchor.to_array())?;
    check_coordinate("anchor", j.anchor).map_err(|e| RagdollError::world(context, e))?;
    if let Some(breaking) = &j.breaking {
        breaking
            .validate()
            .map_err(|e| RagdollError::world(context, e))?;
    }
    check_unit_quat("frame", j.frame).map_err(|e| RagdollError::world(context, e))?;
    match j.kind {
        JointKind::Socket(limits) => {
            check_swing(context, limits.swing)?;
            if let Some(t) = limits.twist {
                angle_range(context, "twist", t)?;
            }
            check_softness(context, limits.softness)
        }
        JointKind::Hinge { range, softness } => {
            if let Some(r) = range {
                angle_range(context, "range", r)?;
            }
            check_softness(context, softness)
        }
        JointKind::Fixed => Ok(()),
    }
}

fn required<T>(context: &str, field: &'static str, value: Option<T>) -> Result<T, RagdollError> {
    value.ok_or_else(|| RagdollError::OutOfRange {
        context: context.to_owned(),
        field,
        reason: "is missing".to_owned(),
    })
}

/// The joint frame at bind pose: +X along `axis`, +Y along `normal` made
/// exactly perpendicular, or (without a normal) the shortest turn from +X
/// to `axis`, as every joint had before normals existed.
pub(crate) fn frame(
    context: &str,
    name: &str,
    axis: [f32; 3],
    normal: Option<[f32; 3]>,
) -> Result<Quat, RagdollError> {
    finite(context, "axis", &axis)?;
    // In f64: the length of [1e38, 1e38, 0] overflows f32, and the axis
    // normalised in f32 became zero.
    let x = DVec3::from(axis.map(f64::from));
    if x.length() <= 1e-6 {
        return Err(RagdollError::ZeroAxis {
            joint: name.to_owned(),
        });
    }
    let x = x.normalize();
    let Some(normal) = normal else {
        return Ok(Quat::from_rotation_arc_portable(Vec3::X, x.as_vec3()));
    };
    finite(context, "normal", &normal)?;
    let n = DVec3::from(normal.map(f64::from));
    let length = n.length();
    range(
        context,
        "normal",
        length > 1e-6 && (n.dot(x) / length).abs() <= 1e-3,
        "must be a direction perpendicular to the axis (within 0.06 degrees)",
    )?;
    let y = (n - x * n.dot(x)).normalize();
    let z = x.cross(y);
    Ok(
        Quat::from_mat3(&Mat3::from_cols(x.as_vec3(), y.as_vec3(), z.as_vec3()))
            .normalize_portable(),
    )
}

/// Half a turn (rad), as the file's 180 degrees reads.
pub(crate) fn half_turn() -> f32 {
    180.0_f32.to_radians()
}

/// A swing limit's half-angles in [0, 180] degrees, ranges within
/// [-180, 180] degrees.
fn check_swing(context: &str, swing: Swing) -> Result<(), RagdollError> {
    let half_angle = |field, x: f32| -> Result<(), RagdollError> {
        finite(context, field, &[x])?;
        range(
            context,
            field,
            (0.0..=half_turn()).contains(&x),
            "must be in [0, 180] degrees",
        )
    };
    match swing {
        Swing::Free => Ok(()),
        Swing::Cone(x) => half_angle("swing", x),
        Swing::Ellipse { y, z } => {
            half_angle("swing.y", y)?;
            half_angle("swing.z", z)
        }
        Swing::Pyramid { y, z } => {
            angle_range(context, "swing.y", y)?;
            angle_range(context, "swing.z", z)
        }
    }
}

/// `[min, max]` (rad) within [-180, 180] degrees.
fn angle_range(
    context: &str,
    field: &'static str,
    [min, max]: [f32; 2],
) -> Result<(), RagdollError> {
    finite(context, field, &[min, max])?;
    range(
        context,
        field,
        -half_turn() <= min && min <= max && max <= half_turn(),
        "must be [min, max] within [-180, 180] degrees",
    )
}

/// `softness = C`, `{ compliance = C, damping = D }` or `{ frequency = F,
/// damping_ratio = Z }`: the limits' softness (`LimitSoftness`); hard
/// without it.
fn softness(context: &str, raw: Option<&RawSoftness>) -> Result<LimitSoftness, RagdollError> {
    Ok(match raw {
        None => LimitSoftness::Hard,
        Some(RawSoftness::Compliance(c)) => LimitSoftness::compliant(*c),
        Some(RawSoftness::Table(t)) => {
            match (t.compliance, t.damping, t.frequency, t.damping_ratio) {
                (Some(compliance), damping, None, None) => {
                    LimitSoftness::Soft(Spring::Compliance {
                        compliance,
                        damping: damping.unwrap_or(0.0),
                    })
                }
                (None, None, Some(frequency), Some(damping_ratio)) => {
                    LimitSoftness::Soft(Spring::Frequency {
                        frequency,
                        damping_ratio,
                    })
                }
                _ => {
                    return Err(RagdollError::OutOfRange {
                    context: context.to_owned(),
                    field: "softness",
                    reason: "takes a compliance, { compliance, damping } or { frequency, damping_ratio }"
                        .to_owned(),
                });
                }
            }
        }
    })
}

/// A limit softness as a description holds it: finite numbers, in the
/// world's ranges (its check, whose reason names the number).
fn check_softness(context: &str, soft: LimitSoftness) -> Result<(), RagdollError> {
    let LimitSoftness::Soft(spring) = soft else {
        return Ok(());
    };
    let (Spring::Compliance {
        compliance: x,
        damping: y,
    }
    | Spring::Frequency {
        frequency: x,
        damping_ratio: y,
    }) = spring;
    finite(context, "softness", &[x, y])?;
    check_spring(context, "softness", spring, SpringField::Limit)
}
