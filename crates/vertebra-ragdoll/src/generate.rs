//! A ragdoll generated from an animation skeleton and per-bone choices, as
//! physics-asset tools do (Unreal's physics asset generation, Jolt's
//! ragdoll samples): which bones become bodies, each body's capsule radius
//! and mass (or density), its joint to its parent body, and whether the
//! spine may become the paper's rod. The bodies are capsules from each
//! chosen bone's origin to the next chosen bone along it, the joints sit at
//! the child bones' origins (their pivots), and the result is an ordinary
//! [`RagdollDesc`], checked as the builder checks one (`docs/ragdolls.md`,
//! "Generating a ragdoll from a skeleton").

use core::f32::consts::PI;

use glam::{Quat, Vec3};
use vertebra_world::{JointKind, LimitSoftness, SwingTwist};

use crate::error::RagdollError;
use crate::joint_def::{JointFrame, JointSpec};
use crate::model::RagdollDesc;
use crate::skeleton::{Skeleton, Transform};
use crate::spec::{BodySpec, SpineSpec};
use vertebra_math::DefaultFloatMode;

/// The shortest capsule segment a generated body may have (m): a body
/// whose end is (nearly) its bone's origin has no direction to give its
/// joint.
pub const MIN_SEGMENT: f32 = 1e-3;

/// A generated body's mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BodyMass {
    /// The mass itself (kg), or its share of the generator's total mass.
    Mass(f32),
    /// A uniform density (kg/m^3) over the capsule's volume (its cylinder
    /// and two half-spheres).
    Density(f32),
}

/// Where a generated body's capsule segment ends (it starts at its bone's
/// origin), in the skeleton's bind pose.
#[derive(Clone, Debug, PartialEq)]
pub enum SegmentEnd {
    /// At the origin of the next chosen bone along this one: the first
    /// chosen bone on its line of first children (its first child, that
    /// child's first child, ...), or else its first child's (a limb's last
    /// body reaching its hand or foot). Refused for a bone without
    /// children.
    Next,
    /// At the origin of the named bone (any other bone of the skeleton).
    Bone(String),
    /// At this point (m) in the bone's own frame.
    Point(Vec3),
    /// This far (m, positive) along the bone's +Y from its origin.
    Length(f32),
}

/// One chosen bone: the body it becomes and the joint to its parent body
/// (the body of its nearest chosen ancestor). The body and the joint are
/// both named after the bone, and the body follows it.
#[derive(Clone, Debug, PartialEq)]
pub struct BoneBody {
    /// The bone's name.
    pub bone: String,
    /// The capsule's radius (m, positive).
    pub radius: f32,
    /// The body's mass or density (positive).
    pub mass: BodyMass,
    /// Where the capsule's segment ends.
    pub end: SegmentEnd,
    /// The joint's kind and limits (rad), as the world takes them;
    /// unused for the root body, which has no parent. A free socket
    /// unless set.
    pub joint: JointKind,
    /// The joint frame's +X (a socket's twist axis, a hinge's rotation
    /// axis) in the bone's frame; by default a socket's is along its
    /// capsule (from the bone's origin to the segment's end), a hinge's
    /// the bone's +X.
    pub axis: Option<Vec3>,
    /// The joint frame's +Y in the bone's frame (sockets only; an
    /// elliptical or pyramid swing needs it): perpendicular to the axis.
    pub normal: Option<Vec3>,
}

impl BoneBody {
    /// Bone `bone` as a capsule of `radius` (m) and `mass`, ending at the
    /// next chosen bone along it ([`SegmentEnd::Next`]), joined to its
    /// parent body by a free socket.
    pub fn new(bone: &str, radius: f32, mass: BodyMass) -> Self {
        Self {
            bone: bone.to_owned(),
            radius,
            mass,
            end: SegmentEnd::Next,
            joint: JointKind::Socket(SwingTwist::FREE),
            axis: None,
            normal: None,
        }
    }

    /// Its capsule ending at bone `bone`'s origin.
    pub fn ending_at(mut self, bone: &str) -> Self {
        self.end = SegmentEnd::Bone(bone.to_owned());
        self
    }

