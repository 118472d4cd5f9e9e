//! The skeleton mapper on the shipped reference skeleton
//! (`Skeleton::reference()`, 63 bones): every bone's role as the
//! definitions give it, bind pose in and out, bones with bodies following
//! them, the rest keeping the animation, the chain modes' properties,
//! locked translations, and every bad input refused by name.

#[path = "support/animation.rs"]
mod animation;

use glam::{Quat, Vec3};
use proptest::prelude::*;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_ragdoll::{
    Bone, BoneRole, BuildOptions, LocalPose, ModelPose, Pose, Ragdoll, RagdollDesc, Skeleton,
    SkeletonMapper, SpineMapping, SpineMode, Transform,
};
use vertebra_world::{SolverConfig, World};

use animation::{earlier, random_animation};

/// The reference skeleton's axis along a bone, in the bone's frame.
const ALONG: Vec3 = Vec3::Y;

const MAPPINGS: [SpineMapping; 3] = [
    SpineMapping::Orientation,
    SpineMapping::PositionOrientation,
    SpineMapping::Arc,
];

fn index(skeleton: &Skeleton, name: &str) -> usize {
    skeleton.bone_index(name).unwrap()
}

/// The angle between two rotations (rad), accurate when they are close.
fn angle(a: Quat, b: Quat) -> f32 {
    let r = a * b.conjugate();
    2.0 * r.xyz().length().atan2(r.w.abs())
}

fn close(a: Transform, b: Transform, metres: f32, radians: f32) -> bool {
    a.translation.distance(b.translation) <= metres && angle(a.rotation, b.rotation) <= radians
}

fn random_place(r: &mut StdRng) -> Transform {
    Transform::new(
        Vec3::new(
            r.random_range(-10.0..10.0),
            r.random_range(-1.0..1.0),
            r.random_range(-10.0..10.0),
        ),
        Quat::from_scaled_axis(Vec3::new(
            r.random_range(-1.0..1.0),
            r.random_range(-3.0..3.0),
            r.random_range(-1.0..1.0),
        )),
    )
}

#[test]
fn every_bone_of_the_reference_skeleton_takes_the_role_the_definitions_give() {
    let skeleton = Skeleton::reference();
    assert_eq!(skeleton.len(), 63);
    let desc = RagdollDesc::reference_humanoid();
    for spine in [SpineMode::Rod, SpineMode::Sockets] {
        let mapper = SkeletonMapper::new(&skeleton, &desc, spine).unwrap();
        let at = |name: &str| index(&skeleton, name);
        let chain = |base: &str, top: &str| BoneRole::Chain {
            base: at(base),
            top: at(top),
        };
        let mut expected: Vec<(&str, BoneRole)> = vec![
            ("root", BoneRole::Free),
            ("neck_1", chain("chest", "head")),
            ("neck_2", chain("chest", "head")),
            ("neck_3", chain("chest", "head")),
            ("clavicle_l", chain("chest", "upper_arm_l")),
            ("clavicle_r", chain("chest", "upper_arm_r")),
        ];
        let spine_bones = ["spine_lower", "spine_middle", "spine_upper", "spine_top"];
        match spine {
            SpineMode::Rod => {
                for bone in spine_bones {
                    expected.push((bone, chain("hips", "chest")));
                }
            }
            SpineMode::Sockets => {
                expected.push(("spine_middle", chain("spine_lower", "spine_upper")));
                expected.push(("spine_top", chain("spine_upper", "chest")));
            }
        }
        for (b, body) in desc.bodies.iter().enumerate() {
            let interior = spine == SpineMode::Rod
                && (body.name == "spine_lower" || body.name == "spine_upper");
            if !interior {
                expected.push((&body.name, BoneRole::Body(b)));
            }
        }
        for (j, bone) in skeleton.bones().iter().enumerate() {
            let want = expected
                .iter()
                .find(|(name, _)| *name == bone.name)
                .map_or(BoneRole::Follows, |&(_, role)| role);
            assert_eq!(mapper.roles()[j], want, "{spine:?}: bone `{}`", bone.name);
        }
        // Every body follows the bone of its name.
        for (b, &bone) in mapper.binding().iter().enumerate() {
            assert_eq!(skeleton.bones()[bone].name, desc.bodies[b].name);
        }
    }
}

