//! Diagnostic: which joints of the anatomical drop go past their limits,
//! and which only fail to hold their axes (docs/joints.md, "The anatomical
//! drop").
//!
//! `cargo run --release -p vertebra-scenes --example limits -- SPINE S I SEED [JOINTS [SCENE]]`
//! (`SPINE` is `rod` or `sockets`; `JOINTS` is `iterative`, the default, or
//! `direct`; `SCENE` is `anatomical`, the default, or `reference`, the
//! reference humanoid's drop) runs the 600-frame drop at S
//! substeps x I iterations from SEED and prints, per joint name (over all
//! 30 ragdolls; `rod` for the rod), the largest limit violation and the
//! largest angular error (the held rotations too), in degrees, each with
//! the frame and ragdoll where it peaked.

use std::collections::{BTreeMap, HashMap};

use vertebra_ragdoll::{RagdollDesc, SpineMode};
use vertebra_scenes::{Scene, SceneConfig, build};

/// A peak: value (rad), frame, ragdoll.
type Peak = (f32, usize, usize);

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |k: usize| -> u64 { args[k].parse().expect("SPINE S I SEED") };
    let spine = match args[0].as_str() {
        "rod" => SpineMode::Rod,
        _ => SpineMode::Sockets,
    };
    let (scene_kind, desc) = match args.get(5).map(String::as_str) {
        Some("reference") => (Scene::RagdollDrop, RagdollDesc::reference_humanoid()),
        _ => (Scene::AnatomicalDrop, RagdollDesc::anatomical_humanoid()),
    };
    let mut config = SceneConfig::new(scene_kind, spine);
    (config.substeps, config.iterations) = (number(1) as u32, number(2) as u32);
    config.seed = number(3);
    if args.get(4).map(String::as_str) == Some("direct") {
        config.joints = vertebra_world::JointSolver::Direct;
    }
    let mut scene = build(&config).expect("the scene builds");
    let (mut joints, mut rods) = (HashMap::new(), HashMap::new());
    for (r, ragdoll) in scene.ragdolls.iter().enumerate() {
        for (j, joint) in ragdoll.joints.iter().enumerate() {
            if let Some(joint) = joint {
                joints.insert(*joint, (r, desc.joints[j].name.as_str()));
            }
        }
        if let Some(rod) = ragdoll.rod {
            rods.insert(rod, (r, "rod"));
        }
    }
    // Per name: (limit violation, angular error) peaks.
    let mut peaks: BTreeMap<&str, (Peak, Peak)> = BTreeMap::new();
    let dt = 1.0 / 60.0;
    for frame in 0..600 {
        scene.advance(scene_kind, frame, dt).expect("a frame");
        let r = scene
            .world
            .residuals()
            .expect("a scene measures its residuals every step");
        let measured = r
            .joints
            .iter()
            .filter_map(|j| Some((joints.get(&j.joint)?, j.limit_rad, j.angular_rad)));
        let rod = r
            .rods
            .iter()
            .filter_map(|j| Some((rods.get(&j.joint)?, j.limit_rad, j.angular_rad)));
        for (&(ragdoll, name), limit, angular) in measured.chain(rod) {
            let (l, a) = peaks.entry(name).or_insert(((0.0, 0, 0), (0.0, 0, 0)));
            if limit > l.0 {
                *l = (limit, frame, ragdoll);
            }
            if angular > a.0 {
                *a = (angular, frame, ragdoll);
            }
        }
    }
    println!("joint: largest limit violation | largest angular error (degrees, frame, ragdoll)");
    for (name, (l, a)) in peaks {
        println!(
            "{name}: {:.2} (frame {}, r{}) | {:.2} (frame {}, r{})",
            l.0.to_degrees(),
            l.1,
            l.2,
            a.0.to_degrees(),
            a.1,
            a.2
        );
    }
}
