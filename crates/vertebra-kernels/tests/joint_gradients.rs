//! Every gradient the joint kinds' parts use (the shaped swing limits, the
//! hinge axis, the lock), against central finite differences of the part's
//! own measurement at random configurations; and the ellipse's nearest
//! point against its defining conditions.

use glam::{Quat as GQuat, Vec3 as GVec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::BodyLanes;
use vertebra_kernels::parts::{ellipse, hinge_axis, lock, pyramid, swing_direction};
use vertebra_math::{Quat, Sym3, Vec3};

fn body(q: GQuat) -> BodyLanes<f32> {
    BodyLanes {
        p: Vec3::zero(),
        inv_mass: 1.0,
        q: q.into(),
        inv_inertia: Sym3::diagonal(Vec3::splat(GVec3::ONE)),
    }
}

fn unit(r: &mut StdRng) -> GVec3 {
    GVec3::new(
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
    )
    .normalize()
}

/// Random bodies and joint frames, b's frame turned from a's by up to
/// `max_angle` (rad) about a random axis.
fn configuration(
    r: &mut StdRng,
    max_angle: f32,
) -> (BodyLanes<f32>, BodyLanes<f32>, Quat<f32>, Quat<f32>) {
    let qa = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    let qb = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    let fa = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    let relative = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..max_angle));
    let fb = qb.inverse() * qa * fa * relative;
    (body(qa), body(qb), fa.into(), fb.into())
}

/// Turns a body by the small world rotation vector `v` (exactly).
fn turned(mut b: BodyLanes<f32>, v: GVec3) -> BodyLanes<f32> {
    b.q = (GQuat::from_scaled_axis(v) * GQuat::from(b.q))
        .normalize()
        .into();
    b
}

/// Central difference of `c` for rotations of b (`of_b`) or a about each
/// world axis.
fn numeric_gradient(
    c: impl Fn(&BodyLanes<f32>, &BodyLanes<f32>) -> f32,
    a: &BodyLanes<f32>,
    b: &BodyLanes<f32>,
    of_b: bool,
) -> GVec3 {
    let h = 1e-3f32;
    let component = |e: GVec3| {
        let step = |s: f32| {
            let v = e * (s * h);
            if of_b {
                c(a, &turned(*b, v))
            } else {
                c(&turned(*a, v), b)
            }
        };
        (step(1.0) - step(-1.0)) / (2.0 * h)
    };
    GVec3::new(
        component(GVec3::X),
        component(GVec3::Y),
        component(GVec3::Z),
    )
}

fn check(name: &str, analytic: GVec3, numeric: GVec3, tolerance: f32) {
    let err = (analytic - numeric).length();
    assert!(
        err <= tolerance,
        "{name}: analytic {analytic} vs numeric {numeric} (error {err:.2e})"
    );
}

#[test]
fn ellipse_gradients_match_finite_differences() {
    let mut r = StdRng::seed_from_u64(11);
    let mut checked = 0;
    for _ in 0..600 {
        let (a, b, fa, fb) = configuration(&mut r, 2.5);
        let (sy, sz) = (r.random_range(0.1..0.9f32), r.random_range(0.1..0.9f32));
        let c = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| {
            ellipse::violation(&swing_direction::measure(a, b, fa, fb), sy, sz)
        };
        let (n, violation) = c(&a, &b);
        if violation < 0.02 {
            continue; // inside, or too close to the boundary for differences
        }
        let value = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| c(a, b).1;
        check(
            "ellipse / b",
            n.into(),
            numeric_gradient(value, &a, &b, true),
            2e-3,
        );
        check(
            "ellipse / a",
            -GVec3::from(n),
            numeric_gradient(value, &a, &b, false),
            2e-3,
        );
        checked += 1;
    }
    assert!(checked > 100, "only {checked} configurations outside");
}

