//! Every gradient a rod part uses, against central finite differences of
//! the part's own measurement, at random configurations.

mod common;

use common::{moved, turned};
use glam::{Mat3, Quat as GQuat, Vec3 as GVec3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_kernels::body::{BodyLanes, PairStart};
use vertebra_kernels::parts::rod::{Frames, bend, curve, frames, length, twist};
use vertebra_math::{Quat, Sym3, Vec3};

fn body(p: GVec3, q: GQuat) -> BodyLanes<f32> {
    let zero = Sym3::diagonal(Vec3::splat(GVec3::ONE));
    BodyLanes {
        p: p.into(),
        inv_mass: 1.0,
        q: q.into(),
        inv_inertia: zero,
    }
}

/// The start of a step at which the bodies' rows held their absolute
/// positions: no gap, no arms (the chord is `p_b - p_a`).
fn origin() -> PairStart<f32> {
    PairStart {
        gap: Vec3::zero(),
        arm_a: Vec3::zero(),
        arm_b: Vec3::zero(),
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

/// A random admissible-ish rod configuration: frames bent by up to 2 rad.
fn configuration(r: &mut StdRng) -> (BodyLanes<f32>, BodyLanes<f32>, Quat<f32>, Quat<f32>) {
    let qa = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    let qb = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    let fa = GQuat::from_scaled_axis(unit(r) * r.random_range(0.0..3.0));
    // b's material frame: a's bent by up to 2 rad about a random axis and
    // twisted, so psi covers (0, 2).
    let bent = GQuat::from_scaled_axis(unit(r) * r.random_range(0.05..2.0)) * (qa * fa);
    let fb = qb.inverse() * bent;
    let pa = unit(r) * r.random_range(0.0..2.0);
    let pb = pa + unit(r) * r.random_range(0.2..1.0);
    (body(pa, qa), body(pb, qb), fa.into(), fb.into())
}

/// Central difference of `c` along each world axis, for rotations of one
/// body (`rotate = true`) or translations, in f64 from f32 measurements.
fn numeric_gradient(
    c: impl Fn(&BodyLanes<f32>, &BodyLanes<f32>) -> f32,
    a: &BodyLanes<f32>,
    b: &BodyLanes<f32>,
    of_b: bool,
    rotate: bool,
) -> GVec3 {
    let h = 1e-3f32;
    let axes = [GVec3::X, GVec3::Y, GVec3::Z];
    let component = |e: GVec3| {
        let step = |s: f32| {
            let v = e * (s * h);
            let apply = |body: &BodyLanes<f32>| {
                if rotate {
                    turned(*body, v)
                } else {
                    moved(*body, v)
                }
            };
            if of_b {
                c(a, &apply(b))
            } else {
                c(&apply(a), b)
            }
        };
        (step(1.0) - step(-1.0)) / (2.0 * h)
    };
    GVec3::new(component(axes[0]), component(axes[1]), component(axes[2]))
}

fn f(a: &BodyLanes<f32>, b: &BodyLanes<f32>, fa: Quat<f32>, fb: Quat<f32>) -> Frames<f32> {
    frames(a, b, fa, fb)
}

fn check(name: &str, analytic: GVec3, numeric: GVec3, scale: f32) {
    let err = (analytic - numeric).length();
    assert!(
        err <= 2e-3 * scale.max(1.0),
        "{name}: analytic {analytic} vs numeric {numeric} (error {err:.2e})"
    );
}

#[test]
fn curve_gradients_match_finite_differences() {
    let mut r = StdRng::seed_from_u64(1);
    for _ in 0..300 {
        let (a, b, fa, fb) = configuration(&mut r);
        let m = curve::measure(&a, &b, &f(&a, &b, fa, fb), &origin());
        if m.theta < 0.05 || m.theta > 3.0 {
            continue; // the axis is ill-defined near 0 and pi
        }
        let c = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| {
            curve::measure(a, b, &f(a, b, fa, fb), &origin()).theta
        };
        check(
            "curve / b",
            m.n_b.into(),
            numeric_gradient(c, &a, &b, true, true),
            1.0,
        );
        check(
            "curve / a",
            -GVec3::from(m.n_a),
            numeric_gradient(c, &a, &b, false, true),
            1.0,
        );
        let scale = GVec3::from(m.g).length();
        check(
            "curve / p_b",
            m.g.into(),
            numeric_gradient(c, &a, &b, true, false),
            scale,
        );
        check(
            "curve / p_a",
            -GVec3::from(m.g),
            numeric_gradient(c, &a, &b, false, false),
            scale,
        );
    }
}

#[test]
fn length_gradients_match_finite_differences() {
    let mut r = StdRng::seed_from_u64(2);
    for _ in 0..300 {
        let (a, b, fa, fb) = configuration(&mut r);
        let l0 = r.random_range(0.2..1.5);
        let (o, _) = length::measure(&a, &b, &f(&a, &b, fa, fb), l0, &origin());
        let c = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| {
            length::measure(a, b, &f(a, b, fa, fb), l0, &origin()).1
        };
        check(
            "length / p_b",
            o.into(),
            numeric_gradient(c, &a, &b, true, false),
            1.0,
        );
        check(
            "length / p_a",
            -GVec3::from(o),
            numeric_gradient(c, &a, &b, false, false),
            1.0,
        );
    }
}

#[test]
fn bend_gradients_match_finite_differences() {
    let mut r = StdRng::seed_from_u64(3);
    for _ in 0..300 {
        let (a, b, fa, fb) = configuration(&mut r);
        let rest: Vec3<f32> =
            (GQuat::from_scaled_axis(unit(&mut r) * r.random_range(0.0..0.8)) * GVec3::X).into();
        let (n, angle) = bend::measure(&f(&a, &b, fa, fb), rest);
        if !(0.05..=3.0).contains(&angle) {
            continue;
        }
        let c = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| bend::measure(&f(a, b, fa, fb), rest).1;
        check(
            "bend / b",
            n.into(),
            numeric_gradient(c, &a, &b, true, true),
            1.0,
        );
        check(
            "bend / a",
            -GVec3::from(n),
            numeric_gradient(c, &a, &b, false, true),
            1.0,
        );
        // The limit's angle is psi itself, about t_a x t_b.
        let (n_psi, psi) = bend::violation(&f(&a, &b, fa, fb), 0.0);
        let c = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| bend::violation(&f(a, b, fa, fb), 0.0).1;
        if psi > 0.05 && psi < 3.0 {
            check(
                "bend limit / b",
                n_psi.into(),
                numeric_gradient(c, &a, &b, true, true),
                1.0,
            );
            check(
                "bend limit / a",
                -GVec3::from(n_psi),
                numeric_gradient(c, &a, &b, false, true),
                1.0,
            );
        }
    }
}

#[test]
fn twist_gradients_match_finite_differences() {
    let mut r = StdRng::seed_from_u64(4);
    for _ in 0..300 {
        let (a, b, fa, fb) = configuration(&mut r);
        let frames = f(&a, &b, fa, fb);
        let tau = twist::measure(&frames);
        if tau.abs() > 3.0 {
            continue; // the wrap-around at +-pi
        }
        let (n_a, n_b) = twist::axes(&frames);
        let scale = GVec3::from(n_a).length().max(GVec3::from(n_b).length());
        let c = |a: &BodyLanes<f32>, b: &BodyLanes<f32>| twist::measure(&f(a, b, fa, fb));
        check(
            "twist / b",
            n_b.into(),
            numeric_gradient(c, &a, &b, true, true),
            scale,
        );
        check(
            "twist / a",
            -GVec3::from(n_a),
            numeric_gradient(c, &a, &b, false, true),
            scale,
        );
    }
}

#[test]
fn generalised_masses_match_their_definitions() {
    // w = 1/m + (r x n)^T I^-1 (r x n), with I^-1 = R S R^T.
    let mut r = StdRng::seed_from_u64(5);
    for _ in 0..100 {
        let q = GQuat::from_scaled_axis(unit(&mut r) * 2.0);
        let s = Mat3::from_diagonal(GVec3::new(1.0, 2.0, 5.0));
        let mut b = body(GVec3::ZERO, q);
        b.inv_inertia = Sym3::diagonal(Vec3::splat(GVec3::new(1.0, 2.0, 5.0)));
        let (arm, n) = (unit(&mut r) * 0.3, unit(&mut r));
        let world = Mat3::from_quat(q) * s * Mat3::from_quat(q).transpose();
        let expected = 1.0 + arm.cross(n).dot(world * arm.cross(n));
        let w = b.positional_weight(arm.into(), n.into());
        assert!((w - expected).abs() < 1e-5 * expected, "{w} vs {expected}");
    }
}

#[test]
fn the_twist_of_a_known_rotation_is_measured_exactly() {
    // F(1) = R(t_b, tau) M F(0): a bend of psi, then a twist of tau.
    let mut r = StdRng::seed_from_u64(6);
    let mut paper_worst = 0.0f32;
    for _ in 0..500 {
        let f0 = GQuat::from_scaled_axis(unit(&mut r) * r.random_range(0.0..3.0));
        let ta = f0 * GVec3::X;
        let n = ta.cross(unit(&mut r)).normalize();
        let psi = r.random_range(0.0..2.5f32);
        let tau = r.random_range(-3.0..3.0f32);
        let bend = GQuat::from_axis_angle(n, psi);
        let tb = bend * ta;
        let f1 = GQuat::from_axis_angle(tb, tau) * bend * f0;
        let frames = Frames {
            fa: f0.into(),
            fb: f1.into(),
            ta: ta.into(),
            tb: tb.into(),
        };
        let measured = twist::measure(&frames);
        assert!(
            (measured - tau).abs() < 2e-5,
            "tau {tau}, psi {psi}: measured {measured}"
        );
        // The paper's tau = xi - psi (eq. 12), xi the total angle between
        // the frames: right only when one of the two is zero.
        let xi = f0.angle_between(f1);
        paper_worst = paper_worst.max(((xi - psi) - tau).abs());
    }
    eprintln!("worst error of the paper's xi - psi over the same rotations: {paper_worst:.3} rad");
    assert!(
        paper_worst > 1.0,
        "the paper's approximation is far off for large bends and twists"
    );
}

#[test]
fn the_chord_and_curvature_closed_forms() {
    // chord(l0, psi) = 2 l0 sin(psi/2)/psi, exactly l0 at psi = 0.
    for &(l0, psi) in &[
        (0.45f32, 0.0f32),
        (0.45, 1e-4),
        (0.45, 1.0),
        (1.0, std::f32::consts::PI),
    ] {
        let expected = if psi == 0.0 {
            l0
        } else {
            2.0 * l0 * (psi / 2.0).sin() / psi
        };
        let got = length::chord(l0, psi);
        assert!(
            (got - expected).abs() < 1e-6,
            "chord({l0}, {psi}) = {got}, expected {expected}"
        );
    }
}
