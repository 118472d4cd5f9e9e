//! Each ragdoll's reference skeleton as a glTF skin: a node per bone
//! under its parent bone's, animated relative to it; inverse bind matrices
//! from the skeleton's bind pose; and a mesh of one octahedron per bone,
//! every vertex bound to its bone alone, so the skin is seen moving.

use glam::{Mat4, Vec3};
use gltf::json::accessor::Type;
use gltf::json::scene::UnitQuaternion;
use gltf::json::{Accessor, Index, Material, Mesh, Node, Skin};
use vertebra_ragdoll::{RagdollError, Skeleton, Transform};

use super::animation::Animator;
use super::document::Document;
use super::meshes::{Skinning, mesh};
use super::record::Skeletons;
use super::shapes::{MeshData, bone};

/// A bone without children is drawn this long (m) along its +Y (the
/// reference skeleton's leaves keep their parent's orientation).
const LEAF_LENGTH: f32 = 0.04;

/// What one ragdoll's skin adds: the root bones' nodes (to place in its
/// group) and the node drawing the skinned mesh (at the scene's root,
/// where glTF wants it: its own transform is not used).
pub struct SkinNodes {
    pub roots: Vec<Index<Node>>,
    pub drawn: Index<Node>,
}

/// The skins of every ragdoll of `skeletons`: one mesh and one set of
/// inverse bind matrices shared by all, a node tree per ragdoll.
pub fn skins(
    doc: &mut Document,
    animator: &mut Animator,
    skeletons: &Skeletons,
    material: Index<Material>,
) -> Result<Vec<SkinNodes>, RagdollError> {
    let skeleton = skeletons.out.skeleton();
    let bind = skeleton.bind_pose().to_model(skeleton)?;
    let inverse_binds: Vec<[f32; 16]> = bind
        .bones
        .iter()
        .map(|t| {
            let inverse = t.inverse();
            Mat4::from_rotation_translation(inverse.rotation, inverse.translation).to_cols_array()
        })
        .collect();
    let inverse_binds = doc.floats(&inverse_binds, Type::Mat4, None, false);
    let (data, joints) = bones_mesh(skeleton, &bind.bones);
    let weights = vec![[1.0, 0.0, 0.0, 0.0]; joints.len()];
    let skinning = Skinning {
        joints: &joints,
        weights: &weights,
    };
    let drawn_mesh = mesh(doc, "bones".to_owned(), &data, material, Some(skinning));
    Ok(skeletons
        .locals
        .iter()
        .enumerate()
        .map(|(k, locals)| {
            one_skin(
                doc,
                animator,
                skeleton,
                locals,
                (k, inverse_binds, drawn_mesh),
            )
        })
        .collect())
}

/// Ragdoll `k`'s bone nodes, animated by `locals` (per bone, per frame),
/// its skin and the node that draws it.
fn one_skin(
    doc: &mut Document,
    animator: &mut Animator,
    skeleton: &Skeleton,
    locals: &[Vec<Transform>],
    (k, inverse_binds, drawn_mesh): (usize, Index<Accessor>, Index<Mesh>),
) -> SkinNodes {
    let joints: Vec<Index<Node>> = skeleton
        .bones()
        .iter()
        .zip(locals)
        .map(|(bone, frames)| bone_node(doc, animator, bone.name.clone(), frames))
        .collect();
    let mut roots = Vec::new();
    for (bone, &node) in skeleton.bones().iter().zip(&joints) {
        match bone.parent {
            Some(p) => doc.root.nodes[joints[p].value()]
                .children
                .get_or_insert_with(Vec::new)
                .push(node),
            None => roots.push(node),
        }
    }
    let skin = doc.root.push(Skin {
        name: Some(format!("ragdoll {k}")),
        inverse_bind_matrices: Some(inverse_binds),
        skeleton: (roots.len() == 1).then(|| roots[0]),
        joints,
        extensions: None,
        extras: Default::default(),
    });
    let drawn = doc.root.push(Node {
        name: Some(format!("ragdoll {k} bones")),
        mesh: Some(drawn_mesh),
        skin: Some(skin),
        ..Default::default()
    });
    SkinNodes { roots, drawn }
}

/// A bone's node: at its first frame's transform, animated unless that
/// stays the same to the bit every frame (a bone no body moves: fingers,
/// toes, twist bones).
fn bone_node(
    doc: &mut Document,
    animator: &mut Animator,
    name: String,
    frames: &[Transform],
) -> Index<Node> {
    let first = frames[0];
    let node = doc.root.push(Node {
        name: Some(name),
        translation: Some(first.translation.to_array()),
        rotation: Some(UnitQuaternion(first.rotation.to_array())),
        ..Default::default()
    });
    let bits = |t: &Transform| {
        (
            t.translation.to_array().map(f32::to_bits),
            t.rotation.to_array().map(f32::to_bits),
        )
    };
    if frames.iter().any(|t| bits(t) != bits(&first)) {
        let translations: Vec<[f32; 3]> = frames.iter().map(|t| t.translation.to_array()).collect();
        let rotations: Vec<[f32; 4]> = frames.iter().map(|t| t.rotation.to_array()).collect();
        animator.animate(doc, node, &translations, &rotations);
    }
    node
}

/// One octahedron per bone but the roots (the model frame's placement,
/// not a part of the body), from its origin to its first child's, in the
/// bind pose (`bind`: model frame), with each vertex's bone (to be
/// bound to it alone, weight 1).
fn bones_mesh(skeleton: &Skeleton, bind: &[Transform]) -> (MeshData, Vec<[u16; 4]>) {
    let bones = skeleton.bones();
    let mut data = MeshData::default();
    let mut joints = Vec::new();
    for (index, _) in bones.iter().enumerate().filter(|(_, b)| b.parent.is_some()) {
        let child = bones.iter().find(|c| c.parent == Some(index));
        let tip = child
            .map(|c| c.bind.translation)
            .filter(|t| t.length() > LEAF_LENGTH / 4.0)
            .unwrap_or(Vec3::Y * LEAF_LENGTH);
        let shape = bone(tip);
        let placed = bind[index];
        data.positions
            .extend(shape.positions.iter().map(|&p| placed.transform_point(p)));
        data.normals
            .extend(shape.normals.iter().map(|&n| placed.transform_vector(n)));
        let first = joints.len() as u32;
        data.indices.extend(shape.indices.iter().map(|i| first + i));
        joints.extend(shape.positions.iter().map(|_| [index as u16, 0, 0, 0]));
    }
    (data, joints)
}