/// At bind pose the bodies are at their bind centres, unrotated, placed by
/// the model frame; and mapped back every bone is at bind, in every mode.
#[test]
fn the_bind_pose_maps_to_the_bodies_bind_pose_and_back() {
    let skeleton = Skeleton::reference();
    let desc = RagdollDesc::reference_humanoid();
    let mut r = StdRng::seed_from_u64(2);
    let bind = skeleton.bind_pose();
    let bind_model = bind.to_model(&skeleton).unwrap();
    for spine in [SpineMode::Rod, SpineMode::Sockets] {
        for lock in [false, true] {
            let mapper = SkeletonMapper::new(&skeleton, &desc, spine)
                .unwrap()
                .with_locked_translations(lock);
            let place = random_place(&mut r);
            let bodies = mapper.map_to_ragdoll(&bind_model, place).unwrap();
            for ((p, q), def) in bodies.bones.iter().zip(&desc.bodies) {
                assert!(
                    p.distance(place.transform_point(def.centre())) < 1e-4,
                    "{}",
                    def.name
                );
                assert!(angle(*q, place.rotation) < 1e-5, "{}", def.name);
            }
            for mapping in MAPPINGS {
                let out = mapper
                    .map_pose_to_skeleton(&bodies, None, &bind, place, mapping)
                    .unwrap();
                for (j, (o, b)) in out.bones.iter().zip(&bind_model.bones).enumerate() {
                    assert!(
                        close(*o, place * *b, 1e-4, 1e-4),
                        "{spine:?}, {mapping:?}, lock {lock}: bone `{}`",
                        skeleton.bones()[j].name
                    );
                }
            }
        }
    }
}

/// Bodies from a random animation, moved together by a random rigid
/// motion `g`: a bone with a body is its animated transform moved by `g`;
/// a bone that follows its parent keeps the animation's local transform;
/// a free bone keeps its animated place; the chains move rigidly with the
/// bodies (the mapping commutes with a rigid motion of the whole ragdoll).
#[test]
fn bones_with_bodies_follow_them_and_the_others_keep_the_animation() {
    let skeleton = Skeleton::reference();
    let desc = RagdollDesc::reference_humanoid();
    let mut r = StdRng::seed_from_u64(3);
    let moving = vec![false; skeleton.len()];
    for trial in 0..20 {
        for spine in [SpineMode::Rod, SpineMode::Sockets] {
            let mapper = SkeletonMapper::new(&skeleton, &desc, spine).unwrap();
            let animation = random_animation(&skeleton, ALONG, &moving, &mut r);
            let place = random_place(&mut r);
            let animated = animation.to_model(&skeleton).unwrap().in_world(place);
            let bodies = mapper
                .map_to_ragdoll(&animation.to_model(&skeleton).unwrap(), place)
                .unwrap();
            let g = Transform::new(
                Vec3::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0), 0.0),
                Quat::from_scaled_axis(Vec3::new(0.3, -0.7, r.random_range(-1.0..1.0))),
            );
            let moved = Pose {
                bones: bodies
                    .bones
                    .iter()
                    .map(|&(p, q)| (g.transform_point(p), (g.rotation * q).normalize()))
                    .collect(),
            };
            for mapping in MAPPINGS {
                let still = mapper
                    .map_pose_to_skeleton(&bodies, None, &animation, place, mapping)
                    .unwrap();
                let out = mapper
                    .map_pose_to_skeleton(&moved, None, &animation, place, mapping)
                    .unwrap();
                let local = out.to_local(&skeleton).unwrap();
                for (j, bone) in skeleton.bones().iter().enumerate() {
                    let ok = match mapper.roles()[j] {
                        BoneRole::Body(_) => close(out.bones[j], g * animated.bones[j], 2e-5, 2e-5),
                        BoneRole::Follows => close(local.bones[j], animation.bones[j], 2e-5, 2e-5),
                        BoneRole::Free => close(out.bones[j], animated.bones[j], 2e-5, 2e-5),
                        BoneRole::Chain { .. } => {
                            close(out.bones[j], g * still.bones[j], 2e-5, 2e-5)
                        }
                    };
                    assert!(
                        ok,
                        "trial {trial}, {spine:?}, {mapping:?}: bone `{}`",
                        bone.name
                    );
                }
            }
        }
    }
}

