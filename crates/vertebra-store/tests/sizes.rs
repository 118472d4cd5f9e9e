//! Shapes of extreme size are refused with the dimension named; every
//! accepted shape gives finite, positive, invertible mass properties.

use glam::Vec3;
use vertebra_store::{Error, MASS_RANGE, MassProperties, SIZE_RANGE, Shape};

fn shapes(s: f32) -> [Shape; 4] {
    [
        Shape::Sphere { radius: s },
        Shape::Box {
            half_extents: Vec3::new(s, 0.1, 0.2),
        },
        Shape::Capsule {
            half_segment: Vec3::ZERO,
            radius: s,
        },
        Shape::capsule(Vec3::ZERO, Vec3::new(0.3, 0.4, 0.0), s),
    ]
}

/// Finite, in range, and with a finite inverse inertia: what a body needs.
fn usable(p: &MassProperties) -> bool {
    MASS_RANGE.contains(&p.mass)
        && p.inertia.is_finite()
        && p.inertia.inverse().is_finite()
        && p.validate().is_ok()
}

#[test]
fn sizes_outside_the_range_are_refused_with_the_dimension_named() {
    let capsule = |radius| Shape::capsule(Vec3::ZERO, Vec3::Y, radius);
    assert_eq!(
        capsule(1e-30).mass_properties_with_mass(1.0),
        Err(Error::OutOfRange("capsule radius (1e-3 to 1e3 m)"))
    );
    assert_eq!(
        capsule(1e30).mass_properties(1000.0),
        Err(Error::OutOfRange("capsule radius (1e-3 to 1e3 m)"))
    );
    assert_eq!(
        Shape::capsule(Vec3::ZERO, Vec3::splat(1e30), 0.1).mass_properties_with_mass(1.0),
        Err(Error::OutOfRange("capsule half segment (at most 1e3 m)"))
    );
    assert_eq!(
        Shape::Sphere { radius: 1e-20 }.mass_properties_with_mass(1.0),
        Err(Error::OutOfRange("sphere radius (1e-3 to 1e3 m)"))
    );
    assert_eq!(
        Shape::Box {
            half_extents: Vec3::new(0.1, 1e20, 0.1)
        }
        .mass_properties(1.0),
        Err(Error::OutOfRange("box half extents (1e-3 to 1e3 m)"))
    );
}

#[test]
fn a_density_that_overflows_the_mass_is_refused() {
    let ball = Shape::Sphere { radius: 1.0 };
    assert_eq!(
        ball.mass_properties(f32::MAX),
        Err(Error::OutOfRange(
            "mass (density x volume, 1e-6 to 1e12 kg)"
        ))
    );
    assert_eq!(
        ball.mass_properties(1e-30),
        Err(Error::OutOfRange(
            "mass (density x volume, 1e-6 to 1e12 kg)"
        ))
    );
    assert_eq!(
        ball.mass_properties_with_mass(1e30),
        Err(Error::OutOfRange("mass (1e-6 to 1e12 kg)"))
    );
}

/// Over the whole size range, at masses across the mass range: either
/// usable mass properties or an error, never `Ok` with NaN, infinite or
/// zero values; and at everyday masses every size in range is accepted.
#[test]
fn every_accepted_shape_has_usable_mass_properties() {
    let (lo, hi) = (*SIZE_RANGE.start(), *SIZE_RANGE.end());
    let sizes = (0..=24).map(|k| lo * (hi / lo).powf(k as f32 / 24.0));
    for s in sizes.chain([lo, hi]) {
        for shape in shapes(s) {
            assert!(shape.validate().is_ok(), "{shape:?} is in range");
            for mass in [1e-6f32, 1e-3, 1.0, 1e3, 1e6, 1e9, 1e12] {
                if let Ok(p) = shape.mass_properties_with_mass(mass) {
                    assert!(usable(&p), "{shape:?} at {mass} kg gave {p:?}");
                }
            }
            for density in [1e-3f32, 1.0, 1e3, 1e6, 1e9] {
                if let Ok(p) = shape.mass_properties(density) {
                    assert!(usable(&p), "{shape:?} at {density} kg/m^3 gave {p:?}");
                }
            }
            let everyday = shape.mass_properties_with_mass(1.0);
            assert!(
                everyday.as_ref().is_ok_and(usable),
                "{shape:?} at 1 kg: {everyday:?}"
            );
        }
    }
}
