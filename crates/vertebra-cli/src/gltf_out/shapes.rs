//! Triangle meshes of the bodies' shapes (body frame, m) and of a bone,
//! with per-vertex normals, every triangle counter-clockwise seen from
//! outside (glTF's front face).

use std::f32::consts::{FRAC_PI_2, TAU};

use glam::{Quat, Vec3};

/// Points around a capsule's axis: a multiple of four, so that the
/// vertices reach the radius along both axes across it.
const SEGMENTS: usize = 24;

/// Latitude bands per hemisphere of a capsule.
const RINGS: usize = 6;

/// A triangle mesh: positions (m), unit normals, three indices a triangle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions (m).
    pub positions: Vec<Vec3>,
    /// Unit vertex normals.
    pub normals: Vec<Vec3>,
    /// Triangles, three vertex indices each.
    pub indices: Vec<u32>,
}

impl MeshData {
    fn vertex(&mut self, position: Vec3, normal: Vec3) -> u32 {
        self.positions.push(position);
        self.normals.push(normal);
        (self.positions.len() - 1) as u32
    }

    /// A flat triangle: its own three vertices with the face normal,
    /// turned to face away from `inside`.
    fn flat_triangle(&mut self, [a, b, c]: [Vec3; 3], inside: Vec3) {
        let normal = (b - a).cross(c - a).normalize();
        let [b, c, normal] = if normal.dot((a + b + c) / 3.0 - inside) < 0.0 {
            [c, b, -normal]
        } else {
            [b, c, normal]
        };
        for p in [a, b, c] {
            let i = self.vertex(p, normal);
            self.indices.push(i);
        }
    }

    /// A triangle of shared vertices, wound to face along its vertices'
    /// normals (outward for a convex solid).
    fn triangle(&mut self, [a, b, c]: [u32; 3]) {
        let p = |i: u32| self.positions[i as usize];
        let n = self.normals[a as usize] + self.normals[b as usize] + self.normals[c as usize];
        let facing = (p(b) - p(a)).cross(p(c) - p(a)).dot(n);
        let (b, c) = if facing < 0.0 { (c, b) } else { (b, c) };
        self.indices.extend([a, b, c]);
    }
}

/// A capsule: the segment from `-half_segment` to `+half_segment` (m)
/// swept by a ball of `radius` (m); a zero segment is a sphere. Two
/// hemispheres of [`RINGS`] bands and a cylinder between, [`SEGMENTS`]
/// points around.
pub fn capsule(half_segment: Vec3, radius: f32) -> MeshData {
    let half = half_segment.length();
    let turn = if half > 0.0 {
        Quat::from_rotation_arc(Vec3::Y, half_segment / half)
    } else {
        Quat::IDENTITY
    };
    let mut mesh = MeshData::default();
    let mut add = |direction: Vec3, centre: f32| {
        let normal = turn * direction;
        mesh.vertex(turn * (Vec3::Y * centre) + normal * radius, normal)
    };
    let top = add(Vec3::Y, half);
    // Rings from the top pole down: the top hemisphere's (its equator
    // last), then the bottom hemisphere's (its equator first, unless it
    // is the top's: a sphere has no cylinder between).
    let band = FRAC_PI_2 / RINGS as f32;
    let latitudes = (1..=RINGS)
        .map(|i| (band * i as f32, half))
        .chain((usize::from(half == 0.0)..RINGS).map(|i| (FRAC_PI_2 + band * i as f32, -half)));
    let rings: Vec<u32> = latitudes
        .flat_map(|(polar, centre)| {
            (0..SEGMENTS).map(move |k| {
                let azimuth = TAU * k as f32 / SEGMENTS as f32;
                let (sin, cos) = polar.sin_cos();
                (
                    Vec3::new(sin * azimuth.cos(), cos, sin * azimuth.sin()),
                    centre,
                )
            })
        })
        .collect::<Vec<_>>()
        .into_iter()
        .map(|(direction, centre)| add(direction, centre))
        .collect();
    let bottom = add(Vec3::NEG_Y, -half);
    let at = |ring: usize, k: usize| rings[ring * SEGMENTS + k % SEGMENTS];
    let last = rings.len() / SEGMENTS - 1;
    for k in 0..SEGMENTS {
        mesh.triangle([top, at(0, k), at(0, k + 1)]);
        for ring in 0..last {
            mesh.triangle([at(ring, k), at(ring + 1, k), at(ring + 1, k + 1)]);
            mesh.triangle([at(ring, k), at(ring + 1, k + 1), at(ring, k + 1)]);
        }
        mesh.triangle([bottom, at(last, k + 1), at(last, k)]);
    }
    mesh
}

/// A box of `half_extents` (m) along the axes: four vertices a face, each
/// with the face's normal.
pub fn cuboid(half_extents: Vec3) -> MeshData {
    let mut mesh = MeshData::default();
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let normal = Vec3::AXES[axis] * sign;
            let (u, v) = (Vec3::AXES[(axis + 1) % 3], Vec3::AXES[(axis + 2) % 3]);
            let corner = |a: f32, b: f32| (normal + u * a + v * b) * half_extents;
            let quad = [
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            ]
            .map(|p| mesh.vertex(p, normal));
            mesh.triangle([quad[0], quad[1], quad[2]]);
            mesh.triangle([quad[0], quad[2], quad[3]]);
        }
    }
    mesh
}

