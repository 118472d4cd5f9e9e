//! Scene queries: rays, swept spheres and capsules, overlaps and shots,
//! against closed forms and against a brute force over every collider.

use glam::{Quat, Vec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_collide::{
    Collider, ColliderShape, CollisionGroups, Collisions, QueryFilter, QueryHit, QueryShape,
};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, SpineMode};
use vertebra_world::{BodyDesc, BodyHandle, BodyKind, Error, Shape, SolverConfig, World};

fn world() -> (World, Collisions) {
    let mut w = World::new(SolverConfig::default()).unwrap();
    let mut c = Collisions::new();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    (w, c)
}

fn humanoid(w: &mut World, c: &mut Collisions, at: Vec3) -> Ragdoll {
    let desc = RagdollDesc::reference_humanoid();
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, at);
    c.build_ragdoll(w, &desc, BuildOptions::new(SpineMode::Rod), &pose, None)
        .unwrap()
}

fn bone(ragdoll: &Ragdoll, name: &str) -> u32 {
    let desc = ragdoll.description();
    desc.bodies.iter().position(|b| b.name == name).unwrap() as u32
}

#[test]
fn a_ray_names_the_bone_it_hits_and_where() {
    let (mut w, mut c) = world();
    let ragdoll = humanoid(&mut w, &mut c, Vec3::ZERO);
    c.refresh_queries(&w).unwrap();
    // Along -z at the chest's height, from in front: the chest capsule
    // (its segment along x at y = 1.45, radius 0.12).
    let hit = c
        .cast_ray(
            &w,
            Vec3::new(0.0, 1.45, 2.0),
            -Vec3::Z,
            10.0,
            &QueryFilter::default(),
        )
        .unwrap()
        .expect("the chest is in the way");
    let part = hit.part.expect("a ragdoll's body");
    assert_eq!(part.ragdoll, ragdoll.first_body().unwrap());
    assert_eq!(part.bone, bone(&ragdoll, "chest"));
    assert_eq!(ragdoll.bodies[part.bone as usize], Some(hit.body));
    assert!((hit.distance - (2.0 - 0.12)).abs() < 1e-4, "{hit:?}");
    assert!((hit.point - Vec3::new(0.0, 1.45, 0.12)).length() < 1e-4);
    assert!((hit.normal - Vec3::Z).length() < 1e-4);
    // Straight down past the ragdoll's side: the ground.
    let down = c
        .cast_ray(
            &w,
            Vec3::new(3.0, 5.0, 0.0),
            -Vec3::Y,
            10.0,
            &QueryFilter::default(),
        )
        .unwrap()
        .unwrap();
    assert_eq!(
        (down.distance, down.normal, down.part),
        (5.0, Vec3::Y, None)
    );
    // Out of reach: nothing.
    let short = c.cast_ray(
        &w,
        Vec3::new(0.0, 1.45, 2.0),
        -Vec3::Z,
        1.0,
        &QueryFilter::default(),
    );
    assert_eq!(short.unwrap(), None);
}

