//! Meshes and their materials in the document: one mesh per distinct
//! shape, shared by every body of that shape.

use std::collections::BTreeMap;

use gltf::json::accessor::Type;
use gltf::json::buffer::Target;
use gltf::json::material::{PbrBaseColorFactor, PbrMetallicRoughness, StrengthFactor};
use gltf::json::mesh::{Mode, Primitive, Semantic};
use gltf::json::validation::Checked::Valid;
use gltf::json::{Index, Material, Mesh};
use vertebra_world::Shape;

use super::document::Document;
use super::record::Solid;
use super::shapes::{MeshData, capsule, cuboid, square};

/// What a mesh is drawn as: a ragdoll's body, the scene's static shapes
/// (seen from both sides: the ground) or a bone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Look {
    Body,
    Scenery,
    Bone,
}

/// The materials of the looks used so far (plain colours, not metallic),
/// each made when first used: a file holds no material it does not use.
#[derive(Default)]
pub struct Materials {
    made: Vec<(Look, Index<Material>)>,
}

impl Materials {
    /// The material of `look`.
    pub fn get(&mut self, doc: &mut Document, look: Look) -> Index<Material> {
        if let Some((_, index)) = self.made.iter().find(|(l, _)| *l == look) {
            return *index;
        }
        let (name, rgb, double_sided) = match look {
            Look::Body => ("body", [0.72, 0.76, 0.84], false),
            Look::Scenery => ("scenery", [0.5, 0.5, 0.48], true),
            Look::Bone => ("bone", [0.95, 0.55, 0.15], false),
        };
        let index = doc.root.push(Material {
            name: Some(name.to_owned()),
            double_sided,
            pbr_metallic_roughness: PbrMetallicRoughness {
                base_color_factor: PbrBaseColorFactor([rgb[0], rgb[1], rgb[2], 1.0]),
                metallic_factor: StrengthFactor(0.0),
                roughness_factor: StrengthFactor(0.8),
                ..Default::default()
            },
            ..Default::default()
        });
        self.made.push((look, index));
        index
    }
}

/// Per-vertex joint indices and weights of a skinned mesh.
pub struct Skinning<'a> {
    pub joints: &'a [[u16; 4]],
    pub weights: &'a [[f32; 4]],
}

/// `data` as a mesh of one triangle list in `material`, skinned if
/// `skinning` is given; named `name`.
pub fn mesh(
    doc: &mut Document,
    name: String,
    data: &MeshData,
    material: Index<Material>,
    skinning: Option<Skinning>,
) -> Index<Mesh> {
    let vertex = Some(Target::ArrayBuffer);
    let positions: Vec<[f32; 3]> = data.positions.iter().map(|p| p.to_array()).collect();
    let normals: Vec<[f32; 3]> = data.normals.iter().map(|n| n.to_array()).collect();
    let mut attributes = BTreeMap::new();
    attributes.insert(
        Valid(Semantic::Positions),
        doc.floats(&positions, Type::Vec3, vertex, true),
    );
    attributes.insert(
        Valid(Semantic::Normals),
        doc.floats(&normals, Type::Vec3, vertex, false),
    );
    if let Some(skinning) = skinning {
        attributes.insert(Valid(Semantic::Joints(0)), doc.joints(skinning.joints));
        attributes.insert(
            Valid(Semantic::Weights(0)),
            doc.floats(skinning.weights, Type::Vec4, vertex, false),
        );
    }
    let primitive = Primitive {
        attributes,
        indices: Some(doc.indices(&data.indices)),
        material: Some(material),
        mode: Valid(Mode::Triangles),
        targets: None,
        extensions: None,
        extras: Default::default(),
    };
    doc.root.push(Mesh {
        name: Some(name),
        primitives: vec![primitive],
        weights: None,
        extensions: None,
        extras: Default::default(),
    })
}

/// The meshes of the bodies' shapes made so far, by shape.
pub struct ShapeMeshes {
    made: Vec<(Solid, Index<Mesh>)>,
    /// A ground plane's half size (m): as far as the scene reaches.
    ground_half_size: f32,
}

impl ShapeMeshes {
    /// None yet; ground planes drawn `ground_half_size` (m) to each side.
    pub fn new(ground_half_size: f32) -> Self {
        Self {
            made: Vec::new(),
            ground_half_size,
        }
    }

    /// The mesh of `solid` (body frame), made the first time it is asked
    /// for, in `material`.
    pub fn get(
        &mut self,
        doc: &mut Document,
        solid: Solid,
        material: Index<Material>,
    ) -> Index<Mesh> {
        if let Some((_, index)) = self.made.iter().find(|(s, _)| *s == solid) {
            return *index;
        }
        let (name, data) = match solid {
            Solid::Shape(Shape::Sphere { radius }) => ("sphere", capsule(glam::Vec3::ZERO, radius)),
            Solid::Shape(Shape::Capsule {
                half_segment,
                radius,
            }) => ("capsule", capsule(half_segment, radius)),
            Solid::Shape(Shape::Box { half_extents }) => ("box", cuboid(half_extents)),
            Solid::Plane(normal) => ("ground", square(normal, self.ground_half_size)),
        };
        let index = mesh(
            doc,
            format!("{name} {}", self.made.len()),
            &data,
            material,
            None,
        );
        self.made.push((solid, index));
        index
    }
}
