//! Contact generation for one pair of colliders, on parry's manifolds:
//! the pair's manifold made new while its memory is kept ([`fresh`]), the
//! ground (a half space) against a box or capsule written into that kept
//! manifold ([`plane_manifold`], parry's own algorithm step for step), and
//! a manifold's points turned into the solver's contacts
//! ([`push_manifold`]).
//!
//! Its own file because these are the bit-exact pieces: each must give
//! parry's contacts to the bit (the unit test below holds the ground's to
//! parry's), whatever the narrow phase around them (`narrow_phase.rs`)
//! does with them. It reads nothing of the crate.

use parry3d::math::Pose;
use parry3d::query::{ContactManifold, TrackedContact};
use parry3d::shape::{PackedFeatureId, PolygonalFeature, Shape as ParryShape, ShapeType};
use vertebra_world::{BodyHandle, Contact, MAX_COORDINATE};

/// Makes `manifolds` what parry gets for a new pair (at most one manifold,
/// as new: every query starts from the same state, whatever pair came
/// before) while keeping its points' memory: our colliders are convex, so
/// parry fills exactly the first manifold, and a manifold's normal seeds
/// its search (a reused one would change contacts).
pub(crate) fn fresh(manifolds: &mut Vec<ContactManifold<(), ()>>) {
    manifolds.truncate(1);
    if let Some(m) = manifolds.first_mut() {
        let mut points = core::mem::take(&mut m.points);
        points.clear();
        *m = ContactManifold {
            points,
            ..ContactManifold::new()
        };
    }
}

/// A half space against a box or capsule (the ground under a body), into
/// `manifolds[0]`; false (nothing done) for any other pair. This is parry's
/// `contact_manifold_halfspace_pfm` (0.31), which its dispatcher runs for
/// these pairs, step for step (so the contacts are its bits), except that
/// it writes into the manifold's point vector instead of a new one: parry
/// takes the old vector away every call (to carry impulses over, which we
/// do not keep), which cost an allocation per body on the ground per frame.
pub(crate) fn plane_manifold(
    pos12: &Pose,
    shape1: &dyn ParryShape,
    shape2: &dyn ParryShape,
    prediction: f32,
    manifolds: &mut Vec<ContactManifold<(), ()>>,
) -> bool {
    let polygonal =
        |s: &dyn ParryShape| matches!(s.shape_type(), ShapeType::Cuboid | ShapeType::Capsule);
    let (pos12, halfspace, (pfm, border_radius), flipped) =
        match (shape1.as_halfspace(), shape2.as_halfspace()) {
            (Some(h), None) if polygonal(shape2) => match shape2.as_polygonal_feature_map() {
                Some(p) => (*pos12, h, p, false),
                None => return false,
            },
            (None, Some(h)) if polygonal(shape1) => match shape1.as_polygonal_feature_map() {
                Some(p) => (pos12.inverse(), h, p, true),
                None => return false,
            },
            _ => return false,
        };
    if manifolds.is_empty() {
        manifolds.push(ContactManifold::new());
    }
    let manifold = &mut manifolds[0];
    let normal1_2 = pos12.rotation.inverse() * halfspace.normal;
    let mut feature2 = PolygonalFeature::default();
    pfm.local_support_feature(-normal1_2, &mut feature2);
    for k in 0..feature2.num_vertices {
        let vtx2 = feature2.vertices[k];
        let vtx2_1 = pos12 * vtx2;
        let dist_to_plane = vtx2_1.dot(halfspace.normal);
        if dist_to_plane - border_radius <= prediction {
            manifold.points.push(TrackedContact::flipped(
                vtx2_1 - halfspace.normal * dist_to_plane,
                vtx2 - normal1_2 * border_radius,
                PackedFeatureId::face(0),
                feature2.vids[k],
                dist_to_plane - border_radius,
                flipped,
            ));
        }
    }
    (manifold.local_n1, manifold.local_n2) = if flipped {
        (-normal1_2, halfspace.normal)
    } else {
        (halfspace.normal, -normal1_2)
    };
    true
}

