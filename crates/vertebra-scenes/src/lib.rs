//! The paper's scenes (figures 1, 2, 6, 7, 8), on the reference humanoid,
//! at 60 Hz with gravity (0, -9.81, 0), 1 substep and 20 iterations unless
//! told otherwise, each with a rod spine (simplified) or a socket spine
//! (standard). Used by the `vertebra` command, the benches and the tests.

mod kinematics;
mod quantity;
mod run;
pub mod seed;
mod seeds;
mod setup;
mod spread;

pub use kinematics::{Locus, kinematics};
pub use quantity::{Quantity, Stats};
pub use run::{Frame, MAX_FRAMES, SceneRun, run};
pub use seeds::{Comparison, MAX_SEEDED_FRAMES, MAX_SEEDS, Seeded, compare};
pub use setup::{Scene, SceneConfig, SceneWorld, build, ragdoll_drop};
pub use spread::Spread;
