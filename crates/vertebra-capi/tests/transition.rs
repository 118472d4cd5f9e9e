//! The switch from animation through the C ABI: the mapper places the
//! bodies where the animation has them, the transition's first skeleton
//! pose is the animation's (no pop), and every bone equals the Rust API's
//! bit for bit a few steps on.

use std::ptr::null_mut;

use glam::{Quat, Vec3};
use vertebra_capi::*;
use vertebra_ragdoll::{
    BuildOptions, Ragdoll, RagdollDesc, Skeleton, SkeletonMapper, SpineMapping, SpineMode,
    Transform, Transition,
};
use vertebra_world::{SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

fn ok(result: VtResult) {
    assert_eq!(result, VtResult::Ok);
}

fn place() -> Transform {
    Transform::new(Vec3::new(40.0, 0.0, -12.0), Quat::from_rotation_y(1.0))
}

/// The animation: the reference skeleton's bind pose with the spine bent.
fn animation(skeleton: &Skeleton) -> Vec<Transform> {
    let mut pose = skeleton.bind_pose();
    let spine = skeleton.bone_index("spine_middle").expect("a spine bone");
    pose.bones[spine].rotation *= Quat::from_rotation_x(0.3);
    pose.bones
}

/// The Rust API's bones after `steps` steps.
fn rust_bones(steps: usize) -> Vec<Transform> {
    let skeleton = Skeleton::reference();
    let desc = RagdollDesc::reference_humanoid();
    let mapper = SkeletonMapper::new(&skeleton, &desc, SpineMode::Rod).expect("a mapper");
    let local = vertebra_ragdoll::LocalPose {
        bones: animation(&skeleton),
    };
    let model = local.to_model(&skeleton).expect("model");
    let bodies = mapper.map_to_ragdoll(&model, place()).expect("bodies");
    let mut world = World::new(SolverConfig::default()).expect("a world");
    let options = BuildOptions::at_switch(SpineMode::Rod);
    let ragdoll = Ragdoll::build(&mut world, &desc, options, &bodies, None).expect("built");
    let transition = Transition::new(
        &mapper,
        &ragdoll,
        &world,
        &local,
        place(),
        SpineMapping::Arc,
        0.3,
    )
    .expect("a transition");
    for _ in 0..steps {
        world.step(DT).expect("a step");
    }
    let since = steps as f32 * DT;
    let pose = transition
        .skeleton_pose(&mapper, &ragdoll, &world, &local, place(), since)
        .expect("bones");
    pose.bones
}

/// The same through the C ABI.
fn c_bones(steps: usize) -> Vec<VtTransform> {
    let vt = |t: Transform| VtTransform::from((t.translation, t.rotation));
    let (mut skeleton, mut desc, mut mapper) = (null_mut(), null_mut(), null_mut());
    let (mut world, mut ragdoll, mut transition) = (null_mut(), null_mut(), null_mut());
    let local: Vec<VtTransform> = animation(&Skeleton::reference())
        .into_iter()
        .map(vt)
        .collect();
    let n = local.len();
    let mut model = vec![vt(Transform::IDENTITY); n];
    let mut bodies = vec![vt(Transform::IDENTITY); 13];
    let mut bones = vec![vt(Transform::IDENTITY); n];
    let options = VtBuildOptions {
        spine: VtSpineMode::Rod as u32,
        at_switch: 1,
        stabilise: 0,
        stabilise_ratio: 1.0,
    };
    // SAFETY: every pointer is to a live local of the right length; every
    // object is made before use and destroyed once, at the end.
    unsafe {
        ok(vt_skeleton_reference(&mut skeleton));
        ok(vt_ragdoll_desc_humanoid(
            VtHumanoid::Reference as u32,
            &mut desc,
        ));
        ok(vt_skeleton_mapper_create(
            skeleton,
            desc,
            VtSpineMode::Rod as u32,
            &mut mapper,
        ));
        ok(vt_skeleton_to_model(
            skeleton,
            local.as_ptr(),
            model.as_mut_ptr(),
            n,
        ));
        ok(vt_skeleton_mapper_map_to_ragdoll(
            mapper,
            model.as_ptr(),
            n,
            vt(place()),
            bodies.as_mut_ptr(),
            bodies.len(),
        ));
        ok(vt_world_create(std::ptr::null(), &mut world));
        ok(vt_ragdoll_build(
            world,
            null_mut(),
            desc,
            &options,
            bodies.as_ptr(),
            std::ptr::null(),
            bodies.len(),
            DT,
            &mut ragdoll,
        ));
        let arc = VtSpineMapping::Arc as u32;
        ok(vt_transition_create(
            mapper,
            ragdoll,
            world,
            local.as_ptr(),
            n,
            vt(place()),
            arc,
            0.3,
            &mut transition,
        ));
        for _ in 0..steps {
            ok(vt_world_step(world, DT));
        }
        let since = steps as f32 * DT;
        ok(vt_transition_skeleton_pose(
            transition,
            mapper,
            ragdoll,
            world,
            local.as_ptr(),
            vt(place()),
            since,
            bones.as_mut_ptr(),
            n,
        ));
        vt_transition_destroy(transition);
        vt_ragdoll_destroy(ragdoll);
        vt_world_destroy(world);
        vt_skeleton_mapper_destroy(mapper);
        vt_ragdoll_desc_destroy(desc);
        vt_skeleton_destroy(skeleton);
    }
    bones
}

#[test]
fn the_first_pose_is_the_animations() {
    let skeleton = Skeleton::reference();
    let local = vertebra_ragdoll::LocalPose {
        bones: animation(&skeleton),
    };
    let animated = local.to_model(&skeleton).expect("model").in_world(place());
    let bones = c_bones(0);
    assert_eq!(bones.len(), 63);
    for (k, (bone, want)) in bones.iter().zip(&animated.bones).enumerate() {
        let at = Vec3::new(bone.position.x, bone.position.y, bone.position.z);
        let gap = at.distance(want.translation);
        assert!(gap < 1e-3, "bone {k} pops by {gap} m at the switch");
    }
}

#[test]
fn the_c_abi_maps_the_bones_the_rust_api_does() {
    for steps in [0, 10] {
        let rust = rust_bones(steps);
        let c = c_bones(steps);
        assert_eq!(rust.len(), c.len());
        for (r, c) in rust.iter().zip(&c) {
            let (p, q) = (r.translation, r.rotation);
            let r = [p.x, p.y, p.z, q.x, q.y, q.z, q.w].map(f32::to_bits);
            let (p, q) = (c.position, c.rotation);
            let c = [p.x, p.y, p.z, q.x, q.y, q.z, q.w].map(f32::to_bits);
            assert_eq!(r, c);
        }
    }
}
