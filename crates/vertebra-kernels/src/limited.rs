//! Soft limits' settings as blocks hold them, and the limits' substep
//! start ([`Starts`]): each limit's violation `C_0` measured before the
//! bodies are predicted, which a damped limit's correction
//! (`parts::limit`) measures its rate against. Run on the blocks that can
//! hold soft limits: the socket's shaped path and the hinge.

use core::marker::PhantomData;

use vertebra_math::Lane;
use vertebra_math::block::BLOCK_LANES;

use crate::body::{BodyLanes, BodyPairs, BodyRows};
use crate::parts::limit::Softness;
use crate::pass::BlockKernel;

/// One joint's limit softness (one lane; see `parts::limit`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitLane {
    /// Compliance (rad / (N m)); 0 with the others 0 is hard.
    pub compliance: f32,
    /// Compliance per unit effective inverse inertia, `1 / omega^2` (s^2),
    /// for limits given by frequency.
    pub period2: f32,
    /// Damping `gamma h` (s): compliance times damping, or `2 zeta / omega`.
    pub damping_time: f32,
}

impl LimitLane {
    /// A hard limit.
    pub const HARD: Self = Self {
        compliance: 0.0,
        period2: 0.0,
        damping_time: 0.0,
    };
}

/// Eight limits' softness, field by field.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct SoftnessBlock {
    /// Compliance (rad / (N m)).
    pub compliance: [f32; BLOCK_LANES],
    /// `1 / omega^2` (s^2).
    pub period2: [f32; BLOCK_LANES],
    /// `gamma h` (s).
    pub damping_time: [f32; BLOCK_LANES],
}

impl SoftnessBlock {
    /// Writes one lane.
    pub fn set(&mut self, lane: usize, s: &LimitLane) {
        self.compliance[lane] = s.compliance;
        self.period2[lane] = s.period2;
        self.damping_time[lane] = s.damping_time;
    }

    /// The lane's settings back.
    pub fn get(&self, lane: usize) -> LimitLane {
        LimitLane {
            compliance: self.compliance[lane],
            period2: self.period2[lane],
            damping_time: self.damping_time[lane],
        }
    }

    /// The lanes from `start`, scaled to the substep (`1 / h`, `1 / h^2`).
    #[inline(always)]
    pub fn lanes<L: Lane>(&self, start: usize, inv_h: L, inv_h2: L) -> Softness<L> {
        Softness::new(
            L::load(&self.compliance[start..]),
            L::load(&self.period2[start..]),
            L::load(&self.damping_time[start..]),
            inv_h,
            inv_h2,
        )
    }
}

/// A block of joints with soft-capable limits: what [`Starts`] needs.
pub trait Limited {
    /// The lanes' bodies.
    fn bodies(&self) -> &BodyPairs;
    /// Measures and stores every limit's violation of the lanes from
    /// `start` on bodies `a`, `b` (the substep's `C_0`).
    fn start_limits<L: Lane>(&mut self, start: usize, a: &BodyLanes<L>, b: &BodyLanes<L>);
}

/// The limits' substep start (before the bodies are predicted; a
/// [`BlockPass`](crate::pass::BlockPass) over `B`s): every limit's
/// violation, for the damping of the next iterations.
pub struct Starts<B>(PhantomData<fn() -> B>);

impl<B: Limited> BlockKernel for Starts<B> {
    type Block = B;
    type Params = ();
    #[inline(always)]
    fn padding(block: &B) -> u32 {
        block.bodies().padding
    }
    #[inline(always)]
    fn solve<L: Lane>(block: &mut B, start: usize, rows: &BodyRows, (): ()) {
        let (a, b) = block.bodies().gather::<L>(rows, start);
        block.start_limits(start, &a, &b);
    }
}
