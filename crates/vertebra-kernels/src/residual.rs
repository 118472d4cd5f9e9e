//! Residual error of joints, the figure-8 metric: one generic pass over any
//! joint block that can measure itself.

use vertebra_math::block::BLOCK_LANES;
use vertebra_math::{Lane, LaneKernel};

use crate::body::BodyRows;

/// A block of joints that measures its residual error.
pub trait Residual {
    /// (linear m, angular rad) of lanes `start .. start + L::WIDTH`.
    fn residual<L: Lane>(&self, rows: &BodyRows, start: usize) -> (L, L);
}

/// Residual error of every lane of `blocks`.
pub struct ResidualPass<'a, B> {
    /// The blocks.
    pub blocks: &'a [B],
    /// Body rows (poses read).
    pub rows: &'a BodyRows,
    /// Per lane of every block: (linear m, angular rad).
    pub out: &'a mut [[f32; 2]],
}

impl<B: Residual> LaneKernel for ResidualPass<'_, B> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        let mut linear = [0.0f32; BLOCK_LANES];
        let mut angular = [0.0f32; BLOCK_LANES];
        for (block, out) in self.blocks.iter().zip(self.out.chunks_mut(BLOCK_LANES)) {
            for start in (0..BLOCK_LANES).step_by(L::WIDTH) {
                let (lin, ang) = block.residual::<L>(self.rows, start);
                lin.store(&mut linear[start..]);
                ang.store(&mut angular[start..]);
            }
            for (lane, o) in out.iter_mut().enumerate() {
                *o = [linear[lane], angular[lane]];
            }
        }
    }
}
