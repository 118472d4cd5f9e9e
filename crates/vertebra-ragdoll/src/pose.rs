//! Poses: one world transform per animation bone (one bone per described
//! body, in file order). A bone's transform is its body's: the centre of
//! mass (m, world) and the orientation relative to bind pose (identity at
//! bind, where body axes are world axes).

use glam::{Quat, Vec3};
use vertebra_math::PortableQuat;
use vertebra_store::{check_coordinate, check_unit_quat};

use crate::error::RagdollError;
use crate::model::RagdollDesc;
use vertebra_math::DefaultFloatMode;

/// A world transform per bone.
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    /// (position, orientation) per bone, in the description's body order.
    pub bones: Vec<(Vec3, Quat)>,
}

impl Pose {
    /// The bind pose: every body at its capsule's midpoint, unrotated.
    pub fn bind(desc: &RagdollDesc) -> Self {
        let _mode = DefaultFloatMode::enter();
        Self {
            bones: desc
                .bodies
                .iter()
                .map(|b| (b.centre(), Quat::IDENTITY))
                .collect(),
        }
    }

    /// This pose turned by `rotation` about `pivot`, then moved by
    /// `translation` (all world).
    pub fn moved(&self, pivot: Vec3, rotation: Quat, translation: Vec3) -> Self {
        let _mode = DefaultFloatMode::enter();
        let bones = self
            .bones
            .iter()
            .map(|&(p, q)| {
                (
                    pivot + rotation * (p - pivot) + translation,
                    rotation.mul_portable(q),
                )
            })
            .collect();
        Self { bones }
    }

    /// Forward kinematics: the root bone at `root`, and each joint turning
    /// its child by `rotations[joint]` about the joint's anchor, relative to
    /// the parent (world frame at bind pose). Identity rotations give the
    /// bind pose moved to `root`. The root's position must be finite and
    /// every orientation and rotation a unit quaternion (within 1e-3).
    pub fn from_joint_rotations(
        desc: &RagdollDesc,
        root: (Vec3, Quat),
        rotations: &[Quat],
    ) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        if rotations.len() != desc.joints.len() {
            return Err(RagdollError::BadPose(format!(
                "{} joint rotations for {} joints",
                rotations.len(),
                desc.joints.len()
            )));
        }
        bone(&desc.bodies[desc.root].name, root)?;
        for (j, &r) in desc.joints.iter().zip(rotations) {
            check_unit_quat("rotation", r)
                .map_err(|e| RagdollError::BadPose(format!("joint `{}`: {e}", j.name)))?;
        }
        let mut bones: Vec<Option<(Vec3, Quat)>> = vec![None; desc.bodies.len()];
        bones[desc.root] = Some(root);
        // Parents before children: repeat until every body is placed (the
        // description is a tree, so each pass places at least one more).
        while bones.iter().any(Option::is_none) {
            for (k, j) in desc.joints.iter().enumerate() {
                if let (Some((pp, pq)), None) = (bones[j.parent], bones[j.child]) {
                    let anchor = pp + pq * (j.anchor - desc.bodies[j.parent].centre());
                    let q = pq.mul_portable(rotations[k]).normalize_portable();
                    bones[j.child] =
                        Some((anchor + q * (desc.bodies[j.child].centre() - j.anchor), q));
                }
            }
        }
        Ok(Self {
            bones: bones.into_iter().map(|b| b.expect("placed")).collect(),
        })
    }

    /// Checks the pose fits `desc`: one transform per bone, positions
    /// within [`MAX_COORDINATE`](vertebra_world::MAX_COORDINATE) of the
    /// origin, unit orientations.
    pub fn validate(&self, desc: &RagdollDesc) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        if self.bones.len() != desc.bodies.len() {
            return Err(RagdollError::BadPose(format!(
                "{} bones for {} bodies",
                self.bones.len(),
                desc.bodies.len()
            )));
        }
        for (&transform, body) in self.bones.iter().zip(&desc.bodies) {
            bone(&body.name, transform)?;
        }
        Ok(())
    }
}

/// A bone's transform: a finite position and a unit orientation.
fn bone(name: &str, (p, q): (Vec3, Quat)) -> Result<(), RagdollError> {
    let bad = |e| RagdollError::BadPose(format!("bone `{name}`: {e}"));
    check_coordinate("position", p).map_err(bad)?;
    check_unit_quat("orientation", q).map_err(bad)
}