/// The modes on the reference skeleton's spine of a simplified ragdoll
/// built at a random animated pose: `Orientation` keeps the lengths
/// between the chain's points (the base body's centre, the four spine
/// bones' origins between the hips and the chest); with
/// `PositionOrientation` each bone moves from there by its share of the
/// chain end's miss of the chest; on the `Arc` (the spine is straight at
/// bind: the bones sit on it) every segment is within the chord factor of
/// its bind length, times the arc's length over the bind polyline's (the
/// rod made at an unevenly bent pose is an arc a little longer or shorter
/// than the spine: under 0.2% here).
#[test]
fn the_chain_modes_keep_what_they_claim_on_the_reference_spine() {
    let skeleton = Skeleton::reference();
    let desc = RagdollDesc::reference_humanoid();
    let bind = skeleton.bind_pose().to_model(&skeleton).unwrap();
    let mapper = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod).unwrap();
    let mut r = StdRng::seed_from_u64(4);
    let moving = vec![false; skeleton.len()];
    let chain: Vec<usize> = ["spine_lower", "spine_middle", "spine_upper", "spine_top"]
        .iter()
        .map(|n| index(&skeleton, n))
        .collect();
    let (hips, chest) = (0, 3);
    let mut bind_points = vec![desc.bodies[hips].centre()];
    bind_points.extend(chain.iter().map(|&j| bind.bones[j].translation));
    bind_points.push(desc.bodies[chest].centre());
    let lengths: Vec<f32> = bind_points
        .windows(2)
        .map(|w| (w[1] - w[0]).length())
        .collect();
    let total: f32 = lengths.iter().sum();
    for trial in 0..20 {
        let animation = random_animation(&skeleton, ALONG, &moving, &mut r);
        let place = random_place(&mut r);
        let bodies = mapper
            .map_to_ragdoll(&animation.to_model(&skeleton).unwrap(), place)
            .unwrap();
        let mut world = World::new(SolverConfig::default()).unwrap();
        let ragdoll = Ragdoll::build(
            &mut world,
            &desc,
            BuildOptions::new(SpineMode::Rod),
            &bodies,
            None,
        )
        .unwrap();
        let [orientation, position, arc] = MAPPINGS.map(|m| {
            mapper
                .map_to_skeleton(&ragdoll, &world, &animation, place, m)
                .unwrap()
        });
        let points = |pose: &ModelPose| {
            let mut p = vec![bodies.bones[hips].0];
            p.extend(chain.iter().map(|&j| pose.bones[j].translation));
            p
        };
        let (o, a) = (points(&orientation), points(&arc));
        for k in 0..chain.len() {
            let bind_length = lengths[k];
            assert!(
                ((o[k + 1] - o[k]).length() - bind_length).abs() < 2e-5,
                "trial {trial}: orientation keeps lengths"
            );
            let ratio = (a[k + 1] - a[k]).length() / bind_length;
            assert!(
                ratio > 0.98 && ratio < 1.002,
                "trial {trial}: arc segment {k}: {ratio}"
            );
        }
        // Where the orientation mode's chain ends: the last bone's frame
        // carried by its bind offset to the chest's centre.
        let last = chain[chain.len() - 1];
        let bind_offset = bind.bones[last]
            .inverse()
            .transform_point(bind_points[bind_points.len() - 1]);
        let end = orientation.bones[last].transform_point(bind_offset);
        let miss = bodies.bones[chest].0 - end;
        let mut along = 0.0;
        for (k, &j) in chain.iter().enumerate() {
            along += lengths[k];
            let shift = position.bones[j].translation - orientation.bones[j].translation;
            assert!(
                (shift - miss * (along / total)).length() < 2e-5,
                "trial {trial}: bone {k} moves by its share"
            );
        }
        assert!(
            miss.length() > 1e-4,
            "unequal spine angles: the orientation mode misses ({miss})"
        );
    }
}