    /// Its capsule `length` (m) long along the bone's +Y (the reference
    /// skeleton's convention: +Y along the bone): for a leaf, such as the
    /// head. A skeleton with another convention gives the end as a point
    /// ([`SegmentEnd::Point`]).
    pub fn with_length(mut self, length: f32) -> Self {
        self.end = SegmentEnd::Length(length);
        self
    }

    /// Joined to its parent by a socket of `limits` (rad): swing about,
    /// and twist around, the axis along its capsule (or [`Self::axis`]).
    pub fn socket(mut self, limits: SwingTwist) -> Self {
        self.joint = JointKind::Socket(limits);
        self
    }

    /// Joined to its parent by a hinge about `axis` (the bone's frame)
    /// within `range` (rad; `None`: unlimited), with hard limits; a
    /// positive angle turns the child counter-clockwise about the axis.
    pub fn hinge(mut self, axis: Vec3, range: Option<[f32; 2]>) -> Self {
        self.joint = JointKind::Hinge {
            range,
            softness: LimitSoftness::Hard,
        };
        self.axis = Some(axis);
        self
    }

    /// Joined rigidly to its parent.
    pub fn fixed(mut self) -> Self {
        self.joint = JointKind::Fixed;
        self
    }

    /// With the joint frame's +Y along `normal` (the bone's frame).
    pub fn with_normal(mut self, normal: Vec3) -> Self {
        self.normal = Some(normal);
        self
    }
}

/// The chain of bodies the simplified ragdoll replaces by one rod (the
/// paper's spine), from bone `from` (the hips) to bone `to` (the chest):
/// the chosen bones on the path between them. Without one, the ragdoll is
/// a socket chain only.
#[derive(Clone, Debug, PartialEq)]
pub struct RodSpine {
    /// The chain's base bone (chosen).
    pub from: String,
    /// The chain's top bone (chosen, a descendant of `from`).
    pub to: String,
    /// The rod's largest bend (rad, 0 to pi).
    pub bend_limit: f32,
    /// The rod's twist range `[min, max]` (rad, within [-pi, pi]).
    pub twist_limit: [f32; 2],
    /// Kirchhoff bending stiffness (N m^2, not negative).
    pub bend_stiffness: f32,
    /// Kirchhoff twisting stiffness (N m^2, not negative).
    pub twist_stiffness: f32,
}

/// Generates a [`RagdollDesc`] from a skeleton: the bones chosen
/// ([`BoneBody`]), an optional rod spine ([`RodSpine`]) and an optional
/// total mass, then [`RagdollGenerator::generate`].
///
/// ```
/// use glam::Vec3;
/// use vertebra_ragdoll::{BodyMass, BoneBody, RagdollDesc, Skeleton};
/// use vertebra_world::{Swing, SwingTwist};
///
/// # fn main() -> Result<(), vertebra_ragdoll::RagdollError> {
/// let skeleton = Skeleton::reference();
/// let cone = SwingTwist::FREE.with_swing(Swing::Cone(0.5));
/// let desc = RagdollDesc::generator("leg", &skeleton)
///     .body(BoneBody::new("thigh_l", 0.07, BodyMass::Mass(7.0)))
///     .body(BoneBody::new("shin_l", 0.055, BodyMass::Density(1000.0)).hinge(Vec3::X, Some([-2.6, 0.0])))
///     .body(BoneBody::new("foot_l", 0.04, BodyMass::Mass(1.0)).ending_at("toes_l").socket(cone))
///     .total_mass(12.0)
///     .generate()?;
/// assert_eq!(desc.joints.len(), 2);
/// assert!((desc.total_mass() - 12.0).abs() < 1e-4);
/// # Ok(())
/// # }
/// ```
#[derive(Clone, Debug)]
pub struct RagdollGenerator {
    name: String,
    skeleton: Skeleton,
    bodies: Vec<BoneBody>,
    spine: Option<RodSpine>,
    total_mass: Option<f32>,
}

impl RagdollDesc {
    /// A generator of a description called `name` whose bodies follow
    /// `skeleton`'s bones (its model frame the description's world frame
    /// at bind pose).
    pub fn generator(name: &str, skeleton: &Skeleton) -> RagdollGenerator {
        RagdollGenerator {
            name: name.to_owned(),
            skeleton: skeleton.clone(),
            bodies: Vec::new(),
            spine: None,
            total_mass: None,
        }
    }
}