#[test]
fn filters_pass_through_bodies_ragdolls_groups_and_kinds() {
    let (mut w, mut c) = world();
    let front = humanoid(&mut w, &mut c, Vec3::new(0.0, 0.0, 0.5));
    let back = humanoid(&mut w, &mut c, Vec3::new(0.0, 0.0, -0.5));
    c.refresh_queries(&w).unwrap();
    let ray = |c: &Collisions, w: &World, filter: &QueryFilter| {
        c.cast_ray(w, Vec3::new(0.0, 1.45, 3.0), -Vec3::Z, 10.0, filter)
            .unwrap()
    };
    let chest = |r: &Ragdoll| r.bodies[bone(r, "chest") as usize].unwrap();
    let all = QueryFilter::default();
    assert_eq!(ray(&c, &w, &all).unwrap().body, chest(&front));
    let past_front = QueryFilter {
        exclude_ragdoll: front.first_body(),
        ..all
    };
    assert_eq!(ray(&c, &w, &past_front).unwrap().body, chest(&back));
    let past_chest = QueryFilter {
        exclude_body: Some(chest(&front)),
        ..all
    };
    // Through the front chest's hole: the back chest.
    assert_eq!(ray(&c, &w, &past_chest).unwrap().body, chest(&back));
    let static_only = QueryFilter {
        dynamic_bodies: false,
        ..all
    };
    assert_eq!(ray(&c, &w, &static_only), None, "no static body in the way");
    // The front ragdoll in group 2 only; a query that sees group 1 only.
    let team = CollisionGroups {
        membership: 2,
        filter: u32::MAX,
    };
    c.set_ragdoll_groups(&front, team).unwrap();
    let group_one = QueryFilter {
        groups: CollisionGroups {
            membership: u32::MAX,
            filter: 1,
        },
        ..all
    };
    assert_eq!(ray(&c, &w, &group_one).unwrap().body, chest(&back));
}

/// The nearest hit over every collider, tested one by one with parry (as
/// a brute force would), ties to the lower index.
fn brute_ray(
    c: &Collisions,
    w: &World,
    origin: Vec3,
    dir: Vec3,
    reach: f32,
) -> Option<(usize, f32)> {
    let ray = parry3d::query::Ray::new(origin, dir.normalize());
    let mut best: Option<(usize, f32)> = None;
    for (k, (collider, shape)) in c.shapes().enumerate() {
        let s = w.body(collider.body).unwrap();
        let pose = parry3d::math::Pose::from_parts(s.position, s.orientation);
        if let Some(hit) = shape.cast_ray_and_get_normal(&pose, &ray, reach, true)
            && best.is_none_or(|(_, b)| hit.time_of_impact < b)
        {
            best = Some((k, hit.time_of_impact));
        }
    }
    best
}

/// A scene of random boxes, spheres and capsules (static and dynamic) on
/// the ground.
fn clutter(seed: u64) -> (World, Collisions) {
    let (mut w, mut c) = world();
    let mut r = StdRng::seed_from_u64(seed);
    for k in 0..120 {
        let shape = match k % 3 {
            0 => Shape::Sphere {
                radius: r.random_range(0.05..0.4),
            },
            1 => Shape::Box {
                half_extents: Vec3::new(
                    r.random_range(0.05..0.5),
                    r.random_range(0.05..0.5),
                    r.random_range(0.05..0.5),
                ),
            },
            _ => Shape::capsule(
                Vec3::new(0.0, -r.random_range(0.05..0.4), 0.0),
                Vec3::new(0.0, r.random_range(0.05..0.4), 0.0),
                r.random_range(0.03..0.2),
            ),
        };
        let at = Vec3::new(
            r.random_range(-6.0..6.0),
            r.random_range(0.0..4.0),
            r.random_range(-6.0..6.0),
        );
        let turn = Quat::from_euler(
            glam::EulerRot::XYZ,
            r.random_range(-3.0..3.0),
            r.random_range(-3.0..3.0),
            r.random_range(-3.0..3.0),
        );
        let desc = if k % 4 == 0 {
            BodyDesc::fixed()
        } else {
            BodyDesc::dynamic(shape.mass_properties(500.0).unwrap())
        };
        let body = w
            .add_body(desc.with_position(at).with_orientation(turn))
            .unwrap();
        c.add(Collider::new(body, ColliderShape::Solid(shape)))
            .unwrap();
    }
    (w, c)
}