/// Locked translations: every bone whose parent is not free has the
/// animation's local translation, and the same rotation as unlocked.
#[test]
fn locked_translations_keep_the_animations_local_translations() {
    let skeleton = Skeleton::reference();
    let desc = RagdollDesc::reference_humanoid();
    let mut r = StdRng::seed_from_u64(5);
    let moving = vec![false; skeleton.len()];
    for spine in [SpineMode::Rod, SpineMode::Sockets] {
        let free = SkeletonMapper::new(&skeleton, &desc, spine).unwrap();
        let locked = free.clone().with_locked_translations(true);
        for _ in 0..10 {
            let animation = random_animation(&skeleton, ALONG, &moving, &mut r);
            let before = earlier(
                &skeleton,
                ALONG,
                &moving,
                &animation,
                0.0..=30.0,
                0.1,
                &mut r,
            );
            let place = random_place(&mut r);
            // Bodies from another pose: the joints stretch.
            let bodies = free
                .map_to_ragdoll(&before.to_model(&skeleton).unwrap(), place)
                .unwrap();
            for mapping in MAPPINGS {
                let a = free
                    .map_pose_to_skeleton(&bodies, None, &animation, place, mapping)
                    .unwrap();
                let b = locked
                    .map_pose_to_skeleton(&bodies, None, &animation, place, mapping)
                    .unwrap();
                let local = b.to_local(&skeleton).unwrap();
                let mut stretched = 0.0f32;
                for (j, bone) in skeleton.bones().iter().enumerate() {
                    assert!(angle(a.bones[j].rotation, b.bones[j].rotation) < 1e-6);
                    let Some(parent) = bone.parent else { continue };
                    if free.roles()[parent] == BoneRole::Free {
                        assert_eq!(a.bones[j], b.bones[j]);
                        continue;
                    }
                    let want = animation.bones[j].translation;
                    assert!(
                        local.bones[j].translation.distance(want) < 2e-5,
                        "bone `{}`",
                        bone.name
                    );
                    let unlocked = a.to_local(&skeleton).unwrap().bones[j].translation;
                    stretched = stretched.max(unlocked.distance(want));
                }
                assert!(
                    stretched > 1e-3,
                    "the unlocked bones stretch ({stretched} m)"
                );
            }
        }
    }
}

fn bone(name: &str, parent: Option<usize>, at: [f32; 3]) -> Bone {
    Bone {
        name: name.to_owned(),
        parent,
        bind: Transform::new(Vec3::from(at), Quat::IDENTITY),
    }
}

/// A skeleton where the head hangs from the spine below the chest: the
/// path from the head down to the hips shares the spine bones with the
/// chest's chain, which comes first (the chest's bone index is lower), so
/// the neck is no chain: it follows its parent. Bones of bodies that the
/// simplified ragdoll does not build follow their parents too.
#[test]
fn a_bone_on_two_paths_belongs_to_the_first_chain() {
    let skeleton = Skeleton::new(vec![
        bone("hips", None, [0.0, 1.0, 0.0]),
        bone("spine_a", Some(0), [0.0, 0.1, 0.0]),
        bone("spine_b", Some(1), [0.0, 0.15, 0.0]),
        bone("chest", Some(2), [0.0, 0.2, 0.0]),
        bone("neck", Some(2), [0.0, 0.25, 0.0]),
        bone("head", Some(4), [0.0, 0.1, 0.0]),
        bone("upper_arm_l", Some(3), [0.2, 0.0, 0.0]),
        bone("forearm_l", Some(6), [0.0, -0.3, 0.0]),
        bone("upper_arm_r", Some(3), [-0.2, 0.0, 0.0]),
        bone("forearm_r", Some(8), [0.0, -0.3, 0.0]),
        bone("thigh_l", Some(0), [0.1, -0.1, 0.0]),
        bone("shin_l", Some(10), [0.0, -0.4, 0.0]),
        bone("thigh_r", Some(0), [-0.1, -0.1, 0.0]),
        bone("shin_r", Some(12), [0.0, -0.4, 0.0]),
        bone("spine_lower", Some(0), [0.0, 0.15, 0.0]),
        bone("spine_upper", Some(0), [0.0, 0.3, 0.0]),
    ])
    .unwrap();
    let desc = RagdollDesc::reference_humanoid();
    let mapper = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod).unwrap();
    let chain = BoneRole::Chain { base: 0, top: 3 };
    let roles = mapper.roles();
    assert_eq!(
        &roles[1..5],
        &[chain, chain, BoneRole::Body(3), BoneRole::Follows]
    );
    assert_eq!(roles[5], BoneRole::Body(4));
    assert_eq!(&roles[14..], &[BoneRole::Follows, BoneRole::Follows]);
}

