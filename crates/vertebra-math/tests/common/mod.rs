//! Inputs and helpers shared by the math layer's tests.
#![allow(dead_code)]

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use vertebra_math::check::{ADVERSARIAL, backends_agree};
use vertebra_math::map::LaneMap;

/// Declares a unit struct implementing `LaneMap` with the given body.
#[macro_export]
macro_rules! lane_map {
    ($name:ident, $inputs:literal -> $outputs:literal, |$i:ident, $o:ident| $body:block) => {
        struct $name;
        impl vertebra_math::map::LaneMap for $name {
            const INPUTS: usize = $inputs;
            const OUTPUTS: usize = $outputs;
            #[inline(always)]
            fn apply<L: vertebra_math::Lane>(&self, $i: &[L], $o: &mut [L]) $body
        }
    };
}

pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// A float from one of three families: any bit pattern (subnormals, NaNs,
/// infinities included), a moderate uniform value, or a log-uniform
/// magnitude between 1e-20 and 1e20 with a random sign.
pub fn random_float(rng: &mut StdRng) -> f32 {
    match rng.random_range(0..3) {
        0 => f32::from_bits(rng.random::<u32>()),
        1 => rng.random_range(-10.0f32..10.0),
        _ => {
            let magnitude = 10f32.powf(rng.random_range(-20.0f32..20.0));
            if rng.random::<bool>() {
                magnitude
            } else {
                -magnitude
            }
        }
    }
}

/// `count` random floats from `range`.
pub fn uniform(rng: &mut StdRng, count: usize, range: core::ops::Range<f32>) -> Vec<f32> {
    (0..count)
        .map(|_| rng.random_range(range.clone()))
        .collect()
}

/// Argument tuples of `arity`: every combination of the adversarial values
/// (for arity <= 2), then `random` tuples drawn from `random_float`.
pub fn arguments(arity: usize, random: usize, seed: u64) -> Vec<Vec<f32>> {
    let mut columns = vec![Vec::new(); arity];
    let combos = if arity <= 2 {
        ADVERSARIAL.len().pow(arity as u32)
    } else {
        0
    };
    for c in 0..combos {
        let mut k = c;
        for column in columns.iter_mut() {
            column.push(ADVERSARIAL[k % ADVERSARIAL.len()]);
            k /= ADVERSARIAL.len();
        }
    }
    // Each adversarial value in every position, with random partners.
    let mut rng = rng(seed);
    for position in 0..arity {
        for &v in ADVERSARIAL {
            for (j, column) in columns.iter_mut().enumerate() {
                column.push(if j == position {
                    v
                } else {
                    random_float(&mut rng)
                });
            }
        }
    }
    for _ in 0..random {
        for column in columns.iter_mut() {
            column.push(random_float(&mut rng));
        }
    }
    columns
}

/// Asserts that every available backend gives the scalar reference's bits.
pub fn assert_agree<M: LaneMap>(map: &M, columns: &[Vec<f32>]) -> Vec<Vec<f32>> {
    let views: Vec<&[f32]> = columns.iter().map(|c| c.as_slice()).collect();
    backends_agree(map, &views).unwrap_or_else(|m| panic!("{m}"))
}
