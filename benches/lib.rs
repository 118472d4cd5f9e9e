//! Workloads shared by the criterion (time) and iai-callgrind (instruction
//! count) benchmarks, so both measure exactly the same work.

use vertebra_math::map::{LaneMap, map_arrays};
use vertebra_math::{Backend, Lane, Quat, Vec3, poly};

/// Elements per workload: 4 KiB per array, in L1 with room to spare.
pub const ELEMENTS: usize = 1024;

/// Input and output arrays for one [`LaneMap`] on one backend.
pub struct Workload {
    backend: Backend,
    inputs: Vec<Vec<f32>>,
    outputs: Vec<Vec<f32>>,
}

impl Workload {
    /// Deterministic inputs in `[lo, hi)` for `map` on `backend`.
    pub fn new<M: LaneMap>(backend: Backend, _map: &M, lo: f32, hi: f32) -> Self {
        if !backend.is_available() {
            eprintln!("warning: {backend} is not available here; it runs as scalar");
        }
        // A low-discrepancy sequence per column: spread, repeatable, no RNG.
        let inputs = (0..M::INPUTS)
            .map(|c| {
                let step = 0.618_034 + 0.1 * c as f32;
                (0..ELEMENTS)
                    .map(|k| lo + (hi - lo) * (k as f32 * step).fract())
                    .collect()
            })
            .collect();
        Self {
            backend,
            inputs,
            outputs: vec![vec![0.0; ELEMENTS]; M::OUTPUTS],
        }
    }

    /// Runs `map` over every element once.
    pub fn run<M: LaneMap>(&mut self, map: &M) {
        let inputs: Vec<&[f32]> = self.inputs.iter().map(|c| c.as_slice()).collect();
        let mut outputs: Vec<&mut [f32]> =
            self.outputs.iter_mut().map(|c| c.as_mut_slice()).collect();
        map_arrays(self.backend, map, &inputs, &mut outputs);
    }

    /// The first output array (to keep the work observable).
    pub fn output(&self) -> &[f32] {
        &self.outputs[0]
    }
}

/// `sin_cos(x)`.
pub struct SinCos;
impl LaneMap for SinCos {
    const INPUTS: usize = 1;
    const OUTPUTS: usize = 2;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        (o[0], o[1]) = poly::sin_cos(i[0]);
    }
}

/// `acos(x)`.
pub struct Acos;
impl LaneMap for Acos {
    const INPUTS: usize = 1;
    const OUTPUTS: usize = 1;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        o[0] = poly::acos(i[0]);
    }
}

/// `atan2(y, x)`.
pub struct Atan2;
impl LaneMap for Atan2 {
    const INPUTS: usize = 2;
    const OUTPUTS: usize = 1;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        o[0] = poly::atan2(i[0], i[1]);
    }
}

/// `sin(x/2)/x`.
pub struct HalfSinc;
impl LaneMap for HalfSinc {
    const INPUTS: usize = 1;
    const OUTPUTS: usize = 1;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        o[0] = poly::half_sinc(i[0]);
    }
}

/// Normalises a quaternion and rotates a vector by it.
pub struct QuatRotate;
impl LaneMap for QuatRotate {
    const INPUTS: usize = 7;
    const OUTPUTS: usize = 3;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        let q = Quat::new(i[0], i[1], i[2], i[3]).normalize();
        let v = q.rotate(Vec3::new(i[4], i[5], i[6]));
        (o[0], o[1], o[2]) = (v.x, v.y, v.z);
    }
}
