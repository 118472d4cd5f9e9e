//! Each primitive's hit against its closed form: from outside and inside,
//! grazing, parallel, behind, beyond `t_max`; and the tree's nearest hit
//! against testing every primitive.

use glam::{Quat, Vec3};

use super::{close, ray};
use crate::render::bvh::Bvh;
use crate::render::primitive::{Hit, Primitive, Ray};

const ANY: (f32, f32) = (0.0, f32::INFINITY);

fn hit(p: Primitive, r: Ray) -> Option<Hit> {
    p.intersect(&r, ANY.0, ANY.1)
}

/// `got` is a hit at `t` with normal `normal` (to 1e-5).
fn expect(got: Option<Hit>, t: f32, normal: Vec3) {
    let got = got.unwrap_or_else(|| panic!("a hit at {t} expected"));
    assert!((got.t - t).abs() < 1e-5, "t {} expected {t}", got.t);
    assert!(
        close(got.normal, normal, 1e-5),
        "normal {} expected {normal}",
        got.normal
    );
}

#[test]
fn sphere_hits_are_the_roots_of_its_quadratic() {
    let s = Primitive::Sphere {
        centre: Vec3::new(1.0, 2.0, 3.0),
        radius: 0.5,
    };
    // Head on: the distance to the centre less the radius.
    expect(
        hit(s, ray(Vec3::new(1.0, 2.0, -2.0), Vec3::Z)),
        4.5,
        -Vec3::Z,
    );
    // Off the centre line by h: D - sqrt(r^2 - h^2).
    let off = ray(Vec3::new(1.3, 2.0, -2.0), Vec3::Z);
    expect(hit(s, off), 5.0 - 0.4, Vec3::new(0.6, 0.0, -0.8));
    // From inside: the exit, normal outward.
    expect(hit(s, ray(Vec3::new(1.0, 2.0, 3.0), Vec3::Z)), 0.5, Vec3::Z);
    // Behind the origin, or beyond t_max: nothing.
    assert_eq!(hit(s, ray(Vec3::new(1.0, 2.0, -2.0), -Vec3::Z)), None);
    assert_eq!(
        s.intersect(&ray(Vec3::new(1.0, 2.0, -2.0), Vec3::Z), 0.0, 4.4),
        None
    );
    // Grazing: the tangent ray touches at one point; a hair further out
    // misses.
    let unit = Primitive::Sphere {
        centre: Vec3::ZERO,
        radius: 1.0,
    };
    expect(
        hit(unit, ray(Vec3::new(-5.0, 1.0, 0.0), Vec3::X)),
        5.0,
        Vec3::Y,
    );
    assert_eq!(hit(unit, ray(Vec3::new(-5.0, 1.001, 0.0), Vec3::X)), None);
}

#[test]
fn capsule_hits_its_side_caps_and_from_inside() {
    let c = Primitive::Capsule {
        a: Vec3::ZERO,
        b: Vec3::new(0.0, 2.0, 0.0),
        radius: 0.5,
    };
    // The side, head on and off the axis's plane: 3 - sqrt(r^2 - h^2).
    expect(
        hit(c, ray(Vec3::new(3.0, 1.0, 0.0), -Vec3::X)),
        2.5,
        Vec3::X,
    );
    let off = ray(Vec3::new(3.0, 1.0, 0.3), -Vec3::X);
    expect(hit(c, off), 2.6, Vec3::new(0.8, 0.0, 0.6));
    // Grazing the side: tangent at z = r.
    expect(
        hit(c, ray(Vec3::new(3.0, 1.0, 0.5), -Vec3::X)),
        3.0,
        Vec3::Z,
    );
    // Across a cap, above the segment's end: its hemisphere.
    let cap = ray(Vec3::new(3.0, 2.3, 0.0), -Vec3::X);
    expect(hit(c, cap), 2.6, Vec3::new(0.8, 0.6, 0.0));
    assert_eq!(hit(c, ray(Vec3::new(3.0, 2.6, 0.0), -Vec3::X)), None);
    // Parallel to the axis: the caps, on the axis and 0.3 off it.
    expect(
        hit(c, ray(Vec3::new(0.0, 5.0, 0.0), -Vec3::Y)),
        2.5,
        Vec3::Y,
    );
    expect(
        hit(c, ray(Vec3::new(0.0, -3.0, 0.0), Vec3::Y)),
        2.5,
        -Vec3::Y,
    );
    let parallel = ray(Vec3::new(0.3, 5.0, 0.0), -Vec3::Y);
    expect(hit(c, parallel), 2.6, Vec3::new(0.6, 0.8, 0.0));
    assert_eq!(hit(c, ray(Vec3::new(0.6, 5.0, 0.0), -Vec3::Y)), None);
    // From inside: the exit through the side, and through a cap.
    expect(hit(c, ray(Vec3::new(0.0, 1.0, 0.0), Vec3::X)), 0.5, Vec3::X);
    expect(hit(c, ray(Vec3::new(0.0, 2.2, 0.0), Vec3::Y)), 0.3, Vec3::Y);
    // A capsule with both ends at one point is a sphere.
    let ball = Primitive::Capsule {
        a: Vec3::ONE,
        b: Vec3::ONE,
        radius: 0.5,
    };
    expect(
        hit(ball, ray(Vec3::new(1.0, 1.0, -4.0), Vec3::Z)),
        4.5,
        -Vec3::Z,
    );
}