#[test]
fn every_bad_binding_is_refused_by_name() {
    let skeleton = Skeleton::reference();
    let desc = RagdollDesc::reference_humanoid();
    let spine = SpineMode::Rod;
    let mut bones: Vec<Option<usize>> = mapper_binding(&skeleton, &desc);
    let refused = |bones: &[Option<usize>]| {
        SkeletonMapper::with_binding(&skeleton, &desc, spine, bones)
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        refused(&bones[1..]),
        "skeleton mapper: binding has 12 entries for 13 bodies"
    );
    bones[4] = None;
    assert_eq!(
        refused(&bones),
        "body `head`: bone is missing: the skeleton has no bone `head` and every body needs one"
    );
    bones[4] = Some(63);
    assert_eq!(
        refused(&bones),
        "body `head`: bone is 63; the skeleton has 63 bones"
    );
    bones[4] = bones[3];
    assert_eq!(
        refused(&bones),
        "body `head`: bone is bone 6 `chest`, which body `chest` follows too"
    );
    let mut renamed = skeleton.bones().to_vec();
    renamed[index(&skeleton, "shin_r")].name = "calf_r".to_owned();
    let message = SkeletonMapper::new(&Skeleton::new(renamed).unwrap(), &desc, spine)
        .unwrap_err()
        .to_string();
    assert_eq!(
        message,
        "body `shin_r`: bone is missing: the skeleton has no bone `shin_r` and every body needs one"
    );
}

fn mapper_binding(skeleton: &Skeleton, desc: &RagdollDesc) -> Vec<Option<usize>> {
    desc.bodies
        .iter()
        .map(|b| skeleton.bone_index(&b.name))
        .collect()
}

