//! The 30-ragdoll drop through the C ABI, for the benchmarks that weigh
//! it against the Rust API (`capi.rs`, `capi_instructions.rs`): the
//! scene's state saved as bytes, and the same scene made through the C
//! functions from them.

use std::ptr::null_mut;

use vertebra_benches::DT;
use vertebra_capi::{
    VtCollisions, VtResult, VtSolverConfig, VtWorld, vt_collisions_create, vt_collisions_destroy,
    vt_collisions_restore, vt_collisions_update, vt_world_create, vt_world_destroy,
    vt_world_restore, vt_world_state_hash, vt_world_step,
};
use vertebra_scenes::SceneWorld;

/// The scene's state as bytes: the world's and the collision layer's.
pub struct Saved {
    /// The world's snapshot.
    pub world: Vec<u8>,
    /// The collision layer's snapshot.
    pub collisions: Vec<u8>,
}

pub fn save(scene: &SceneWorld) -> Saved {
    let collisions = scene.collisions.as_ref().expect("the drop has colliders");
    Saved {
        world: scene.world.snapshot().as_bytes().to_vec(),
        collisions: collisions
            .snapshot(&scene.world)
            .expect("the set serves its world")
            .as_bytes()
            .to_vec(),
    }
}

/// Puts the Rust scene back to `saved`.
pub fn put_back(scene: &mut SceneWorld, saved: &Saved) {
    let world = vertebra_world::Snapshot::from_bytes(saved.world.clone());
    scene.world.restore(&world).expect("the world back");
    let layer = vertebra_collide::CollisionSnapshot::from_bytes(saved.collisions.clone());
    let collisions = scene.collisions.as_mut().expect("colliders");
    collisions
        .restore(&layer, &scene.world)
        .expect("the colliders back");
}

/// The same scene made through the C ABI: a world of the scene's settings
/// and a collision layer, restored from the scene's bytes.
pub struct CScene {
    world: *mut VtWorld,
    collisions: *mut VtCollisions,
}

impl CScene {
    pub fn new(scene: &SceneWorld, saved: &Saved) -> Self {
        let config = VtSolverConfig::from(scene.world.config());
        let (mut world, mut collisions) = (null_mut(), null_mut());
        // SAFETY: valid pointers to a config and to the two output places.
        let made = unsafe {
            [
                vt_world_create(&config, &mut world),
                vt_collisions_create(&mut collisions),
            ]
        };
        assert_eq!(made, [VtResult::Ok; 2]);
        let scene = Self { world, collisions };
        scene.put_back(saved);
        scene
    }

    pub fn put_back(&self, saved: &Saved) {
        // SAFETY: live objects made in `new`; the byte slices' own pointers
        // and lengths.
        let restored = unsafe {
            [
                vt_world_restore(self.world, saved.world.as_ptr(), saved.world.len()),
                vt_collisions_restore(
                    self.collisions,
                    self.world,
                    saved.collisions.as_ptr(),
                    saved.collisions.len(),
                ),
            ]
        };
        assert_eq!(restored, [VtResult::Ok; 2]);
    }

    pub fn frame(&self) {
        // SAFETY: live objects made in `new`, used by this thread only.
        let done = unsafe {
            [
                vt_collisions_update(self.collisions, self.world, DT),
                vt_world_step(self.world, DT),
            ]
        };
        assert_eq!(done, [VtResult::Ok; 2]);
    }

    pub fn hash(&self) -> u64 {
        let mut hash = 0;
        // SAFETY: a live world; a valid output place.
        let done = unsafe { vt_world_state_hash(self.world, &mut hash) };
        assert_eq!(done, VtResult::Ok);
        hash
    }
}

impl Drop for CScene {
    fn drop(&mut self) {
        // SAFETY: made in `new`, destroyed once, here.
        unsafe {
            vt_collisions_destroy(self.collisions);
            vt_world_destroy(self.world);
        }
    }
}