impl RagdollGenerator {
    /// With a chosen bone.
    pub fn body(mut self, body: BoneBody) -> Self {
        self.bodies.push(body);
        self
    }

    /// With the chain a rod replaces in the simplified ragdoll.
    pub fn spine(mut self, spine: RodSpine) -> Self {
        self.spine = Some(spine);
        self
    }

    /// With the bodies' masses scaled to `kg` in all, their ratios kept.
    pub fn total_mass(mut self, kg: f32) -> Self {
        self.total_mass = Some(kg);
        self
    }

    /// The description: one body per chosen bone, in the skeleton's bone
    /// order (the root body, the one chosen bone without a chosen
    /// ancestor, first), each a capsule from its bone's origin to its
    /// [`SegmentEnd`] at bind pose and following its bone; one joint per
    /// other body, at its bone's origin, from the body of its nearest
    /// chosen ancestor; the spine, if given; masses scaled to the total,
    /// if given. Refused, naming the bone and the reason, for an unknown
    /// bone, a bone chosen twice, a radius, mass or density not finite or
    /// not positive, an end not finite or that cannot be found, a segment
    /// shorter than [`MIN_SEGMENT`] or a length that is not positive, a
    /// joint given to the root body, a normal on a hinge or fixed joint or
    /// an axis on a fixed one, a second chosen bone without a chosen
    /// ancestor, or a spine whose ends are not chosen or not one above the
    /// other; and for whatever the builder refuses ([`RagdollDesc::builder`]:
    /// joint limits, axes and normals, sizes and masses out of the
    /// world's range), naming the body or joint (the bone's name).
    pub fn generate(self) -> Result<RagdollDesc, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let skeleton = &self.skeleton;
        let model = skeleton.bind_pose().to_model(skeleton)?.bones;
        let chosen = self.chosen()?;
        let first_child = first_children(skeleton);
        let mut builder = RagdollDesc::builder(&self.name).skeleton(skeleton.clone());
        let mut root: Option<usize> = None;
        for (bone, body) in chosen.iter().enumerate() {
            let Some(body) = body.map(|b| &self.bodies[b]) else {
                continue;
            };
            let name = &body.bone;
            let (capsule, along) = capsule(body, bone, &model, skeleton, &chosen, &first_child)?;
            builder = builder.body(capsule);
            match (ancestor(skeleton, bone, &chosen), root) {
                (Some(parent), _) => {
                    let parent = &skeleton.bones()[parent].name;
                    builder = builder.joint(joint(body, parent, model[bone], along)?);
                }
                (None, None) => {
                    no_joint(body)?;
                    root = Some(bone);
                }
                (None, Some(first)) => {
                    return Err(refused(
                        name,
                        "ancestor",
                        format!(
                            "is not chosen, and only the root body (`{}`) may have none: choose a bone above it, or leave it out",
                            skeleton.bones()[first].name
                        ),
                    ));
                }
            }
        }
        if let Some(spine) = &self.spine {
            builder = builder.spine(spine_chain(spine, skeleton, &chosen)?);
        }
        if let Some(kg) = self.total_mass {
            builder = builder.total_mass(kg);
        }
        builder.build()
    }

    /// Per bone of the skeleton, the index of the [`BoneBody`] that
    /// chooses it.
    fn chosen(&self) -> Result<Vec<Option<usize>>, RagdollError> {
        let mut chosen = vec![None; self.skeleton.len()];
        for (k, body) in self.bodies.iter().enumerate() {
            let bone = bone_index(&self.skeleton, &body.bone, "generator", "bone")?;
            if chosen[bone].replace(k).is_some() {
                return Err(refused(
                    &body.bone,
                    "bone",
                    "is chosen twice; a bone has at most one body".to_owned(),
                ));
            }
        }
        Ok(chosen)
    }
}

/// The error for bone `bone`'s `field`.
fn refused(bone: &str, field: &'static str, reason: String) -> RagdollError {
    RagdollError::OutOfRange {
        context: format!("bone `{bone}`"),
        field,
        reason,
    }
}