#[test]
fn every_bad_pose_is_refused_by_name() {
    let skeleton = Skeleton::reference();
    let desc = RagdollDesc::reference_humanoid();
    let mapper = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod).unwrap();
    let bind = skeleton.bind_pose();
    let model = bind.to_model(&skeleton).unwrap();
    let bodies = Pose::bind(&desc);
    let map =
        |bodies: &Pose, rod: Option<(Quat, Quat)>, animation: &LocalPose, place: Transform| {
            mapper
                .map_pose_to_skeleton(bodies, rod, animation, place, SpineMapping::Arc)
                .unwrap_err()
                .to_string()
        };
    let id = Transform::IDENTITY;
    let mut short = bind.clone();
    short.bones.pop();
    assert_eq!(
        map(&bodies, None, &short, id),
        "bad pose: animation: 62 transforms for 63 bones"
    );
    let mut nan = bind.clone();
    nan.bones[index(&skeleton, "middle_2_l")].translation.y = f32::NAN;
    assert_eq!(
        map(&bodies, None, &nan, id),
        "bad pose: animation: bone 16 `middle_2_l`: translation is not finite"
    );
    let mut scaled = bind.clone();
    scaled.bones[2].rotation *= 1.1;
    assert!(
        map(&bodies, None, &scaled, id)
            .starts_with("bad pose: animation: bone 2 `spine_lower`: rotation")
    );
    let far = Transform::new(Vec3::new(2e6, 0.0, 0.0), Quat::IDENTITY);
    assert!(map(&bodies, None, &bind, far).starts_with("model_to_world: translation is"));
    let mut few = bodies.clone();
    few.bones.pop();
    assert_eq!(
        map(&few, None, &bind, id),
        "bad pose: 12 bones for 13 bodies"
    );
    let bad_frame = Some((Quat::IDENTITY, Quat::from_xyzw(0.0, 0.0, 0.0, 2.0)));
    assert!(
        map(&bodies, bad_frame, &bind, id).starts_with("spine rod `hips`-`chest`: rod frame_b")
    );
    let mut wrong = model.clone();
    wrong.bones[0].rotation = Quat::from_xyzw(f32::INFINITY, 0.0, 0.0, 1.0);
    let message = mapper.map_to_ragdoll(&wrong, id).unwrap_err().to_string();
    assert!(
        message.starts_with("bad pose: animation: bone 0 `root`: rotation"),
        "{message}"
    );
    // A ragdoll the mapper was not made for.
    let mut world = World::new(SolverConfig::default()).unwrap();
    let ragdoll = Ragdoll::build(
        &mut world,
        &desc,
        BuildOptions::new(SpineMode::Sockets),
        &bodies,
        None,
    )
    .unwrap();
    let message = mapper
        .map_to_skeleton(&ragdoll, &world, &bind, id, SpineMapping::Arc)
        .unwrap_err()
        .to_string();
    assert!(
        message.starts_with(
            "skeleton mapper: ragdoll is `reference-humanoid` (13 bodies, Sockets spine)"
        ),
        "{message}"
    );
}

fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -2.0f32..2.0,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(-1e30f32),
        1 => Just(0.0f32),
    ]
}

