//! Ragdolls generated from a skeleton and per-bone choices: the shipped
//! humanoids' bone choices on the reference skeleton give descriptions
//! that validate and read back as themselves, with every capsule from its
//! bone's origin to the next chosen bone's, every joint at its bone's
//! origin in the frame asked for, the masses summing to the total; built
//! and dropped tumbling, their joints hold and their momentum changes by
//! gravity's impulse alone; every inconsistent choice is refused by bone
//! and reason. Expectations come from the skeleton's bind pose and the
//! humanoid files, whatever the bones' positions are.

#[path = "support/separation.rs"]
mod separation;

use glam::{Quat, Vec3};
use proptest::prelude::*;
use separation::worst_separation;
use vertebra_ragdoll::{
    BodyMass, BoneBody, BuildOptions, MIN_SEGMENT, Pose, Ragdoll, RagdollDesc, RagdollGenerator,
    RodSpine, SegmentEnd, Skeleton, SkeletonMapper, SpineMode, Transform,
};
use vertebra_world::{JointKind, SolverConfig, Swing, SwingTwist, World};

const DT: f32 = 1.0 / 60.0;

fn model(skeleton: &Skeleton) -> Vec<Transform> {
    skeleton.bind_pose().to_model(skeleton).unwrap().bones
}

fn bone(skeleton: &Skeleton, name: &str) -> usize {
    skeleton
        .bone_index(name)
        .unwrap_or_else(|| panic!("no bone `{name}`"))
}

/// Where each body of the humanoids' choice ends: the next chosen bone
/// along its line of first children, or its first child for a limb's last
/// body; the chest is ended at the neck's base and the head is given a
/// length.
const ENDS: [(&str, &str); 14] = [
    ("hips", "spine_lower"),
    ("spine_lower", "spine_upper"),
    ("spine_upper", "chest"),
    ("chest", "neck_1"),
    ("upper_arm_l", "forearm_l"),
    ("forearm_l", "hand_l"),
    ("upper_arm_r", "forearm_r"),
    ("forearm_r", "hand_r"),
    ("thigh_l", "shin_l"),
    ("shin_l", "foot_l"),
    ("thigh_r", "shin_r"),
    ("shin_r", "foot_r"),
    ("foot_l", "toes_l"),
    ("foot_r", "toes_r"),
];
const HEAD_LENGTH: f32 = 0.12;

/// The choice a designer makes from a humanoid file: its bodies' bones,
/// radii and masses, each joint's kind and limits (with the file's axis
/// and normal carried into the bone's frame when `own_axes`, else the
/// generator's default axes), its spine as a rod, its total mass.
fn choice(humanoid: &RagdollDesc, skeleton: &Skeleton, own_axes: bool) -> RagdollGenerator {
    let pose = model(skeleton);
    let mut generator = RagdollDesc::generator("generated", skeleton);
    for body in &humanoid.bodies {
        let mut chosen = BoneBody::new(&body.name, body.radius, BodyMass::Mass(body.mass));
        chosen = match body.name.as_str() {
            "chest" => chosen.ending_at("neck_1"),
            "head" => chosen.with_length(HEAD_LENGTH),
            _ => chosen,
        };
        if let Some(j) = humanoid
            .joints
            .iter()
            .find(|j| humanoid.bodies[j.child].name == body.name)
        {
            chosen.joint = j.kind;
            if own_axes {
                let into_bone = pose[bone(skeleton, &body.name)].rotation.conjugate();
                chosen.axis = Some(into_bone * j.axis());
                if let JointKind::Socket(_) = j.kind {
                    chosen.normal = Some(into_bone * (j.frame * Vec3::Y));
                }
            }
        }
        generator = generator.body(chosen);
    }
    let spine = humanoid
        .spine
        .as_ref()
        .expect("both humanoids have a spine");
    let name = |i: usize| humanoid.bodies[i].name.clone();
    generator
        .spine(RodSpine {
            from: name(spine.bodies[0]),
            to: name(*spine.bodies.last().unwrap()),
            bend_limit: spine.bend_limit,
            twist_limit: spine.twist_limit,
            bend_stiffness: spine.bend_stiffness,
            twist_stiffness: spine.twist_stiffness,
        })
        .total_mass(humanoid.total_mass())
}

