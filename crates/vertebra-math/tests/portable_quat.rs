//! The portable quaternion operations and trigonometry: on x86-64 they give
//! exactly glam's SSE2 bits (so replacing glam's calls moved no result
//! there), glam's `Quat * Vec3` is one formula on every target, and the
//! trigonometry is the correctly rounded value wherever the platform's
//! double-precision function and ours agree on it.

mod common;

use common::{random_float, rng};
use glam::{Quat, Vec3};
use rand::RngExt;
use vertebra_math::check::{ADVERSARIAL, same_bits};
use vertebra_math::{PortableQuat, trig};

/// Quaternions: unit ones (the operations' real inputs), arbitrary bit
/// patterns, and every adversarial value in every component.
fn quats() -> Vec<Quat> {
    let mut rng = rng(34);
    let mut out = Vec::new();
    for _ in 0..20_000 {
        let q = Quat::from_xyzw(
            rng.random_range(-1.0f32..1.0),
            rng.random_range(-1.0f32..1.0),
            rng.random_range(-1.0f32..1.0),
            rng.random_range(-1.0f32..1.0),
        );
        out.push(q.normalize_portable());
        out.push(Quat::from_xyzw(
            random_float(&mut rng),
            random_float(&mut rng),
            random_float(&mut rng),
            random_float(&mut rng),
        ));
    }
    for (k, &a) in ADVERSARIAL.iter().enumerate() {
        let b = ADVERSARIAL[(k * 7 + 3) % ADVERSARIAL.len()];
        out.push(Quat::from_xyzw(a, b, -a, 0.5));
        out.push(Quat::from_xyzw(0.0, a, b, a));
    }
    out
}

#[cfg(target_arch = "x86_64")]
fn same_quat(a: Quat, b: Quat) -> bool {
    a.to_array()
        .into_iter()
        .zip(b.to_array())
        .all(|(x, y)| same_bits(x, y))
}

#[cfg(target_arch = "x86_64")]
#[test]
fn portable_operations_are_glams_sse2_bits_on_x86_64() {
    let qs = quats();
    for (k, &a) in qs.iter().enumerate() {
        let b = qs[(k * 31 + 17) % qs.len()];
        assert!(same_quat(a.mul_portable(b), a * b), "{a:?} * {b:?}");
        assert!(same_bits(a.dot_portable(b), a.dot(b)), "{a:?} . {b:?}");
        assert!(same_bits(a.length_portable(), a.length()), "|{a:?}|");
        assert!(
            same_quat(a.normalize_portable(), a.normalize()),
            "{a:?} normalised"
        );
        let (from, to) = (a.xyz().normalize_or_zero(), b.xyz().normalize_or_zero());
        if from != Vec3::ZERO && to != Vec3::ZERO && from.is_finite() && to.is_finite() {
            assert!(
                same_quat(
                    Quat::from_rotation_arc_portable(from, to),
                    Quat::from_rotation_arc(from, to)
                ),
                "arc {from:?} -> {to:?}"
            );
            assert!(same_quat(
                Quat::from_rotation_arc_portable(from, -from),
                Quat::from_rotation_arc(from, -from)
            ));
        }
    }
}

#[test]
fn glams_rotation_of_a_vector_is_one_formula_on_every_target() {
    // glam's scalar `mul_vec3`, written out: on x86-64 its SSE2 code must
    // give these bits, elsewhere glam runs this code.
    let rotate = |q: Quat, v: Vec3| {
        let (w, b) = (q.w, q.xyz());
        let b2 = b.dot(b);
        v * (w * w - b2) + b * (v.dot(b) * 2.0) + b.cross(v) * (w * 2.0)
    };
    let qs = quats();
    for (k, &q) in qs.iter().enumerate() {
        let v = qs[(k * 13 + 5) % qs.len()].xyz();
        let (got, want) = (q * v, rotate(q, v));
        assert!(
            got.to_array()
                .into_iter()
                .zip(want.to_array())
                .all(|(x, y)| same_bits(x, y)),
            "{q:?} * {v:?}: {got:?} vs {want:?}"
        );
    }
}

