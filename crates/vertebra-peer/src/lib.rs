//! The peer comparison: vertebra's scenes rebuilt body for body in
//! [rapier3d](https://rapier.rs), stepped by rapier, and measured by
//! vertebra's own residual code.
//!
//! [`RapierScene::from_scene`] translates a built [`SceneWorld`]: every
//! body with its mass, inertia, pose, velocity and damping; every collider
//! with the same parry shape, friction, restitution and filtering; every
//! socket as a rapier spherical joint (anchors and frames equal, the swing
//! cone as limits on the two swing axes, the twist range on the twist axis),
//! or a fixed joint for a pin (a drive of zero compliance). Rods have no
//! rapier counterpart, so the peer runs standard (socket-spine) ragdolls.
//!
//! Each frame, [`RapierScene::mirror`] copies rapier's body poses into the
//! scene's own world, where [`SceneWorld::measure`] computes `eps_lin` and
//! `eps_ang` exactly as it does for vertebra: one metric for both engines.
//! What is matched and what cannot be is listed in `docs/performance.md`.

mod rapier;
mod run;

pub use rapier::{PeerError, RapierScene, RapierSettings};
pub use run::{PeerRun, run};

#[cfg(doc)]
use vertebra_scenes::SceneWorld;
