//! One pass over blocks, whatever the kernel: [`BlockPass`] walks its
//! blocks and runs a [`BlockKernel`] on every live slice of each
//! ([`for_live_slices`]), so that a kernel states only what it does to one
//! slice of lanes, what the pass shares ([`BlockKernel::Params`]) and
//! which blocks it leaves alone.

use vertebra_math::block::{LaneSlices, for_live_slices};
use vertebra_math::{Backend, Lane, LaneKernel};

use crate::body::BodyRows;

/// The substep's `1 / h` (1/s) and `1 / h^2` (1/s^2), which scale a
/// drive's `gamma` and the soft parts' compliance and damping
/// (`parts::drive`, `parts::limit`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubstepScale {
    /// `1 / h`.
    pub inv_h: f32,
    /// `1 / h^2`.
    pub inv_h2: f32,
}

/// A kernel run on every block of a [`BlockPass`]: one variant of a
/// kind's position, velocity or substep-start solve.
pub trait BlockKernel {
    /// The blocks it solves.
    type Block;
    /// What every block of a pass shares (the substep's scales, the
    /// substep `h`, or nothing).
    type Params: Copy;
    /// The block's padding lanes (bit `i` set: lane `i` is padding).
    fn padding(block: &Self::Block) -> u32;
    /// Whether the pass leaves `block` alone (none unless a kernel says
    /// so): read from the layout, never from lane data.
    #[inline(always)]
    fn skips(_block: &Self::Block) -> bool {
        false
    }
    /// Solves lanes `start .. start + L::WIDTH` of `block`.
    fn solve<L: Lane>(block: &mut Self::Block, start: usize, rows: &BodyRows, params: Self::Params);
}

/// `K` over every block of `blocks`, each on its live slices.
pub struct BlockPass<'a, K: BlockKernel> {
    /// The blocks (one colour's, or the overflow set).
    pub blocks: &'a mut [K::Block],
    /// Body rows, read and, as the kernel says, written.
    pub rows: &'a BodyRows,
    /// What every block shares.
    pub params: K::Params,
}

impl<K: BlockKernel> LaneKernel for BlockPass<'_, K> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        for block in self.blocks.iter_mut() {
            if K::skips(block) {
                continue;
            }
            let padding = K::padding(block);
            let mut slices = Slices::<K> {
                block,
                rows: self.rows,
                params: self.params,
            };
            for_live_slices::<L, _>(padding, &mut slices);
        }
    }
}

/// Runs `K` over `blocks` on `backend` with what its pass shares: one
/// [`BlockPass`].
#[inline(always)]
pub fn run<K: BlockKernel>(
    backend: Backend,
    blocks: &mut [K::Block],
    rows: &BodyRows,
    params: K::Params,
) {
    backend.dispatch(BlockPass::<K> {
        blocks,
        rows,
        params,
    });
}

/// One block of a [`BlockPass`].
struct Slices<'a, K: BlockKernel> {
    block: &'a mut K::Block,
    rows: &'a BodyRows,
    params: K::Params,
}

impl<K: BlockKernel> LaneSlices for Slices<'_, K> {
    #[inline(always)]
    fn slice<L: Lane>(&mut self, start: usize) {
        K::solve::<L>(self.block, start, self.rows, self.params);
    }
}
