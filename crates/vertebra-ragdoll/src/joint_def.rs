//! A described joint: its kind (socket, hinge, fixed), its frame at bind
//! pose, and its limits, read from a `[[joint]]` table and checked field
//! by field (`docs/ragdolls.md` gives the format).

use std::collections::HashMap;

use glam::{DVec3, Mat3, Quat, Vec3};
use serde::Deserialize;
use vertebra_world::{
    JointKind, LimitSoftness, MAX_DRIVE_DAMPING_RATIO, MAX_DRIVE_DAMPING_TIME, MIN_DRIVE_FREQUENCY,
    Swing, SwingTwist, check_coordinate,
};

use crate::description::{finite, range};
use crate::drive::Strength;
use crate::drive_def::RawStrength;
use crate::error::RagdollError;

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
    pub drive: Option<Strength>,
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
    axis: Option<[f32; 3]>,
    normal: Option<[f32; 3]>,
    swing: Option<RawSwing>,
    twist: Option<[f32; 2]>,
    range: Option<[f32; 2]>,
    softness: Option<RawSoftness>,
    drive: Option<RawStrength>,
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
#[derive(Deserialize)]
#[serde(untagged)]
enum RawSwing {
    Cone(f32),
    Ellipse { y: f32, z: f32 },
    Pyramid { y: [f32; 2], z: [f32; 2] },
}

/// Fields each kind takes besides name, parent, child and anchor.
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

/// Reads and checks one joint defined at `line`.
pub(crate) fn joint(
    j: &RawJoint,
    line: usize,
    index: &HashMap<String, usize>,
) -> Result<JointDef, RagdollError> {
    let context = format!("line {line}: joint `{}`", j.name);
    let lookup = |field: &'static str, name: &str| {
        index
            .get(name)
            .copied()
            .ok_or_else(|| RagdollError::UnknownBody {
                context: context.clone(),
                field,
                name: name.to_owned(),
            })
    };
    let (parent, child) = (lookup("parent", &j.parent)?, lookup("child", &j.child)?);
    finite(&context, "anchor", &j.anchor)?;
    check_coordinate("anchor", Vec3::from(j.anchor))
        .map_err(|e| RagdollError::world(&context, e))?;
    let kind = j.kind.as_deref().unwrap_or("socket");
    let allowed: &[&str] = match kind {
        "socket" => &SOCKET_FIELDS,
        "hinge" => &HINGE_FIELDS,
        "fixed" => &[],
        other => {
            return Err(RagdollError::OutOfRange {
                context,
                field: "kind",
                reason: format!("is `{other}`; must be socket, hinge or fixed"),
            });
        }
    };
    for (field, present) in j.present() {
        let owners = match field {
            "range" => "hinges",
            "normal" | "swing" | "twist" => "sockets",
            _ => "sockets and hinges",
        };
        range(
            &context,
            field,
            !present || allowed.contains(&field),
            &format!("is for {owners} only; this joint is a {kind}"),
        )?;
    }
    let softness = softness(&context, j.softness.as_ref())?;
    let drive = j.drive.map(|d| d.read(&context)).transpose()?;
    let (frame, kind) = match kind {
        "socket" => {
            let frame = frame(
                &context,
                &j.name,
                required(&context, "axis", j.axis)?,
                j.normal,
            )?;
            let swing = swing(&context, j.swing.as_ref(), j.normal.is_some())?;
            let twist = j
                .twist
                .map(|t| angle_range(&context, "twist", t, -180.0, 180.0))
                .transpose()?;
            let limits = SwingTwist {
                swing,
                twist,
                softness,
            };
            (frame, JointKind::Socket(limits))
        }
        "hinge" => {
            let frame = frame(&context, &j.name, required(&context, "axis", j.axis)?, None)?;
            let range = j
                .range
                .map(|r| angle_range(&context, "range", r, -180.0, 180.0))
                .transpose()?;
            (frame, JointKind::Hinge { range, softness })
        }
        _ => (Quat::IDENTITY, JointKind::Fixed),
    };
    Ok(JointDef {
        name: j.name.clone(),
        parent,
        child,
        anchor: Vec3::from(j.anchor),
        frame,
        kind,
        drive,
    })
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
fn frame(
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
        return Ok(Quat::from_rotation_arc(Vec3::X, x.as_vec3()));
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
    Ok(Quat::from_mat3(&Mat3::from_cols(x.as_vec3(), y.as_vec3(), z.as_vec3())).normalize())
}

