//! An animation shared by the partial-ragdoll and blending tests.

use core::f32::consts::TAU;

use glam::{Quat, Vec3};
use vertebra_ragdoll::{Pose, RagdollDesc};

/// The reference humanoid walking along +Z at 1.2 m/s, one stride per
/// second, at time `t` (s): legs swinging 0.4 rad either way with the
/// knees bending up to 0.6 rad, arms swinging against them, the spine
/// turning a little, the hips bobbing 2 cm and turning 0.1 rad.
pub fn walking(desc: &RagdollDesc, t: f32) -> Pose {
    let joint = |name: &str| desc.joints.iter().position(|j| j.name == name).unwrap();
    let phase = TAU * t;
    let swing = 0.4 * phase.sin();
    let mut rotations = vec![Quat::IDENTITY; desc.joints.len()];
    rotations[joint("hip_l")] = Quat::from_rotation_x(-swing);
    rotations[joint("hip_r")] = Quat::from_rotation_x(swing);
    rotations[joint("knee_l")] = Quat::from_rotation_x(0.3 * (1.0 - phase.cos()));
    rotations[joint("knee_r")] = Quat::from_rotation_x(0.3 * (1.0 + phase.cos()));
    rotations[joint("shoulder_l")] = Quat::from_rotation_x(0.8 * swing);
    rotations[joint("shoulder_r")] = Quat::from_rotation_x(-0.8 * swing);
    for spine in ["spine_1", "spine_2", "spine_3"] {
        rotations[joint(spine)] = Quat::from_rotation_y(0.05 * phase.sin());
    }
    let root = (
        Vec3::new(0.0, 1.0 + 0.02 * (2.0 * phase).cos(), 1.2 * t),
        Quat::from_rotation_y(0.1 * phase.sin()),
    );
    Pose::from_joint_rotations(desc, root, &rotations).unwrap()
}

/// The angle (rad) between two orientations, from the sine of its half
/// (which resolves small angles where the cosine does not).
pub fn angle(a: Quat, b: Quat) -> f32 {
    let turn = (a * b.conjugate()).normalize();
    2.0 * turn.xyz().length().min(1.0).asin()
}
