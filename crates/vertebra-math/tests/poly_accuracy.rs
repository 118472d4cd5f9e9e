//! Each polynomial stays within its documented error bound against an `f64`
//! reference over its whole domain, and behaves sanely outside it.

mod common;

use common::{arguments, assert_agree};
use vertebra_math::poly;

lane_map!(Eval, 2 -> 8, |i, o| {
    let (s, c) = poly::sin_cos(i[0]);
    o[0] = s;
    o[1] = c;
    o[2] = poly::asin(i[0]);
    o[3] = poly::acos(i[0]);
    o[4] = poly::atan2(i[0], i[1]);
    o[5] = poly::half_sinc(i[0]);
    o[6] = poly::atan2(i[1], i[0]);
    o[7] = poly::half_sinc_slope(i[0]);
});

/// Evaluates the polynomials at `x` (and `y` for atan2) on the scalar
/// reference (the other backends give the same bits, see poly_bitexact).
fn eval(x: &[f32], y: &[f32]) -> Vec<Vec<f32>> {
    assert_agree(&Eval, &[x.to_vec(), y.to_vec()])
}

/// `count + 1` evenly spaced points covering [lo, hi], ends included.
fn grid(lo: f32, hi: f32, count: usize) -> Vec<f32> {
    (0..=count)
        .map(|k| (lo as f64 + (hi as f64 - lo as f64) * k as f64 / count as f64) as f32)
        .collect()
}

