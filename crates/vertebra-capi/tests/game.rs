//! The calls a game makes every frame, through the C ABI as C calls them:
//! the frame in one call, a shot at a bone, which bone hit the floor how
//! hard, a joint found by name torn off past its threshold; bit for bit
//! what the Rust API does, and refusals that change nothing.

use std::ffi::CString;
use std::ptr::{null, null_mut};

use glam::Vec3;
use vertebra_capi::*;
use vertebra_collide::{Collider, ColliderShape, Collisions, QueryFilter};
use vertebra_ragdoll::{BuildOptions, Pose, RagdollDesc, SpineMode};
use vertebra_world::{BodyDesc, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

/// A zeroed plain C struct, as C's `= {0}` makes one.
fn zeroed<T: Copy>() -> T {
    // SAFETY: only called for the C ABI's plain structs, whose every field
    // is a number: any bits are a value.
    unsafe { std::mem::zeroed() }
}

fn ok(result: VtResult) {
    assert_eq!(result, VtResult::Ok, "{result:?}");
}

/// A C world with a ground plane and the reference humanoid 0.3 m up, its
/// left elbow breaking past `threshold` newtons.
struct Game {
    world: *mut VtWorld,
    layer: *mut VtCollisions,
    desc: *mut VtRagdollDesc,
    ragdoll: *mut VtRagdoll,
}

impl Game {
    fn new(threshold: f32) -> Self {
        // SAFETY: every pointer below is a live object or a local.
        unsafe {
            let (mut world, mut layer, mut desc) = (null_mut(), null_mut(), null_mut());
            ok(vt_world_create(null(), &mut world));
            ok(vt_collisions_create(&mut layer));
            ok(vt_ragdoll_desc_humanoid(
                VtHumanoid::Reference as u32,
                &mut desc,
            ));
            let mut ground_desc = zeroed();
            let mut ground = VtBody::default();
            ok(vt_body_desc_default(
                VtBodyKind::Static as u32,
                &mut ground_desc,
            ));
            ok(vt_world_add_body(world, &ground_desc, &mut ground));
            let mut plane = zeroed();
            ok(vt_collider_default(ground, &mut plane));
            plane.kind = VtColliderKind::Plane as u32;
            ok(vt_collisions_add(layer, &plane, null_mut()));
            let mut count = 0;
            ok(vt_ragdoll_desc_body_count(desc, &mut count));
            let mut pose = vec![zeroed::<VtTransform>(); count];
            ok(vt_ragdoll_desc_bind_pose(desc, pose.as_mut_ptr(), count));
            for p in &mut pose {
                p.position.y += 0.3;
            }
            let options = VtBuildOptions {
                spine: VtSpineMode::Sockets as u32,
                at_switch: 0,
                stabilise: 0,
                stabilise_ratio: 1.0,
            };
            let mut ragdoll = null_mut();
            ok(vt_ragdoll_build(
                world,
                layer,
                desc,
                &options,
                pose.as_ptr(),
                null(),
                count,
                DT,
                &mut ragdoll,
            ));
            let game = Self {
                world,
                layer,
                desc,
                ragdoll,
            };
            if threshold.is_finite() {
                let elbow = game.joint("elbow_l");
                let mut d = zeroed();
                ok(vt_world_joint(world, elbow, &mut d));
                d.has_breaking = 1;
                d.break_force = threshold;
                d.break_torque = f32::INFINITY;
                ok(vt_world_remove_joint(world, elbow));
                let mut again = VtJoint::default();
                ok(vt_world_add_joint(world, &d, &mut again));
            }
            game
        }
    }

    fn joint(&self, name: &str) -> VtJoint {
        let name = CString::new(name).unwrap();
        let (mut index, mut joint, mut present) = (0, VtJoint::default(), 0);
        // SAFETY: live objects and locals.
        unsafe {
            ok(vt_ragdoll_desc_joint_index(
                self.desc,
                name.as_ptr(),
                &mut index,
            ));
            ok(vt_ragdoll_joint(
                self.ragdoll,
                index,
                &mut joint,
                &mut present,
            ));
        }
        assert_eq!(present, 1);
        joint
    }

    fn step(&self) {
        // SAFETY: live objects.
        ok(unsafe { vt_collisions_step(self.layer, self.world, DT) });
    }

    fn began(&self) -> Vec<VtTouching> {
        let mut count = 0;
        // SAFETY: a null array of capacity 0 asks the count.
        let asked = unsafe { vt_collisions_began(self.layer, null_mut(), 0, &mut count) };
        assert!(asked == VtResult::Ok || asked == VtResult::BufferTooSmall);
        // SAFETY: live objects, room for `count`.
        unsafe {
            let mut out = vec![zeroed::<VtTouching>(); count];
            ok(vt_collisions_began(
                self.layer,
                out.as_mut_ptr(),
                count,
                &mut count,
            ));
            out
        }
    }

    fn hash(&self) -> u64 {
        let mut hash = 0;
        // SAFETY: a live world.
        ok(unsafe { vt_world_state_hash(self.world, &mut hash) });
        hash
    }
}

impl Drop for Game {
    fn drop(&mut self) {
        // SAFETY: made above, destroyed once.
        unsafe {
            vt_ragdoll_destroy(self.ragdoll);
            vt_collisions_destroy(self.layer);
            vt_world_destroy(self.world);
            vt_ragdoll_desc_destroy(self.desc);
        }
    }
}

#[test]
fn a_c_game_hears_bones_hit_the_floor_shoots_one_and_tears_off_a_limb() {
    let game = Game::new(800.0);
    let mut first = VtBody::default();
    // SAFETY: a live ragdoll.
    ok(unsafe { vt_ragdoll_first_body(game.ragdoll, &mut first) });
    let mut bones = Vec::new();
    for _ in 0..40 {
        game.step();
        for hit in game.began() {
            if hit.part_b.present == 1 && hit.part_a.present == 0 {
                assert_eq!(hit.part_b.ragdoll, first);
                assert!(hit.impulse > 0.0 && hit.closing_speed > 0.5, "{hit:?}");
                bones.push(hit.part_b.bone);
            }
        }
    }
    assert!(!bones.is_empty(), "bones hit the floor");
    // A shot at the chest from the front, 40 N s.
    let mut filter = zeroed();
    // SAFETY: a local.
    ok(unsafe { vt_query_filter_default(&mut filter) });
    let (mut hit, mut found) = (zeroed::<VtQueryHit>(), 0);
    let mut state = zeroed::<VtBodyState>();
    let name = CString::new("chest").unwrap();
    let (mut chest_index, mut chest, mut present) = (0, VtBody::default(), 0);
    // SAFETY: live objects and locals.
    unsafe {
        ok(vt_ragdoll_desc_body_index(
            game.desc,
            name.as_ptr(),
            &mut chest_index,
        ));
        ok(vt_ragdoll_body(
            game.ragdoll,
            chest_index,
            &mut chest,
            &mut present,
        ));
        ok(vt_world_body_state(game.world, chest, &mut state));
        let origin = VtVec3 {
            z: state.position.z + 3.0,
            ..state.position
        };
        let back = VtVec3 {
            x: 0.0,
            y: 0.0,
            z: -1.0,
        };
        ok(vt_collisions_shoot(
            game.layer, game.world, origin, back, 10.0, 40.0, &filter, &mut hit, &mut found,
        ));
    }
    assert_eq!(found, 1);
    assert_eq!(hit.body, chest);
    assert_eq!((hit.part.present, hit.part.bone as usize), (1, chest_index));
    // Yanked by its hand: the elbow (800 N) tears, named by the world.
    let hand = CString::new("forearm_l").unwrap();
    let (mut index, mut forearm) = (0, VtBody::default());
    // SAFETY: live objects and locals.
    unsafe {
        ok(vt_ragdoll_desc_body_index(
            game.desc,
            hand.as_ptr(),
            &mut index,
        ));
        ok(vt_ragdoll_body(
            game.ragdoll,
            index,
            &mut forearm,
            &mut present,
        ));
        let up = VtVec3 {
            x: 0.0,
            y: 1.0,
            z: 0.0,
        };
        let zero = VtVec3::default();
        ok(vt_world_set_body_velocity(
            game.world,
            forearm,
            VtVec3 { x: 30.0, ..up },
            zero,
        ));
    }
    game.step();
    let mut count = 0;
    let mut broken = vec![zeroed::<VtBrokenJoint>(); 4];
    // SAFETY: room for 4.
    ok(unsafe { vt_world_broken_joints(game.world, broken.as_mut_ptr(), 4, &mut count) });
    assert_eq!(count, 1, "the elbow tore");
    let load = broken[0].load.force;
    assert!(Vec3::new(load.x, load.y, load.z).length() > 800.0);
    let mut force = zeroed::<VtJointForce>();
    // SAFETY: locals; the joint is gone.
    let refused = unsafe { vt_world_joint_force(game.world, broken[0].joint, &mut force) };
    assert_eq!(refused, VtResult::StaleHandle);
}

/// The same frames through Rust: the same bits.
#[test]
fn the_c_frame_is_the_rust_frame_bit_for_bit() {
    let game = Game::new(f32::INFINITY);
    let mut w = World::new(SolverConfig::default()).unwrap();
    let mut c = Collisions::new();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    let desc = RagdollDesc::reference_humanoid();
    let pose = Pose::bind(&desc).moved(Vec3::ZERO, glam::Quat::IDENTITY, Vec3::Y * 0.3);
    let options = BuildOptions::new(SpineMode::Sockets);
    let ragdoll = c
        .build_ragdoll(&mut w, &desc, options, &pose, None)
        .unwrap();
    for frame in 0..60 {
        game.step();
        c.step(&mut w, DT).unwrap();
        assert_eq!(game.hash(), w.state_hash(), "frame {frame}");
        let began: Vec<u32> = game.began().iter().map(|t| t.part_b.bone).collect();
        let rust: Vec<u32> = (c.events().began().iter())
            .map(|t| t.part_b.map_or(0, |p| p.bone))
            .collect();
        assert_eq!(began, rust, "frame {frame}");
    }
    let hit = c
        .cast_ray(
            &w,
            Vec3::new(0.0, 3.0, 0.0),
            -Vec3::Y,
            5.0,
            &QueryFilter::default(),
        )
        .unwrap();
    assert!(hit.is_some_and(|h| ragdoll.bone_of(h.body).is_some() || h.body == ground));
}

#[test]
fn the_new_calls_refuse_nulls_bad_enums_and_stale_handles_and_change_nothing() {
    let game = Game::new(f32::INFINITY);
    game.step();
    let before = game.hash();
    let mut filter = zeroed();
    // SAFETY: a local.
    ok(unsafe { vt_query_filter_default(&mut filter) });
    let origin = VtVec3 {
        x: 0.0,
        y: 3.0,
        z: 0.0,
    };
    let down = VtVec3 {
        x: 0.0,
        y: -1.0,
        z: 0.0,
    };
    let (mut hit, mut found) = (zeroed::<VtQueryHit>(), 0);
    // SAFETY: each call is given one bad argument; the others are live.
    unsafe {
        let null_filter = vt_collisions_cast_ray(
            game.layer,
            game.world,
            origin,
            down,
            5.0,
            null(),
            &mut hit,
            &mut found,
        );
        assert_eq!(null_filter, VtResult::NullPointer);
        let null_out = vt_collisions_shoot(
            game.layer,
            game.world,
            origin,
            down,
            5.0,
            10.0,
            &filter,
            null_mut(),
            &mut found,
        );
        assert_eq!(null_out, VtResult::NullPointer);
        let nan = VtVec3 {
            x: f32::NAN,
            ..origin
        };
        let bad = vt_collisions_shoot(
            game.layer, game.world, nan, down, 5.0, 10.0, &filter, &mut hit, &mut found,
        );
        assert_eq!(bad, VtResult::NonFinite);
        let shape = VtQueryShape {
            kind: 7,
            radius: 0.1,
            half_segment: VtVec3::default(),
        };
        let pose = VtTransform {
            position: origin,
            rotation: VtQuat {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 1.0,
            },
        };
        let enum_refused = vt_collisions_cast_shape(
            game.layer, game.world, &shape, pose, down, 5.0, &filter, &mut hit, &mut found,
        );
        assert_eq!(enum_refused, VtResult::InvalidEnum);
        let mut load = zeroed::<VtJointForce>();
        let stale = VtJoint {
            index: 9999,
            lineage: 1,
            generation: 3,
        };
        assert_ne!(
            vt_world_joint_force(game.world, stale, &mut load),
            VtResult::Ok
        );
        assert_eq!(
            vt_collisions_after_step(game.layer, game.world),
            VtResult::WorldMismatch
        );
        assert_eq!(
            vt_collisions_step(game.layer, game.world, -1.0),
            VtResult::NonPositive
        );
        let mut index = 0;
        let missing = CString::new("tail").unwrap();
        let refused = vt_ragdoll_desc_joint_index(game.desc, missing.as_ptr(), &mut index);
        assert_eq!(refused, VtResult::Ragdoll);
    }
    assert_eq!(game.hash(), before, "refused calls changed nothing");
}