#[test]
fn box_hits_its_faces_turned_and_from_inside() {
    let b = |rotation: Quat| Primitive::Box {
        centre: Vec3::ZERO,
        rotation,
        half_extents: Vec3::new(1.0, 2.0, 3.0),
    };
    expect(
        hit(b(Quat::IDENTITY), ray(Vec3::new(5.0, 0.0, 0.0), -Vec3::X)),
        4.0,
        Vec3::X,
    );
    // Oblique onto the top face (y = 2): from (0, 6, 0) at 45 degrees.
    let oblique = ray(Vec3::new(0.0, 6.0, -3.5), Vec3::new(0.0, -1.0, 1.0));
    expect(hit(b(Quat::IDENTITY), oblique), 4.0 * 2f32.sqrt(), Vec3::Y);
    // Turned 90 degrees about +Y: its z half-extent (3) lies along x.
    let turned = b(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2));
    expect(
        hit(turned, ray(Vec3::new(5.0, 0.0, 0.0), -Vec3::X)),
        2.0,
        Vec3::X,
    );
    // From inside: the exit.
    expect(
        hit(b(Quat::IDENTITY), ray(Vec3::ZERO, Vec3::Y)),
        2.0,
        Vec3::Y,
    );
    // Parallel to a slab: outside it misses, inside it hits the far
    // faces; grazing along a face's plane still meets the box's edge.
    assert_eq!(
        hit(b(Quat::IDENTITY), ray(Vec3::new(0.0, 3.0, -10.0), Vec3::Z)),
        None
    );
    expect(
        hit(b(Quat::IDENTITY), ray(Vec3::new(0.0, 1.0, -10.0), Vec3::Z)),
        7.0,
        -Vec3::Z,
    );
    expect(
        hit(b(Quat::IDENTITY), ray(Vec3::new(1.0, 0.0, -10.0), Vec3::Z)),
        7.0,
        -Vec3::Z,
    );
    // Pointing away: nothing.
    assert_eq!(
        hit(b(Quat::IDENTITY), ray(Vec3::new(5.0, 0.0, 0.0), Vec3::X)),
        None
    );
}

#[test]
fn plane_hits_along_its_normal_and_never_parallel() {
    let p = Primitive::Plane {
        normal: Vec3::Y,
        offset: 0.5,
    };
    expect(
        hit(p, ray(Vec3::new(0.0, 2.0, 0.0), -Vec3::Y)),
        1.5,
        Vec3::Y,
    );
    // Slanted: the height over the cosine.
    let slanted = ray(Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.6, -0.8, 0.0));
    expect(hit(p, slanted), 1.5 / 0.8, Vec3::Y);
    // From below, it is met too (the normal stays outward).
    expect(
        hit(p, ray(Vec3::new(0.0, -1.0, 0.0), Vec3::Y)),
        1.5,
        Vec3::Y,
    );
    assert_eq!(hit(p, ray(Vec3::new(0.0, 2.0, 0.0), Vec3::X)), None);
    assert_eq!(hit(p, ray(Vec3::new(0.0, 2.0, 0.0), Vec3::Y)), None);
}

/// A deterministic stream of numbers in [0, 1).
fn numbers(mut state: u64) -> impl FnMut() -> f32 {
    move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    }
}

#[test]
fn the_tree_finds_the_nearest_hit_that_testing_every_primitive_finds() {
    let mut next = numbers(7);
    let mut point = |spread: f32| Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * spread;
    let primitives: Vec<Primitive> = (0..300)
        .map(|k| {
            let at = point(4.0);
            match k % 3 {
                0 => Primitive::Capsule {
                    a: at,
                    b: at + point(0.8),
                    radius: 0.05,
                },
                1 => Primitive::Sphere {
                    centre: at,
                    radius: 0.08,
                },
                _ => Primitive::Box {
                    centre: at,
                    rotation: Quat::from_rotation_y(at.x),
                    half_extents: Vec3::new(0.1, 0.05, 0.2),
                },
            }
        })
        .collect();
    let bounds: Vec<_> = primitives.iter().map(|p| p.bounds().unwrap()).collect();
    let tree = Bvh::new(&bounds);
    let mut hits = 0;
    for _ in 0..2000 {
        let origin = point(10.0);
        let r = ray(origin, point(3.0) - origin);
        let brute = primitives
            .iter()
            .filter_map(|p| p.intersect(&r, 0.0, f32::INFINITY))
            .map(|h| h.t)
            .fold(f32::INFINITY, f32::min);
        let mut walked = f32::INFINITY;
        tree.walk(&r, f32::INFINITY, |k, t_max| {
            if let Some(h) = primitives[k].intersect(&r, 0.0, t_max) {
                walked = h.t;
            }
            Some(walked.min(t_max))
        });
        assert_eq!(walked.to_bits(), brute.to_bits(), "ray {r:?}");
        hits += usize::from(brute.is_finite());
    }
    assert!(
        hits > 200,
        "the rays hit something often enough to check ({hits})"
    );
}