fn humanoids() -> [(RagdollDesc, bool); 2] {
    [
        (RagdollDesc::reference_humanoid(), false),
        (RagdollDesc::anatomical_humanoid(), true),
    ]
}

#[test]
fn the_humanoids_choice_gives_capsules_between_the_bones_and_joints_at_their_origins() {
    let skeleton = Skeleton::reference();
    let pose = model(&skeleton);
    for (humanoid, own_axes) in humanoids() {
        let desc = choice(&humanoid, &skeleton, own_axes).generate().unwrap();
        desc.validate().unwrap();
        assert_eq!(desc.skeleton.as_ref(), Some(&skeleton));
        // One body per chosen bone, in bone order (the root body first),
        // bound to its bone with the bind poses' offset.
        let mut names: Vec<&str> = humanoid.bodies.iter().map(|b| b.name.as_str()).collect();
        names.sort_by_key(|n| bone(&skeleton, n));
        let generated: Vec<&str> = desc.bodies.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(generated, names);
        assert_eq!(desc.bodies[desc.root].name, "hips");
        for body in &desc.bodies {
            let b = bone(&skeleton, &body.name);
            let end = match ENDS.iter().find(|(from, _)| *from == body.name) {
                Some((_, to)) => pose[bone(&skeleton, to)].translation,
                None if body.name == "head" => pose[b].transform_point(Vec3::Y * HEAD_LENGTH),
                None => panic!("no end for `{}`", body.name),
            };
            assert_eq!(body.segment, [pose[b].translation, end], "{}", body.name);
            let same = humanoid
                .bodies
                .iter()
                .find(|h| h.name == body.name)
                .unwrap();
            assert_eq!(body.radius, same.radius);
            let binding = body.bone.expect("every generated body follows its bone");
            assert_eq!(binding.bone, b);
            let placed = pose[b] * binding.offset;
            assert!(
                placed.translation.distance(body.centre()) < 1e-6,
                "{}",
                body.name
            );
            assert!(placed.rotation.angle_between(Quat::IDENTITY) < 1e-3);
        }
        // The masses keep the file's ratios and sum to its total.
        let total = humanoid.total_mass();
        assert!(
            (desc.total_mass() - total).abs() < 1e-4 * total,
            "{}",
            desc.total_mass()
        );
        for body in &desc.bodies {
            let same = humanoid
                .bodies
                .iter()
                .find(|h| h.name == body.name)
                .unwrap();
            assert!(
                (body.mass - same.mass).abs() < 1e-5 * same.mass,
                "{}",
                body.name
            );
        }
        // A joint per body but the root, named after its bone, at the
        // bone's origin, from the body of the nearest chosen ancestor: the
        // file's joint tree.
        assert_eq!(desc.joints.len(), humanoid.joints.len());
        for j in &desc.joints {
            let child = &desc.bodies[j.child].name;
            assert_eq!(&j.name, child);
            assert_eq!(
                j.anchor,
                pose[bone(&skeleton, child)].translation,
                "{child}"
            );
            let file = humanoid
                .joints
                .iter()
                .find(|f| &humanoid.bodies[f.child].name == child)
                .unwrap();
            assert_eq!(
                desc.bodies[j.parent].name,
                humanoid.bodies[file.parent].name
            );
            assert_eq!(j.kind, file.kind, "{child}");
            if own_axes {
                // The file's frame, carried through the bone's.
                let turned = j.frame.angle_between(file.frame);
                assert!(turned < 1e-5, "{child}: {turned} rad from the file's frame");
            } else {
                // A socket's twist axis runs along its capsule.
                let [a, b] = desc.bodies[j.child].segment;
                let along = (b - a).normalize();
                assert!(
                    j.axis().distance(along) < 1e-6,
                    "{child}: {} {along}",
                    j.axis()
                );
            }
        }
        // The spine: the chosen bones from hips to chest.
        let spine = desc.spine.as_ref().unwrap();
        let chain: Vec<&str> = spine
            .bodies
            .iter()
            .map(|&i| desc.bodies[i].name.as_str())
            .collect();
        let file = humanoid.spine.as_ref().unwrap();
        let expected: Vec<&str> = file
            .bodies
            .iter()
            .map(|&i| humanoid.bodies[i].name.as_str())
            .collect();
        assert_eq!(chain, expected);
        assert_eq!(
            (spine.bend_limit, spine.twist_limit, spine.bend_stiffness),
            (file.bend_limit, file.twist_limit, file.bend_stiffness)
        );
        // Written and read back as itself, bit for bit.
        assert_eq!(RagdollDesc::from_toml(&desc.to_toml()).unwrap(), desc);
        // The mapper puts every body at its bind frame from the skeleton's
        // bind pose.
        let mapper = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod).unwrap();
        let bodies = mapper
            .map_to_ragdoll(
                &skeleton.bind_pose().to_model(&skeleton).unwrap(),
                Transform::IDENTITY,
            )
            .unwrap();
        for ((at, turned), body) in bodies.bones.iter().zip(&desc.bodies) {
            assert!(at.distance(body.centre()) < 1e-6, "{}", body.name);
            assert!(turned.angle_between(Quat::IDENTITY) < 1e-3, "{}", body.name);
        }
    }
}

