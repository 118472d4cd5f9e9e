//! Every gradient the joint kinds' parts use (the shaped swing limits, the
//! hinge axis, the lock), against central finite differences of the part's
//! own measurement at random configurations; the hinge axis part's
//! one-step alignment and the hinge range measured in the bodies' frames;
//! and the ellipse's nearest point against its defining conditions.
mod common;

use common::turned;

use glam::{Quat as GQuat, Vec3 as GVec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::BodyLanes;
use vertebra_kernels::parts::{
    ellipse, frames, hinge_axis, lock, pyramid, swing, swing_direction, twist,
};
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
        // The axis comes in a's body frame: the world gradient is R_a n.
        let n = a.q.rotate(n);
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
            let n = a.q.rotate(n); // a's body frame to the world
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

/// The hinge axis part's rows: `n` is the gradient of the swing angle
/// `theta` (b's; a's is `-n`), and turning either body about `m` leaves
/// `theta` unchanged to first order (the `m` row's error stays zero) while
/// tilting b's axis out of the plane of the two axes at `|m| / 2` per
/// radian (`cos(theta / 2)`: nonzero below 180 degrees).
#[test]
fn hinge_axis_rows_match_finite_differences() {
    let mut r = StdRng::seed_from_u64(13);
    let mut checked = 0;
    for _ in 0..300 {
        let (a, b, fa, fb) = configuration(&mut r, 3.1);
        let rows = hinge_axis::measure(&a, &b, fa, fb);
        if rows.sin < 0.05 {
            continue; // theta = |u| has no gradient at 0
        }
        // The rows are measured in each body's frame: the same world vectors.
        let [n, m] = rows.a.map(|row| a.q.rotate(row));
        for (in_a, in_b) in [n, m].into_iter().zip(rows.b.map(|row| b.q.rotate(row))) {
            check(
                "hinge axis row in b's frame",
                in_a.into(),
                in_b.into(),
                1e-5,
            );
        }
        let theta = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| swing::measure(a, b, fa, fb).1;
        check(
            "hinge axis n / b",
            n.into(),
            numeric_gradient(theta, &a, &b, true),
            1e-3,
        );
        check(
            "hinge axis n / a",
            -GVec3::from(n),
            numeric_gradient(theta, &a, &b, false),
            1e-3,
        );
        let (m, m_length) = {
            let m = GVec3::from(m);
            (m.normalize(), m.length())
        };
        for of_b in [true, false] {
            let along_m = numeric_gradient(theta, &a, &b, of_b).dot(m);
            assert!(along_m.abs() < 1e-3, "theta along m: {along_m}");
        }
        // b's axis leaves the plane (the component along n) as b turns about m.
        let n0 = GVec3::from(n);
        let out_of_plane =
            |a: &BodyLanes<f32>, b: &BodyLanes<f32>| n0.dot(frames(a, b, fa, fb).tb.into());
        let tilt = numeric_gradient(out_of_plane, &a, &b, true).dot(m);
        assert!(
            (tilt + 0.5 * m_length).abs() < 1e-3,
            "tilt {tilt} against -|m| / 2 = {}",
            -0.5 * m_length
        );
        checked += 1;
    }
    assert!(checked > 250, "only {checked} configurations off alignment");
}

/// The hinge's range measured in the bodies' own frames is the twist
/// part's angle, about the same axis `t_b`.
#[test]
fn the_twist_measured_in_the_bodies_frames_is_the_twist() {
    let mut r = StdRng::seed_from_u64(18);
    for _ in 0..300 {
        let (a, b, fa, fb) = configuration(&mut r, 3.0);
        let (tb, phi) = twist::measure(&a, &b, fa, fb);
        let ([in_a, in_b], local) = twist::measure_local(&a, &b, fa, fb);
        if phi.abs() < 3.1 {
            assert!((local - phi).abs() < 1e-5, "twist {local} against {phi}");
        }
        check(
            "twist axis in a's frame",
            a.q.rotate(in_a).into(),
            tb.into(),
            1e-5,
        );
        check(
            "twist axis in b's frame",
            b.q.rotate(in_b).into(),
            tb.into(),
            1e-5,
        );
    }
}

/// The angle between the frames' +X axes (rad), in double precision.
fn misalignment(a: &BodyLanes<f32>, b: &BodyLanes<f32>, fa: Quat<f32>, fb: Quat<f32>) -> f64 {
    let f = frames(a, b, fa, fb);
    let (ta, tb) = (GVec3::from(f.ta).as_dvec3(), GVec3::from(f.tb).as_dvec3());
    ta.cross(tb).length().atan2(ta.dot(tb))
}

/// A random inverse inertia with principal values `1 / 20` to `20` (a
/// 400:1 anisotropy at most) about random axes.
fn anisotropic(r: &mut StdRng) -> Sym3<f32> {
    let q = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    let mut spread = || 20f32.powf(r.random_range(-1.0..1.0));
    let m = glam::Mat3::from_quat(q)
        * glam::Mat3::from_diagonal(GVec3::new(spread(), spread(), spread()))
        * glam::Mat3::from_quat(q.inverse());
    Sym3 {
        xx: m.x_axis.x,
        yy: m.y_axis.y,
        zz: m.z_axis.z,
        xy: m.y_axis.x,
        xz: m.z_axis.x,
        yz: m.z_axis.y,
    }
}

/// Random bodies whose frames' +X axes are `theta` apart, each dynamic
/// (anisotropic) or static.
fn tilted(
    r: &mut StdRng,
    theta: f32,
    dynamic: [bool; 2],
) -> (BodyLanes<f32>, BodyLanes<f32>, Quat<f32>, Quat<f32>) {
    let qa = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    let qb = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    let fa = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    // b's frame: a's turned by theta about an axis perpendicular to +X,
    // then twisted about +X.
    let phi = r.random_range(-3.2..3.2f32);
    let tilt = GQuat::from_axis_angle(GVec3::new(0.0, phi.cos(), phi.sin()), theta);
    let twist = GQuat::from_rotation_x(r.random_range(-3.2..3.2));
    let fb = qb.inverse() * qa * fa * tilt * twist;
    let (mut a, mut b) = (body(qa), body(qb));
    for (body, on) in [(&mut a, dynamic[0]), (&mut b, dynamic[1])] {
        body.inv_inertia = if on {
            anisotropic(r)
        } else {
            Sym3::diagonal(Vec3::zero())
        };
    }
    (a, b, fa.into(), fb.into())
}

/// The part's promise: with one dynamic body, whatever its inertia, one
/// step brings the axes together from any angle below 180 degrees. To
/// float precision relative to the turn: the turn's Gibbs vector
/// `tan(angle / 2)` (up to ~1100 at 179.9 degrees) carries the solve's
/// rounding, up to the 400:1 anisotropy times `f32`'s epsilon.
#[test]
fn hinge_axis_aligns_one_dynamic_body_in_one_step() {
    let mut r = StdRng::seed_from_u64(16);
    let degrees = [
        0.06f32, 6.0, 60.0, 85.0, 90.0, 95.0, 115.0, 145.0, 170.0, 178.0, 179.9,
    ];
    for theta in degrees.map(f32::to_radians) {
        for dynamic in [[false, true], [true, false]] {
            for _ in 0..50 {
                let (mut a, mut b, fa, fb) = tilted(&mut r, theta, dynamic);
                let (qa, qb) = (GQuat::from(a.q), GQuat::from(b.q));
                hinge_axis::solve(&mut a, &mut b, fa, fb);
                let after = misalignment(&a, &b, fa, fb);
                let turned = |q: GQuat, before: GQuat| (q * before.inverse()).to_axis_angle().1;
                let turn = turned(a.q.into(), qa) + turned(b.q.into(), qb);
                let gibbs = f64::from(turn / 2.0).tan();
                assert!(
                    after < 2e-5 * gibbs.max(1.0),
                    "{theta} rad off, dynamic {dynamic:?}: {after:e} rad after one step (Gibbs {gibbs})"
                );
            }
        }
    }
}

/// Two dynamic bodies of any inertia: not exact in one step, but every
/// step brings the axes closer from any angle below 180 degrees, and a few
/// bring them together (never to the antiparallel pose).
#[test]
fn hinge_axis_brings_two_dynamic_bodies_together() {
    let mut r = StdRng::seed_from_u64(17);
    let mut worst = 0;
    for theta in [6.0f32, 60.0, 90.0, 115.0, 145.0, 170.0, 178.0, 179.9].map(f32::to_radians) {
        for _ in 0..100 {
            let (mut a, mut b, fa, fb) = tilted(&mut r, theta, [true, true]);
            let mut last = misalignment(&a, &b, fa, fb);
            let mut steps = 0;
            while last > 1e-5 {
                hinge_axis::solve(&mut a, &mut b, fa, fb);
                let now = misalignment(&a, &b, fa, fb);
                assert!(now < last, "{theta} rad off: {last} then {now}");
                (last, steps) = (now, steps + 1);
                assert!(steps <= 12, "{theta} rad off: {last} after {steps} steps");
            }
            worst = worst.max(steps);
        }
    }
    eprintln!("two dynamic bodies: at most {worst} steps to 1e-5 rad");
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
