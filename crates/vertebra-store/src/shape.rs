//! Collision shapes as far as the solver needs them: mass and inertia of a
//! uniform solid about its centre of mass.

use core::f32::consts::PI;

use glam::{Mat3, Vec3};

use crate::error::{Error, check_finite, check_positive};
use vertebra_math::DefaultFloatMode;

/// A solid centred on its body's centre of mass, in the body frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Shape {
    /// A ball of `radius` metres.
    Sphere {
        /// Radius (m).
        radius: f32,
    },
    /// A box of the given half extents along the body axes (m).
    Box {
        /// Half the size along x, y and z (m).
        half_extents: Vec3,
    },
    /// A capsule: the segment from `-half_segment` to `+half_segment`
    /// (body frame, m) swept by a ball of `radius` (m).
    Capsule {
        /// Half the core segment, from the centre to one end (m).
        half_segment: Vec3,
        /// Radius (m).
        radius: f32,
    },
}

/// Mass (kg) and inertia tensor (kg m^2, body frame, about the centre of
/// mass) of a rigid body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    /// Mass (kg).
    pub mass: f32,
    /// Inertia tensor (kg m^2), body frame, about the centre of mass.
    pub inertia: Mat3,
}

impl Shape {
    /// A capsule between two points `a` and `b` of the body frame whose
    /// midpoint is the centre of mass (m).
    pub fn capsule(a: Vec3, b: Vec3, radius: f32) -> Self {
        Shape::Capsule {
            half_segment: (b - a) * 0.5,
            radius,
        }
    }

    /// Checks that the shape has finite, positive size (what a collider
    /// needs; mass properties need [`SIZE_RANGE`] too).
    pub fn validate(&self) -> Result<(), Error> {
        match *self {
            Shape::Sphere { radius } => positive_size("sphere radius", radius),
            Shape::Box { half_extents } => {
                check_finite("box half extents", half_extents)?;
                if half_extents.min_element() > 0.0 {
                    Ok(())
                } else {
                    Err(Error::DegenerateShape("box half extents must be positive"))
                }
            }
            Shape::Capsule {
                half_segment,
                radius,
            } => {
                check_finite("capsule segment", half_segment)?;
                positive_size("capsule radius", radius)
            }
        }
    }

    /// Checks a valid shape's dimensions (radius, half extents) lie in
    /// [`SIZE_RANGE`], and a capsule's half segment is at most its end.
    fn check_size_range(&self) -> Result<(), Error> {
        let (dimensions, what) = match *self {
            Shape::Sphere { radius } => ([radius; 3], "sphere radius (1e-3 to 1e3 m)"),
            Shape::Box { half_extents } => {
                (half_extents.to_array(), "box half extents (1e-3 to 1e3 m)")
            }
            Shape::Capsule {
                half_segment,
                radius,
            } => {
                if half_segment.length() > *SIZE_RANGE.end() {
                    return Err(Error::OutOfRange("capsule half segment (at most 1e3 m)"));
                }
                ([radius; 3], "capsule radius (1e-3 to 1e3 m)")
            }
        };
        if dimensions.iter().all(|d| SIZE_RANGE.contains(d)) {
            Ok(())
        } else {
            Err(Error::OutOfRange(what))
        }
    }

    /// Volume (m^3).
    pub fn volume(&self) -> f32 {
        match *self {
            Shape::Sphere { radius } => 4.0 / 3.0 * PI * radius.powi(3),
            Shape::Box { half_extents: h } => 8.0 * h.x * h.y * h.z,
            Shape::Capsule {
                half_segment,
                radius,
            } => {
                PI * radius * radius * (2.0 * half_segment.length())
                    + 4.0 / 3.0 * PI * radius.powi(3)
            }
        }
    }

    /// Mass properties at uniform `density` (kg/m^3): dimensions within
    /// [`SIZE_RANGE`], the result checked as
    /// [`MassProperties::validate`] checks them: the mass (density times
    /// volume) within [`MASS_RANGE`], the inertia invertible.
    pub fn mass_properties(&self, density: f32) -> Result<MassProperties, Error> {
        let _mode = DefaultFloatMode::enter();
        self.validate()?;
        self.check_size_range()?;
        check_positive("density", density)?;
        let unit = self.unit_density_properties();
        // In f64: density times volume may overflow f32.
        let mass = f64::from(density) * f64::from(unit.mass);
        if !(f64::from(*MASS_RANGE.start())..=f64::from(*MASS_RANGE.end())).contains(&mass) {
            return Err(Error::OutOfRange(
                "mass (density x volume, 1e-6 to 1e12 kg)",
            ));
        }
        unit.scaled(density).checked()
    }

    /// Mass properties of a uniform solid of total `mass` (kg): dimensions
    /// within [`SIZE_RANGE`], the result checked as
    /// [`MassProperties::validate`] checks them.
    pub fn mass_properties_with_mass(&self, mass: f32) -> Result<MassProperties, Error> {
        let _mode = DefaultFloatMode::enter();
        self.validate()?;
        self.check_size_range()?;
        check_mass(mass)?;
        let unit = self.unit_density_properties();
        unit.scaled(mass / unit.mass).checked()
    }

