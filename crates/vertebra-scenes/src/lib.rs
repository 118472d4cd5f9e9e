//! The paper's scenes (figures 1, 2, 6, 7, 8), on the reference humanoid,
//! three on the anatomical humanoid (a hit reaction, the drop, the stagger:
//! standing and walking on capped drives, hit on the chest), and a chain
//! with a 1:1000 mass ratio across a joint, at 60 Hz
//! with gravity (0, -9.81, 0), 1 substep and 20 iterations unless told
//! otherwise, each with a rod spine (simplified) or a socket spine
//! (standard). Used by the `vertebra` command, the benches and the tests.

mod builder;
mod config;
mod controllability;
mod following;
mod frame;
mod gait;
mod heavy_chain;
mod hit_reaction;
mod kinematics;
mod passive_bending;
mod quantity;
mod ragdoll_drop;
mod recovery;
mod run;
mod scene;
mod scene_world;
pub mod seed;
mod seeds;
mod setup;
mod skeleton_out;
mod spread;
mod stagger;
mod stagger_hit;
mod stagger_sweep;
mod walk;

pub use builder::build;
pub use config::SceneConfig;
pub use following::Following;
pub use frame::Frame;
pub use gait::{Foot, Gait};
pub use heavy_chain::{HEAVY_MASS, LINK_MASS, LINKS, heavy_chain};
pub use hit_reaction::HIT_FRAMES;
pub use kinematics::{Locus, kinematics};
pub use quantity::{Quantity, Stats};
pub use ragdoll_drop::ragdoll_drop;
pub use recovery::{RECOVERED, Recovery};
pub use run::{FRAME_DT, MAX_FRAMES, SceneRun, run, run_observed};
pub use scene::Scene;
pub use scene_world::SceneWorld;
pub use seeds::{Comparison, MAX_SEEDED_FRAMES, MAX_SEEDS, Seeded, compare};
pub use skeleton_out::SkeletonOut;
pub use spread::Spread;
pub use stagger::{
    STAGGER_HIT, WALK_SPEED, WALK_START, stagger_profile, stagger_walk, standing_lift,
};
pub use stagger_hit::{Activity, Side, StaggerHit, Tracking, UPRIGHT_FRACTION};
pub use stagger_sweep::{
    STAGGER_IMPULSES, STANDING_HIT_FRAME, StaggerSweep, TRACKED_FRAMES, WALKING_HIT_FRAME,
    WATCHED_FRAMES,
};
pub use walk::Walk;
