//! The skeleton mapper: a ragdoll's bodies onto an animation skeleton that
//! has more bones than the ragdoll has bodies, and an animation pose of the
//! skeleton back onto the bodies (as Jolt's `SkeletonMapper`, with the
//! paper's section 6 for the bones between two bodies).
//!
//! Frames: the description's world frame at bind pose is the skeleton's
//! model frame (both bind poses are in it, metres, +Y up). A body's pose is
//! its centre of mass and its rotation relative to bind pose (bodies are
//! unrotated at bind), in the world; a bone's output is its transform in
//! the world, the model frame placed by the caller's `model_to_world`.
//!
//! Every bone gets one role, fixed when the mapper is made:
//!
//! - **body**: a body of the built ragdoll follows it. Its world transform
//!   is the body's times the fixed offset the two bind poses give.
//! - **chain**: it lies on the path from a body bone up to the nearest body
//!   bone above it, with no body bone between (the simplified ragdoll's
//!   spine bones between the hips and the chest, a neck between the chest
//!   and the head). The chain is placed by a [`SpineMapping`] from its two
//!   bodies. A bone on two such paths belongs to the first (by the lower
//!   body bone's index); the second path is then no chain, and its bones
//!   that the first does not hold follow their parents.
//! - **follows**: no body, below a body or chain bone, and in no chain (a
//!   finger, a twist bone, a toe): it keeps the animation's local
//!   transform relative to its parent.
//! - **free**: no body bone above it (a root or motion bone above the
//!   hips): it keeps the animation's model transform, placed in the world
//!   by `model_to_world`.
//!
//! With locked translations (Jolt's `LockTranslations`) every bone whose
//! parent is not free takes its animation's local translation relative to
//! its parent (keeping its rotation), which hides a joint's stretch and a
//! chain's change of length.

use glam::{Quat, Vec3};
use vertebra_math::PortableQuat;

use crate::error::RagdollError;
use crate::mapping::{Chain, SpineMapping};
use crate::model::RagdollDesc;
use crate::model::{SpineMode, rod_name};
use crate::pose::Pose;
use crate::skeleton::{Bone, LocalPose, ModelPose, Skeleton, Transform};
use vertebra_math::DefaultFloatMode;

/// Per described body its world pose (centre of mass, rotation relative to
/// bind; a simplified ragdoll's interior spine bodies unread), and a
/// simplified ragdoll's rod's material frames.
pub(crate) type Bodies = (Vec<(Vec3, Quat)>, Option<(Quat, Quat)>);

/// What places a bone (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BoneRole {
    /// Follows this body (index in the description).
    Body(usize),
    /// Between body bones `base` and `top` (skeleton indices), placed by
    /// the spine mapping.
    Chain {
        /// The body bone at the chain's base.
        base: usize,
        /// The body bone at its top.
        top: usize,
    },
    /// Keeps the animation's local transform relative to its parent.
    Follows,
    /// Keeps the animation's model transform.
    Free,
}

/// Maps between a ragdoll's bodies and an animation skeleton; made once
/// per skeleton, description and spine mode.
#[derive(Clone, Debug, PartialEq)]
pub struct SkeletonMapper {
    pub(crate) desc: RagdollDesc,
    pub(crate) spine: SpineMode,
    skeleton: Skeleton,
    /// Per body, its bone.
    binding: Vec<usize>,
    /// Per body, its bone's bind transform in the body's frame.
    offsets: Vec<Transform>,
    /// Per body, its rotation at the skeleton's bind pose relative to the
    /// description's bind (the identity unless an authored offset turns
    /// it).
    bind_turns: Vec<Quat>,
    roles: Vec<BoneRole>,
    chains: Vec<Chain>,
    lock_translations: bool,
}

