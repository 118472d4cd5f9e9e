//! `vertebra check FILE`: validates a ragdoll file (with its skeleton), a
//! ragdoll generator file (on a skeleton) or a skeleton file, told apart
//! by content, and prints what it holds, or every problem found.

use std::fmt::Write as _;
use std::path::Path;

use vertebra_ragdoll::{Profile, RagdollDesc, RagdollError, RagdollGenerator, Skeleton, read_text};
use vertebra_world::{JointKind, LimitSoftness, Spring, Swing};

/// What the file at `path` holds, as text; or every problem found, one a
/// line, each naming the file and the line. `skeleton` is the skeleton
/// file a generator file is read against (the reference skeleton without
/// one); it is refused for other files.
pub fn check(path: &Path, skeleton: Option<&Path>) -> Result<String, String> {
    // Through the loaders' one reader (a regular file within the size cap,
    // checked before it is opened): a FIFO, a device or a directory is
    // refused, never opened.
    let text = read_text(path, "ragdoll").map_err(|e| e.to_string())?;
    let kind = kind(&text);
    if skeleton.is_some() && !matches!(kind, Kind::Generator) {
        return Err(format!(
            "{}: --skeleton is for a generator file ([[body]] tables that name a bone and no body name)",
            path.display()
        ));
    }
    match kind {
        Kind::Ragdoll => RagdollDesc::check_file(path)
            .map(|desc| ragdoll(path, &desc))
            .map_err(lines),
        Kind::Generator => generated(path, skeleton),
        Kind::Skeleton => Skeleton::check_file(path)
            .map(|s| self::skeleton(path, &s))
            .map_err(lines),
        Kind::Neither => Err(format!(
            "{}: neither a ragdoll file ([[body]] tables) nor a skeleton file ([[bone]] tables)",
            path.display()
        )),
    }
}

/// Problems, one a line.
fn lines(problems: Vec<RagdollError>) -> String {
    let lines: Vec<String> = problems.iter().map(ToString::to_string).collect();
    lines.join("\n")
}

/// What the generator file at `path` generates on the skeleton file at
/// `skeleton` (the reference skeleton without one), or its problems.
fn generated(path: &Path, skeleton: Option<&Path>) -> Result<String, String> {
    let (bones, on) = match skeleton {
        Some(file) => (
            Skeleton::check_file(file).map_err(lines)?,
            file.display().to_string(),
        ),
        None => (Skeleton::reference(), "the reference skeleton".to_owned()),
    };
    let desc = RagdollGenerator::check_file(path, &bones).map_err(lines)?;
    Ok(format!(
        "{}: ragdoll generator, on {on} ({} bones): generates\n{}",
        path.display(),
        bones.len(),
        ragdoll(path, &desc)
    ))
}

enum Kind {
    Ragdoll,
    Generator,
    Skeleton,
    Neither,
}

/// A ragdoll file has `[[body]]` tables, each with a `name`; a generator
/// file has `[[body]]` tables that name a `bone` and none a `name` (a
/// generated body is named after its bone); a skeleton file has `[[bone]]`
/// tables only. Text that cannot be parsed is read as a ragdoll file,
/// unless it has `[[bone]]` and no `[[body]]`: the loader then names the
/// problem.
fn kind(text: &str) -> Kind {
    match text.parse::<toml::Table>() {
        Ok(table) => match table.get("body") {
            Some(toml::Value::Array(bodies)) if bodies.iter().all(generator_body) => {
                Kind::Generator
            }
            Some(_) => Kind::Ragdoll,
            None if table.contains_key("bone") => Kind::Skeleton,
            None => Kind::Neither,
        },
        Err(_) if text.contains("[[bone]]") && !text.contains("[[body]]") => Kind::Skeleton,
        Err(_) => Kind::Ragdoll,
    }
}

/// A generator's `[[body]]` table: a `bone`, no `name`.
fn generator_body(body: &toml::Value) -> bool {
    body.as_table()
        .is_some_and(|t| t.contains_key("bone") && !t.contains_key("name"))
}

