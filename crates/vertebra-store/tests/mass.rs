//! Mass properties against closed forms and against a numerical integration
//! over a voxel grid (independent of the formulas in the code).

use glam::{Mat3, Quat, Vec3};
use vertebra_store::Shape;

/// Mass and inertia of a uniform solid of density 1 by summing voxels.
fn integrate(inside: impl Fn(Vec3) -> bool, half: f32, n: usize) -> (f64, [[f64; 3]; 3]) {
    let step = 2.0 * half as f64 / n as f64;
    let dv = step * step * step;
    let (mut mass, mut inertia) = (0.0f64, [[0.0f64; 3]; 3]);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = [i, j, k].map(|c| -half as f64 + (c as f64 + 0.5) * step);
                if !inside(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)) {
                    continue;
                }
                mass += dv;
                let r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
                for a in 0..3 {
                    for b in 0..3 {
                        inertia[a][b] += dv * (if a == b { r2 } else { 0.0 } - p[a] * p[b]);
                    }
                }
            }
        }
    }
    (mass, inertia)
}

fn assert_close(shape: Shape, inside: impl Fn(Vec3) -> bool, half: f32) {
    let props = shape.mass_properties(1.0).unwrap();
    // 140 voxels: a 5 mm step for a 0.35 m half width, so box faces fall
    // on voxel boundaries.
    let (mass, inertia) = integrate(inside, half, 140);
    assert!(
        (props.mass as f64 - mass).abs() / mass < 0.01,
        "{shape:?}: mass {} vs {mass}",
        props.mass
    );
    let m = props.inertia.to_cols_array_2d();
    let scale = inertia[0][0].max(inertia[1][1]).max(inertia[2][2]);
    for a in 0..3 {
        for b in 0..3 {
            let err = (m[a][b] as f64 - inertia[a][b]).abs() / scale;
            assert!(
                err < 0.01,
                "{shape:?}: I[{a}][{b}] = {} vs {}",
                m[a][b],
                inertia[a][b]
            );
        }
    }
}

#[test]
fn closed_forms_of_sphere_and_box() {
    let sphere = Shape::Sphere { radius: 0.5 }
        .mass_properties_with_mass(3.0)
        .unwrap();
    assert_eq!(
        sphere.inertia,
        Mat3::from_diagonal(Vec3::splat(0.4 * 3.0 * 0.25))
    );
    let cuboid = Shape::Box {
        half_extents: Vec3::new(1.0, 2.0, 3.0),
    }
    .mass_properties_with_mass(12.0)
    .unwrap();
    // m/12 (b^2 + c^2) with full extents 2, 4, 6.
    let expected = Vec3::new(16.0 + 36.0, 4.0 + 36.0, 4.0 + 16.0);
    assert!(
        (cuboid.inertia.diagonal() - expected).length() < 1e-4,
        "{:?}",
        cuboid.inertia
    );
}

#[test]
fn shapes_match_a_voxel_integration() {
    assert_close(Shape::Sphere { radius: 0.4 }, |p| p.length() <= 0.4, 0.4);
    let h = Vec3::new(0.2, 0.35, 0.1);
    assert_close(
        Shape::Box { half_extents: h },
        |p| p.abs().cmple(h).all(),
        0.35,
    );
    // Capsules along an axis and along a tilted segment (off-diagonal terms).
    for dir in [Vec3::Y, Vec3::X, Vec3::new(1.0, 1.0, 0.5).normalize()] {
        let (half_segment, radius) = (dir * 0.25, 0.15);
        let inside = |p: Vec3| {
            let t = p.dot(dir).clamp(-0.25, 0.25);
            (p - dir * t).length() <= radius
        };
        assert_close(
            Shape::Capsule {
                half_segment,
                radius,
            },
            inside,
            0.45,
        );
    }
}

#[test]
fn a_capsule_between_two_points_is_centred() {
    let a = Shape::capsule(Vec3::new(-0.06, 0.0, 0.0), Vec3::new(0.06, 0.0, 0.0), 0.1);
    assert_eq!(
        a,
        Shape::Capsule {
            half_segment: Vec3::new(0.06, 0.0, 0.0),
            radius: 0.1
        }
    );
    // Rotating the segment rotates the tensor.
    let q = Quat::from_rotation_z(0.7);
    let b = Shape::Capsule {
        half_segment: q * Vec3::new(0.06, 0.0, 0.0),
        radius: 0.1,
    };
    let (ia, ib) = (
        a.mass_properties(1.0).unwrap().inertia,
        b.mass_properties(1.0).unwrap().inertia,
    );
    let r = Mat3::from_quat(q);
    assert!(
        (r * ia * r.transpose() - ib)
            .to_cols_array()
            .iter()
            .all(|x| x.abs() < 1e-6)
    );
}
