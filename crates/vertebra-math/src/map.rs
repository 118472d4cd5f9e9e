//! Applying one lane-generic function across arrays on a chosen backend:
//! how the polynomials and vector operations are run in bulk, benchmarked,
//! and cross-checked between backends.

use crate::backend::{Backend, LaneKernel};
use crate::lane::Lane;

/// The most inputs or outputs a [`LaneMap`] may have.
pub const MAX_ARGUMENTS: usize = 24;

/// A function from `INPUTS` lane values to `OUTPUTS` lane values, lane by
/// lane, written once for every lane type.
pub trait LaneMap {
    /// How many input arrays (at most [`MAX_ARGUMENTS`]).
    const INPUTS: usize;
    /// How many output arrays (at most [`MAX_ARGUMENTS`]).
    const OUTPUTS: usize;
    /// Computes `outputs` from `inputs` (slices of `INPUTS` and `OUTPUTS`
    /// values). Mark it `#[inline(always)]`, as every lane-generic body.
    fn apply<L: Lane>(&self, inputs: &[L], outputs: &mut [L]);
}

/// Runs `map` over arrays on `backend`: `outputs[j][i]` is output `j` of
/// the function at `inputs[0][i], inputs[1][i], ...`. A tail shorter than
/// the lane width is padded with zeros, whose results are dropped.
///
/// # Panics
/// If the counts of arrays do not match the map's, or the arrays' lengths
/// differ.
pub fn map_arrays<M: LaneMap>(
    backend: Backend,
    map: &M,
    inputs: &[&[f32]],
    outputs: &mut [&mut [f32]],
) {
    assert!(M::INPUTS <= MAX_ARGUMENTS && M::OUTPUTS <= MAX_ARGUMENTS);
    assert_eq!(inputs.len(), M::INPUTS, "input array count");
    assert_eq!(outputs.len(), M::OUTPUTS, "output array count");
    let len = inputs.first().map_or(0, |a| a.len());
    assert!(
        inputs.iter().all(|a| a.len() == len),
        "input lengths differ"
    );
    assert!(
        outputs.iter().all(|a| a.len() == len),
        "output lengths differ"
    );
    backend.dispatch(MapKernel {
        map,
        inputs,
        outputs,
        len,
    });
}

struct MapKernel<'a, 'b, M> {
    map: &'a M,
    inputs: &'a [&'a [f32]],
    outputs: &'a mut [&'b mut [f32]],
    len: usize,
}

impl<M: LaneMap> LaneKernel for MapKernel<'_, '_, M> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lane>(self) {
        let mut lanes_in = [L::splat(0.0); MAX_ARGUMENTS];
        let mut lanes_out = [L::splat(0.0); MAX_ARGUMENTS];
        let (ins, outs) = (&mut lanes_in[..M::INPUTS], &mut lanes_out[..M::OUTPUTS]);
        let full = self.len - self.len % L::WIDTH;
        for start in (0..full).step_by(L::WIDTH) {
            for (lane, array) in ins.iter_mut().zip(self.inputs) {
                *lane = L::load(&array[start..]);
            }
            self.map.apply(ins, outs);
            for (lane, array) in outs.iter().zip(self.outputs.iter_mut()) {
                lane.store(&mut array[start..]);
            }
        }
        if full == self.len {
            return;
        }
        // The tail: padded with zeros, whose results are dropped.
        let count = self.len - full;
        let mut padded = [0.0f32; MAX_LANES];
        for (lane, array) in ins.iter_mut().zip(self.inputs) {
            padded[..count].copy_from_slice(&array[full..]);
            *lane = L::load(&padded);
        }
        self.map.apply(ins, outs);
        for (lane, array) in outs.iter().zip(self.outputs.iter_mut()) {
            lane.store(&mut padded);
            array[full..].copy_from_slice(&padded[..count]);
        }
    }
}

/// The widest lane type's width.
const MAX_LANES: usize = crate::block::BLOCK_LANES;
