//! Each joint block's start of step: where its lanes' bodies stand as the
//! step begins (`StartLane`: the anchors' separation and lever arms, in
//! double precision), measured once before the substeps, each block
//! reading only the bodies and writing only itself, so that the step can
//! do it in chunks on its workers (`step::start_blocks_all`).

use vertebra_kernels::body::{BodyPairs, StartLane};
use vertebra_kernels::fixed::FixedBlock;
use vertebra_kernels::hinge::HingeBlock;
use vertebra_kernels::rod::RodBlock;
use vertebra_kernels::socket::SocketBlock;
use vertebra_math::block::BLOCK_LANES;
use vertebra_store::BodyStore;

/// The lanes of a block that hold a joint: a padding lane's start of step
/// stays as laid out (zero: the null row at the origin, no anchors), which
/// is what measuring it would give, and no kernel reads it into a row.
fn live_lanes(pairs: &BodyPairs) -> impl Iterator<Item = usize> + use<> {
    let padding = pairs.padding;
    (0..BLOCK_LANES).filter(move |lane| padding & (1 << lane) == 0)
}

/// A joint block whose lanes measure where their bodies stand as the step
/// begins, each block reading only the bodies and writing only itself.
pub(crate) trait StartBlock: Send {
    /// Every live lane's start of step, from `bodies`.
    fn start(&mut self, bodies: &BodyStore);
}

/// Sockets, hinges and fixed joints: their anchors (m, body frames).
macro_rules! start_at_anchors {
    ($($block:ty),*) => {$(
        impl StartBlock for $block {
            fn start(&mut self, bodies: &BodyStore) {
                for lane in live_lanes(&self.bodies) {
                    let anchors = (self.anchor_a.get(lane), self.anchor_b.get(lane));
                    start_lane(&mut self.bodies, lane, anchors, bodies);
                }
                self.reaction.reset();
            }
        }
    )*};
}

start_at_anchors!(SocketBlock, HingeBlock, FixedBlock);

/// Rods: the chord between the centres of mass.
impl StartBlock for RodBlock {
    fn start(&mut self, bodies: &BodyStore) {
        for lane in live_lanes(&self.bodies) {
            let centres = (glam::Vec3::ZERO, glam::Vec3::ZERO);
            start_lane(&mut self.bodies, lane, centres, bodies);
        }
    }
}

/// Each of `blocks`' start of step ([`StartBlock`]).
pub(crate) fn start_blocks<B: StartBlock>(blocks: &mut [B], bodies: &BodyStore) {
    blocks.iter_mut().for_each(|b| b.start(bodies));
}

/// Sets `lane`'s start of step for points `local` (m, body frames) on its
/// bodies; padding lanes (the null row) start at the origin.
fn start_lane(
    pairs: &mut BodyPairs,
    lane: usize,
    (local_a, local_b): (glam::Vec3, glam::Vec3),
    bodies: &BodyStore,
) {
    let pose = |row: u32| match row.checked_sub(1) {
        Some(i) => (
            bodies.precise_position(i as usize),
            bodies.orientation[i as usize],
        ),
        None => (glam::DVec3::ZERO, glam::Quat::IDENTITY),
    };
    let ((pa, qa), (pb, qb)) = (pose(pairs.body_a[lane]), pose(pairs.body_b[lane]));
    pairs.set_start(lane, &StartLane::new(pa, qa, local_a, pb, qb, local_b));
}