/// The swing limit: free without `swing`; a shaped one needs the frame's
/// `normal` to say which way its axes lie.
fn swing(context: &str, raw: Option<&RawSwing>, has_normal: bool) -> Result<Swing, RagdollError> {
    let half_angle = |field, x: f32| -> Result<f32, RagdollError> {
        finite(context, field, &[x])?;
        range(
            context,
            field,
            (0.0..=180.0).contains(&x),
            "must be in [0, 180] degrees",
        )?;
        Ok(x.to_radians())
    };
    let shaped = |ok: bool| {
        range(
            context,
            "normal",
            ok,
            "is missing: an elliptical or pyramid swing needs it to place its axes",
        )
    };
    Ok(match raw {
        None => Swing::Free,
        Some(RawSwing::Cone(x)) => Swing::Cone(half_angle("swing", *x)?),
        Some(RawSwing::Ellipse { y, z }) => {
            shaped(has_normal)?;
            Swing::Ellipse {
                y: half_angle("swing.y", *y)?,
                z: half_angle("swing.z", *z)?,
            }
        }
        Some(RawSwing::Pyramid { y, z }) => {
            shaped(has_normal)?;
            Swing::Pyramid {
                y: angle_range(context, "swing.y", *y, -180.0, 180.0)?,
                z: angle_range(context, "swing.z", *z, -180.0, 180.0)?,
            }
        }
    })
}

/// `[min, max]` in degrees within `[lo, hi]`, in radians.
fn angle_range(
    context: &str,
    field: &'static str,
    [min, max]: [f32; 2],
    lo: f32,
    hi: f32,
) -> Result<[f32; 2], RagdollError> {
    finite(context, field, &[min, max])?;
    range(
        context,
        field,
        lo <= min && min <= max && max <= hi,
        &format!("must be [min, max] within [{lo}, {hi}] degrees"),
    )?;
    Ok([min.to_radians(), max.to_radians()])
}

/// `softness = C`, `{ compliance = C, damping = D }` or `{ frequency = F,
/// damping_ratio = Z }`: the limits' softness (`LimitSoftness`); hard
/// without it. Checked as the world will check it, by name.
fn softness(context: &str, raw: Option<&RawSoftness>) -> Result<LimitSoftness, RagdollError> {
    let soft = match raw {
        None => return Ok(LimitSoftness::Hard),
        Some(RawSoftness::Compliance(c)) => LimitSoftness::compliant(*c),
        Some(RawSoftness::Table(t)) => {
            match (t.compliance, t.damping, t.frequency, t.damping_ratio) {
                (Some(compliance), damping, None, None) => LimitSoftness::Compliance {
                    compliance,
                    damping: damping.unwrap_or(0.0),
                },
                (None, None, Some(frequency), Some(damping_ratio)) => LimitSoftness::Spring {
                    frequency,
                    damping_ratio,
                },
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
    };
    let numbers = match soft {
        LimitSoftness::Hard => vec![],
        LimitSoftness::Compliance {
            compliance,
            damping,
        } => vec![compliance, damping],
        LimitSoftness::Spring {
            frequency,
            damping_ratio,
        } => vec![frequency, damping_ratio],
    };
    finite(context, "softness", &numbers)?;
    let (ok, reason) = match soft {
        LimitSoftness::Compliance {
            compliance,
            damping,
        } => (
            compliance >= 0.0 && damping >= 0.0 && compliance * damping <= MAX_DRIVE_DAMPING_TIME,
            "must be a compliance (rad / (N m)) and damping (N m s / rad) of 0 or more, compliance times damping at most 1e6 s",
        ),
        LimitSoftness::Spring {
            frequency,
            damping_ratio,
        } => (
            frequency >= MIN_DRIVE_FREQUENCY
                && (0.0..=MAX_DRIVE_DAMPING_RATIO).contains(&damping_ratio),
            "must be a frequency of at least 1e-3 Hz and a damping ratio in [0, 1e3]",
        ),
        LimitSoftness::Hard => (true, ""),
    };
    range(context, "softness", ok, reason)?;
    Ok(soft)
}