#[test]
fn the_next_chosen_bone_ends_a_body_and_a_density_gives_its_mass() {
    let skeleton = Skeleton::reference();
    let pose = model(&skeleton);
    let density = 1000.0;
    // The hips end at the next chosen bone up the spine, skipping the
    // unchosen spine_lower and spine_middle; the thigh at its first child.
    let desc = RagdollDesc::generator("trunk", &skeleton)
        .body(BoneBody::new("hips", 0.1, BodyMass::Mass(10.0)))
        .body(BoneBody::new(
            "spine_upper",
            0.1,
            BodyMass::Density(density),
        ))
        .body(BoneBody::new("thigh_l", 0.07, BodyMass::Mass(7.0)))
        .generate()
        .unwrap();
    let at = |name: &str| pose[bone(&skeleton, name)].translation;
    assert_eq!(desc.bodies[0].segment, [at("hips"), at("spine_upper")]);
    assert_eq!(desc.bodies[1].segment, [at("spine_upper"), at("spine_top")]);
    assert_eq!(desc.bodies[2].segment, [at("thigh_l"), at("shin_l")]);
    // A capsule's volume: its cylinder and two half-spheres.
    let (r, length) = (0.1f32, at("spine_upper").distance(at("spine_top")));
    let volume =
        core::f32::consts::PI * r * r * length + 4.0 / 3.0 * core::f32::consts::PI * r.powi(3);
    assert!((desc.bodies[1].mass - density * volume).abs() < 1e-4 * density * volume);
    assert_eq!(desc.spine, None);
}

/// The ragdoll's linear momentum (kg m/s) and mass (kg) in the world.
fn momentum(w: &World, ragdoll: &Ragdoll) -> (Vec3, f32) {
    let (mut p, mut m) = (Vec3::ZERO, 0.0);
    for b in ragdoll.bodies.iter().flatten() {
        let mass = w.bodies().mass[b.index()];
        p += w.body(*b).unwrap().linear_velocity * mass;
        m += mass;
    }
    (p, m)
}

