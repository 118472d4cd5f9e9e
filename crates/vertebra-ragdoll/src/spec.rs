//! A ragdoll description built in code: the file's tables as values
//! ([`BodySpec`], [`JointSpec`](crate::JointSpec), [`SpineSpec`]) given to
//! a [`RagdollBuilder`](crate::RagdollBuilder) (`builder.rs`), which
//! assembles and checks them as the file loader does (the same code, the
//! errors without a line).

use glam::Vec3;

use crate::skeleton::Transform;

/// A body as a builder gives it (and as a `[[body]]` table reads).
#[derive(Clone, Debug, PartialEq)]
pub struct BodySpec {
    /// Unique name.
    pub name: String,
    /// Where the capsule's core segment lies at bind pose.
    pub shape: BodyShape,
    /// Capsule radius (m, 1e-3 to 1e3).
    pub radius: f32,
    /// Mass (kg, 1e-6 to 1e12), or its share of a `total_mass`.
    pub mass: f32,
    /// The bone the body follows; by default the bone of the body's name,
    /// or else (a body placed by bones) its `from` bone, when the
    /// description has a skeleton.
    pub bone: Option<String>,
    /// The body's frame in its bone's frame ([`BoneBinding::offset`]); by
    /// default what the bind poses give.
    ///
    /// [`BoneBinding::offset`]: crate::BoneBinding::offset
    pub offset: Option<Transform>,
}

/// Where a body's capsule lies at bind pose.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyShape {
    /// The core segment's ends (m, world at bind pose).
    Segment([Vec3; 2]),
    /// From one bone's origin to another's, in the skeleton's bind pose
    /// (its model frame is the world at bind pose).
    Bones {
        /// The bone at the segment's first end.
        from: String,
        /// The bone at its second end.
        to: String,
    },
}

impl BodySpec {
    /// A capsule of `radius` (m) and `mass` (kg) around `segment` (m,
    /// world at bind pose).
    pub fn capsule(name: &str, segment: [Vec3; 2], radius: f32, mass: f32) -> Self {
        Self::new(name, BodyShape::Segment(segment), radius, mass)
    }

    /// A capsule of `radius` (m) and `mass` (kg) from bone `from`'s origin
    /// to bone `to`'s, in the skeleton's bind pose.
    pub fn from_bones(name: &str, from: &str, to: &str, radius: f32, mass: f32) -> Self {
        let shape = BodyShape::Bones {
            from: from.to_owned(),
            to: to.to_owned(),
        };
        Self::new(name, shape, radius, mass)
    }

    fn new(name: &str, shape: BodyShape, radius: f32, mass: f32) -> Self {
        Self {
            name: name.to_owned(),
            shape,
            radius,
            mass,
            bone: None,
            offset: None,
        }
    }

    /// Following bone `bone`.
    pub fn with_bone(mut self, bone: &str) -> Self {
        self.bone = Some(bone.to_owned());
        self
    }

    /// With the body's frame at `offset` in its bone's frame.
    pub fn with_offset(mut self, offset: Transform) -> Self {
        self.offset = Some(offset);
        self
    }
}

/// The spine chain as a builder gives it (the `[spine]` table).
#[derive(Clone, Debug, PartialEq)]
pub struct SpineSpec {
    /// Body names from the base (hips) to the top (chest), each joined to
    /// the next by a joint.
    pub bodies: Vec<String>,
    /// The rod's largest bend (rad, 0 to pi).
    pub bend_limit: f32,
    /// The rod's twist range `[min, max]` (rad, within [-pi, pi]).
    pub twist_limit: [f32; 2],
    /// Kirchhoff bending stiffness (N m^2, not negative).
    pub bend_stiffness: f32,
    /// Kirchhoff twisting stiffness (N m^2, not negative).
    pub twist_stiffness: f32,
}
