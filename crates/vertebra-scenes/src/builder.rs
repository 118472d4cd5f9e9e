//! Building a scene's world: each scene's own file builds it
//! (with what `setup.rs` gives them all); here is the one dispatch.

use vertebra_ragdoll::{RagdollDesc, RagdollError};

use crate::{
    Scene, SceneConfig, SceneWorld, controllability, heavy_chain, hit_reaction, passive_bending,
    ragdoll_drop, stagger,
};
use vertebra_math::DefaultFloatMode;

/// Builds `config`'s scene at its first frame.
pub fn build(config: &SceneConfig) -> Result<SceneWorld, RagdollError> {
    let _mode = DefaultFloatMode::enter();
    let desc = description(config)?;
    let drive = config.drive()?;
    let world = config.world()?;
    let built = match config.scene {
        Scene::PassiveBending => passive_bending::build(world, &desc, config),
        Scene::Controllability => controllability::build(world, &desc, config),
        Scene::RagdollDrop | Scene::AnatomicalDrop => ragdoll_drop::build(world, &desc, config),
        Scene::HitReaction => hit_reaction::build(world, &desc, config, &drive),
        Scene::HeavyChain => heavy_chain::build(world, &desc, config),
        Scene::Stagger => stagger::build(world, &desc, config),
    };
    Ok(built?.watching(config.measure_residuals))
}

/// The ragdoll `config`'s scene builds: its own, the heavy chain, or the
/// humanoid its scene is measured on.
pub(crate) fn description(config: &SceneConfig) -> Result<RagdollDesc, RagdollError> {
    match (config.scene, &config.ragdoll) {
        (Scene::HeavyChain, None) => heavy_chain::heavy_chain(),
        (Scene::HeavyChain, Some(_)) => Err(RagdollError::OutOfRange {
            context: "scene".to_owned(),
            field: "ragdoll",
            reason: "is given; the heavy chain hangs its own chain of bodies".to_owned(),
        }),
        (_, Some(desc)) => Ok(desc.clone()),
        (scene, None) if scene.is_paper() => Ok(RagdollDesc::reference_humanoid()),
        (_, None) => Ok(RagdollDesc::anatomical_humanoid()),
    }
}
