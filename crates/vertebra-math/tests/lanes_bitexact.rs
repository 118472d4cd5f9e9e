//! Every lane operation gives the scalar reference's bits on every backend,
//! for random and adversarial inputs (NaN payloads aside, see
//! `vertebra_math::lane`).

mod common;

use std::hint::black_box;

use common::{arguments, assert_agree};
use vertebra_math::check::same_bits;
use vertebra_math::map::{LaneMap, map_arrays};
use vertebra_math::{Backend, Mask};

const RANDOM: usize = 20_000;

lane_map!(AddOp, 2 -> 1, |i, o| { o[0] = i[0] + i[1]; });
lane_map!(SubOp, 2 -> 1, |i, o| { o[0] = i[0] - i[1]; });
lane_map!(MulOp, 2 -> 1, |i, o| { o[0] = i[0] * i[1]; });
lane_map!(DivOp, 2 -> 1, |i, o| { o[0] = i[0] / i[1]; });
lane_map!(AssignOps, 2 -> 1, |i, o| {
    let mut x = i[0];
    x += i[1];
    x *= i[1];
    x -= i[0];
    o[0] = x;
});
lane_map!(NegOp, 1 -> 1, |i, o| { o[0] = -i[0]; });
lane_map!(SqrtOp, 1 -> 1, |i, o| { o[0] = i[0].sqrt(); });
lane_map!(AbsOp, 1 -> 1, |i, o| { o[0] = i[0].abs(); });
lane_map!(RoundOp, 1 -> 1, |i, o| { o[0] = i[0].round(); });
lane_map!(MinMaxOp, 2 -> 2, |i, o| { o[0] = i[0].min(i[1]); o[1] = i[0].max(i[1]); });
lane_map!(ClampOp, 3 -> 1, |i, o| { o[0] = i[0].clamp(i[1], i[2]); });
// `min` and `max` against a constant zero, as the kernels write them
// (`x.max(zero)`, `c.min(zero)`): a compiler that knows one operand may
// pick other instructions than for two loaded lanes.
lane_map!(ZeroBoundsOp, 1 -> 4, |i, o| {
    let (zero, minus_zero) = (L::splat(0.0), L::splat(-0.0));
    o[0] = i[0].min(zero);
    o[1] = i[0].max(zero);
    o[2] = minus_zero.min(i[0]);
    o[3] = minus_zero.max(i[0]);
});
lane_map!(MulAddOp, 3 -> 1, |i, o| { o[0] = i[0].mul_add(i[1], i[2]); });
lane_map!(CopysignOp, 2 -> 1, |i, o| { o[0] = i[0].copysign(i[1]); });
lane_map!(SplatOp, 1 -> 1, |i, o| {
    // Splat of a constant next to a loaded lane: both paths agree.
    o[0] = i[0] + L::splat(-0.0);
});
lane_map!(ReduceOp, 1 -> 1, |i, o| { o[0] = L::splat(i[0].reduce_add()); });

// Each comparison as a select between 1 and 0, so masks are compared too.
lane_map!(CompareOps, 2 -> 7, |i, o| {
    let (one, zero) = (L::splat(1.0), L::splat(0.0));
    let (a, b) = (i[0], i[1]);
    for (slot, mask) in [a.lt(b), a.le(b), a.gt(b), a.ge(b), a.eq(b), a.ne(b), a.is_nan()]
        .into_iter()
        .enumerate()
    {
        o[slot] = L::select(mask, one, zero);
    }
});

// Mask algebra and select passing both operands' bits through.
lane_map!(MaskOps, 3 -> 4, |i, o| {
    let p = i[0].lt(i[1]);
    let q = i[1].le(i[2]);
    o[0] = L::select(p & q, i[0], i[2]);
    o[1] = L::select(p | q, i[1], i[0]);
    o[2] = L::select(!p, i[2], i[1]);
    o[3] = L::select(p.and_not(q), i[0], i[1]);
});

