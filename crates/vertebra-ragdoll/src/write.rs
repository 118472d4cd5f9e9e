//! A description written back as a ragdoll file: reading it gives the
//! same description, bit for bit. Numbers are written in Rust's shortest
//! form that reads back to the same `f32`; angles as the degrees whose
//! conversion gives the same radians; a joint frame as the shortest axis
//! (and normal) that rebuilds it exactly, or else as the quaternion itself.

use glam::{Quat, Vec3};
use vertebra_world::{JointKind, LimitSoftness, Spring, Swing};

use crate::drive::DriveSettings;
use crate::joint_def::{JointDef, frame, kind_name};
use crate::model::{BodyDef, RagdollDesc};
use crate::profile::Profile;
use crate::skeleton::{Skeleton, Transform};
use crate::skeleton_file::write_bones;
use crate::text::{float, floats, same_bits, string};

impl RagdollDesc {
    /// The description as a ragdoll file (`docs/ragdolls.md`): the bodies
    /// with their final masses (no `total_mass`), each bound body's bone
    /// by name (and its offset where the bind poses do not give it), the
    /// joints, `[spine]`, `[drive]`, and the skeleton as `[[bone]]`
    /// tables. [`RagdollDesc::from_toml`] of it gives this description
    /// back, bit for bit, for any description a file or a builder made.
    pub fn to_toml(&self) -> String {
        let mut out = format!("name = {}\n\n", string(&self.name));
        let model = self
            .skeleton
            .as_ref()
            .and_then(|s| s.bind_pose().to_model(s).ok());
        for b in &self.bodies {
            write_body(
                &mut out,
                b,
                self.skeleton.as_ref(),
                model.as_ref().map(|m| &m.bones[..]),
            );
        }
        let body = |i: usize| {
            self.bodies
                .get(i)
                .map_or(format!("body {i}"), |b| b.name.clone())
        };
        // A joint's own compliance without a damping of its own reads
        // back with the `[drive]` table's.
        let damping = match self.drive.as_ref().map(|d| d.strength) {
            Some(Spring::Compliance { damping, .. }) => damping,
            _ => 0.0,
        };
        for j in &self.joints {
            write_joint(&mut out, j, [&body(j.parent), &body(j.child)], damping);
        }
        if let Some(s) = &self.spine {
            let names: Vec<String> = s.bodies.iter().map(|&i| string(&body(i))).collect();
            out.push_str("[spine]\n");
            out.push_str(&format!("bodies = [{}]\n", names.join(", ")));
            out.push_str(&format!("bend_limit = {}\n", float(degrees(s.bend_limit))));
            out.push_str(&format!(
                "twist_limit = {}\n",
                floats(&s.twist_limit.map(degrees))
            ));
            out.push_str(&format!("bend_stiffness = {}\n", float(s.bend_stiffness)));
            out.push_str(&format!(
                "twist_stiffness = {}\n\n",
                float(s.twist_stiffness)
            ));
        }
        if let Some(d) = &self.drive {
            write_drive(&mut out, d);
        }
        for p in &self.profiles {
            write_profile(&mut out, p, self);
        }
        if let Some(skeleton) = &self.skeleton {
            write_bones(skeleton, &mut out);
        }
        out
    }
}

fn write_body(
    out: &mut String,
    b: &BodyDef,
    skeleton: Option<&Skeleton>,
    model: Option<&[Transform]>,
) {
    out.push_str("[[body]]\n");
    out.push_str(&format!("name = {}\n", string(&b.name)));
    let [p, q] = b.segment;
    out.push_str(&format!(
        "segment = [{}, {}]\n",
        floats(&p.to_array()),
        floats(&q.to_array())
    ));
    out.push_str(&format!("radius = {}\n", float(b.radius)));
    out.push_str(&format!("mass = {}\n", float(b.mass)));
    if let Some(binding) = b.bone {
        let name = skeleton
            .and_then(|s| s.bones().get(binding.bone))
            .map_or(format!("bone {}", binding.bone), |bone| bone.name.clone());
        out.push_str(&format!("bone = {}\n", string(&name)));
        let derived = model
            .and_then(|m| m.get(binding.bone))
            .map(|&bone| bone.inverse() * b.bind_frame());
        if !derived.is_some_and(|d| same_transform(d, binding.offset)) {
            let t = binding.offset.translation.to_array();
            let r = binding.offset.rotation.to_array();
            out.push_str(&format!(
                "offset = {{ translation = {}, rotation = {} }}\n",
                floats(&t),
                floats(&r)
            ));
        }
    }
    out.push('\n');
}

fn same_transform(a: Transform, b: Transform) -> bool {
    same_bits(&a.translation.to_array(), &b.translation.to_array())
        && same_bits(&a.rotation.to_array(), &b.rotation.to_array())
}

