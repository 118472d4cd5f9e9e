//! The animation skeleton in an engine's terms: bones with parents and
//! names, a bind pose of parent-local transforms, and poses in local and in
//! model space (as Jolt's `Skeleton` and `SkeletonPose`, ozz's local and
//! model-space transforms).
//!
//! Conventions (`docs/ragdolls.md`, "Skeletons"): right-handed, +Y up,
//! metres. A bone's local transform maps points from the bone's frame into
//! its parent's; its model transform maps them into the model frame (the
//! skeleton root's parent: the character's frame, which the engine places
//! in the world). Parents come before their children, so one pass from the
//! first bone converts a local pose to model space.

use core::ops::Mul;
use vertebra_math::PortableQuat;

use glam::{Quat, Vec3};
use vertebra_store::check_unit_quat;
use vertebra_world::MAX_COORDINATE;

use crate::error::RagdollError;
use vertebra_math::DefaultFloatMode;

/// The most bones a skeleton may have.
pub const MAX_BONES: usize = 4096;

/// A rigid transform: a rotation, then a translation (no scale).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Transform {
    /// Translation (m).
    pub translation: Vec3,
    /// Rotation (unit quaternion).
    pub rotation: Quat,
}

impl Transform {
    /// No rotation, no translation.
    pub const IDENTITY: Self = Self {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
    };

    /// A transform of `translation` (m) and `rotation`.
    pub fn new(translation: Vec3, rotation: Quat) -> Self {
        let _mode = DefaultFloatMode::enter();
        Self {
            translation,
            rotation,
        }
    }

    /// The transform that undoes this one.
    pub fn inverse(self) -> Self {
        let rotation = self.rotation.conjugate();
        Self {
            translation: rotation * -self.translation,
            rotation,
        }
    }

    /// `point` (m) mapped by this transform.
    pub fn transform_point(self, point: Vec3) -> Vec3 {
        self.translation + self.rotation * point
    }

    /// `vector` rotated by this transform (no translation).
    pub fn transform_vector(self, vector: Vec3) -> Vec3 {
        self.rotation * vector
    }

    /// Checks that the translation is finite and within
    /// [`MAX_COORDINATE`] and the rotation a unit quaternion (within 1e-3);
    /// the error names `context` and the field.
    pub fn validate(self, context: &str) -> Result<(), RagdollError> {
        self.validate_in(|| context.to_owned())
    }

    /// [`Self::validate`], naming the item only when refusing: a valid
    /// transform costs no allocation (poses check every bone every call).
    fn validate_in(self, context: impl Fn() -> String) -> Result<(), RagdollError> {
        let t = self.translation;
        if !t.is_finite() {
            return Err(RagdollError::NonFinite {
                context: context(),
                field: "translation",
            });
        }
        if t.abs().max_element() > MAX_COORDINATE {
            return Err(RagdollError::OutOfRange {
                context: context(),
                field: "translation",
                reason: format!("is {t}; each coordinate must be within {MAX_COORDINATE} m"),
            });
        }
        check_unit_quat("rotation", self.rotation).map_err(|e| match e {
            vertebra_world::Error::NonFinite(field) => RagdollError::NonFinite {
                context: context(),
                field,
            },
            _ => RagdollError::OutOfRange {
                context: context(),
                field: "rotation",
                reason: format!(
                    "has length {}; must be a unit quaternion (within 1e-3)",
                    self.rotation.length_portable()
                ),
            },
        })
    }
}

/// `a * b` applies `b`, then `a`: a child's model transform is its
/// parent's model transform times its local one.
impl Mul for Transform {
    type Output = Transform;
    fn mul(self, b: Transform) -> Transform {
        Transform {
            translation: self.transform_point(b.translation),
            rotation: self.rotation.mul_portable(b.rotation).normalize_portable(),
        }
    }
}

/// One bone of a [`Skeleton`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bone {
    /// Unique, non-empty name.
    pub name: String,
    /// The parent bone's index (before this bone's), or `None` for a root.
    pub parent: Option<usize>,
    /// The bind pose: this bone's transform relative to its parent (or to
    /// the model frame, for a root).
    pub bind: Transform,
}