#[test]
fn binary_arithmetic_agrees() {
    let args = arguments(2, RANDOM, 1);
    assert_agree(&AddOp, &args);
    assert_agree(&SubOp, &args);
    assert_agree(&MulOp, &args);
    assert_agree(&DivOp, &args);
    assert_agree(&AssignOps, &args);
    assert_agree(&CopysignOp, &args);
}

#[test]
fn unary_operations_agree() {
    let args = arguments(1, RANDOM, 2);
    assert_agree(&NegOp, &args);
    assert_agree(&SqrtOp, &args);
    assert_agree(&AbsOp, &args);
    assert_agree(&RoundOp, &args);
    assert_agree(&SplatOp, &args);
}

#[test]
fn min_max_clamp_agree_with_the_documented_nan_rule() {
    let args = arguments(2, RANDOM, 3);
    let out = assert_agree(&MinMaxOp, &args);
    // The reference itself follows `if a < b { a } else { b }`.
    for (k, (&a, &b)) in args[0].iter().zip(&args[1]).enumerate() {
        let min = if a < b { a } else { b };
        let max = if a > b { a } else { b };
        assert!(same_bits(out[0][k], min), "min({a}, {b})");
        assert!(same_bits(out[1][k], max), "max({a}, {b})");
    }
    assert_agree(&ClampOp, &arguments(3, RANDOM, 4));
}

/// The values on which `minps`/`maxps`, NEON's `FMIN`/`FMAX` and
/// WebAssembly's `f32x4.min`/`max` disagree: signed zeros, NaN of either
/// sign; with infinities, ones and the smallest subnormals beside them.
const SIGNED_ZEROS_AND_NAN: [f32; 10] = [
    0.0,
    -0.0,
    f32::NAN,
    -f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    1.0,
    -1.0,
    1.0e-45,
    -1.0e-45,
];

/// Every `arity`-tuple of `values`, as argument columns.
fn every_tuple(values: &[f32], arity: usize) -> Vec<Vec<f32>> {
    let count = values.len().pow(arity as u32);
    (0..arity as u32)
        .map(|position| {
            let stride = values.len().pow(position);
            (0..count)
                .map(|c| values[c / stride % values.len()])
                .collect()
        })
        .collect()
}

/// `map`'s outputs on `backend` for the argument columns `args`.
fn run_on<M: LaneMap>(backend: Backend, map: &M, args: &[Vec<f32>]) -> Vec<Vec<f32>> {
    let inputs: Vec<&[f32]> = args.iter().map(Vec::as_slice).collect();
    let mut out = vec![vec![0.0; args[0].len()]; M::OUTPUTS];
    let mut outputs: Vec<&mut [f32]> = out.iter_mut().map(Vec::as_mut_slice).collect();
    map_arrays(backend, map, &inputs, &mut outputs);
    out
}

/// Asserts that `backend`'s `got` for `op` of `args` has `want`'s bits.
fn assert_rule(backend: Backend, op: &str, args: &[f32], got: f32, want: f32) {
    assert!(
        same_bits(got, want),
        "{backend}: {op}{args:?} = {got:e} ({:#010x}), the rule gives {want:e} ({:#010x})",
        got.to_bits(),
        want.to_bits()
    );
}

