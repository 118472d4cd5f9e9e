//! A scene's settings reach the world it builds.

use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{Scene, SceneConfig, build};
use vertebra_world::JointSolver;

#[test]
fn the_scene_config_sets_the_worlds_joint_solver() {
    for joints in [JointSolver::Iterative, JointSolver::Direct] {
        for scene in Scene::ALL {
            let mut config = SceneConfig::new(scene, SpineMode::Sockets);
            config.joints = joints;
            assert_eq!(
                build(&config).unwrap().world.config().joints,
                joints,
                "{scene}"
            );
        }
    }
}
