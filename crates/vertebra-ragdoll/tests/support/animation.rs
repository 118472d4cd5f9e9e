//! Random animation poses of a skeleton for the reference humanoid, within
//! its joint limits. Each bone turns about its axis along the bone, in its
//! own frame: `along` (+Y on the shipped `Skeleton::reference()`).

use core::ops::RangeInclusive;

use glam::{Quat, Vec3};
use rand::RngExt;
use rand::rngs::StdRng;
use vertebra_ragdoll::{LocalPose, Skeleton, Transform};

/// How far a bone may turn from its bind pose in its own frame: a swing
/// across its axis `along` and a twist about it (rad). The spine bones each turn on
/// their own (a spine with unequal joint angles); the bones between two
/// bodies stay together within the sockets' limits (up to two spine bones
/// per spine socket: 11 of 20 degrees of swing; the neck's four: 28 of 40).
fn range(name: &str) -> (f32, f32) {
    let is = |prefix: &str| name.starts_with(prefix);
    if is("hips") {
        (0.5, 0.5)
    } else if is("spine") || is("chest") {
        (0.1, 0.05)
    } else if is("neck") || is("head") {
        (0.12, 0.1)
    } else if is("clavicle") {
        (0.1, 0.05)
    } else if is("upper_arm_twist") || is("forearm_twist") || is("thigh_twist") {
        (0.0, 0.3)
    } else if is("upper_arm") {
        (0.6, 0.3)
    } else if is("forearm") || is("shin") {
        (0.6, 0.05)
    } else if is("thigh") {
        (0.5, 0.2)
    } else {
        (0.4, 0.1)
    }
}

/// A unit vector across `axis`, at a random angle about it.
fn across(axis: Vec3, r: &mut StdRng) -> Vec3 {
    let side = axis.any_orthonormal_vector();
    Quat::from_axis_angle(axis, r.random_range(0.0..core::f32::consts::TAU)) * side
}

/// A random pose: every bone but the `still` ones turned from bind within
/// its range, the root moved up to 1 m and turned about +Y.
pub fn random_animation(
    skeleton: &Skeleton,
    along: Vec3,
    still: &[bool],
    r: &mut StdRng,
) -> LocalPose {
    let bones = skeleton
        .bones()
        .iter()
        .zip(still)
        .map(|(bone, &still)| {
            let (swing, twist) = if still { (0.0, 0.0) } else { range(&bone.name) };
            let turn = Quat::from_axis_angle(across(along, r), r.random_range(0.0..=swing))
                * Quat::from_axis_angle(along, r.random_range(-twist..=twist));
            let mut local = bone.bind * Transform::new(Vec3::ZERO, turn);
            if bone.parent.is_none() {
                local.translation +=
                    Vec3::new(r.random_range(-1.0..1.0), 0.0, r.random_range(-1.0..1.0));
                local.rotation = Quat::from_rotation_y(r.random_range(-3.0..3.0)) * local.rotation;
            }
            local
        })
        .collect();
    LocalPose { bones }
}

/// The pose `dt` seconds before `pose` of an animation that turns every
/// bone but the `still` ones about a random axis of its own frame at a
/// rate drawn from `rates` (rad/s) and moves the root at up to 1 m/s.
pub fn earlier(
    skeleton: &Skeleton,
    along: Vec3,
    still: &[bool],
    pose: &LocalPose,
    rates: RangeInclusive<f32>,
    dt: f32,
    r: &mut StdRng,
) -> LocalPose {
    let bones = pose
        .bones
        .iter()
        .zip(skeleton.bones().iter().zip(still))
        .map(|(&local, (bone, &still))| {
            let axis = across(along, r)
                .lerp(along, r.random_range(0.0..1.0))
                .normalize();
            let rate = if still {
                0.0
            } else {
                r.random_range(rates.clone())
            };
            let back = Quat::from_axis_angle(axis, -rate * dt);
            let mut before = local * Transform::new(Vec3::ZERO, back);
            if bone.parent.is_none() {
                before.translation -=
                    Vec3::new(r.random_range(-1.0..1.0), 0.0, r.random_range(-1.0..1.0)) * dt;
            }
            before
        })
        .collect();
    LocalPose { bones }
}