#[test]
fn pyramid_gradients_match_finite_differences() {
    let mut r = StdRng::seed_from_u64(12);
    let mut checked = 0;
    for _ in 0..600 {
        let (a, b, fa, fb) = configuration(&mut r, 2.5);
        let range = |r: &mut StdRng| {
            let lo = r.random_range(-1.5..0.3f32);
            [lo, r.random_range(lo + 0.05..1.5)]
        };
        let (y, z) = (range(&mut r), range(&mut r));
        for k in 0..2 {
            let c = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| {
                pyramid::violations(&swing_direction::measure(a, b, fa, fb), y, z)[k]
            };
            let (n, violation) = c(&a, &b);
            if violation < 0.02 {
                continue;
            }
            let value = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| c(a, b).1;
            check(
                "pyramid / b",
                n.into(),
                numeric_gradient(value, &a, &b, true),
                2e-3,
            );
            check(
                "pyramid / a",
                -GVec3::from(n),
                numeric_gradient(value, &a, &b, false),
                2e-3,
            );
            checked += 1;
        }
    }
    assert!(checked > 100, "only {checked} configurations outside");
}

#[test]
fn hinge_axis_gradients_match_finite_differences() {
    let mut r = StdRng::seed_from_u64(13);
    for _ in 0..300 {
        let (a, b, fa, fb) = configuration(&mut r, 3.0);
        let (_, rows) = hinge_axis::measure(&a, &b, fa, fb);
        for (k, row) in rows.into_iter().enumerate() {
            let c = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| hinge_axis::measure(a, b, fa, fb).0[k];
            check(
                "hinge axis / b",
                row.into(),
                numeric_gradient(c, &a, &b, true),
                1e-3,
            );
            check(
                "hinge axis / a",
                -GVec3::from(row),
                numeric_gradient(c, &a, &b, false),
                1e-3,
            );
        }
    }
}

/// The lock's `dC/dtheta_b = 1`, `dC/dtheta_a = -1` hold to first order in
/// the error: checked where the frames are at most 0.05 rad apart.
#[test]
fn lock_gradients_match_finite_differences() {
    let mut r = StdRng::seed_from_u64(14);
    for _ in 0..300 {
        let (a, b, fa, fb) = configuration(&mut r, 0.05);
        for (k, e) in [GVec3::X, GVec3::Y, GVec3::Z].into_iter().enumerate() {
            let c = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| {
                GVec3::from(lock::measure(a, b, fa, fb))[k]
            };
            check("lock / b", e, numeric_gradient(c, &a, &b, true), 0.05);
            check("lock / a", -e, numeric_gradient(c, &a, &b, false), 0.05);
        }
    }
}

/// The ellipse's nearest point lies on the ellipse, and the point it came
/// from lies along the ellipse's normal there.
#[test]
fn the_ellipse_target_is_the_nearest_point() {
    let mut r = StdRng::seed_from_u64(15);
    let mut checked = 0;
    for _ in 0..2000 {
        let (semi_y, semi_z) = (r.random_range(0.05..1.0f32), r.random_range(0.05..1.0f32));
        let p = [r.random_range(-1.0..1.0f32), r.random_range(-1.0..1.0f32)];
        if (p[0] / semi_y).powi(2) + (p[1] / semi_z).powi(2) <= 1.0 {
            continue;
        }
        let q = ellipse::nearest(p, semi_y, semi_z);
        let on = (q[0] / semi_y).powi(2) + (q[1] / semi_z).powi(2);
        assert!(
            (on - 1.0).abs() < 1e-4,
            "nearest point off the ellipse: {on}"
        );
        // The normal at q is (q_y / A^2, q_z / B^2); p - q must be along it.
        let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
        let (nx, ny) = (q[0] / (semi_y * semi_y), q[1] / (semi_z * semi_z));
        let sine = (dx * ny - dy * nx) / ((dx * dx + dy * dy).sqrt() * (nx * nx + ny * ny).sqrt());
        assert!(
            sine.abs() < 1e-3 || (dx * dx + dy * dy) < 1e-10,
            "not the nearest point: sine {sine} (A {semi_y}, B {semi_z}, p {p:?})"
        );
        checked += 1;
    }
    assert!(checked > 500);
}