/// A validated skeleton: at most [`MAX_BONES`] bones, names unique and
/// non-empty, every parent before its child, bind transforms finite with
/// unit rotations.
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    bones: Vec<Bone>,
}

impl Skeleton {
    /// A skeleton of `bones`, checked; the error names the bone and field.
    pub fn new(bones: Vec<Bone>) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        if bones.is_empty() || bones.len() > MAX_BONES {
            return Err(RagdollError::OutOfRange {
                context: "skeleton".to_owned(),
                field: "bones",
                reason: format!("has {}; must have 1 to {MAX_BONES}", bones.len()),
            });
        }
        for (i, bone) in bones.iter().enumerate() {
            let context = bone_context(i, &bone.name);
            let out_of_range = |field, reason: String| RagdollError::OutOfRange {
                context: context.clone(),
                field,
                reason,
            };
            if bone.name.is_empty() {
                return Err(out_of_range("name", "is empty".to_owned()));
            }
            if let Some(first) = bones[..i].iter().position(|b| b.name == bone.name) {
                return Err(out_of_range("name", format!("is bone {first}'s too")));
            }
            if let Some(parent) = bone.parent.filter(|&p| p >= i) {
                return Err(out_of_range(
                    "parent",
                    format!("is {parent}; must be a bone before this one (below {i})"),
                ));
            }
            bone.bind.validate(&context)?;
        }
        Ok(Self { bones })
    }

    /// The bones, parents first.
    pub fn bones(&self) -> &[Bone] {
        &self.bones
    }

    /// How many bones.
    pub fn len(&self) -> usize {
        self.bones.len()
    }

    /// Never: a skeleton has at least one bone.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The index of the bone called `name`.
    pub fn bone_index(&self, name: &str) -> Option<usize> {
        self.bones.iter().position(|b| b.name == name)
    }

    /// The bind pose, parent-local.
    pub fn bind_pose(&self) -> LocalPose {
        let _mode = DefaultFloatMode::enter();
        LocalPose {
            bones: self.bones.iter().map(|b| b.bind).collect(),
        }
    }

    /// Checks that `transforms` has one transform per bone, each finite
    /// with a unit rotation; the error names `what` (if not empty) and the
    /// bone. Nothing is formatted unless refused.
    pub(crate) fn check(&self, what: &str, transforms: &[Transform]) -> Result<(), RagdollError> {
        let named = |item: String| match what {
            "" => item,
            _ => format!("{what}: {item}"),
        };
        if transforms.len() != self.bones.len() {
            return Err(RagdollError::BadPose(named(format!(
                "{} transforms for {} bones",
                transforms.len(),
                self.bones.len()
            ))));
        }
        for (i, (t, bone)) in transforms.iter().zip(&self.bones).enumerate() {
            t.validate_in(|| named(bone_context(i, &bone.name)))
                .map_err(|e| RagdollError::BadPose(e.to_string()))?;
        }
        Ok(())
    }
}

fn bone_context(index: usize, name: &str) -> String {
    format!("bone {index} `{name}`")
}

/// A pose of a skeleton in local space: each bone's transform relative to
/// its parent (a root's relative to the model frame), in bone order.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalPose {
    /// Per bone, parent-local.
    pub bones: Vec<Transform>,
}

/// A pose of a skeleton in model space: each bone's transform relative to
/// the model frame, in bone order.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelPose {
    /// Per bone, in the model frame.
    pub bones: Vec<Transform>,
}

impl LocalPose {
    /// This pose in model space (parents first, one pass). Refused if it
    /// does not fit `skeleton` (count, a non-finite transform or
    /// non-unit rotation: the error names the bone).
    pub fn to_model(&self, skeleton: &Skeleton) -> Result<ModelPose, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        skeleton.check("", &self.bones)?;
        let mut model: Vec<Transform> = Vec::with_capacity(self.bones.len());
        for (local, bone) in self.bones.iter().zip(&skeleton.bones) {
            let local = unit(*local);
            let placed = match bone.parent {
                Some(p) => model[p] * local,
                None => local,
            };
            model.push(placed);
        }
        Ok(ModelPose { bones: model })
    }
}