#[test]
fn signed_zeros_and_nan_in_min_max_clamp_follow_the_rule_on_every_backend() {
    // The contract (`vertebra_math::lane`) written out here, each backend
    // checked against it rather than against the scalar reference: the
    // second operand on equality (so `min(-0.0, 0.0)` is `0.0` and
    // `min(0.0, -0.0)` is `-0.0`) and when either operand is NaN.
    // Through `black_box`: with a constant operand the compiler may make
    // these `FMINNM` on AArch64, the very fold the lanes must not make.
    let min = |a: f32, b: f32| {
        let (a, b) = black_box((a, b));
        if a < b { a } else { b }
    };
    let max = |a: f32, b: f32| {
        let (a, b) = black_box((a, b));
        if a > b { a } else { b }
    };
    let singles = every_tuple(&SIGNED_ZEROS_AND_NAN, 1);
    let pairs = every_tuple(&SIGNED_ZEROS_AND_NAN, 2);
    let triples = every_tuple(&SIGNED_ZEROS_AND_NAN, 3);
    for backend in Backend::available() {
        let min_max = run_on(backend, &MinMaxOp, &pairs);
        for (k, (&a, &b)) in pairs[0].iter().zip(&pairs[1]).enumerate() {
            assert_rule(backend, "min", &[a, b], min_max[0][k], min(a, b));
            assert_rule(backend, "max", &[a, b], min_max[1][k], max(a, b));
        }
        let clamp = run_on(backend, &ClampOp, &triples);
        for (k, &x) in triples[0].iter().enumerate() {
            let (lo, hi) = (triples[1][k], triples[2][k]);
            assert_rule(
                backend,
                "clamp",
                &[x, lo, hi],
                clamp[0][k],
                min(max(x, lo), hi),
            );
        }
        let zero = run_on(backend, &ZeroBoundsOp, &singles);
        for (k, &x) in singles[0].iter().enumerate() {
            assert_rule(backend, "min", &[x, 0.0], zero[0][k], min(x, 0.0));
            assert_rule(backend, "max", &[x, 0.0], zero[1][k], max(x, 0.0));
            assert_rule(backend, "min", &[-0.0, x], zero[2][k], min(-0.0, x));
            assert_rule(backend, "max", &[-0.0, x], zero[3][k], max(-0.0, x));
        }
    }
}

#[test]
fn round_is_ties_to_even_everywhere() {
    let args = arguments(1, RANDOM, 5);
    let out = assert_agree(&RoundOp, &args);
    for (x, r) in args[0].iter().zip(&out[0]) {
        assert!(same_bits(*r, x.round_ties_even()), "round({x:e}) = {r:e}");
    }
}

#[test]
fn fused_multiply_add_agrees_and_fuses() {
    let args = arguments(3, RANDOM, 6);
    let out = assert_agree(&MulAddOp, &args);
    for k in 0..args[0].len() {
        let expected = args[0][k].mul_add(args[1][k], args[2][k]);
        assert!(same_bits(out[0][k], expected));
    }
}

#[test]
fn comparisons_and_masks_agree() {
    assert_agree(&CompareOps, &arguments(2, RANDOM, 7));
    assert_agree(&MaskOps, &arguments(3, RANDOM, 8));
}

#[test]
fn reduction_adds_in_lane_order() {
    // Within one backend the reduction is of one call's lanes; the map
    // applies it per chunk, so compare each backend with its own order.
    let values: Vec<f32> = (0..64)
        .map(|i| 1.0e8 * (-1.0f32).powi(i) + i as f32)
        .collect();
    for backend in Backend::available() {
        let mut out = vec![0.0; values.len()];
        map_arrays(backend, &ReduceOp, &[&values], &mut [&mut out]);
        let w = backend.lanes();
        for (chunk, sums) in values.chunks(w).zip(out.chunks(w)) {
            let expected = chunk.iter().skip(1).fold(chunk[0], |s, &x| s + x);
            assert!(
                sums.iter().all(|&s| s.to_bits() == expected.to_bits()),
                "{backend}"
            );
        }
    }
}

#[test]
fn this_machine_runs_the_simd_backends() {
    // The bit-exact tests above are only as good as the backends they ran.
    let names: Vec<_> = Backend::available().map(|b| b.name()).collect();
    eprintln!("backends on this CPU: {names:?}");
    assert!(Backend::Portable.is_available() && Backend::Scalar.is_available());
    #[cfg(target_arch = "x86_64")]
    assert!(
        Backend::Sse41.is_available(),
        "x86_64 CI machines have SSE4.1; without it the SIMD paths went untested"
    );
    #[cfg(target_arch = "aarch64")]
    assert_eq!(Backend::best(), Backend::Neon, "every AArch64 CPU has NEON");
    #[cfg(target_arch = "wasm32")]
    assert_eq!(
        Backend::Simd128.is_available(),
        cfg!(target_feature = "simd128"),
        "SIMD128 runs exactly in the builds made with it"
    );
}