#[test]
fn rays_hit_what_a_brute_force_over_every_collider_hits() {
    for seed in 0..4 {
        let (w, mut c) = clutter(seed);
        let mut r = StdRng::seed_from_u64(100 + seed);
        let rays: Vec<(Vec3, Vec3, f32)> = (0..500)
            .map(|_| {
                let origin = Vec3::new(
                    r.random_range(-8.0..8.0),
                    r.random_range(-1.0..6.0),
                    r.random_range(-8.0..8.0),
                );
                let toward = Vec3::new(
                    r.random_range(-6.0..6.0),
                    r.random_range(0.0..4.0),
                    r.random_range(-6.0..6.0),
                );
                let reach = if r.random_bool(0.2) {
                    f32::INFINITY
                } else {
                    r.random_range(0.0..20.0)
                };
                (origin, (toward - origin).normalize(), reach)
            })
            .collect();
        let all = QueryFilter::default();
        let answer = |c: &Collisions, (o, d, reach): (Vec3, Vec3, f32)| {
            c.cast_ray(&w, o, d, reach, &all)
                .unwrap()
                .map(|h: QueryHit| (h.collider, h.distance))
        };
        let untreed: Vec<_> = rays.iter().map(|&ray| answer(&c, ray)).collect();
        c.refresh_queries(&w).unwrap();
        let mut hits = 0;
        for (k, &(o, d, reach)) in rays.iter().enumerate() {
            let expected = brute_ray(&c, &w, o, d, reach.min(2e6));
            let treed = answer(&c, (o, d, reach));
            assert_eq!(treed, expected, "seed {seed}, ray {k}");
            assert_eq!(
                untreed[k], expected,
                "seed {seed}, ray {k} without the tree"
            );
            hits += usize::from(expected.is_some());
        }
        assert!(hits > 200, "the rays hit things: {hits}");
    }
}

#[test]
fn a_moved_body_is_hit_where_it_is_now_even_before_the_tree_is_refreshed() {
    let (mut w, mut c) = world();
    let shape = Shape::Sphere { radius: 0.5 };
    let ball = w
        .add_body(
            BodyDesc::dynamic(shape.mass_properties(100.0).unwrap())
                .with_position(Vec3::new(0.0, 1.0, 0.0)),
        )
        .unwrap();
    c.add(Collider::new(ball, ColliderShape::Solid(shape)))
        .unwrap();
    c.refresh_queries(&w).unwrap();
    let ray = |c: &Collisions, w: &World| {
        c.cast_ray(
            w,
            Vec3::new(5.0, 1.0, 3.0),
            -Vec3::X,
            20.0,
            &QueryFilter::default(),
        )
        .unwrap()
    };
    assert_eq!(ray(&c, &w), None);
    w.set_body_pose(ball, Vec3::new(0.0, 1.0, 3.0), Quat::IDENTITY)
        .unwrap();
    let hit = ray(&c, &w).expect("found where it is now");
    assert_eq!((hit.body, hit.distance), (ball, 4.5));
}