/// Dropped tumbling (turning at 3 rad/s, a forearm kicked), both
/// generated humanoids in both spine modes keep their joints together and
/// stay finite, and, with no other force than gravity on them, their
/// momentum grows by exactly gravity's impulse.
#[test]
fn a_generated_ragdoll_dropped_tumbling_holds_its_joints() {
    let skeleton = Skeleton::reference();
    for (humanoid, own_axes) in humanoids() {
        let desc = choice(&humanoid, &skeleton, own_axes).generate().unwrap();
        for spine in [SpineMode::Sockets, SpineMode::Rod] {
            let config = SolverConfig::default();
            let mut w = World::new(config).unwrap();
            let bind = Pose::bind(&desc);
            let pivot = desc.bodies[desc.root].centre();
            let lift = Vec3::new(0.0, 2.0, 0.0);
            let now = bind.moved(pivot, Quat::from_rotation_z(0.3), lift);
            let before = bind.moved(pivot, Quat::from_rotation_z(0.3 - 3.0 * DT), lift);
            let options = BuildOptions::new(spine);
            let ragdoll =
                Ragdoll::build(&mut w, &desc, options, &now, Some((&before, DT))).unwrap();
            ragdoll
                .apply_impulse(&mut w, "forearm_l", Vec3::new(3.0, 2.0, -4.0), None)
                .unwrap();
            w.step(DT).unwrap();
            let (start, mass) = momentum(&w, &ragdoll);
            let (mut separation, frames) = (worst_separation(&mut w), 120);
            for _ in 0..frames {
                w.step(DT).unwrap();
                separation = separation.max(worst_separation(&mut w));
                for b in ragdoll.bodies.iter().flatten() {
                    let s = w.body(*b).unwrap();
                    assert!(s.position.is_finite() && s.orientation.is_finite());
                    assert!(s.linear_velocity.is_finite() && s.angular_velocity.is_finite());
                }
            }
            let gained = momentum(&w, &ragdoll).0 - start;
            let gravity = config.gravity * mass * frames as f32 * DT;
            eprintln!(
                "{} {spine:?}: worst joint separation {separation:.3} cm; momentum gained \
                 {gained} against gravity's {gravity}",
                humanoid.name
            );
            assert!(separation < 0.5, "{separation} cm");
            assert!(
                (gained - gravity).length() < 1e-5 * gravity.length(),
                "{gained} {gravity}"
            );
        }
    }
}

fn refusal(generator: RagdollGenerator) -> String {
    generator.generate().unwrap_err().to_string()
}

/// The hips, the left leg and the head, with `edit` applied to the body
/// on bone `on`.
fn leg(on: &str, edit: impl Fn(BoneBody) -> BoneBody) -> RagdollGenerator {
    let skeleton = Skeleton::reference();
    let bodies = [
        BoneBody::new("hips", 0.1, BodyMass::Mass(10.0)),
        BoneBody::new("thigh_l", 0.07, BodyMass::Mass(7.0)),
        BoneBody::new("shin_l", 0.055, BodyMass::Mass(4.0)).hinge(Vec3::X, Some([-2.6, 0.0])),
        BoneBody::new("head", 0.1, BodyMass::Mass(5.0)).with_length(0.2),
    ];
    bodies
        .into_iter()
        .fold(RagdollDesc::generator("leg", &skeleton), |g, b| {
            g.body(if b.bone == on { edit(b) } else { b })
        })
}