/// A `[[joint]]` table between `parent` and `child`; its drive's damping
/// is written unless it is `damping` (the `[drive]` table's).
fn write_joint(out: &mut String, j: &JointDef, [parent, child]: [&str; 2], damping: f32) {
    out.push_str("[[joint]]\n");
    out.push_str(&format!("name = {}\n", string(&j.name)));
    out.push_str(&format!("parent = {}\n", string(parent)));
    out.push_str(&format!("child = {}\n", string(child)));
    out.push_str(&format!("anchor = {}\n", floats(&j.anchor.to_array())));
    if !matches!(j.kind, JointKind::Socket(_)) {
        out.push_str(&format!("kind = \"{}\"\n", kind_name(&j.kind)));
    }
    match written_frame(j) {
        Written::Nothing => {}
        Written::Axis(axis, normal) => {
            out.push_str(&format!("axis = {}\n", floats(&axis.to_array())));
            if let Some(n) = normal {
                out.push_str(&format!("normal = {}\n", floats(&n.to_array())));
            }
        }
        Written::Rotation(q) => out.push_str(&format!("frame = {}\n", floats(&q.to_array()))),
    }
    let softness = match j.kind {
        JointKind::Socket(limits) => {
            match limits.swing {
                Swing::Free => {}
                Swing::Cone(x) => out.push_str(&format!("swing = {}\n", float(degrees(x)))),
                Swing::Ellipse { y, z } => out.push_str(&format!(
                    "swing = {{ y = {}, z = {} }}\n",
                    float(degrees(y)),
                    float(degrees(z))
                )),
                Swing::Pyramid { y, z } => out.push_str(&format!(
                    "swing = {{ y = {}, z = {} }}\n",
                    floats(&y.map(degrees)),
                    floats(&z.map(degrees))
                )),
            }
            if let Some(t) = limits.twist {
                out.push_str(&format!("twist = {}\n", floats(&t.map(degrees))));
            }
            limits.softness
        }
        JointKind::Hinge { range, softness } => {
            if let Some(r) = range {
                out.push_str(&format!("range = {}\n", floats(&r.map(degrees))));
            }
            softness
        }
        JointKind::Fixed => LimitSoftness::Hard,
    };
    match softness {
        LimitSoftness::Hard => {}
        LimitSoftness::Soft(Spring::Compliance {
            compliance,
            damping,
        }) if same_bits(&[damping], &[0.0]) => {
            out.push_str(&format!("softness = {}\n", float(compliance)));
        }
        LimitSoftness::Soft(spring) => out.push_str(&format!(
            "softness = {{ {} }}\n",
            spring_fields(spring, 0.0).join(", ")
        )),
    }
    if let Some(s) = j.drive {
        out.push_str(&format!(
            "drive = {{ {} }}\n",
            strength(s, damping).join(", ")
        ));
    }
    if let Some(b) = j.breaking {
        // An infinite threshold is the one not written.
        for (key, value) in [("break_force", b.force), ("break_torque", b.torque)] {
            if value.is_finite() {
                out.push_str(&format!("{key} = {}\n", float(value)));
            }
        }
    }
    out.push('\n');
}

/// A drive strength's fields as `key = value` pairs: `strength =
/// "infinite"` for [`Spring::RIGID`], else the spring's (its damping only
/// when it is not `damping`, the one it reads back with).
fn strength(s: Spring, damping: f32) -> Vec<String> {
    match s {
        Spring::Compliance {
            compliance,
            damping: own,
        } if same_bits(&[compliance, own], &[0.0, 0.0]) => {
            vec!["strength = \"infinite\"".to_owned()]
        }
        _ => spring_fields(s, damping),
    }
}

/// A spring's fields as `key = value` pairs, its damping only when it
/// is not `damping` (the one it takes without).
fn spring_fields(s: Spring, damping: f32) -> Vec<String> {
    match s {
        Spring::Compliance {
            compliance,
            damping: own,
        } => {
            let mut fields = vec![format!("compliance = {}", float(compliance))];
            if !same_bits(&[own], &[damping]) {
                fields.push(format!("damping = {}", float(own)));
            }
            fields
        }
        Spring::Frequency {
            frequency,
            damping_ratio,
        } => vec![
            format!("frequency = {}", float(frequency)),
            format!("damping_ratio = {}", float(damping_ratio)),
        ],
    }
}

fn write_drive(out: &mut String, d: &DriveSettings) {
    out.push_str("[drive]\n");
    for field in strength(d.strength, 0.0) {
        out.push_str(&field);
        out.push('\n');
    }
    if d.max_torque != f32::INFINITY {
        out.push_str(&format!("max_torque = {}\n", float(d.max_torque)));
    }
    out.push('\n');
}