/// A manifold's points as solver contacts: the normal from the first shape
/// to the second, the point midway between the surfaces, depth = -distance,
/// held to the depths the world accepts (`MAX_COORDINATE` either way): a
/// body a million metres under a ground plane is as deep as a contact
/// gets, and the rest of the list is still accepted.
pub(crate) fn push_manifold(
    out: &mut Vec<Contact>,
    m: &ContactManifold<(), ()>,
    (body_a, pose_a): (BodyHandle, &Pose),
    (body_b, pose_b): (BodyHandle, &Pose),
    friction: f32,
    restitution: f32,
) {
    let normal = (pose_a.rotation * m.local_n1).normalize();
    for point in &m.points {
        let pa = pose_a.transform_point(point.local_p1);
        let pb = pose_b.transform_point(point.local_p2);
        out.push(Contact {
            body_a,
            body_b,
            point: (pa + pb) * 0.5,
            normal,
            depth: (-point.dist).clamp(-MAX_COORDINATE, MAX_COORDINATE),
            friction,
            restitution,
        });
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};
    use parry3d::query::{DefaultQueryDispatcher, PersistentQueryDispatcher};
    use parry3d::shape::SharedShape;

    use super::*;

    /// Poses of a shape around a plane through the origin: a grid of
    /// heights, tilts and turns (resting, touching, apart, half sunk).
    fn poses() -> impl Iterator<Item = Pose> {
        (0..9).flat_map(|h| {
            (0..7).flat_map(move |t| {
                (0..5).map(move |r| {
                    let height = -0.3 + 0.09 * h as f32;
                    let tilt = Quat::from_rotation_x(0.37 * t as f32);
                    let turn = Quat::from_rotation_y(1.3 * r as f32);
                    Pose::from_parts(Vec3::new(0.2, height, -0.1), turn * tilt)
                })
            })
        })
    }

    /// Parry's manifolds for a new pair.
    fn parry(
        pos12: &Pose,
        s1: &dyn ParryShape,
        s2: &dyn ParryShape,
    ) -> Vec<ContactManifold<(), ()>> {
        let mut manifolds = Vec::new();
        DefaultQueryDispatcher
            .contact_manifolds(pos12, s1, s2, 0.05, &mut manifolds, &mut None)
            .unwrap();
        manifolds
    }

    /// A manifold's normals and points, bit for bit.
    fn bits(m: &ContactManifold<(), ()>) -> Vec<u32> {
        let v = |v: Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        let mut out = [v(m.local_n1), v(m.local_n2)].concat();
        for p in &m.points {
            out.extend(v(p.local_p1));
            out.extend(v(p.local_p2));
            out.extend([p.dist.to_bits(), p.fid1.0, p.fid2.0]);
        }
        out
    }

    #[test]
    fn the_ground_makes_parrys_contacts_bit_for_bit_in_a_kept_manifold() {
        let plane = SharedShape::halfspace(Vec3::new(0.0, 0.6, 0.8));
        let solids = [
            SharedShape::capsule(Vec3::new(0.0, -0.2, 0.0), Vec3::new(0.0, 0.2, 0.0), 0.06),
            SharedShape::cuboid(0.3, 0.15, 0.2),
        ];
        let mut kept = Vec::new();
        let mut points = 0;
        for solid in &solids {
            for pose in poses() {
                for (s1, s2, pos12) in [(&plane, solid, pose), (solid, &plane, pose.inverse())] {
                    fresh(&mut kept);
                    assert!(plane_manifold(
                        &pos12,
                        s1.as_ref(),
                        s2.as_ref(),
                        0.05,
                        &mut kept
                    ));
                    let expected = parry(&pos12, s1.as_ref(), s2.as_ref());
                    assert_eq!(kept.len(), 1);
                    assert_eq!(bits(&kept[0]), bits(&expected[0]), "{pose:?}");
                    points += kept[0].points.len();
                }
            }
        }
        assert!(points > 100, "the grid makes contacts: {points}");
        // Other pairs are parry's to make.
        let ball = SharedShape::ball(0.1);
        let pose = Pose::from_parts(Vec3::Y * 0.05, Quat::IDENTITY);
        assert!(!plane_manifold(
            &pose,
            plane.as_ref(),
            ball.as_ref(),
            0.05,
            &mut kept
        ));
        assert!(!plane_manifold(
            &pose,
            solids[0].as_ref(),
            solids[1].as_ref(),
            0.05,
            &mut kept
        ));
    }
}