    fn unit_density_properties(&self) -> MassProperties {
        match *self {
            Shape::Sphere { radius } => {
                let mass = self.volume();
                MassProperties {
                    mass,
                    inertia: Mat3::from_diagonal(Vec3::splat(0.4 * mass * radius * radius)),
                }
            }
            Shape::Box { half_extents: h } => {
                let mass = self.volume();
                let sq = h * h;
                let diagonal = Vec3::new(sq.y + sq.z, sq.x + sq.z, sq.x + sq.y) * (mass / 3.0);
                MassProperties {
                    mass,
                    inertia: Mat3::from_diagonal(diagonal),
                }
            }
            Shape::Capsule {
                half_segment,
                radius: r,
            } => {
                let length = 2.0 * half_segment.length();
                let cylinder = PI * r * r * length;
                let caps = 4.0 / 3.0 * PI * r.powi(3);
                let axial = cylinder * r * r / 2.0 + caps * 0.4 * r * r;
                // Two hemispheres at the segment's ends (parallel axis theorem
                // about their own centres of mass, 3r/8 from the flat face).
                let across = cylinder * (length * length / 12.0 + r * r / 4.0)
                    + caps * (0.4 * r * r + length * length / 4.0 + 3.0 * length * r / 8.0);
                let d = half_segment.normalize_or(Vec3::Y);
                let dd = Mat3::from_cols(d * d.x, d * d.y, d * d.z);
                let inertia = (Mat3::IDENTITY - dd) * across + dd * axial;
                MassProperties {
                    mass: cylinder + caps,
                    inertia,
                }
            }
        }
    }
}

fn positive_size(what: &'static str, x: f32) -> Result<(), Error> {
    if !x.is_finite() {
        return Err(Error::NonFinite(what));
    }
    if x > 0.0 {
        Ok(())
    } else {
        Err(Error::DegenerateShape(what))
    }
}

/// The dimensions a shape may have (m): radii, half extents and half
/// segment lengths, a millimetre to a kilometre. Over this range a unit
/// density's volume (about `s^3`) and inertia (about `s^5`) stay normal
/// `f32` numbers (1e-15 to 1e16), so the scale from them to any mass in
/// [`MASS_RANGE`] is finite and non-zero. A capsule radius of 1e-30 m has
/// a volume of zero and a mass of NaN; at 1e6 m coordinates an `f32`
/// resolves 6 cm, so nothing below a millimetre could be placed anyway.
pub const SIZE_RANGE: core::ops::RangeInclusive<f32> = 1.0e-3..=1.0e3;

/// A finite mass within [`MASS_RANGE`].
fn check_mass(mass: f32) -> Result<(), Error> {
    check_positive("mass", mass)?;
    if !MASS_RANGE.contains(&mass) {
        return Err(Error::OutOfRange("mass (1e-6 to 1e12 kg)"));
    }
    Ok(())
}

/// The masses a body may have (kg): a milligram to a mountain.
pub const MASS_RANGE: core::ops::RangeInclusive<f32> = 1.0e-6..=1.0e12;

impl MassProperties {
    /// Given directly: `mass` (kg) and the body-frame `inertia` (kg m^2).
    pub fn new(mass: f32, inertia: Mat3) -> Result<Self, Error> {
        let props = Self { mass, inertia };
        props.validate()?;
        Ok(props)
    }

    /// Checks a positive mass within [`MASS_RANGE`] and a symmetric positive
    /// definite inertia tensor (Sylvester's criterion on the leading minors)
    /// whose inverse is finite in `f32` (the solver works with inverses: a
    /// 1e24 kg m^2 tensor's determinant overflows, and its inverse is NaN).
    pub fn validate(&self) -> Result<(), Error> {
        check_mass(self.mass)?;
        let m = self.inertia;
        if !m.to_cols_array().iter().all(|x| x.is_finite()) {
            return Err(Error::NonFinite("inertia"));
        }
        let scale = m.to_cols_array().iter().fold(0.0f32, |a, x| a.max(x.abs()));
        let asymmetric = (m - m.transpose())
            .to_cols_array()
            .iter()
            .any(|x| x.abs() > 1e-5 * scale);
        let minor2 = m.x_axis.x * m.y_axis.y - m.x_axis.y * m.y_axis.x;
        if asymmetric || m.x_axis.x <= 0.0 || minor2 <= 0.0 || m.determinant() <= 0.0 {
            return Err(Error::InvalidInertia);
        }
        if !(m.determinant().is_finite() && m.inverse().is_finite()) {
            return Err(Error::OutOfRange("inertia (its inverse overflows)"));
        }
        Ok(())
    }

    /// `Ok(self)` if it passes [`MassProperties::validate`].
    fn checked(self) -> Result<Self, Error> {
        self.validate()?;
        Ok(self)
    }

    fn scaled(self, factor: f32) -> Self {
        Self {
            mass: self.mass * factor,
            inertia: self.inertia * factor,
        }
    }
}