impl SkeletonMapper {
    /// A mapper where each body follows the bone its description binds it
    /// to (`BodyDef::bone`: the bone of that name in `skeleton`, at the
    /// binding's offset), or else the bone of its own name (the shipped
    /// humanoids' bodies are `hips`, `spine_lower`, `spine_upper`, `chest`,
    /// `head`, `upper_arm_l`, `forearm_l`, ...) at the offset the two bind
    /// poses give. Refused, naming the body, when the skeleton has no such
    /// bone, for a description that fails [`RagdollDesc::validate`], and
    /// for a rod spine of a description without a `[spine]`
    /// ([`RagdollDesc::check_spine`]).
    pub fn new(
        skeleton: &Skeleton,
        desc: &RagdollDesc,
        spine: SpineMode,
    ) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        desc.validate()?;
        if let Some(own) = &desc.skeleton {
            same_bind(own, skeleton)?;
        }
        let mut binding = Vec::with_capacity(desc.bodies.len());
        for def in &desc.bodies {
            let name = match (&def.bone, &desc.skeleton) {
                (Some(bound), Some(own)) => own.bones()[bound.bone].name.as_str(),
                (None, Some(_)) => {
                    return Err(RagdollError::OutOfRange {
                        context: format!("body `{}`", def.name),
                        field: "bone",
                        reason: "is none: the description binds it to no bone (a prop), and the mapper needs a bone for every body".to_owned(),
                    });
                }
                (_, None) => def.name.as_str(),
            };
            let bone = skeleton
                .bone_index(name)
                .ok_or_else(|| RagdollError::OutOfRange {
                    context: format!("body `{}`", def.name),
                    field: "bone",
                    reason: format!(
                        "is missing: the skeleton has no bone `{name}` and every body needs one"
                    ),
                })?;
            binding.push(Some(bone));
        }
        let authored: Vec<Option<Transform>> = desc
            .bodies
            .iter()
            .map(|def| def.bone.as_ref().map(|bound| bound.offset))
            .collect();
        Self::bound(skeleton, desc, spine, &binding, &authored)
    }

    /// A mapper where body `i` follows bone `bones[i]` (skeleton index),
    /// at the offset the two bind poses give (the description's own
    /// bindings are not read). Every body needs a bone of its own (a
    /// simplified ragdoll's interior spine bodies too: the rod is made
    /// through their bones); refused, naming the body and field, when one
    /// has none, one names a bone the skeleton lacks or two share a bone,
    /// and for a description that fails [`RagdollDesc::validate`].
    pub fn with_binding(
        skeleton: &Skeleton,
        desc: &RagdollDesc,
        spine: SpineMode,
        bones: &[Option<usize>],
    ) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        Self::bound(skeleton, desc, spine, bones, &vec![None; bones.len()])
    }

    /// [`SkeletonMapper::with_binding`] where body `i`'s frame in its
    /// bone's is `authored[i]` when given (else what the bind poses give).
    /// The chains are laid out in the skeleton's bind pose, each body where
    /// its bone and offset put it there.
    fn bound(
        skeleton: &Skeleton,
        desc: &RagdollDesc,
        spine: SpineMode,
        bones: &[Option<usize>],
        authored: &[Option<Transform>],
    ) -> Result<Self, RagdollError> {
        desc.validate()?;
        desc.check_spine(spine)?;
        let count = skeleton.len();
        if bones.len() != desc.bodies.len() {
            return Err(RagdollError::OutOfRange {
                context: "skeleton mapper".to_owned(),
                field: "binding",
                reason: format!(
                    "has {} entries for {} bodies",
                    bones.len(),
                    desc.bodies.len()
                ),
            });
        }
        let mut binding = Vec::with_capacity(bones.len());
        let mut owner: Vec<Option<usize>> = vec![None; count];
        for (b, (&bone, def)) in bones.iter().zip(&desc.bodies).enumerate() {
            let refuse = |reason: String| RagdollError::OutOfRange {
                context: format!("body `{}`", def.name),
                field: "bone",
                reason,
            };
            let bone = match bone {
                None => {
                    return Err(refuse(format!(
                        "is missing: the skeleton has no bone `{}` and every body needs one",
                        def.name
                    )));
                }
                Some(bone) if bone >= count => {
                    return Err(refuse(format!("is {bone}; the skeleton has {count} bones")));
                }
                Some(bone) => bone,
            };
            if let Some(other) = owner[bone] {
                return Err(refuse(format!(
                    "is bone {bone} `{}`, which body `{}` follows too",
                    skeleton.bones()[bone].name,
                    desc.bodies[other].name
                )));
            }
            owner[bone] = Some(b);
            binding.push(bone);
        }
        let bind = skeleton.bind_pose().to_model(skeleton)?;
        // Each body at the skeleton's bind pose (centre of mass, rotation
        // from the description's bind), and its bone in its frame.
        let (at_bind, offsets): (Vec<Transform>, Vec<Transform>) = binding
            .iter()
            .zip(&desc.bodies)
            .zip(authored)
            .map(|((&bone, def), authored)| {
                let t = bind.bones[bone];
                match authored {
                    Some(offset) => (t * *offset, offset.inverse()),
                    None => (
                        Transform::new(def.centre(), Quat::IDENTITY),
                        Transform::new(t.translation - def.centre(), t.rotation),
                    ),
                }
            })
            .unzip();
        // Bodies the built ragdoll has: a simplified ragdoll has no
        // interior spine bodies, so their bones join the spine's chain.
        let spine_def = desc.spine.as_ref().filter(|_| spine == SpineMode::Rod);
        let built =
            |b: usize| spine_def.is_none_or(|s| !s.bodies[1..s.bodies.len() - 1].contains(&b));
        let body_of: Vec<Option<usize>> = owner.iter().map(|o| o.filter(|&b| built(b))).collect();
        let parent = |j: usize| skeleton.bones()[j].parent;

        let mut roles: Vec<Option<BoneRole>> =
            body_of.iter().map(|b| b.map(BoneRole::Body)).collect();
        let mut chains = Vec::new();
        for top in 0..count {
            let Some(top_body) = body_of[top] else {
                continue;
            };
            let mut interior = Vec::new();
            let mut at = parent(top);
            while let Some(j) = at.filter(|&j| body_of[j].is_none()) {
                interior.push(j);
                at = parent(j);
            }
            let Some(base) = at else {
                continue; // no body bone above: the bones passed are free
            };
            if interior.is_empty() || interior.iter().any(|&j| roles[j].is_some()) {
                continue;
            }
            interior.reverse();
            for &j in &interior {
                roles[j] = Some(BoneRole::Chain { base, top });
            }
            let base_body = body_of[base].expect("a body bone");
            let points = core::iter::once(at_bind[base_body].translation)
                .chain(interior.iter().map(|&j| bind.bones[j].translation))
                .chain(core::iter::once(at_bind[top_body].translation))
                .collect();
            let rotations = interior.iter().map(|&j| bind.bones[j].rotation).collect();
            let rod = spine_def.is_some_and(|s| {
                s.bodies[0] == base_body && s.bodies[s.bodies.len() - 1] == top_body
            });
            chains.push(Chain::new(
                base_body, top_body, interior, points, rotations, rod,
            ));
        }
        let mut placed: Vec<BoneRole> = Vec::with_capacity(count);
        for (j, role) in roles.into_iter().enumerate() {
            let role = role.unwrap_or(match parent(j) {
                Some(p) if placed[p] != BoneRole::Free => BoneRole::Follows,
                _ => BoneRole::Free,
            });
            placed.push(role);
        }
        Ok(Self {
            desc: desc.clone(),
            spine,
            skeleton: skeleton.clone(),
            binding,
            bind_turns: at_bind.iter().map(|t| t.rotation).collect(),
            offsets,
            roles: placed,
            chains,
            lock_translations: false,
        })
    }

    /// A skeleton of one bone per body (at its centre of mass, unrotated
    /// at bind, parented as the joints are) and the mapper onto it: the
    /// bodies-as-bones view of [`Ragdoll::skeleton_pose`].
    pub(crate) fn bodies_as_bones(
        desc: &RagdollDesc,
        spine: SpineMode,
    ) -> Result<Self, RagdollError> {
        // Parents before children: the root, then each body once its
        // parent is in (the joints form a tree over the bodies).
        let parent_body = |b: usize| desc.parent_joint[b].map(|j| desc.joints[j].parent);
        let mut order = vec![desc.root];
        let mut index: Vec<Option<usize>> = vec![None; desc.bodies.len()];
        index[desc.root] = Some(0);
        while order.len() < desc.bodies.len() {
            let before = order.len();
            for b in 0..desc.bodies.len() {
                if index[b].is_none() && parent_body(b).is_some_and(|p| index[p].is_some()) {
                    index[b] = Some(order.len());
                    order.push(b);
                }
            }
            if order.len() == before {
                return Err(RagdollError::NotATree(
                    "a body is not reached from the root".to_owned(),
                ));
            }
        }
        let bones = order
            .iter()
            .map(|&b| {
                let def = &desc.bodies[b];
                let parent = parent_body(b);
                let from = parent.map_or(Vec3::ZERO, |p| desc.bodies[p].centre());
                Bone {
                    name: def.name.clone(),
                    parent: parent.and_then(|p| index[p]),
                    bind: Transform::new(def.centre() - from, Quat::IDENTITY),
                }
            })
            .collect();
        Self::with_binding(&Skeleton::new(bones)?, desc, spine, &index)
    }

    /// With every bone whose parent is not free keeping the animation's
    /// local translation (rotations still mapped), as Jolt's
    /// `LockTranslations`: hides joint stretch and a chain's change of
    /// length; the body bones then sit where the animation's lengths put
    /// them, off their bodies by the stretch.
    pub fn with_locked_translations(mut self, lock: bool) -> Self {
        self.lock_translations = lock;
        self
    }

    /// The skeleton it maps onto.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Per described body, the bone it follows (skeleton index).
    pub fn binding(&self) -> &[usize] {
        &self.binding
    }

    /// Per bone, what places it.
    pub fn roles(&self) -> &[BoneRole] {
        &self.roles
    }

    /// Every body's world pose (centre of mass, rotation relative to bind)
    /// from an animation pose in model space and the model frame's place
    /// in the world: for [`Ragdoll::build`](crate::Ragdoll::build) (two of them, a frame apart,
    /// give the bodies the animation's velocities) and for
    /// [`Ragdoll::drive_to`](crate::Ragdoll::drive_to) /
    /// [`Ragdoll::drive_following`](crate::Ragdoll::drive_following). Refused,
    /// naming the bone and field, for a pose that does not fit the
    /// skeleton.
    pub fn map_to_ragdoll(
        &self,
        animation: &ModelPose,
        model_to_world: Transform,
    ) -> Result<Pose, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.check_bones("animation", &animation.bones)?;
        model_to_world.validate("model_to_world")?;
        let bones = self
            .binding
            .iter()
            .zip(&self.offsets)
            .map(|(&bone, offset)| {
                let body = model_to_world * animation.bones[bone] * offset.inverse();
                (body.translation, body.rotation)
            })
            .collect();
        Ok(Pose { bones })
    }

    /// As [`SkeletonMapper::map_to_skeleton`], from bodies given as a pose
    /// (one entry per described body; a simplified ragdoll's interior
    /// spine bodies are not read) and, for a simplified ragdoll's arc, its
    /// rod's material frames (`RodDesc::frame_a`, `frame_b`; without them
    /// the arc is the one a rod made at bind pose would take).
    pub fn map_pose_to_skeleton(
        &self,
        bodies: &Pose,
        rod_frames: Option<(Quat, Quat)>,
        animation: &LocalPose,
        model_to_world: Transform,
        mapping: SpineMapping,
    ) -> Result<ModelPose, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        bodies.validate(&self.desc)?;
        if let Some((a, b)) = rod_frames {
            for (field, q) in [("rod frame_a", a), ("rod frame_b", b)] {
                vertebra_store::check_unit_quat(field, q).map_err(|e| RagdollError::World {
                    context: rod_name(&self.desc),
                    error: e,
                })?;
            }
        }
        self.map(
            &bodies.bones,
            rod_frames,
            animation,
            model_to_world,
            mapping,
            None,
        )
    }

    /// Writes each chain bone's world transform as its chain places it
    /// into `out` (one entry per bone; other entries untouched).
    pub(crate) fn place_chains(
        &self,
        bodies: &[(Vec3, Quat)],
        rod_frames: Option<(Quat, Quat)>,
        mapping: SpineMapping,
        out: &mut [Transform],
    ) {
        for chain in &self.chains {
            // The chains are laid out in the skeleton's bind pose: each
            // body's rotation from there, and the rod's frames in those.
            let (turn_a, turn_b) = (self.bind_turns[chain.base], self.bind_turns[chain.top]);
            let from_bind = |(p, q): (Vec3, Quat), turn: Quat| (p, q.mul_portable(turn.inverse()));
            chain.place(
                mapping,
                from_bind(bodies[chain.base], turn_a),
                from_bind(bodies[chain.top], turn_b),
                rod_frames.map(|(a, b)| (turn_a.mul_portable(a), turn_b.mul_portable(b))),
                out,
            );
        }
    }

    /// Every bone's world transform, each chain bone `k` moved by
    /// `corrections.0[k]` scaled by `corrections.1` (in `[0, 1]`) in its
    /// own frame, before the bones below it are placed.
    pub(crate) fn map(
        &self,
        bodies: &[(Vec3, Quat)],
        rod_frames: Option<(Quat, Quat)>,
        animation: &LocalPose,
        model_to_world: Transform,
        mapping: SpineMapping,
        corrections: Option<(&[Transform], f32)>,
    ) -> Result<ModelPose, RagdollError> {
        self.check_bones("animation", &animation.bones)?;
        model_to_world.validate("model_to_world")?;
        let local = &animation.bones;
        let mut out = vec![Transform::IDENTITY; self.skeleton.len()];
        self.place_chains(bodies, rod_frames, mapping, &mut out);
        for (j, bone) in self.skeleton.bones().iter().enumerate() {
            let parent = bone.parent.map(|p| out[p]);
            let placed = match self.roles[j] {
                BoneRole::Body(b) => {
                    let (p, q) = bodies[b];
                    Transform::new(p, q) * self.offsets[b]
                }
                BoneRole::Chain { .. } => match corrections {
                    Some((c, weight)) => out[j] * scaled(c[j], weight),
                    None => out[j],
                },
                BoneRole::Follows | BoneRole::Free => parent.unwrap_or(model_to_world) * local[j],
            };
            out[j] = match (parent, bone.parent.map(|p| self.roles[p])) {
                (Some(parent), Some(role)) if self.lock_translations && role != BoneRole::Free => {
                    Transform::new(
                        parent.transform_point(local[j].translation),
                        placed.rotation,
                    )
                }
                _ => placed,
            };
        }
        Ok(ModelPose { bones: out })
    }

    /// Checks one transform per bone, as [`Skeleton`]'s poses are checked
    /// (finite, within `MAX_COORDINATE`, unit rotations); the error names
    /// `what` and the bone.
    pub(crate) fn check_bones(
        &self,
        what: &str,
        transforms: &[Transform],
    ) -> Result<(), RagdollError> {
        self.skeleton.check(what, transforms)
    }
}