#[test]
fn every_inconsistent_choice_is_refused_by_bone_and_reason() {
    leg("", |b| b).generate().unwrap();
    let spine = |from: &str, to: &str| RodSpine {
        from: from.to_owned(),
        to: to.to_owned(),
        bend_limit: 1.0,
        twist_limit: [-0.5, 0.5],
        bend_stiffness: 2.0,
        twist_stiffness: 2.0,
    };
    let cases = [
        (
            leg("", |b| b).body(BoneBody::new("tail", 0.05, BodyMass::Mass(1.0))),
            "generator: bone `tail` is not a bone of the skeleton".to_owned(),
        ),
        (
            leg("", |b| b).body(BoneBody::new("thigh_l", 0.05, BodyMass::Mass(1.0))),
            "bone `thigh_l`: bone is chosen twice; a bone has at most one body".to_owned(),
        ),
        (
            leg("thigh_l", |b| b.ending_at("thigh_l")),
            format!("bone `thigh_l`: end is 0 m from the bone's origin; a segment is at least {MIN_SEGMENT} m long"),
        ),
        (
            leg("head", |b| b.with_length(0.0)),
            "bone `head`: length is 0; must be positive".to_owned(),
        ),
        (
            leg("head", |b| b.with_length(-0.2)),
            "bone `head`: length is -0.2; must be positive".to_owned(),
        ),
        (
            leg("shin_l", |b| b.with_normal(Vec3::Y)),
            "bone `shin_l`: normal is for sockets only".to_owned(),
        ),
        (
            leg("shin_l", |b| BoneBody { axis: Some(Vec3::NAN), ..b.fixed() }),
            "bone `shin_l`: axis is for sockets and hinges only".to_owned(),
        ),
        (
            leg("hips", |b| b.hinge(Vec3::X, Some([f32::NAN, 1.0]))),
            "bone `hips`: joint is given, but the root body has no parent body to join".to_owned(),
        ),
        (
            leg("hips", |b| BoneBody::new("spine_lower", b.radius, b.mass)),
            "bone `thigh_l`: ancestor is not chosen, and only the root body (`spine_lower`) may have none: choose a bone above it, or leave it out".to_owned(),
        ),
        (
            leg("head", |b| BoneBody { end: SegmentEnd::Next, ..b }),
            "bone `head`: end is the next bone along it, but it has no child; give its end (a bone, or a length)".to_owned(),
        ),
        (
            leg("thigh_l", |b| b.ending_at("knee")),
            "bone `thigh_l`: end `knee` is not a bone of the skeleton".to_owned(),
        ),
        (
            leg("head", |b| b.with_length(f32::NAN)),
            "bone `head`: length is not finite".to_owned(),
        ),
        (
            leg("head", |b| BoneBody { end: SegmentEnd::Point(Vec3::new(0.0, f32::NAN, 0.0)), ..b }),
            "bone `head`: end is not finite".to_owned(),
        ),
        (
            leg("thigh_l", |b| BoneBody { radius: f32::NAN, ..b }),
            "bone `thigh_l`: radius is not finite".to_owned(),
        ),
        (
            leg("thigh_l", |b| BoneBody { radius: -0.07, ..b }),
            "bone `thigh_l`: radius is -0.07; must be positive".to_owned(),
        ),
        (
            leg("thigh_l", |b| BoneBody { mass: BodyMass::Mass(0.0), ..b }),
            "bone `thigh_l`: mass is 0; must be positive".to_owned(),
        ),
        (
            leg("thigh_l", |b| BoneBody { mass: BodyMass::Mass(f32::INFINITY), ..b }),
            "bone `thigh_l`: mass is not finite".to_owned(),
        ),
        (
            leg("thigh_l", |b| BoneBody { mass: BodyMass::Density(-1000.0), ..b }),
            "bone `thigh_l`: density is -1000; must be positive".to_owned(),
        ),
        (
            leg("shin_l", |b| b.hinge(Vec3::X, Some([0.0, 4.0]))),
            "joint `shin_l`: range must be [min, max] within [-180, 180] degrees".to_owned(),
        ),
        (
            leg("shin_l", |b| b.hinge(Vec3::ZERO, None)),
            "joint `shin_l`: axis has zero length".to_owned(),
        ),
        (
            leg("thigh_l", |b| b.socket(SwingTwist::FREE.with_swing(Swing::Ellipse { y: 1.0, z: 0.5 }))),
            "joint `thigh_l`: normal is missing: an elliptical or pyramid swing needs it to place its axes".to_owned(),
        ),
        (
            leg("", |b| b).spine(spine("hips", "spine_upper")),
            "bone `spine_upper`: to is a spine end, but not a chosen bone".to_owned(),
        ),
        (
            leg("", |b| b).spine(spine("thigh_l", "head")),
            "bone `head`: to is not below `thigh_l`; a spine runs from a bone to one of its descendants".to_owned(),
        ),
        (
            leg("", |b| b).spine(spine("hips", "hips")),
            "bone `hips`: to is the spine's from bone; a spine joins two".to_owned(),
        ),
        (
            leg("", |b| b).spine(spine("pelvis", "head")),
            "spine: from `pelvis` is not a bone of the skeleton".to_owned(),
        ),
        (
            leg("", |b| b).total_mass(-1.0),
            "ragdoll: total_mass must be positive".to_owned(),
        ),
    ];
    for (generator, expected) in cases {
        assert_eq!(refusal(generator), expected);
    }
}