#[test]
fn swept_shapes_stop_where_they_first_touch() {
    let (mut w, mut c) = world();
    let wall = w
        .add_body(BodyDesc::fixed().with_position(Vec3::new(3.0, 1.0, 0.0)))
        .unwrap();
    c.add(Collider::new(
        wall,
        ColliderShape::Solid(Shape::Box {
            half_extents: Vec3::new(0.1, 1.0, 1.0),
        }),
    ))
    .unwrap();
    c.refresh_queries(&w).unwrap();
    let all = QueryFilter::default();
    // A sphere of 0.25 m dropped from 2 m lands at 1.75 m.
    let sphere = QueryShape::Sphere { radius: 0.25 };
    let drop = c
        .cast_shape(
            &w,
            sphere,
            Vec3::new(0.0, 2.0, 0.0),
            Quat::IDENTITY,
            -Vec3::Y,
            5.0,
            &all,
        )
        .unwrap()
        .unwrap();
    assert!((drop.distance - 1.75).abs() < 1e-4, "{drop:?}");
    assert!((drop.normal - Vec3::Y).length() < 1e-4 && drop.point.y.abs() < 1e-4);
    // A capsule lying along z, swept along +x into the wall's face at 2.9.
    let capsule = QueryShape::Capsule {
        half_segment: Vec3::new(0.0, 0.0, 0.3),
        radius: 0.1,
    };
    let hit = c
        .cast_shape(
            &w,
            capsule,
            Vec3::new(0.0, 1.0, 0.0),
            Quat::IDENTITY,
            Vec3::X,
            5.0,
            &all,
        )
        .unwrap()
        .unwrap();
    assert_eq!(hit.body, wall);
    assert!((hit.distance - 2.8).abs() < 1e-4, "{hit:?}");
    assert!((hit.normal + Vec3::X).length() < 1e-4);
    // Turned to lie along x, it reaches the wall 0.3 m sooner.
    let along_x = Quat::from_rotation_y(core::f32::consts::FRAC_PI_2);
    let hit = c
        .cast_shape(
            &w,
            capsule,
            Vec3::new(0.0, 1.0, 0.0),
            along_x,
            Vec3::X,
            5.0,
            &all,
        )
        .unwrap()
        .unwrap();
    assert!((hit.distance - 2.5).abs() < 1e-4, "{hit:?}");
    // Starting inside the wall: distance 0.
    let inside = c
        .cast_shape(
            &w,
            sphere,
            Vec3::new(3.0, 1.0, 0.0),
            Quat::IDENTITY,
            Vec3::X,
            5.0,
            &all,
        )
        .unwrap()
        .unwrap();
    assert_eq!((inside.body, inside.distance), (wall, 0.0));
}

#[test]
fn overlaps_list_every_collider_touched_by_index() {
    let (mut w, mut c) = world();
    let front = humanoid(&mut w, &mut c, Vec3::ZERO);
    c.refresh_queries(&w).unwrap();
    let mut out = Vec::new();
    // A 30 cm sphere at the left hand: the left forearm, not the ground.
    let hand = Vec3::new(0.22, 1.0, 0.0);
    c.overlaps(
        &w,
        QueryShape::Sphere { radius: 0.3 },
        hand,
        Quat::IDENTITY,
        &QueryFilter::default(),
        &mut out,
    )
    .unwrap();
    let names: Vec<&str> = out
        .iter()
        .map(|o| {
            front.description().bodies[o.part.unwrap().bone as usize]
                .name
                .as_str()
        })
        .collect();
    assert!(
        names.contains(&"forearm_l") && names.contains(&"hips"),
        "{names:?}"
    );
    assert!(
        !names.contains(&"head") && !names.contains(&"forearm_r"),
        "{names:?}"
    );
    assert!(out.windows(2).all(|p| p[0].collider < p[1].collider));
    // Sunk into the floor: the ground too (the plane is collider 0).
    c.overlaps(
        &w,
        QueryShape::Sphere { radius: 0.3 },
        Vec3::new(5.0, 0.1, 0.0),
        Quat::IDENTITY,
        &QueryFilter::default(),
        &mut out,
    )
    .unwrap();
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].collider, 0);
}

