//! Every polynomial gives the scalar reference's bits on every backend, for
//! random and adversarial inputs and the edges of each domain.

mod common;

use common::{arguments, assert_agree, rng, uniform};
use vertebra_math::poly;

lane_map!(SinCos, 1 -> 4, |i, o| {
    let (s, c) = poly::sin_cos(i[0]);
    o[0] = s;
    o[1] = c;
    o[2] = poly::sin(i[0]);
    o[3] = poly::cos(i[0]);
});
lane_map!(Inverse, 1 -> 4, |i, o| {
    o[0] = poly::asin(i[0]);
    o[1] = poly::acos(i[0]);
    o[2] = poly::half_sinc(i[0]);
    o[3] = poly::half_sinc_slope(i[0]);
});
lane_map!(Atan2, 2 -> 1, |i, o| { o[0] = poly::atan2(i[0], i[1]); });
lane_map!(Wrap, 1 -> 1, |i, o| { o[0] = poly::wrap_angle(i[0]); });

#[test]
fn sin_cos_agree() {
    assert_agree(&SinCos, &arguments(1, 50_000, 11));
    let mut r = rng(12);
    assert_agree(&SinCos, &[uniform(&mut r, 50_000, -10.0..10.0)]);
}

#[test]
fn inverse_functions_and_half_sinc_agree() {
    assert_agree(&Inverse, &arguments(1, 50_000, 13));
    let mut r = rng(14);
    assert_agree(&Inverse, &[uniform(&mut r, 50_000, -1.1..1.1)]);
    assert_agree(&Inverse, &[uniform(&mut r, 50_000, -4.0..4.0)]);
}

#[test]
fn atan2_agrees() {
    assert_agree(&Atan2, &arguments(2, 50_000, 15));
    let mut r = rng(16);
    let y = uniform(&mut r, 50_000, -2.0..2.0);
    let x = uniform(&mut r, 50_000, -2.0..2.0);
    assert_agree(&Atan2, &[y, x]);
}

#[test]
fn wrap_angle_agrees() {
    assert_agree(&Wrap, &arguments(1, 50_000, 17));
    let mut r = rng(18);
    assert_agree(&Wrap, &[uniform(&mut r, 50_000, -20.0..20.0)]);
}