/// A `[[profile]]` table: its uprights, then a `[[profile.bone]]` table for
/// every body whose joint above it or whose world drive has a setting, so
/// that each entry reads back exactly (a profile has no shared base).
fn write_profile(out: &mut String, p: &Profile, desc: &RagdollDesc) {
    out.push_str(&format!("[[profile]]\nname = {}\n", string(&p.name)));
    let uprights: Vec<String> = (desc.bodies.iter().zip(&p.bodies))
        .filter_map(|(b, s)| {
            let u = s.upright?;
            let mut fields = vec![format!("body = {}", string(&b.name))];
            fields.extend(strength(u.strength, 0.0));
            fields.extend(cap("max_torque", u.max_torque));
            Some(format!("    {{ {} }},\n", fields.join(", ")))
        })
        .collect();
    if !uprights.is_empty() {
        out.push_str(&format!("upright = [\n{}]\n", uprights.concat()));
    }
    out.push('\n');
    for (b, (body, s)) in desc.bodies.iter().zip(&p.bodies).enumerate() {
        let joint = desc.parent_joint[b].map(|k| p.joints[k]);
        let joints: Vec<String> = joint.map_or(Vec::new(), |j| {
            let mut fields = j.strength.map_or(Vec::new(), |s| strength(s, 0.0));
            fields.extend(cap("max_torque", j.max_torque));
            fields
        });
        let mut world: Vec<String> = Vec::new();
        for (name, part) in [("linear", s.linear), ("angular", s.angular)] {
            if let Some(part) = part {
                world.push(format!("{name} = {{ {} }}", strength(part, 0.0).join(", ")));
            }
        }
        world.extend(cap("max_acceleration", s.max_acceleration));
        world.extend(cap("max_torque", s.max_torque));
        if joints.is_empty() && world.is_empty() {
            continue;
        }
        out.push_str(&format!(
            "[[profile.bone]]\nbody = {}\n",
            string(&body.name)
        ));
        if !joints.is_empty() {
            out.push_str(&format!("joints = {{ {} }}\n", joints.join(", ")));
        }
        if !world.is_empty() {
            out.push_str(&format!("world = {{ {} }}\n", world.join(", ")));
        }
        out.push('\n');
    }
}

/// `name = cap`, unless the cap is unlimited (no field).
fn cap(name: &str, cap: f32) -> Option<String> {
    (cap != f32::INFINITY).then(|| format!("{name} = {}", float(cap)))
}

/// How a joint's frame is written.
enum Written {
    /// A fixed joint's identity frame: nothing.
    Nothing,
    /// `axis` (and `normal`).
    Axis(Vec3, Option<Vec3>),
    /// `frame = [x, y, z, w]`.
    Rotation(Quat),
}

/// The shortest axis (and, for a socket, normal) whose frame is the
/// joint's to the bit, trying the frame's axes rounded to 1 to 9 decimals
/// and then unrounded; the quaternion itself if none is.
fn written_frame(j: &JointDef) -> Written {
    let exact = |q: Quat| same_bits(&q.to_array(), &j.frame.to_array());
    // Whether the frame may be written without a normal, and with one.
    let (without_normal, with_normal) = match j.kind {
        JointKind::Fixed if exact(Quat::IDENTITY) => return Written::Nothing,
        JointKind::Fixed => return Written::Rotation(j.frame),
        JointKind::Socket(limits) => (
            !matches!(limits.swing, Swing::Ellipse { .. } | Swing::Pyramid { .. }),
            true,
        ),
        JointKind::Hinge { .. } => (true, false),
    };
    let builds = |axis: Vec3, normal: Option<Vec3>| {
        frame("", "", axis.to_array(), normal.map(|n| n.to_array())).is_ok_and(exact)
    };
    let (x, y) = (j.frame * Vec3::X, j.frame * Vec3::Y);
    for digits in (1..=9).map(Some).chain([None]) {
        let axis = rounded(x, digits);
        if without_normal && builds(axis, None) {
            return Written::Axis(axis, None);
        }
        let normal = rounded(y, digits);
        if with_normal && builds(axis, Some(normal)) {
            return Written::Axis(axis, Some(normal));
        }
    }
    Written::Rotation(j.frame)
}

/// `v` rounded to `digits` decimals (`None`: as it is), as a file reads
/// the rounded numbers back.
fn rounded(v: Vec3, digits: Option<usize>) -> Vec3 {
    let Some(digits) = digits else { return v };
    Vec3::from(v.to_array().map(|c| {
        format!("{c:.digits$}")
            .parse::<f64>()
            .map_or(c, |x| x as f32)
    }))
}

/// The shortest degrees whose conversion to radians (as the loader
/// converts) gives `radians` to the bit: among `radians` in degrees
/// rounded to 0 to 6 decimals and its neighbours up to 4 ulps away; the
/// plain conversion when none is (an angle set in radians by hand may fall
/// between two conversions).
fn degrees(radians: f32) -> f32 {
    let d = radians.to_degrees();
    let rounded = (0..=6).filter_map(|digits| {
        format!("{d:.digits$}")
            .parse::<f64>()
            .ok()
            .map(|x| x as f32)
    });
    let mut neighbours = Vec::with_capacity(9);
    let (mut up, mut down) = (d, d);
    for _ in 0..=4 {
        neighbours.extend([up, down]);
        (up, down) = (up.next_up(), down.next_down());
    }
    rounded
        .chain(neighbours)
        .filter(|c| c.to_radians().to_bits() == radians.to_bits())
        .min_by(|a, b| {
            let key = |c: &f32| (float(*c).len(), (c - d).abs());
            key(a)
                .partial_cmp(&key(b))
                .unwrap_or(core::cmp::Ordering::Equal)
        })
        .unwrap_or(d)
}