/// `x` with at most `digits` decimals, trailing zeros dropped.
fn number(x: f32, digits: usize) -> String {
    let s = format!("{x:.digits$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" {
        "0".to_owned()
    } else {
        s.to_owned()
    }
}

/// An angle (rad) in degrees.
fn deg(radians: f32) -> String {
    number(radians.to_degrees(), 2)
}

fn range(name: &str, [lo, hi]: [f32; 2]) -> String {
    format!("{name} {} .. {} deg", deg(lo), deg(hi))
}

fn strength(s: Spring) -> String {
    match s {
        _ if s == Spring::RIGID => "infinite".to_owned(),
        Spring::Compliance {
            compliance,
            damping: 0.0,
        } => format!("compliance {compliance} rad/(N m)"),
        Spring::Compliance {
            compliance,
            damping,
        } => format!("compliance {compliance} rad/(N m), damping {damping} N m s/rad"),
        Spring::Frequency {
            frequency,
            damping_ratio,
        } => format!(
            "spring {} Hz, damping ratio {}",
            number(frequency, 3),
            number(damping_ratio, 3)
        ),
    }
}

fn softness(s: LimitSoftness) -> Option<String> {
    match s {
        LimitSoftness::Hard => None,
        LimitSoftness::Soft(Spring::Compliance {
            compliance,
            damping,
        }) => Some(format!(
            "soft: compliance {compliance} rad/(N m), damping {damping} N m s/rad"
        )),
        LimitSoftness::Soft(Spring::Frequency {
            frequency,
            damping_ratio,
        }) => Some(format!(
            "soft: {} Hz, damping ratio {}",
            number(frequency, 3),
            number(damping_ratio, 3)
        )),
    }
}

/// A joint's kind and limits, in degrees.
fn limits(kind: &JointKind) -> (&'static str, Vec<String>) {
    match kind {
        JointKind::Socket(st) => {
            let mut parts = Vec::new();
            match st.swing {
                Swing::Free => parts.push("swing free".to_owned()),
                Swing::Cone(x) => parts.push(format!("swing {} deg", deg(x))),
                Swing::Ellipse { y, z } => {
                    parts.push(format!("swing ellipse y {} z {} deg", deg(y), deg(z)))
                }
                Swing::Pyramid { y, z } => parts.push(format!(
                    "swing pyramid y {} .. {} z {} .. {} deg",
                    deg(y[0]),
                    deg(y[1]),
                    deg(z[0]),
                    deg(z[1])
                )),
            }
            parts.push(
                st.twist
                    .map_or("twist free".to_owned(), |t| range("twist", t)),
            );
            parts.extend(softness(st.softness));
            ("socket", parts)
        }
        JointKind::Hinge {
            range: r,
            softness: s,
        } => {
            let mut parts = vec![r.map_or("range free".to_owned(), |r| range("range", r))];
            parts.extend(softness(*s));
            ("hinge", parts)
        }
        JointKind::Fixed => ("fixed", Vec::new()),
    }
}

fn ragdoll(path: &Path, desc: &RagdollDesc) -> String {
    let mut out = String::new();
    let bones = desc.skeleton.as_ref().map(|s| s.bones());
    let _ = writeln!(
        out,
        "{}: ragdoll `{}`: {} bodies, {} joints, {} kg",
        path.display(),
        desc.name,
        desc.bodies.len(),
        desc.joints.len(),
        number(desc.total_mass(), 3)
    );
    let width = desc.bodies.iter().map(|b| b.name.len()).max().unwrap_or(0);
    let _ = writeln!(out, "bodies:");
    for b in &desc.bodies {
        // Each body's bone, when there is a skeleton to have one in.
        let bone = match (b.bone, bones) {
            (Some(binding), Some(bones)) => format!("  bone {}", bones[binding.bone].name),
            (None, Some(_)) => "  no bone".to_owned(),
            (_, None) => String::new(),
        };
        let _ = writeln!(
            out,
            "  {:width$}  {:>8} kg  radius {} m{bone}",
            b.name,
            number(b.mass, 3),
            number(b.radius, 3)
        );
    }
    let _ = writeln!(out, "joints:");
    let jwidth = desc.joints.iter().map(|j| j.name.len()).max().unwrap_or(0);
    for j in &desc.joints {
        let (kind, mut parts) = limits(&j.kind);
        if let Some(s) = j.drive {
            parts.push(format!("drive {}", strength(s)));
        }
        let _ = writeln!(
            out,
            "  {:jwidth$}  {kind:6}  {} -> {}  {}",
            j.name,
            desc.bodies[j.parent].name,
            desc.bodies[j.child].name,
            parts.join(", ")
        );
    }
    match &desc.spine {
        Some(s) => {
            let names: Vec<&str> = s
                .bodies
                .iter()
                .map(|&b| desc.bodies[b].name.as_str())
                .collect();
            let _ = writeln!(
                out,
                "spine: {} (one rod in the simplified ragdoll): bend {} deg, {}, stiffness {} / {} N m^2",
                names.join(", "),
                deg(s.bend_limit),
                range("twist", s.twist_limit),
                number(s.bend_stiffness, 3),
                number(s.twist_stiffness, 3)
            );
        }
        None => {
            let _ = writeln!(out, "spine: none");
        }
    }
    match &desc.drive {
        Some(d) => {
            let mut parts = vec![strength(d.strength)];
            if d.max_torque.is_finite() {
                parts.push(format!("max torque {} N m", number(d.max_torque, 3)));
            }
            let _ = writeln!(out, "drive: {}", parts.join(", "));
        }
        None => {
            let _ = writeln!(out, "drive: none");
        }
    }
    let profiles: Vec<String> = desc.profiles.iter().map(profile).collect();
    match profiles.is_empty() {
        true => {
            let _ = writeln!(out, "profiles: none");
        }
        false => {
            let _ = writeln!(out, "profiles:");
            for p in profiles {
                let _ = writeln!(out, "  {p}");
            }
        }
    }
    match &desc.skeleton {
        Some(s) => {
            let bound = desc.bodies.iter().filter(|b| b.bone.is_some()).count();
            let _ = writeln!(
                out,
                "skeleton: {} bones, {bound} followed by a body",
                s.len()
            );
        }
        None => {
            let _ = writeln!(out, "skeleton: none");
        }
    }
    out
}

/// A profile in a line: how many joints it drives, how many bodies it
/// pulls in the world, how many it keeps upright.
fn profile(p: &Profile) -> String {
    let joints = p.joints.iter().filter(|j| j.strength.is_some()).count();
    let world = (p.bodies.iter())
        .filter(|b| b.linear.is_some() || b.angular.is_some())
        .count();
    let upright = p.bodies.iter().filter(|b| b.upright.is_some()).count();
    format!(
        "{}: {joints} of {} joints driven, {world} of {} bodies held in the world, {upright} upright",
        p.name,
        p.joints.len(),
        p.bodies.len()
    )
}

fn skeleton(path: &Path, s: &Skeleton) -> String {
    let mut out = String::new();
    let roots = s.bones().iter().filter(|b| b.parent.is_none()).count();
    let _ = writeln!(
        out,
        "{}: skeleton: {} bones, {roots} root{}",
        path.display(),
        s.len(),
        if roots == 1 { "" } else { "s" }
    );
    let model = s
        .bind_pose()
        .to_model(s)
        .map(|pose| pose.bones)
        .unwrap_or_default();
    let width = s.bones().iter().map(|b| b.name.len()).max().unwrap_or(0);
    let _ = writeln!(out, "bones (parent, bind position in the model frame, m):");
    for (b, t) in s.bones().iter().zip(&model) {
        let parent = b.parent.map_or("-", |p| s.bones()[p].name.as_str());
        let p = t.translation;
        let _ = writeln!(
            out,
            "  {:width$}  {parent:width$}  ({}, {}, {})",
            b.name,
            number(p.x, 4),
            number(p.y, 4),
            number(p.z, 4)
        );
    }
    out
}