/// A square of side `2 half_size` (m) in the plane through the origin
/// with unit `normal`, facing along it: a plane collider drawn as far as
/// the scene reaches.
pub fn square(normal: Vec3, half_size: f32) -> MeshData {
    let (u, v) = normal.any_orthonormal_pair();
    let mut mesh = MeshData::default();
    let quad = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(a, b)| mesh.vertex((u * a + v * b) * half_size, normal));
    mesh.triangle([quad[0], quad[1], quad[2]]);
    mesh.triangle([quad[0], quad[2], quad[3]]);
    mesh
}

/// Where a bone's shape is widest, as a fraction of its length from its
/// origin, and how wide (its half width over its length).
const BONE_WAIST: f32 = 0.15;
const BONE_WIDTH: f32 = 0.08;

/// A bone drawn as the usual octahedron: from its origin (the bone
/// frame's) to `tip` (m, bone frame; not zero), widest near the origin.
/// Flat faces, three vertices each.
pub fn bone(tip: Vec3) -> MeshData {
    let waist = tip * BONE_WAIST;
    let (u, v) = (tip / tip.length()).any_orthonormal_pair();
    let width = tip.length() * BONE_WIDTH;
    let corners = [u, v, -u, -v].map(|d| waist + d * width);
    let mut mesh = MeshData::default();
    for k in 0..4 {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        mesh.flat_triangle([Vec3::ZERO, a, b], waist);
        mesh.flat_triangle([tip, b, a], waist);
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle faces away from `inside(centroid)`, and its vertex
    /// normals are unit.
    fn faces_out(mesh: &MeshData, inside: impl Fn(Vec3) -> Vec3) {
        assert_eq!(mesh.indices.len() % 3, 0);
        assert!(mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-5));
        for t in mesh.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
            let centroid = (a + b + c) / 3.0;
            let facing = (b - a).cross(c - a).dot(centroid - inside(centroid));
            assert!(facing > 0.0, "triangle {t:?} faces in");
        }
    }

    /// The closest point to `p` of the segment `-h .. h`.
    fn on_segment(h: Vec3, p: Vec3) -> Vec3 {
        let t = (p.dot(h) / h.length_squared()).clamp(-1.0, 1.0);
        h * t
    }

    #[test]
    fn a_capsule_lies_on_its_radius_about_its_segment_and_faces_out() {
        let (h, r) = (Vec3::new(0.1, -0.2, 0.05), 0.07);
        let mesh = capsule(h, r);
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            let closest = on_segment(h, *p);
            assert!(
                (p.distance(closest) - r).abs() < 1e-6,
                "{p} off the surface"
            );
            assert!(n.distance((*p - closest) / r) < 1e-5, "normal at {p}");
        }
        let reach = mesh
            .positions
            .iter()
            .map(|p| p.dot(h.normalize()))
            .fold(0.0f32, f32::max);
        assert!((reach - (h.length() + r)).abs() < 1e-6);
        faces_out(&mesh, |c| on_segment(h, c));
    }

    #[test]
    fn a_sphere_is_a_capsule_of_no_segment() {
        let mesh = capsule(Vec3::ZERO, 0.5);
        assert!(
            mesh.positions
                .iter()
                .all(|p| (p.length() - 0.5).abs() < 1e-6)
        );
        faces_out(&mesh, |_| Vec3::ZERO);
    }

    #[test]
    fn a_box_reaches_its_half_extents_and_faces_out() {
        let half = Vec3::new(0.3, 0.15, 0.05);
        let mesh = cuboid(half);
        assert_eq!(mesh.positions.len(), 24);
        for p in &mesh.positions {
            assert_eq!(p.abs(), half, "{p} is not a corner");
        }
        faces_out(&mesh, |_| Vec3::ZERO);
    }

    #[test]
    fn a_square_faces_along_its_normal() {
        let n = Vec3::new(0.0, 0.6, 0.8);
        let mesh = square(n, 4.0);
        assert!(mesh.positions.iter().all(|p| p.dot(n).abs() < 1e-6));
        faces_out(&mesh, |c| c - n);
    }

    #[test]
    fn a_bone_runs_from_its_origin_to_its_tip_and_faces_out() {
        let tip = Vec3::new(0.02, 0.3, -0.01);
        let mesh = bone(tip);
        let along: Vec<f32> = mesh
            .positions
            .iter()
            .map(|p| p.dot(tip) / tip.length_squared())
            .collect();
        assert_eq!(along.iter().copied().fold(f32::INFINITY, f32::min), 0.0);
        assert!((along.iter().copied().fold(0.0, f32::max) - 1.0).abs() < 1e-6);
        faces_out(&mesh, |_| tip * BONE_WAIST);
    }
}