/// Checks that every bone of `own` (a description's skeleton) is in
/// `given` by name, at the same bind pose (model frame, within 0.1 mm and
/// 1e-4 rad): the bindings' offsets were made in `own`'s.
fn same_bind(own: &Skeleton, given: &Skeleton) -> Result<(), RagdollError> {
    let (own_bind, given_bind) = (
        own.bind_pose().to_model(own)?,
        given.bind_pose().to_model(given)?,
    );
    for (bone, at) in own.bones().iter().zip(&own_bind.bones) {
        let refuse = |reason: String| RagdollError::OutOfRange {
            context: format!("skeleton bone `{}`", bone.name),
            field: "bind",
            reason,
        };
        let Some(j) = given.bone_index(&bone.name) else {
            return Err(refuse(
                "is in the description's skeleton but not in the one given".to_owned(),
            ));
        };
        let there = given_bind.bones[j];
        let (moved, turned) = (
            there.translation.distance(at.translation),
            2.0 * at
                .rotation
                .inverse()
                .mul_portable(there.rotation)
                .xyz()
                .length(),
        );
        if !(moved <= 1e-4 && turned <= 1e-4) {
            return Err(refuse(format!(
                "is {moved} m and {turned} rad from the description's skeleton's in the one given; map with the skeleton the description was bound to"
            )));
        }
    }
    Ok(())
}

/// `t` scaled by `weight` in `[0, 1]`: its translation times `weight`, its
/// rotation that share of the way from the identity.
fn scaled(t: Transform, weight: f32) -> Transform {
    if weight >= 1.0 {
        t
    } else {
        Transform::new(
            t.translation * weight,
            Quat::IDENTITY.slerp_portable(t.rotation, weight),
        )
    }
}