/// `t` with its rotation normalised: a rotation accepted as unit within
/// the checks' tolerance would otherwise scale the translations it turns
/// by its squared length.
fn unit(t: Transform) -> Transform {
    Transform::new(t.translation, t.rotation.normalize_portable())
}

impl ModelPose {
    /// This pose in local space: each bone relative to its parent. Refused
    /// as [`LocalPose::to_model`] refuses.
    pub fn to_local(&self, skeleton: &Skeleton) -> Result<LocalPose, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        skeleton.check("", &self.bones)?;
        let bones = self
            .bones
            .iter()
            .zip(&skeleton.bones)
            .map(|(model, bone)| match bone.parent {
                Some(p) => unit(self.bones[p]).inverse() * unit(*model),
                None => unit(*model),
            })
            .collect();
        Ok(LocalPose { bones })
    }

    /// This pose placed in the world by the model frame's transform
    /// `model_to_world` (the character's). The other way, a pose in the
    /// world (the mapper's and the transition's output) back in the model
    /// frame: `pose.in_world(model_to_world.inverse())`.
    pub fn in_world(&self, model_to_world: Transform) -> ModelPose {
        let _mode = DefaultFloatMode::enter();
        ModelPose {
            bones: self.bones.iter().map(|&t| model_to_world * t).collect(),
        }
    }
}

impl LocalPose {
    /// This pose blended bone by bone with `other`, in local space: bone
    /// `k` at `weights[k]` (0: this pose's transform, 1: `other`'s,
    /// exactly; in between, translations (m, parent frame) interpolated
    /// linearly and rotations along the shorter arc), as Unreal's physics
    /// blend weight blends an animation pose with the simulated one.
    /// Refused, naming the bone and the field, when either pose does not
    /// fit `skeleton` or a weight is not finite or outside [0, 1] (one
    /// weight per bone).
    pub fn blend(
        &self,
        skeleton: &Skeleton,
        other: &LocalPose,
        weights: &[f32],
    ) -> Result<LocalPose, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        skeleton.check("", &self.bones)?;
        skeleton.check("", &other.bones)?;
        check_weights(weights, skeleton.len(), |k| {
            bone_context(k, &skeleton.bones[k].name)
        })?;
        let bones = self
            .bones
            .iter()
            .zip(&other.bones)
            .zip(weights)
            .map(|((a, b), &w)| {
                let (translation, rotation) =
                    blend_bone((a.translation, a.rotation), (b.translation, b.rotation), w);
                Transform::new(translation, rotation)
            })
            .collect();
        Ok(LocalPose { bones })
    }
}

/// Checks one weight per bone, each finite and in [0, 1]; `context(k)`
/// names bone `k` in the error.
pub(crate) fn check_weights(
    weights: &[f32],
    bones: usize,
    context: impl Fn(usize) -> String,
) -> Result<(), RagdollError> {
    if weights.len() != bones {
        return Err(RagdollError::OutOfRange {
            context: "blend".to_owned(),
            field: "weights",
            reason: format!("has {} entries for {bones} bones", weights.len()),
        });
    }
    for (k, &w) in weights.iter().enumerate() {
        if !w.is_finite() {
            return Err(RagdollError::NonFinite {
                context: context(k),
                field: "weight",
            });
        }
        if !(0.0..=1.0).contains(&w) {
            return Err(RagdollError::OutOfRange {
                context: context(k),
                field: "weight",
                reason: format!("is {w}; must be within [0, 1]"),
            });
        }
    }
    Ok(())
}

/// `a` and `b` blended at weight `w` (0: `a`, 1: `b`, exactly):
/// translation `a (1 - w) + b w`, rotation along the shorter arc
/// ([`PortableQuat::slerp_portable`]).
pub(crate) fn blend_bone((pa, qa): (Vec3, Quat), (pb, qb): (Vec3, Quat), w: f32) -> (Vec3, Quat) {
    if w == 0.0 {
        (pa, qa)
    } else if w == 1.0 {
        (pb, qb)
    } else {
        (pa * (1.0 - w) + pb * w, qa.slerp_portable(qb, w))
    }
}
