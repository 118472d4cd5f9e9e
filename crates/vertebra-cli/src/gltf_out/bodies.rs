//! A node per body with a shape: its mesh (the shape in the body frame,
//! centred on the centre of mass as the store's shapes are), its pose the
//! body's, animated for a ragdoll's bodies and for any other that moves.

use gltf::json::scene::UnitQuaternion;
use gltf::json::{Index, Node};

use super::animation::Animator;
use super::document::Document;
use super::meshes::{Look, Materials, ShapeMeshes};
use super::record::{Body, Recording, Solid};

/// The smallest half size of a drawn ground plane (m), and how far past
/// the farthest body it reaches.
const GROUND_MIN: f32 = 5.0;
const GROUND_MARGIN: f32 = 1.0;

/// The body nodes: those of no ragdoll (ground, walls, boxes), and per
/// ragdoll its bodies'.
pub struct BodyNodes {
    pub scenery: Vec<Index<Node>>,
    pub ragdolls: Vec<Vec<Index<Node>>>,
}

/// Every body of `recording` as a node with its shape's mesh.
pub fn body_nodes(
    doc: &mut Document,
    animator: &mut Animator,
    recording: &Recording,
    materials: &mut Materials,
) -> BodyNodes {
    let mut meshes = ShapeMeshes::new(ground_half_size(recording));
    let mut nodes = BodyNodes {
        scenery: Vec::new(),
        ragdolls: vec![Vec::new(); recording.ragdolls],
    };
    for body in &recording.bodies {
        let look = match body.ragdoll {
            Some(_) => Look::Body,
            None => Look::Scenery,
        };
        let material = materials.get(doc, look);
        let (position, orientation) = body.poses[0];
        let mesh = meshes.get(doc, body.solid, material);
        let node = doc.root.push(Node {
            name: Some(body.name.clone()),
            mesh: Some(mesh),
            translation: Some(position.to_array()),
            rotation: Some(UnitQuaternion(orientation.to_array())),
            ..Default::default()
        });
        if body.ragdoll.is_some() || moves(body) {
            let translations: Vec<[f32; 3]> = body.poses.iter().map(|p| p.0.to_array()).collect();
            let rotations: Vec<[f32; 4]> = body.poses.iter().map(|p| p.1.to_array()).collect();
            animator.animate(doc, node, &translations, &rotations);
        }
        match body.ragdoll {
            Some(k) => nodes.ragdolls[k].push(node),
            None => nodes.scenery.push(node),
        }
    }
    nodes
}

/// Whether `body`'s pose changes by any bit over the run.
fn moves(body: &Body) -> bool {
    let bits = |(p, q): &(glam::Vec3, glam::Quat)| {
        (
            p.to_array().map(f32::to_bits),
            q.to_array().map(f32::to_bits),
        )
    };
    body.poses.iter().any(|p| bits(p) != bits(&body.poses[0]))
}

/// How far (m) a ground plane is drawn from its body's origin: past the
/// farthest any body is from it along the plane in the run.
fn ground_half_size(recording: &Recording) -> f32 {
    let mut reach = 0.0f32;
    for ground in &recording.bodies {
        let Solid::Plane(normal) = ground.solid else {
            continue;
        };
        let origin = ground.poses[0].0;
        for body in &recording.bodies {
            for (p, _) in &body.poses {
                let off = *p - origin;
                reach = reach.max((off - normal * off.dot(normal)).length());
            }
        }
    }
    (reach + GROUND_MARGIN).max(GROUND_MIN)
}