/// `value` if finite and positive; refused naming `bone` and `field`.
fn positive(bone: &str, field: &'static str, value: f32) -> Result<f32, RagdollError> {
    check_positive(bone, field, value).map(|()| value)
}

fn check_positive(bone: &str, field: &'static str, value: f32) -> Result<(), RagdollError> {
    if !value.is_finite() {
        return Err(RagdollError::NonFinite {
            context: format!("bone `{bone}`"),
            field,
        });
    }
    if value <= 0.0 {
        return Err(refused(
            bone,
            field,
            format!("is {value}; must be positive"),
        ));
    }
    Ok(())
}

/// The index of bone `name`; refused as an unknown bone of `context`'s
/// `field`.
fn bone_index(
    skeleton: &Skeleton,
    name: &str,
    context: &str,
    field: &'static str,
) -> Result<usize, RagdollError> {
    skeleton
        .bone_index(name)
        .ok_or_else(|| RagdollError::UnknownBone {
            context: context.to_owned(),
            field,
            name: name.to_owned(),
        })
}

/// Per bone, its first child (the first bone whose parent it is).
fn first_children(skeleton: &Skeleton) -> Vec<Option<usize>> {
    let mut first = vec![None; skeleton.len()];
    for (i, bone) in skeleton.bones().iter().enumerate() {
        if let Some(p) = bone.parent {
            first[p].get_or_insert(i);
        }
    }
    first
}

/// The nearest chosen ancestor of `bone`.
fn ancestor(skeleton: &Skeleton, bone: usize, chosen: &[Option<usize>]) -> Option<usize> {
    let mut at = skeleton.bones()[bone].parent;
    while let Some(a) = at {
        if chosen[a].is_some() {
            return Some(a);
        }
        at = skeleton.bones()[a].parent;
    }
    None
}

/// Where `body`'s segment ends (m, model frame at bind pose).
fn segment_end(
    body: &BoneBody,
    bone: usize,
    model: &[Transform],
    skeleton: &Skeleton,
    chosen: &[Option<usize>],
    first_child: &[Option<usize>],
) -> Result<Vec3, RagdollError> {
    match &body.end {
        SegmentEnd::Next => {
            let mut line = core::iter::successors(first_child[bone], |&b| first_child[b]);
            let next = line.find(|&b| chosen[b].is_some()).or(first_child[bone]);
            next.map(|b| model[b].translation).ok_or_else(|| {
                refused(
                    &body.bone,
                    "end",
                    "is the next bone along it, but it has no child; give its end (a bone, or a length)".to_owned(),
                )
            })
        }
        SegmentEnd::Bone(name) => {
            let context = format!("bone `{}`", body.bone);
            let end = bone_index(skeleton, name, &context, "end")?;
            Ok(model[end].translation)
        }
        SegmentEnd::Point(p) => {
            if !p.is_finite() {
                return Err(RagdollError::NonFinite {
                    context: format!("bone `{}`", body.bone),
                    field: "end",
                });
            }
            Ok(model[bone].transform_point(*p))
        }
        SegmentEnd::Length(length) => {
            let length = positive(&body.bone, "length", *length)?;
            Ok(model[bone].transform_point(Vec3::Y * length))
        }
    }
}

/// `body`'s capsule on bone `bone` (`model`: the bind pose in model
/// space), checked, and its segment from start to end (m).
fn capsule(
    body: &BoneBody,
    bone: usize,
    model: &[Transform],
    skeleton: &Skeleton,
    chosen: &[Option<usize>],
    first_child: &[Option<usize>],
) -> Result<(BodySpec, Vec3), RagdollError> {
    let name = &body.bone;
    check_positive(name, "radius", body.radius)?;
    let end = segment_end(body, bone, model, skeleton, chosen, first_child)?;
    let start = model[bone].translation;
    let length = start.distance(end);
    if length < MIN_SEGMENT {
        return Err(refused(
            name,
            "end",
            format!(
                "is {length} m from the bone's origin; a segment is at least {MIN_SEGMENT} m long"
            ),
        ));
    }
    let mass = match body.mass {
        BodyMass::Mass(kg) => positive(name, "mass", kg)?,
        BodyMass::Density(d) => positive(name, "density", d)? * volume(body.radius, length),
    };
    let spec = BodySpec::capsule(name, [start, end], body.radius, mass);
    Ok((spec, end - start))
}

