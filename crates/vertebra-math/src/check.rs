//! Cross-checking backends bit for bit: the adversarial inputs every kernel
//! is tried on, the one equality used (bits, with every NaN one value), and
//! a runner that compares each available backend with the scalar reference.

use core::fmt;

use crate::backend::Backend;
use crate::map::{LaneMap, map_arrays};

/// Inputs that break careless lane code: signed zeros, subnormals,
/// infinities, NaN, huge and tiny magnitudes, rounding ties, and the edges
/// of the polynomials' domains.
pub const ADVERSARIAL: &[f32] = &[
    0.0,
    -0.0,
    1.0e-45,
    -1.0e-45,
    1.0e-40,
    f32::MIN_POSITIVE,
    1.0e-30,
    -1.0e-30,
    1.0e-7,
    0.5,
    -0.5,
    1.5,
    2.5,
    -2.5,
    1.0,
    -1.0,
    1.000_000_1,
    0.999_999_94,
    -1.000_000_1,
    -0.999_999_94,
    core::f32::consts::FRAC_PI_4,
    core::f32::consts::FRAC_PI_2,
    core::f32::consts::PI,
    -core::f32::consts::PI,
    core::f32::consts::PI.next_up(),
    6.283_185_5,
    8192.0,
    -8192.0,
    8_388_607.5,
    8_388_608.0,
    1.0e30,
    -1.0e30,
    f32::MAX,
    f32::MIN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
];

/// Equality by bits, except that every NaN equals every NaN: Rust leaves a
/// NaN result's payload and sign unspecified, everything else is exact
/// (so `0.0` and `-0.0` differ here).
pub fn same_bits(a: f32, b: f32) -> bool {
    (a.is_nan() && b.is_nan()) || a.to_bits() == b.to_bits()
}

/// A backend's result that differs from the scalar reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Mismatch {
    /// The backend that differed.
    pub backend: Backend,
    /// Which output array.
    pub output: usize,
    /// Which element.
    pub index: usize,
    /// The inputs at that element.
    pub inputs: Vec<f32>,
    /// The scalar reference's value.
    pub expected: f32,
    /// The backend's value.
    pub actual: f32,
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} differs from scalar at output {} index {} for inputs {:?}: {:e} ({:#010x}) vs {:e} ({:#010x})",
            self.backend,
            self.output,
            self.index,
            self.inputs,
            self.actual,
            self.actual.to_bits(),
            self.expected,
            self.expected.to_bits()
        )
    }
}

/// Runs `map` on every backend this CPU has and compares each with
/// [`Backend::Scalar`] by [`same_bits`]. Returns the scalar outputs, or the
/// first mismatch.
pub fn backends_agree<M: LaneMap>(map: &M, inputs: &[&[f32]]) -> Result<Vec<Vec<f32>>, Mismatch> {
    let len = inputs.first().map_or(0, |a| a.len());
    let run = |backend: Backend| {
        let mut outputs = vec![vec![0.0f32; len]; M::OUTPUTS];
        let mut views: Vec<&mut [f32]> = outputs.iter_mut().map(|o| o.as_mut_slice()).collect();
        map_arrays(backend, map, inputs, &mut views);
        outputs
    };
    let expected = run(Backend::Scalar);
    for backend in Backend::available().filter(|&b| b != Backend::Scalar) {
        let actual = run(backend);
        for (output, (e, a)) in expected.iter().zip(&actual).enumerate() {
            if let Some(index) = (0..len).find(|&i| !same_bits(e[i], a[i])) {
                return Err(Mismatch {
                    backend,
                    output,
                    index,
                    inputs: inputs.iter().map(|x| x[index]).collect(),
                    expected: e[index],
                    actual: a[index],
                });
            }
        }
    }
    Ok(expected)
}