/// A number that is nearly always in range, once in a while not finite,
/// zero, negative or huge (often enough that a choice of ten bones is
/// refused about half the time).
fn number(valid: core::ops::Range<f32>) -> impl Strategy<Value = f32> {
    prop_oneof![
        150 => valid,
        1 => prop_oneof![
            Just(f32::NAN),
            Just(f32::INFINITY),
            Just(0.0),
            Just(-0.1),
            Just(1e30),
        ],
    ]
}

/// Any choice of one bone: any radius, mass or density, end and joint.
fn bone_body(name: String) -> impl Strategy<Value = BoneBody> {
    let names = Skeleton::reference()
        .bones()
        .iter()
        .map(|b| b.name.clone())
        .chain(["nope".to_owned()])
        .collect::<Vec<_>>();
    let end = prop_oneof![
        1 => Just(SegmentEnd::Next),
        1 => proptest::sample::select(names).prop_map(SegmentEnd::Bone),
        3 => (number(-0.3..0.3), number(-0.3..0.3), number(-0.3..0.3))
            .prop_map(|(x, y, z)| SegmentEnd::Point(Vec3::new(x, y, z))),
    ];
    let mass = prop_oneof![
        number(0.1..20.0).prop_map(BodyMass::Mass),
        number(100.0..2000.0).prop_map(BodyMass::Density),
    ];
    let axis = (number(-1.0..1.0), number(-1.0..1.0), number(-1.0..1.0))
        .prop_map(|(x, y, z)| Vec3::new(x, y, z));
    // Angles as a file gives them: degrees, converted (an angle set in
    // radians by hand may fall between two conversions, and is written
    // back as the nearest one).
    let angle = |degrees| number(degrees).prop_map(f32::to_radians);
    let joint = prop_oneof![
        Just(JointKind::Socket(SwingTwist::FREE)),
        (angle(0.0..190.0), angle(-190.0..0.0), angle(0.0..190.0)).prop_map(|(cone, lo, hi)| {
            let limits = SwingTwist::FREE.with_swing(Swing::Cone(cone));
            JointKind::Socket(limits.with_twist(lo, hi))
        }),
        (angle(-190.0..0.0), angle(0.0..190.0)).prop_map(|(lo, hi)| JointKind::Hinge {
            range: Some([lo, hi]),
            softness: vertebra_world::LimitSoftness::Hard,
        }),
        Just(JointKind::Fixed),
    ];
    (
        number(0.01..0.2),
        mass,
        end,
        joint,
        proptest::option::of(axis),
    )
        .prop_map(move |(radius, mass, end, joint, axis)| BoneBody {
            end,
            joint,
            axis,
            ..BoneBody::new(&name, radius, mass)
        })
}