fn any_transform() -> impl Strategy<Value = Transform> {
    (
        any_f32(),
        any_f32(),
        any_f32(),
        any_f32(),
        any_f32(),
        any_f32(),
        any_f32(),
    )
        .prop_map(|(x, y, z, a, b, c, d)| Transform {
            translation: Vec3::new(x, y, z),
            rotation: Quat::from_xyzw(a, b, c, d),
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any transforms at all (non-finite, unnormalised, huge) in the
    /// animation, the model frame or the bodies: a result, never a panic,
    /// and a finite pose whenever it is accepted.
    #[test]
    fn no_input_panics(
        bone in 0usize..63,
        body in 0usize..13,
        t in any_transform(),
        place in any_transform(),
        frames in (any_transform(), any_transform()),
    ) {
        let skeleton = Skeleton::reference();
        let desc = RagdollDesc::reference_humanoid();
        for spine in [SpineMode::Rod, SpineMode::Sockets] {
            let mapper = SkeletonMapper::new(&skeleton, &desc, spine).unwrap();
            let mut animation = skeleton.bind_pose();
            animation.bones[bone] = t;
            let mut bodies = Pose::bind(&desc);
            bodies.bones[body] = (t.translation, t.rotation);
            let rod = Some((frames.0.rotation, frames.1.rotation));
            for mapping in MAPPINGS {
                for (b, a) in [(&bodies, &skeleton.bind_pose()), (&Pose::bind(&desc), &animation)] {
                    if let Ok(out) = mapper.map_pose_to_skeleton(b, rod, a, place, mapping) {
                        prop_assert!(out.bones.iter().all(|t| t.translation.is_finite() && t.rotation.is_finite()));
                    }
                }
            }
            let model = ModelPose { bones: animation.bones.clone() };
            if let Ok(pose) = mapper.map_to_ragdoll(&model, place) {
                prop_assert!(pose.validate(&desc).is_ok());
            }
        }
    }
}

/// A body follows the bone its description binds it to, at the binding's
/// offset: the head bound to `neck_3`; the hips renamed `pelvis` and bound
/// to `hips` with its frame half a metre above the bone. Before, the
/// mapper bound bodies by name only: the head to `head`, and `pelvis` was
/// refused.
#[test]
fn the_mapper_follows_the_descriptions_bindings() {
    let skeleton = Skeleton::reference();
    let text = vertebra_ragdoll::REFERENCE_HUMANOID
        .replace("\"hips\"", "\"pelvis\"")
        .replacen(
            "name = \"pelvis\"",
            "name = \"pelvis\"\nbone = \"hips\"\noffset = { translation = [0.0, 0.5, 0.0], rotation = [0.0, 0.0, 0.0, 1.0] }",
            1,
        )
        .replacen("name = \"head\"", "name = \"head\"\nbone = \"neck_3\"", 1);
    let mut desc = RagdollDesc::from_toml_with_skeleton(&text, &skeleton).unwrap();
    // The chest's frame authored 5 cm up its bone and turned 0.3 rad: a
    // body off its bind relation, at the end of the spine and neck chains.
    let chest = desc.body_index("chest").unwrap();
    let bound = desc.bodies[chest].bone.as_mut().unwrap();
    bound.offset = Transform::new(
        bound.offset.translation + Vec3::new(0.0, 0.05, 0.0),
        Quat::from_rotation_z(0.3) * bound.offset.rotation,
    );
    desc.validate().unwrap();
    for spine in [SpineMode::Rod, SpineMode::Sockets] {
        let mapper = SkeletonMapper::new(&skeleton, &desc, spine).unwrap();
        let body = |name: &str| desc.body_index(name).unwrap();
        assert_eq!(mapper.binding()[body("head")], index(&skeleton, "neck_3"));
        assert_eq!(mapper.binding()[body("pelvis")], index(&skeleton, "hips"));
        let bind = skeleton.bind_pose().to_model(&skeleton).unwrap();
        let place = Transform::new(Vec3::new(3.0, 0.0, -2.0), Quat::from_rotation_y(0.7));
        let bodies = mapper.map_to_ragdoll(&bind, place).unwrap();
        // The pelvis: the hips bone (1 m up at bind) times the offset.
        let hips = place * bind.bones[index(&skeleton, "hips")];
        let (p, q) = bodies.bones[body("pelvis")];
        let expected = hips * Transform::new(Vec3::new(0.0, 0.5, 0.0), Quat::IDENTITY);
        assert!(
            p.distance(expected.translation) < 1e-5,
            "{p} against {expected:?}"
        );
        assert!(angle(q, expected.rotation) < 1e-5);
        // The head keeps its bind offset from `neck_3`.
        let (p, _) = bodies.bones[body("head")];
        let head = place.transform_point(desc.bodies[body("head")].centre());
        assert!(p.distance(head) < 1e-5, "{p} against {head}");
        // And the skeleton's bind pose comes back through the bodies, the
        // chains to the chest (spine, neck, clavicles) included: they are
        // laid out where the bindings put the bodies.
        let local = skeleton.bind_pose();
        for mapping in MAPPINGS {
            let back = mapper
                .map_pose_to_skeleton(&bodies, None, &local, place, mapping)
                .unwrap();
            for (j, (got, want)) in back
                .bones
                .iter()
                .zip(&bind.in_world(place).bones)
                .enumerate()
            {
                assert!(
                    close(*got, *want, 2e-5, 2e-5),
                    "{spine:?} {mapping:?}: bone `{}`: {got:?} against {want:?}",
                    skeleton.bones()[j].name
                );
            }
        }
    }
}

/// A description edited by hand into one `validate` refuses is refused by
/// the mapper and by `body_masses`, naming the problem; before, a spine of
/// no bodies panicked in both, and a NaN segment mapped to NaN bodies.
#[test]
fn the_mapper_and_the_masses_refuse_a_broken_description() {
    let skeleton = Skeleton::reference();
    let good = RagdollDesc::reference_humanoid();
    let mut broken = Vec::new();
    let mut d = good.clone();
    d.spine.as_mut().unwrap().bodies.clear();
    broken.push(d);
    let mut d = good.clone();
    d.spine.as_mut().unwrap().bodies.truncate(1);
    broken.push(d);
    let mut d = good.clone();
    d.spine.as_mut().unwrap().bodies[1] = 99;
    broken.push(d);
    let mut d = good.clone();
    d.bodies[0].segment[0] = Vec3::NAN;
    broken.push(d);
    let mut d = good.clone();
    d.root = 99;
    broken.push(d);
    let mut d = good.clone();
    d.bodies.clear();
    broken.push(d);
    for (k, d) in broken.iter().enumerate() {
        let expected = d.validate().unwrap_err().to_string();
        for spine in [SpineMode::Rod, SpineMode::Sockets] {
            let got = SkeletonMapper::new(&skeleton, d, spine).unwrap_err();
            assert_eq!(got.to_string(), expected, "case {k}");
            let options = BuildOptions::new(spine);
            let got = vertebra_ragdoll::body_masses(d, &options).unwrap_err();
            assert_eq!(got.to_string(), expected, "case {k}");
        }
    }
}

/// Body positions beyond the world's coordinate range are refused by the
/// mapping from a pose, naming the body; before, 1e20 m mapped to
/// infinite bones.
#[test]
fn a_pose_out_of_range_is_refused() {
    let skeleton = Skeleton::reference();
    let desc = RagdollDesc::reference_humanoid();
    let mapper = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod).unwrap();
    let bind = skeleton.bind_pose();
    let mut pose = mapper
        .map_to_ragdoll(&bind.to_model(&skeleton).unwrap(), Transform::IDENTITY)
        .unwrap();
    for far in [1e20, 2e6] {
        pose.bones[0].0 = Vec3::splat(far);
        let message = mapper
            .map_pose_to_skeleton(&pose, None, &bind, Transform::IDENTITY, SpineMapping::Arc)
            .unwrap_err()
            .to_string();
        assert!(message.contains("bone `hips`: position"), "{message}");
    }
}

/// A description bound to a skeleton is mapped only with that skeleton
/// (same bones at the same bind pose, or a larger one holding them): its
/// offsets were made there. Before, a skeleton of the same names at twice
/// the size mapped the bind pose 1.48 m off, and one with two bones'
/// names swapped 0.2 m off.
#[test]
fn a_bound_description_refuses_another_skeleton() {
    let skeleton = Skeleton::reference();
    let desc =
        RagdollDesc::from_toml_with_skeleton(vertebra_ragdoll::REFERENCE_HUMANOID, &skeleton)
            .unwrap();
    assert!(SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod).is_ok());
    let mut doubled = skeleton.bones().to_vec();
    for bone in &mut doubled {
        bone.bind.translation *= 2.0;
    }
    let mut swapped = skeleton.bones().to_vec();
    let (chest, head) = (index(&skeleton, "chest"), index(&skeleton, "head"));
    swapped[chest].name = "head".to_owned();
    swapped[head].name = "chest".to_owned();
    for (bones, expected) in [
        (doubled, "skeleton bone `hips`: bind is 1 m and 0 rad"),
        (swapped, "skeleton bone `chest`: bind is"),
    ] {
        let other = Skeleton::new(bones).unwrap();
        let message = SkeletonMapper::new(&other, &desc, SpineMode::Rod)
            .unwrap_err()
            .to_string();
        assert!(message.starts_with(expected), "{message}");
    }
}

/// A body its description binds to no bone (a prop) cannot be mapped: the
/// mapper says so, naming it. Before, it fell back to the bone of its
/// name, and refused that bone as followed by another body.
#[test]
fn a_prop_body_is_refused_by_the_mapper_by_name() {
    let skeleton = Skeleton::reference();
    let mut desc =
        RagdollDesc::from_toml_with_skeleton(vertebra_ragdoll::REFERENCE_HUMANOID, &skeleton)
            .unwrap();
    let head = desc.body_index("head").unwrap();
    desc.bodies[head].bone = None;
    desc.validate().unwrap();
    let message = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod)
        .unwrap_err()
        .to_string();
    assert!(
        message.starts_with("body `head`: bone is none"),
        "{message}"
    );
}
