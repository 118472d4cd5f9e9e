//! Rays at the 30-ragdoll pile: through the query tree they hit what
//! testing every collider hits, bit for bit, and they name the ragdoll and
//! bone.

use glam::Vec3;
use vertebra_collide::QueryFilter;
use vertebra_ragdoll::SpineMode;
use vertebra_scenes::{FRAME_DT, Scene, SceneConfig, build};

#[test]
fn rays_at_the_pile_hit_what_every_collider_tested_hits() {
    let config = SceneConfig::new(Scene::RagdollDrop, SpineMode::Rod);
    let mut scene = build(&config).unwrap();
    for frame in 0..180 {
        scene.advance(config.scene, frame, FRAME_DT).unwrap();
    }
    // A lattice of rays from a dome over the pit toward points in it.
    let rays: Vec<(Vec3, Vec3)> = (0..1200)
        .map(|k| {
            let (a, b) = (k as f32 * 0.618_034, k as f32 * 0.381_966);
            let from = Vec3::new(
                4.0 * a.sin(),
                2.0 + (b * 3.0).sin().abs() * 2.0,
                4.0 * a.cos(),
            );
            let to = Vec3::new(
                1.5 * (b * 7.0).sin(),
                0.3 * (a * 5.0).cos().abs(),
                1.5 * (a * 3.0).cos(),
            );
            (from, (to - from).normalize())
        })
        .collect();
    let set = scene.collisions.as_mut().unwrap();
    let all = QueryFilter::default();
    let every: Vec<_> = (rays.iter())
        .map(|&(o, d)| set.cast_ray(&scene.world, o, d, 20.0, &all).unwrap())
        .collect();
    set.refresh_queries(&scene.world).unwrap();
    let mut bones = 0;
    for (k, &(o, d)) in rays.iter().enumerate() {
        let treed = set.cast_ray(&scene.world, o, d, 20.0, &all).unwrap();
        assert_eq!(treed, every[k], "ray {k}");
        if let Some(hit) = treed
            && let Some(part) = hit.part
        {
            let ragdoll = (scene.ragdolls.iter())
                .find(|r| r.first_body() == Some(part.ragdoll))
                .expect("the ragdoll named");
            assert_eq!(ragdoll.bodies[part.bone as usize], Some(hit.body));
            bones += 1;
        }
    }
    assert!(bones > 300, "the rays hit the ragdolls' bones: {bones}");
}
