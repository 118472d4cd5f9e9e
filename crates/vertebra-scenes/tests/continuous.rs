//! Continuous collision changes no bit of the paper's drop: every frame
//! followed by `Collisions::after_step` (fast bodies swept against the
//! pit and put back where their cores would first have passed into it,
//! the contact events, the query tree) ends in the state of the plain run,
//! so no body of the 30-ragdoll pile ever came close to passing through a
//! wall (docs/contacts.md, "Fast limbs").

use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{FRAME_DT, Scene, SceneConfig, build, run};
use vertebra_world::JointSolver;

/// Four seconds: the fall, the impacts and the pile forming.
const FRAMES: usize = 240;

#[test]
fn the_drop_followed_by_continuous_collision_keeps_every_bit() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        for joints in [JointSolver::Iterative, JointSolver::Direct] {
            let mut config = SceneConfig::new(Scene::RagdollDrop, spine);
            config.joints = joints;
            config.frames = Some(FRAMES);
            let plain = run(&config, |_, _| {}).unwrap().state_hash;
            let mut scene = build(&config).unwrap();
            let mut began = 0;
            for frame in 0..FRAMES {
                scene.advance(config.scene, frame, FRAME_DT).unwrap();
                let set = scene.collisions.as_mut().expect("the drop collides");
                let moves = set.continuous_bodies(&scene.world);
                assert!(
                    moves.is_empty(),
                    "{spine:?}, {joints:?}, frame {frame}: {moves:?}"
                );
                set.after_step(&mut scene.world).unwrap();
                began += set.events().began().len();
            }
            assert_eq!(scene.world.state_hash(), plain, "{spine:?}, {joints:?}");
            assert!(
                began > 30,
                "{spine:?}, {joints:?}: {began} pairs began touching"
            );
        }
    }
}
