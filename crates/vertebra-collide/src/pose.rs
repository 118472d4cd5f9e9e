//! Poses composed with the same bits on every target.
//!
//! Its own file because the narrow phase, the scene queries and continuous
//! collision all put one pose in another's frame, and each must do it the
//! same way for their answers to agree bit for bit across targets.

use parry3d::math::Pose;
use vertebra_math::PortableQuat;

/// `b` in `a`'s frame: parry's `a.inv_mul(b)`, with the rotations composed
/// by [`PortableQuat::mul_portable`] (glam's product has other bits on
/// other targets) and the translation turned as parry turns it (`Quat *
/// Vec3`, the same bits everywhere).
pub(crate) fn relative_pose(a: &Pose, b: &Pose) -> Pose {
    let turn = a.rotation.inverse();
    Pose::from_parts(
        turn * (b.translation - a.translation),
        turn.mul_portable(b.rotation),
    )
}