fn max_error(xs: &[f32], got: &[f32], reference: impl Fn(f64) -> f64) -> (f64, f32) {
    xs.iter()
        .zip(got)
        .map(|(&x, &g)| ((g as f64 - reference(x as f64)).abs(), x))
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

fn report(name: &str, bound: f64, (error, at): (f64, f32)) {
    eprintln!("{name}: max abs error {error:.3e} at {at:e} (bound {bound:.1e})");
    assert!(
        error <= bound,
        "{name}: error {error:e} at {at:e} exceeds {bound:e}"
    );
}

#[test]
fn sin_and_cos_within_bound_on_their_domain() {
    let near = grid(-8.0, 8.0, 400_000);
    let far = grid(-8192.0, 8192.0, 2_000_000);
    for xs in [near, far] {
        let out = eval(&xs, &xs);
        report("sin", 1.0e-7, max_error(&xs, &out[0], f64::sin));
        report("cos", 1.0e-7, max_error(&xs, &out[1], f64::cos));
    }
}

#[test]
fn asin_and_acos_within_bound_on_their_domain() {
    let mut xs = grid(-1.0, 1.0, 2_000_000);
    // Every float in the last few thousand ulps below 1, where acos is steep.
    xs.extend((0..4096).map(|k| f32::from_bits(1.0f32.to_bits() - k)));
    let out = eval(&xs, &xs);
    report("asin", 1.5e-7, max_error(&xs, &out[2], f64::asin));
    report("acos", 2.6e-7, max_error(&xs, &out[3], f64::acos));
    // Near x = 1 acos is accurate relative to its small result as well.
    for (&x, &a) in xs.iter().zip(&out[3]).filter(|(x, _)| **x > 0.999) {
        let exact = (x as f64).acos();
        assert!(
            (a as f64 - exact).abs() <= 4.0 * f32::EPSILON as f64 * exact + 1e-30,
            "acos({x})"
        );
    }
}

#[test]
fn atan2_within_bound_all_around_the_circle() {
    let angles = grid(-std::f32::consts::PI, std::f32::consts::PI, 1_000_000);
    let radii = [1.0e-30f32, 1.0e-3, 1.0, 7.5, 1.0e20];
    for r in radii {
        let y: Vec<f32> = angles.iter().map(|&a| r * a.sin()).collect();
        let x: Vec<f32> = angles.iter().map(|&a| r * a.cos()).collect();
        let out = eval(&y, &x);
        let error = y
            .iter()
            .zip(&x)
            .zip(&out[4])
            .map(|((&y, &x), &g)| ((g as f64 - (y as f64).atan2(x as f64)).abs(), y))
            .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
        report(&format!("atan2 (radius {r:e})"), 2.7e-7, error);
    }
}

#[test]
fn half_sinc_within_bound_and_exact_at_zero() {
    let xs = grid(-std::f32::consts::PI, std::f32::consts::PI, 2_000_000);
    let out = eval(&xs, &xs);
    let reference = |x: f64| if x == 0.0 { 0.5 } else { (x / 2.0).sin() / x };
    report("half_sinc", 5.0e-8, max_error(&xs, &out[5], reference));
    let at_zero = eval(&[0.0, -0.0, 1.0e-30, 1.0e-20], &[0.0; 4]);
    assert!(at_zero[5].iter().all(|&v| v == 0.5), "{:?}", at_zero[5]);
}

/// The slope against the derivative's closed form,
/// `(x/2 cos(x/2) - sin(x/2)) / x^2`, in `f64` (its own series near zero,
/// where the closed form cancels): 0 at zero, odd.
#[test]
fn half_sinc_slope_within_bound_zero_at_zero_and_odd() {
    let xs = grid(-std::f32::consts::PI, std::f32::consts::PI, 2_000_000);
    let out = eval(&xs, &xs);
    let reference = |x: f64| {
        if x.abs() < 1e-3 {
            -x / 24.0 + x.powi(3) / 960.0
        } else {
            ((x / 2.0) * (x / 2.0).cos() - (x / 2.0).sin()) / (x * x)
        }
    };
    report(
        "half_sinc_slope",
        5.0e-8,
        max_error(&xs, &out[7], reference),
    );
    let at_zero = eval(&[0.0, -0.0, 1.0e-30], &[0.0; 3]);
    assert!(
        at_zero[7][..2].iter().all(|&v| v == 0.0),
        "{:?}",
        at_zero[7]
    );
    assert_eq!(
        at_zero[7][2],
        -1.0e-30 / 24.0,
        "the slope near zero is -x/24"
    );
    let negated: Vec<f32> = xs.iter().map(|x| -x).collect();
    let mirrored = eval(&negated, &negated);
    assert!(
        (out[7].iter().zip(&mirrored[7])).all(|(a, b)| a.to_bits() == (-b).to_bits()),
        "not odd"
    );
}

#[test]
fn special_values_follow_ieee_conventions() {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let cases: &[(f32, f32, f32)] = &[
        (0.0, 1.0, 0.0),
        (0.0, -0.0, PI),
        (-0.0, -0.0, -PI),
        (-0.0, 1.0, -0.0),
        (1.0, 0.0, FRAC_PI_2),
        (-1.0, 0.0, -FRAC_PI_2),
        (f32::INFINITY, f32::INFINITY, FRAC_PI_4),
        (f32::INFINITY, 1.0, FRAC_PI_2),
        (1.0, f32::NEG_INFINITY, PI),
        (1.0e-45, 1.0e30, 0.0),
    ];
    let (y, x): (Vec<f32>, Vec<f32>) = cases.iter().map(|c| (c.0, c.1)).unzip();
    let out = eval(&y, &x);
    for (k, c) in cases.iter().enumerate() {
        let expected = c.2;
        assert!(
            (out[4][k] - expected).abs() <= 2.7e-7
                && out[4][k].is_sign_negative() == expected.is_sign_negative(),
            "atan2({}, {}) = {} (expected {})",
            c.0,
            c.1,
            out[4][k],
            expected
        );
    }
    let exact = eval(&[1.0, -1.0, 0.0], &[0.0; 3]);
    assert_eq!(
        exact[3],
        vec![0.0, PI, FRAC_PI_2],
        "acos(1), acos(-1), acos(0)"
    );
    assert_eq!(exact[2][2], 0.0, "asin(0)");
    assert_eq!(exact[1][2], 1.0, "cos(0)");
}

#[test]
fn outside_the_domain_results_stay_finite_and_bounded() {
    // Every finite input, any magnitude: no NaN where the math allows a value.
    let args = arguments(2, 200_000, 21);
    let out = eval(&args[0], &args[1]);
    for k in 0..args[0].len() {
        let (x, y) = (args[0][k], args[1][k]);
        if !x.is_finite() {
            assert!(
                out[0][k].is_nan() && out[1][k].is_nan(),
                "sin/cos({x}) should be NaN"
            );
            continue;
        }
        for (f, name) in [(0, "sin"), (1, "cos")] {
            assert!(
                (-1.0..=1.0).contains(&out[f][k]),
                "{name}({x:e}) = {}",
                out[f][k]
            );
        }
        assert!(
            out[2][k].abs() <= std::f32::consts::FRAC_PI_2,
            "asin({x:e})"
        );
        assert!(
            (0.0..=std::f32::consts::PI).contains(&out[3][k]),
            "acos({x:e})"
        );
        assert!(
            (0.0..=0.5).contains(&out[5][k]),
            "half_sinc({x:e}) = {}",
            out[5][k]
        );
        if y.is_finite() {
            assert!(
                out[4][k].abs() <= std::f32::consts::PI,
                "atan2({x:e}, {y:e})"
            );
        }
    }
    // Clamping: beyond the domain the value at the domain's edge.
    let edge = eval(&[1.5, -7.0, 4.0, -100.0], &[0.0; 4]);
    assert_eq!(edge[3][..2], [0.0, std::f32::consts::PI]);
    let at_pi = eval(&[std::f32::consts::PI], &[0.0])[5][0];
    assert_eq!(edge[5][2..], [at_pi, at_pi]);
    // NaN in, NaN out.
    let nan = eval(&[f32::NAN], &[1.0]);
    assert!(nan.iter().all(|o| o[0].is_nan()));
}

lane_map!(Wrap, 1 -> 1, |i, o| { o[0] = poly::wrap_angle(i[0]); });

#[test]
fn wrap_angle_lands_in_minus_pi_to_pi_on_the_same_angle() {
    use std::f32::consts::PI;
    let bound = 3.5e-7;
    let xs = grid(-4.0 * PI, 4.0 * PI, 2_000_000);
    let got = assert_agree(&Wrap, std::slice::from_ref(&xs)).remove(0);
    // The same angle: `got - x` is a whole number of turns, to within the bound.
    let tau = std::f64::consts::TAU;
    let off_turns = |(&x, &g): (&f32, &f32)| {
        let d = g as f64 - x as f64;
        ((d - tau * (d / tau).round()).abs(), x)
    };
    let worst = xs
        .iter()
        .zip(&got)
        .map(off_turns)
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    report("wrap_angle", bound, worst);
    let widest = got.iter().map(|&g| g.abs() as f64).fold(0.0, f64::max);
    assert!(widest <= PI as f64 + bound, "wrapped to {widest}");
    // Pi stays pi (ties to even), and just past it the short way is taken.
    let edges = assert_agree(&Wrap, &[vec![PI, -PI, 3.3, -3.3]]).remove(0);
    assert_eq!(edges[..2], [PI, -PI]);
    assert!((edges[2] - (3.3 - 2.0 * PI)).abs() < 1e-6, "{edges:?}");
    assert!((edges[3] + (3.3 - 2.0 * PI)).abs() < 1e-6, "{edges:?}");
}
