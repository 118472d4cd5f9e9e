//! A dense animation skeleton for the reference humanoid (69 bones): a
//! root and an IK helper above the hips, five spine bones between the hips
//! and the chest, three neck bones, a jaw and eyes, clavicles, twist bones
//! on the long bones, hands with five three-bone fingers, feet with toes.
//! The bones the humanoid's bodies follow carry the bodies' names and sit
//! at the joints' anchors; each bone's +X points along it, so bind
//! rotations are not the identity. Used by `tests/transition.rs` only:
//! the shipped reference skeleton (`Skeleton::reference()`, which the
//! mapper tests and the bench use) puts a body's bone at its capsule's end,
//! not at its joint's pivot, so an animation turning those bones moves the
//! joints' anchors apart at the switch and the first step pulls the bodies
//! together: 9.1 mm on the first frame, which does not shrink with the
//! frame (docs/ragdolls.md, "Transition").

use core::f32::consts::{FRAC_PI_2, PI};

use glam::{Quat, Vec3};
use vertebra_ragdoll::{Bone, Skeleton, Transform};

/// The dense skeleton, bind pose in the humanoid's frame (metres, +Y up,
/// facing +Z, left +X).
pub fn dense_skeleton() -> Skeleton {
    let up = Quat::from_rotation_z(FRAC_PI_2); // +X along +Y
    let down = Quat::from_rotation_z(-FRAC_PI_2); // +X along -Y
    let forward = Quat::from_rotation_y(-FRAC_PI_2); // +X along +Z
    // Per bone: name, parent, model-space origin (m) and rotation.
    let mut model: Vec<(String, Option<usize>, Vec3, Quat)> = Vec::new();
    let mut add = |name: &str, parent: Option<&str>, at: [f32; 3], rotation: Quat| {
        let parent = parent.map(|p| {
            model
                .iter()
                .position(|b| b.0 == p)
                .expect("a parent before its child")
        });
        model.push((name.to_owned(), parent, Vec3::from(at), rotation));
    };
    add("root", None, [0.0, 0.0, 0.0], Quat::IDENTITY);
    add("ik_root", Some("root"), [0.0, 0.0, 0.0], Quat::IDENTITY);
    add("ik_hand_l", Some("ik_root"), [0.22, 0.95, 0.0], down);
    add("hips", Some("root"), [0.0, 1.0, 0.0], up);
    let spine = [
        ("spine_01", 1.04),
        ("spine_lower", 1.08),
        ("spine_03", 1.15),
        ("spine_upper", 1.22),
        ("spine_05", 1.29),
        ("chest", 1.36),
        ("neck_01", 1.47),
        ("neck_02", 1.51),
        ("neck_03", 1.55),
        ("head", 1.59),
    ];
    let mut parent = "hips";
    for (name, y) in spine {
        add(name, Some(parent), [0.0, y, 0.0], up);
        parent = name;
    }
    add("jaw", Some("head"), [0.0, 1.66, 0.05], forward);
    add("eye_l", Some("head"), [0.03, 1.72, 0.08], forward);
    add("eye_r", Some("head"), [-0.03, 1.72, 0.08], forward);
    for (side, s) in [("l", 1.0f32), ("r", -1.0)] {
        let n = |bone: &str| format!("{bone}_{side}");
        let outward = Quat::from_rotation_y(if s > 0.0 { 0.0 } else { PI });
        add(
            &n("clavicle"),
            Some("chest"),
            [0.05 * s, 1.46, 0.0],
            outward,
        );
        add(
            &n("upper_arm"),
            Some(&n("clavicle")),
            [0.22 * s, 1.48, 0.0],
            down,
        );
        add(
            &n("upper_arm_twist"),
            Some(&n("upper_arm")),
            [0.22 * s, 1.34, 0.0],
            down,
        );
        add(
            &n("forearm"),
            Some(&n("upper_arm")),
            [0.22 * s, 1.205, 0.0],
            down,
        );
        add(
            &n("forearm_twist"),
            Some(&n("forearm")),
            [0.22 * s, 1.10, 0.0],
            down,
        );
        add(&n("hand"), Some(&n("forearm")), [0.22 * s, 0.95, 0.0], down);
        for (f, finger) in ["thumb", "index", "middle", "ring", "pinky"]
            .iter()
            .enumerate()
        {
            let x = (0.22 + 0.012 * (f as f32 - 2.0)) * s;
            let (z, lift) = if f == 0 { (0.03, 0.02) } else { (0.0, 0.0) };
            let curl = down * Quat::from_rotation_x(0.1 * f as f32);
            let mut parent = n("hand");
            for (k, y) in [0.90, 0.87, 0.845].into_iter().enumerate() {
                let name = n(&format!("{finger}_{:02}", k + 1));
                add(&name, Some(&parent), [x, y + lift, z], curl);
                parent = name;
            }
        }
        add(&n("thigh"), Some("hips"), [0.10 * s, 0.94, 0.0], down);
        add(
            &n("thigh_twist"),
            Some(&n("thigh")),
            [0.10 * s, 0.73, 0.0],
            down,
        );
        add(&n("shin"), Some(&n("thigh")), [0.10 * s, 0.525, 0.0], down);
        add(&n("foot"), Some(&n("shin")), [0.10 * s, 0.08, 0.0], forward);
        add(
            &n("toes"),
            Some(&n("foot")),
            [0.10 * s, 0.02, 0.12],
            forward,
        );
    }
    let bones = model
        .iter()
        .map(|(name, parent, at, rotation)| {
            let placed = Transform::new(*at, *rotation);
            Bone {
                name: name.clone(),
                parent: *parent,
                bind: match parent {
                    Some(p) => Transform::new(model[*p].2, model[*p].3).inverse() * placed,
                    None => placed,
                },
            }
        })
        .collect();
    Skeleton::new(bones).expect("the dense skeleton is valid")
}
