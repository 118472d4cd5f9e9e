//! The passes a substep runs over its blocks: the position iteration
//! ([`Positions`]) and the velocity and relax passes ([`Velocities`]),
//! each one [`Pass`] whatever the block: joints through their kind's
//! kernels ([`JointBlock`]), contacts, and the direct solve's trees.

use vertebra_kernels::body::BodyRows;
use vertebra_kernels::contact::{self, ContactBlock, VelocitySettings};
use vertebra_kernels::direct::{self, Topology, TreeBlock};
use vertebra_kernels::pass::{SubstepScale, run};
use vertebra_math::Backend;
use vertebra_math::block::BLOCK_LANES;

use crate::kinds::{BlockKind, JointBlock};

/// One kind of pass over a stage's blocks.
pub(crate) trait Pass: Sync {
    /// Whether the pass has work for joints: else the substep leaves their
    /// stages out, and never calls [`Self::joints`].
    const JOINTS: bool;
    /// Joint blocks, all of `kind` (nothing but in a pass with
    /// [`Self::JOINTS`]).
    fn joints<B: JointBlock>(&self, _: &mut [B], _: BlockKind, _: &BodyRows, _: Backend) {}
    /// Contacts.
    fn contacts(&self, blocks: &mut [ContactBlock], rows: &BodyRows, backend: Backend);
    /// The direct solve's trees (nothing but in the position pass):
    /// `joined`, all of `blocks` are one solve (trees cut into pieces),
    /// else each block is.
    fn trees(&self, _: &mut [TreeBlock], _: &[Topology], _: &BodyRows, _: Backend, _: bool) {}
}

/// The position iteration.
#[derive(Clone, Copy)]
pub(crate) struct Positions {
    pub scale: SubstepScale,
    /// How many times a tree solve may factor its tree
    /// (`direct::PositionPass::passes`).
    pub passes: usize,
}

impl Pass for Positions {
    const JOINTS: bool = true;
    fn joints<B: JointBlock>(
        &self,
        blocks: &mut [B],
        kind: BlockKind,
        rows: &BodyRows,
        backend: Backend,
    ) {
        B::positions(blocks, kind, self.scale, rows, backend);
    }
    fn contacts(&self, blocks: &mut [ContactBlock], rows: &BodyRows, backend: Backend) {
        run::<contact::Positions>(backend, blocks, rows, ());
    }
    fn trees(
        &self,
        blocks: &mut [TreeBlock],
        topologies: &[Topology],
        rows: &BodyRows,
        backend: Backend,
        joined: bool,
    ) {
        let solve = |blocks: &mut [TreeBlock], backend: Backend| {
            direct::PositionPass {
                blocks,
                topologies,
                rows,
                scale: self.scale,
                passes: self.passes,
            }
            .run(backend);
        };
        if joined {
            solve(blocks, backend);
        } else {
            for block in blocks.chunks_mut(1) {
                solve(block, backend_for_tree(backend, &block[0]));
            }
        }
    }
}

/// The backend a tree block is solved on: the world's, except that a
/// block of one live tree (a shape seen once) runs on the scalar path
/// where the world's is 4-lane SSE4.1: there the scalar path measured
/// cheaper for it (the single ragdoll's direct step: 498k
/// instructions against 532k on sse4), where on AVX2 the 4-lane half is
/// (457k). Every backend gives the same bits.
fn backend_for_tree(backend: Backend, block: &TreeBlock) -> Backend {
    let live = (!block.padding & ((1 << BLOCK_LANES) - 1)).count_ones();
    match backend {
        Backend::Sse41 if live == 1 => Backend::Scalar,
        _ => backend,
    }
}

/// The velocity pass (contact friction and restitution; joints have none:
/// drives damp at the position level), or with `relax` a relax pass
/// (`contact::Velocities`: the contacts take back their push-out's speed).
pub(crate) struct Velocities(pub VelocitySettings);

impl Pass for Velocities {
    const JOINTS: bool = false;
    fn contacts(&self, blocks: &mut [ContactBlock], rows: &BodyRows, backend: Backend) {
        run::<contact::Velocities>(backend, blocks, rows, self.0);
    }
}