/// Any choice of bones of the reference skeleton, with or without a spine
/// between two of its bones.
fn any_choice() -> impl Strategy<Value = RagdollGenerator> {
    let names: Vec<String> = Skeleton::reference()
        .bones()
        .iter()
        .map(|b| b.name.clone())
        .collect();
    // A spine between two of the chosen bones (by their places in the
    // choice), or none.
    let spine = proptest::option::weighted(0.3, (any::<usize>(), any::<usize>()));
    // Mostly the skeleton's root is chosen too, so that every other bone
    // has a chosen ancestor.
    let rooted = proptest::bool::weighted(0.8);
    (proptest::sample::subsequence(names, 1..12), spine, rooted)
        .prop_flat_map(|(mut chosen, spine, rooted)| {
            if rooted && chosen[0] != "root" {
                chosen.insert(0, "root".to_owned());
            }
            let spine = spine.map(|(a, b)| {
                (
                    chosen[a % chosen.len()].clone(),
                    chosen[b % chosen.len()].clone(),
                )
            });
            let bodies: Vec<_> = chosen.into_iter().map(bone_body).collect();
            (bodies, Just(spine))
        })
        .prop_map(|(bodies, spine)| {
            let generator = RagdollDesc::generator("any", &Skeleton::reference());
            let generator = bodies.into_iter().fold(generator, RagdollGenerator::body);
            match spine {
                Some((from, to)) => generator.spine(RodSpine {
                    from,
                    to,
                    bend_limit: 1.0,
                    twist_limit: [-0.5, 0.5],
                    bend_stiffness: 2.0,
                    twist_stiffness: 2.0,
                }),
                None => generator,
            }
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]
    /// Whatever is chosen, generating never panics: it gives a
    /// description that validates, reads back as itself and has its
    /// joints at its bones' origins, or a refusal.
    #[test]
    fn any_choice_generates_a_valid_description_or_is_refused(generator in any_choice()) {
        let skeleton = Skeleton::reference();
        let pose = model(&skeleton);
        match generator.generate() {
            Ok(desc) => {
                prop_assert!(desc.validate().is_ok());
                prop_assert_eq!(&RagdollDesc::from_toml(&desc.to_toml()).unwrap(), &desc);
                for j in &desc.joints {
                    let b = bone(&skeleton, &desc.bodies[j.child].name);
                    prop_assert_eq!(j.anchor, pose[b].translation);
                }
            }
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
    }
}

/// The reference humanoid's choice as a generator file, every form of end,
/// mass and joint on some body.
const GENERATOR: &str = r#"
name = "generated"
total_mass = 69.0

[[body]]
bone = "hips"
radius = 0.1
mass = 11.0

[[body]]
bone = "spine_lower"
radius = 0.1
mass = 6.0
joint = { swing = 20.0, twist = [-10.0, 10.0] }

[[body]]
bone = "spine_upper"
radius = 0.1
density = 1000.0
joint = { kind = "socket", axis = [0.0, 1.0, 0.0], normal = [1.0, 0.0, 0.0], swing = { y = 20.0, z = 10.0 }, softness = 0.001 }

[[body]]
bone = "chest"
radius = 0.12
mass = 12.0
end = "neck_1"
joint = { kind = "fixed" }

[[body]]
bone = "head"
radius = 0.1
mass = 5.0
length = 0.12

[[body]]
bone = "shin_l"
radius = 0.055
mass = 4.0
point = [0.0, 0.3, 0.0]
joint = { kind = "hinge", range = [-150.0, 0.0] }

[[body]]
bone = "thigh_l"
radius = 0.07
mass = 7.0

[spine]
from = "hips"
to = "chest"
bend_limit = 60.0
twist_limit = [-30.0, 30.0]
bend_stiffness = 2.0
twist_stiffness = 2.0
"#;

#[test]
fn a_generator_file_reads_as_the_same_choices_in_code() {
    let skeleton = Skeleton::reference();
    let from_file = RagdollGenerator::from_toml(GENERATOR, &skeleton)
        .unwrap()
        .generate()
        .unwrap();
    let degrees = |d: f32| d.to_radians();
    let ellipse = SwingTwist {
        swing: Swing::Ellipse {
            y: degrees(20.0),
            z: degrees(10.0),
        },
        twist: None,
        softness: vertebra_world::LimitSoftness::compliant(0.001),
    };
    let cone = SwingTwist::FREE
        .with_swing(Swing::Cone(degrees(20.0)))
        .with_twist(degrees(-10.0), degrees(10.0));
    let in_code = RagdollDesc::generator("generated", &skeleton)
        .body(BoneBody::new("hips", 0.1, BodyMass::Mass(11.0)))
        .body(BoneBody::new("spine_lower", 0.1, BodyMass::Mass(6.0)).socket(cone))
        .body(BoneBody {
            axis: Some(Vec3::Y),
            ..BoneBody::new("spine_upper", 0.1, BodyMass::Density(1000.0))
                .socket(ellipse)
                .with_normal(Vec3::X)
        })
        .body(
            BoneBody::new("chest", 0.12, BodyMass::Mass(12.0))
                .ending_at("neck_1")
                .fixed(),
        )
        .body(BoneBody::new("head", 0.1, BodyMass::Mass(5.0)).with_length(0.12))
        .body(BoneBody {
            end: SegmentEnd::Point(Vec3::new(0.0, 0.3, 0.0)),
            axis: None,
            ..BoneBody::new("shin_l", 0.055, BodyMass::Mass(4.0))
                .hinge(Vec3::X, Some([degrees(-150.0), degrees(0.0)]))
        })
        .body(BoneBody::new("thigh_l", 0.07, BodyMass::Mass(7.0)))
        .spine(RodSpine {
            from: "hips".to_owned(),
            to: "chest".to_owned(),
            bend_limit: degrees(60.0),
            twist_limit: [degrees(-30.0), degrees(30.0)],
            bend_stiffness: 2.0,
            twist_stiffness: 2.0,
        })
        .total_mass(69.0)
        .generate()
        .unwrap();
    assert_eq!(from_file, in_code);
    // The hinge without an axis turns about the shin's +X.
    let pose = model(&skeleton);
    let shin = from_file
        .joints
        .iter()
        .find(|j| j.name == "shin_l")
        .unwrap();
    let x = pose[bone(&skeleton, "shin_l")].rotation * Vec3::X;
    assert!(shin.axis().distance(x) < 1e-6, "{}", shin.axis());
}

#[test]
fn malformed_generator_files_are_refused_by_line_bone_and_field() {
    let skeleton = Skeleton::reference();
    let edited = |from: &str, to: &str| {
        assert!(GENERATOR.contains(from), "`{from}`");
        GENERATOR.replacen(from, to, 1)
    };
    let cases = [
        (
            edited("mass = 11.0", "mass = 11.0\ndensity = 900.0"),
            "line 5: bone `hips`: mass and density both give the mass; give one",
        ),
        (
            edited("mass = 11.0\n", ""),
            "line 5: bone `hips`: mass is missing: give mass or density",
        ),
        (
            edited("length = 0.12", "length = 0.12\nend = \"neck_3\""),
            "line 29: bone `head`: end is given twice: give one of end, length and point",
        ),
        (
            edited(
                "joint = { kind = \"hinge\",",
                "joint = { kind = \"hinge\", swing = 20.0,",
            ),
            "line 35: bone `shin_l`: joint: swing is for sockets only; this joint is a hinge",
        ),
        (
            edited("kind = \"fixed\"", "kind = \"weld\""),
            "line 22: bone `chest`: joint: kind is `weld`; must be socket, hinge or fixed",
        ),
        (
            edited(
                "radius = 0.1\nmass = 11.0",
                "radius = 0.1\nmass = 11.0\ncolour = \"red\"",
            ),
            "malformed generator file: line 9: unknown field `colour`",
        ),
    ];
    for (text, expected) in cases {
        let e = RagdollGenerator::from_toml(&text, &skeleton)
            .unwrap_err()
            .to_string();
        assert!(e.contains(expected), "{e}\nnot {expected}");
    }
    // What reads is checked when generated, by bone.
    let unknown = edited("bone = \"thigh_l\"", "bone = \"femur\"");
    let e = RagdollGenerator::from_toml(&unknown, &skeleton)
        .unwrap()
        .generate()
        .unwrap_err()
        .to_string();
    assert_eq!(e, "generator: bone `femur` is not a bone of the skeleton");
}

#[test]
fn a_generator_file_is_read_from_disk_and_named_in_its_errors() {
    let skeleton = Skeleton::reference();
    let dir = std::env::temp_dir().join(format!("vertebra-generate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("generator.toml");
    std::fs::write(&path, GENERATOR).unwrap();
    let read = RagdollGenerator::from_file(&path, &skeleton).unwrap();
    let parsed = RagdollGenerator::from_toml(GENERATOR, &skeleton).unwrap();
    assert_eq!(read.generate().unwrap(), parsed.generate().unwrap());
    std::fs::write(
        &path,
        GENERATOR.replacen("radius = 0.1", "radius = \"wide\"", 1),
    )
    .unwrap();
    let e = RagdollGenerator::from_file(&path, &skeleton)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!(
            "{}: malformed generator file: line 7",
            path.display()
        )),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
    let e = RagdollGenerator::from_file(&path, &skeleton)
        .unwrap_err()
        .to_string();
    assert!(e.contains("cannot read the generator file"), "{e}");
}