#[test]
fn a_shot_pushes_the_bone_it_hits_at_the_point_it_hits() {
    let (mut w, mut c) = world();
    let ragdoll = humanoid(&mut w, &mut c, Vec3::ZERO);
    let before: Vec<_> = ragdoll
        .bodies
        .iter()
        .flatten()
        .map(|&b| w.body(b).unwrap())
        .collect();
    // From the left, at the chest's height, off its centre by 5 cm in z.
    let origin = Vec3::new(-3.0, 1.45, 0.05);
    let hit = c
        .shoot(&mut w, origin, Vec3::X, 10.0, 20.0, &QueryFilter::default())
        .unwrap()
        .unwrap();
    let chest = ragdoll.bodies[bone(&ragdoll, "chest") as usize].unwrap();
    assert_eq!(hit.body, chest);
    let s = w.body(chest).unwrap();
    let mass = 1.0 / w.bodies().inverse_mass[chest.index()];
    let j = Vec3::X * 20.0;
    assert!((s.linear_velocity * mass - j).length() < 1e-3 * 20.0);
    let inertia = w.bodies().inertia[chest.index()];
    let q = s.orientation;
    let angular = q * (inertia * (q.inverse() * s.angular_velocity));
    let moment = (hit.point - s.position).cross(j);
    assert!(
        (angular - moment).length() < 1e-3 * moment.length(),
        "{angular} {moment}"
    );
    // Nothing else moved.
    for (state, &b) in before.iter().zip(ragdoll.bodies.iter().flatten()) {
        if b != chest {
            assert_eq!(w.body(b).unwrap(), *state);
        }
    }
    // A static body hit stops the shot and takes nothing.
    let down = c
        .shoot(
            &mut w,
            Vec3::new(4.0, 2.0, 0.0),
            -Vec3::Y,
            5.0,
            20.0,
            &QueryFilter::default(),
        )
        .unwrap()
        .unwrap();
    assert_eq!(w.bodies().kind[down.body.index()], BodyKind::Static);
}

#[test]
fn refused_queries_name_the_value_and_change_nothing() {
    let (mut w, mut c) = world();
    humanoid(&mut w, &mut c, Vec3::ZERO);
    let all = QueryFilter::default();
    let o = Vec3::new(0.0, 1.0, 3.0);
    let hash = w.state_hash();
    let refused = [
        c.cast_ray(&w, Vec3::NAN, -Vec3::Z, 1.0, &all).unwrap_err(),
        c.cast_ray(&w, o, Vec3::ZERO, 1.0, &all).unwrap_err(),
        c.cast_ray(&w, o, Vec3::new(0.0, 0.0, -2.0), 1.0, &all)
            .unwrap_err(),
        c.cast_ray(&w, o, -Vec3::Z, -1.0, &all).unwrap_err(),
        c.cast_ray(&w, o, -Vec3::Z, f32::NAN, &all).unwrap_err(),
        c.cast_ray(&w, Vec3::splat(1e7), -Vec3::Z, 1.0, &all)
            .unwrap_err(),
        c.cast_shape(
            &w,
            QueryShape::Sphere { radius: 0.0 },
            o,
            Quat::IDENTITY,
            -Vec3::Z,
            1.0,
            &all,
        )
        .unwrap_err(),
        c.cast_shape(
            &w,
            QueryShape::Sphere { radius: 1e5 },
            o,
            Quat::IDENTITY,
            -Vec3::Z,
            1.0,
            &all,
        )
        .unwrap_err(),
        c.cast_shape(
            &w,
            QueryShape::Sphere { radius: 0.1 },
            o,
            Quat::from_xyzw(0.0, 0.0, 0.0, 2.0),
            -Vec3::Z,
            1.0,
            &all,
        )
        .unwrap_err(),
        c.shoot(&mut w, o, -Vec3::Z, 10.0, f32::INFINITY, &all)
            .unwrap_err(),
        c.shoot(&mut w, o, -Vec3::Z, 10.0, -1.0, &all).unwrap_err(),
    ];
    for e in &refused {
        assert!(
            matches!(
                e,
                Error::NonFinite(_)
                    | Error::NotNormalized(_)
                    | Error::NonPositive(_)
                    | Error::OutOfRange(_)
            ),
            "{e:?}"
        );
    }
    assert_eq!(w.state_hash(), hash);
    // Another world, or one restored since: refused.
    let other = World::new(SolverConfig::default()).unwrap();
    let snapshot = w.snapshot();
    w.step(1.0 / 60.0).unwrap();
    w.restore(&snapshot).unwrap();
    for world in [&other, &w] {
        let e = c.cast_ray(world, o, -Vec3::Z, 10.0, &all).unwrap_err();
        assert!(
            matches!(e, Error::WorldMismatch(_) | Error::Collider { .. }),
            "{e:?}"
        );
    }
    let _: Option<BodyHandle> = None;
}