#[test]
fn trigonometry_is_the_platforms_double_precision_result_rounded_once() {
    // The platform's `f64` functions are another implementation (glibc,
    // wasi-libc); each is within an ulp of the truth, so rounded to `f32`
    // the two agree except where the value is within an `f64` ulp of an
    // `f32` rounding boundary, which none of these inputs is.
    let mut rng = rng(35);
    let mut inputs: Vec<f32> = ADVERSARIAL
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .collect();
    inputs.extend((0..50_000).map(|_| rng.random_range(-7.0f32..7.0)));
    inputs.extend((0..5_000).map(|_| rng.random_range(-1.0e4f32..1.0e4)));
    for &x in &inputs {
        let y = inputs[(x.to_bits() as usize) % inputs.len()];
        let d = f64::from(x);
        assert_eq!(
            trig::sin(x).to_bits(),
            (d.sin() as f32).to_bits(),
            "sin {x:e}"
        );
        assert_eq!(
            trig::cos(x).to_bits(),
            (d.cos() as f32).to_bits(),
            "cos {x:e}"
        );
        assert_eq!(trig::sin_cos(x), (trig::sin(x), trig::cos(x)));
        assert_eq!(
            trig::atan2(x, y).to_bits(),
            (d.atan2(f64::from(y)) as f32).to_bits(),
            "atan2({x:e}, {y:e})"
        );
    }
    assert!(trig::sin(f32::NAN).is_nan() && trig::cos(f32::INFINITY).is_nan());
}

/// `a` and `b` in double precision: the turn `a* b`'s angle (rad, in
/// `[0, pi]`), the reference the portable angle and slerp are held to.
fn angle_f64(a: Quat, b: Quat) -> f64 {
    let ([ax, ay, az, aw], [bx, by, bz, bw]) = (a.to_array(), b.to_array());
    let [ax, ay, az, aw, bx, by, bz, bw] = [ax, ay, az, aw, bx, by, bz, bw].map(f64::from);
    // (-a.xyz, a.w) * (b.xyz, b.w).
    let x = aw * bx - ax * bw - (ay * bz - az * by);
    let y = aw * by - ay * bw - (az * bx - ax * bz);
    let z = aw * bz - az * bw - (ax * by - ay * bx);
    let w = aw * bw + ax * bx + ay * by + az * bz;
    2.0 * (x * x + y * y + z * z).sqrt().atan2(w.abs())
}

#[test]
fn slerp_turns_the_fraction_of_the_turn_and_the_angle_is_the_turns() {
    let mut rng = rng(36);
    // `quats()`'s unit ones (every other).
    let units: Vec<Quat> = quats().into_iter().step_by(2).take(20_000).collect();
    let unit = |rng: &mut rand::rngs::StdRng| units[rng.random_range(0..units.len())];
    for k in 0..20_000 {
        let a = unit(&mut rng);
        // Large turns, and small ones (down to 1e-6 rad) where an `acos`
        // of the dot product loses them.
        let b = if k % 2 == 0 {
            unit(&mut rng)
        } else {
            let axis = unit(&mut rng).xyz().normalize();
            let small = 10f32.powi(-rng.random_range(1..7));
            a.mul_portable(Quat::from_axis_angle_portable(axis, small))
        };
        let whole = angle_f64(a, b);
        let got = f64::from(a.angle_between_portable(b));
        assert!(
            (got - whole).abs() <= 1e-6 + 1e-6 * whole,
            "{a:?} to {b:?}: {got} rad, not {whole}"
        );
        let w = rng.random_range(0.0f32..1.0);
        let s = a.slerp_portable(b, w);
        let (from_a, to_b) = (angle_f64(a, s), angle_f64(s, b));
        let tol = 2e-6 + 2e-6 * whole;
        assert!(
            (from_a - f64::from(w) * whole).abs() <= tol
                && (to_b - f64::from(1.0 - w) * whole).abs() <= tol,
            "{a:?} to {b:?} at {w}: {from_a} and {to_b} of {whole} rad"
        );
    }
    let a = unit(&mut rng);
    assert_eq!(a.slerp_portable(a, 0.5), a, "no turn: a itself");
    assert_eq!(a.angle_between_portable(a), 0.0);
}
