//! Residual error of joints, the figure-8 metric: one generic pass over any
//! joint block that can measure itself.

use vertebra_math::block::BLOCK_LANES;
use vertebra_math::{Lane, LaneKernel};

use crate::body::BodyRows;

/// One joint's residual error, per lane.
#[derive(Clone, Copy, Debug)]
pub struct Measured<L> {
    /// Linear error (m): anchor separation, a rod's `|C_len|`.
    pub linear: L,
    /// Angular error (rad): the held rotations' error plus `limit`.
    pub angular: L,
    /// The part of `angular` that is limit overshoot (rad): how far past a
    /// swing cone, twist or hinge range, or a rod's bend or twist limit.
    pub limit: L,
}

/// A block of joints that measures its residual error.
pub trait Residual {
    /// The residual of lanes `start .. start + L::WIDTH`.
    fn residual<L: Lane>(&self, rows: &BodyRows, start: usize) -> Measured<L>;
}

/// Residual error of every lane of `blocks`.
pub struct ResidualPass<'a, B> {
    /// The blocks.
    pub blocks: &'a [B],
    /// Body rows (poses read).
    pub rows: &'a BodyRows,
    /// Per lane of every block: (linear m, angular rad, of which limit
    /// overshoot rad).
    pub out: &'a mut [[f32; 3]],
}

impl<B: Residual> LaneKernel for ResidualPass<'_, B> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        let mut linear = [0.0f32; BLOCK_LANES];
        let mut angular = [0.0f32; BLOCK_LANES];
        let mut limit = [0.0f32; BLOCK_LANES];
        for (block, out) in self.blocks.iter().zip(self.out.chunks_mut(BLOCK_LANES)) {
            for start in (0..BLOCK_LANES).step_by(L::WIDTH) {
                let m = block.residual::<L>(self.rows, start);
                m.linear.store(&mut linear[start..]);
                m.angular.store(&mut angular[start..]);
                m.limit.store(&mut limit[start..]);
            }
            for (lane, o) in out.iter_mut().enumerate() {
                *o = [linear[lane], angular[lane], limit[lane]];
            }
        }
    }
}