/// The volume (m^3) of a capsule of `radius` around a segment `length`
/// long (m).
fn volume(radius: f32, length: f32) -> f32 {
    PI * radius * radius * (length + 4.0 / 3.0 * radius)
}

/// `body`'s joint to its parent body `parent`: at its bone's origin
/// (`placed`, the bone's bind model transform), its frame from the bone's
/// axes, or for a socket without an axis along `along` (the segment).
fn joint(
    body: &BoneBody,
    parent: &str,
    placed: Transform,
    along: Vec3,
) -> Result<JointSpec, RagdollError> {
    let unused = |field: &'static str, given: bool, kinds: &str| {
        if given {
            Err(refused(&body.bone, field, format!("is for {kinds} only")))
        } else {
            Ok(())
        }
    };
    match body.joint {
        JointKind::Fixed => {
            unused("axis", body.axis.is_some(), "sockets and hinges")?;
            unused("normal", body.normal.is_some(), "sockets")?;
        }
        JointKind::Hinge { .. } => unused("normal", body.normal.is_some(), "sockets")?,
        JointKind::Socket(_) => {}
    }
    let rotate = |v: Vec3| placed.rotation * v;
    let frame = match body.joint {
        JointKind::Fixed => JointFrame::Rotation(Quat::IDENTITY),
        JointKind::Hinge { .. } => JointFrame::Axis {
            axis: rotate(body.axis.unwrap_or(Vec3::X)),
            normal: None,
        },
        JointKind::Socket(_) => JointFrame::Axis {
            axis: body.axis.map_or(along, rotate),
            normal: body.normal.map(rotate),
        },
    };
    Ok(JointSpec {
        name: body.bone.clone(),
        parent: parent.to_owned(),
        child: body.bone.clone(),
        anchor: placed.translation,
        frame,
        kind: body.joint,
        drive: None,
        breaking: None,
    })
}

/// Refuses a joint given to the root body, which has no parent to join:
/// it would be dropped unchecked.
fn no_joint(body: &BoneBody) -> Result<(), RagdollError> {
    let free = body.joint == JointKind::Socket(SwingTwist::FREE);
    if free && body.axis.is_none() && body.normal.is_none() {
        return Ok(());
    }
    Err(refused(
        &body.bone,
        "joint",
        "is given, but the root body has no parent body to join".to_owned(),
    ))
}

/// The spine as the chosen bones from `spine.to` up to `spine.from`, base
/// first.
fn spine_chain(
    spine: &RodSpine,
    skeleton: &Skeleton,
    chosen: &[Option<usize>],
) -> Result<SpineSpec, RagdollError> {
    let end = |name: &str, field| -> Result<usize, RagdollError> {
        let bone = bone_index(skeleton, name, "spine", field)?;
        if chosen[bone].is_none() {
            return Err(refused(
                name,
                field,
                "is a spine end, but not a chosen bone".to_owned(),
            ));
        }
        Ok(bone)
    };
    let (base, top) = (end(&spine.from, "from")?, end(&spine.to, "to")?);
    let mut bodies = vec![top];
    while let Some(&last) = bodies.last().filter(|&&b| b != base) {
        let next = ancestor(skeleton, last, chosen).ok_or_else(|| {
            refused(
                &spine.to,
                "to",
                format!(
                    "is not below `{}`; a spine runs from a bone to one of its descendants",
                    spine.from
                ),
            )
        })?;
        bodies.push(next);
    }
    if bodies.len() < 2 {
        return Err(refused(
            &spine.to,
            "to",
            "is the spine's from bone; a spine joins two".to_owned(),
        ));
    }
    bodies.reverse();
    Ok(SpineSpec {
        bodies: bodies
            .into_iter()
            .map(|b| skeleton.bones()[b].name.clone())
            .collect(),
        bend_limit: spine.bend_limit,
        twist_limit: spine.twist_limit,
        bend_stiffness: spine.bend_stiffness,
        twist_stiffness: spine.twist_stiffness,
    })
}
