//! Plain structs every part of the API shares: vectors, quaternions,
//! transforms and handles, each with an explicit C layout, and the
//! conversions to the Rust API's types.

use glam::{Quat, Vec3};
use vertebra_world::{BodyHandle, JointHandle, RodHandle};

use crate::error::{Failure, VtResult};

/// A vector (m, m/s, rad/s or N, as the field says), in the world frame
/// unless the field says otherwise.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VtVec3 {
    /// x.
    pub x: f32,
    /// y (up in the shipped scenes: gravity is -y).
    pub y: f32,
    /// z.
    pub z: f32,
}

/// A rotation as a unit quaternion `(x, y, z, w)`, `w` the scalar part.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VtQuat {
    /// x.
    pub x: f32,
    /// y.
    pub y: f32,
    /// z.
    pub z: f32,
    /// w, the scalar part.
    pub w: f32,
}

/// A rigid transform: a position (m) and a rotation.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VtTransform {
    /// Position (m).
    pub position: VtVec3,
    /// Rotation (unit quaternion).
    pub rotation: VtQuat,
}

/// A body of a world. Any bits make a handle: a world refuses one it did
/// not issue (`VT_RESULT_STALE_HANDLE`, `VT_RESULT_FOREIGN_HANDLE`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VtBody {
    /// Slot index.
    pub index: u32,
    /// The issuing world's lineage.
    pub lineage: u32,
    /// Generation of the slot.
    pub generation: u64,
}

/// A joint of a world (as [`VtBody`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VtJoint {
    /// Slot index.
    pub index: u32,
    /// The issuing world's lineage.
    pub lineage: u32,
    /// Generation of the slot.
    pub generation: u64,
}

/// A rod of a world (as [`VtBody`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VtRod {
    /// Slot index.
    pub index: u32,
    /// The issuing world's lineage.
    pub lineage: u32,
    /// Generation of the slot.
    pub generation: u64,
}

impl From<VtVec3> for Vec3 {
    fn from(v: VtVec3) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}

impl From<Vec3> for VtVec3 {
    fn from(v: Vec3) -> Self {
        Self {
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }
}

impl From<VtQuat> for Quat {
    fn from(q: VtQuat) -> Self {
        Quat::from_xyzw(q.x, q.y, q.z, q.w)
    }
}

impl From<Quat> for VtQuat {
    fn from(q: Quat) -> Self {
        Self {
            x: q.x,
            y: q.y,
            z: q.z,
            w: q.w,
        }
    }
}

impl From<VtTransform> for (Vec3, Quat) {
    fn from(t: VtTransform) -> Self {
        (t.position.into(), t.rotation.into())
    }
}

impl From<(Vec3, Quat)> for VtTransform {
    fn from((position, rotation): (Vec3, Quat)) -> Self {
        Self {
            position: position.into(),
            rotation: rotation.into(),
        }
    }
}

/// Each C handle to its Rust handle and back: the same three numbers.
macro_rules! handle_conversions {
    ($($c:ident <-> $rust:ident),*) => {$(
        impl From<$c> for $rust {
            fn from(h: $c) -> Self {
                $rust::from_raw(h.index, h.lineage, h.generation)
            }
        }

        impl From<$rust> for $c {
            fn from(h: $rust) -> Self {
                let (index, lineage, generation) = h.to_raw();
                Self { index, lineage, generation }
            }
        }
    )*};
}

handle_conversions!(VtBody <-> BodyHandle, VtJoint <-> JointHandle, VtRod <-> RodHandle);

/// The value of an enum field, or a refusal naming the field.
pub(crate) fn pick<T: Copy>(value: u32, field: &str, values: &[T]) -> Result<T, Failure> {
    values.get(value as usize).copied().ok_or_else(|| {
        Failure::new(
            VtResult::InvalidEnum,
            format!("{field} is {value}; it takes 0 to {}", values.len() - 1),
        )
    })
}

/// A C flag: 0 is false, anything else true.
pub(crate) fn flag(value: u32) -> bool {
    value != 0
}
