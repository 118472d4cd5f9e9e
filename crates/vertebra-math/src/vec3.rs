//! `Vec3<L>`: three lane values, one 3-vector per lane.

use core::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

use crate::lane::Lane;

/// A 3-vector in every lane (structure of arrays: `x` holds every lane's x).
/// Units and frame are the caller's; kernels use metres and world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3<L> {
    /// x components.
    pub x: L,
    /// y components.
    pub y: L,
    /// z components.
    pub z: L,
}

impl<L: Lane> Vec3<L> {
    /// From components.
    #[inline(always)]
    pub fn new(x: L, y: L, z: L) -> Self {
        Self { x, y, z }
    }

    /// The zero vector.
    #[inline(always)]
    pub fn zero() -> Self {
        Self::splat(glam::Vec3::ZERO)
    }

    /// The same vector in every lane.
    #[inline(always)]
    pub fn splat(v: glam::Vec3) -> Self {
        Self::new(L::splat(v.x), L::splat(v.y), L::splat(v.z))
    }

    /// Loads lanes from three component arrays (`WIDTH` values each).
    #[inline(always)]
    pub fn load(x: &[f32], y: &[f32], z: &[f32]) -> Self {
        Self::new(L::load(x), L::load(y), L::load(z))
    }

    /// Stores lanes into three component arrays (`WIDTH` values each).
    #[inline(always)]
    pub fn store(self, x: &mut [f32], y: &mut [f32], z: &mut [f32]) {
        self.x.store(x);
        self.y.store(y);
        self.z.store(z);
    }

    /// Dot product.
    #[inline(always)]
    pub fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross product `self x o`.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }

    /// Squared length.
    #[inline(always)]
    pub fn length_squared(self) -> L {
        self.dot(self)
    }

    /// Length.
    #[inline(always)]
    pub fn length(self) -> L {
        self.length_squared().sqrt()
    }

    /// The unit vector along `self`, and the length. A lane whose length is
    /// zero, NaN or infinite gives the zero vector: the safe zero case,
    /// decided by a select. The length comes from the squared length, so
    /// |v| below about 1e-22 counts as zero and above 1.8e19 as infinite.
    #[inline(always)]
    pub fn normalize_or_zero(self) -> (Self, L) {
        let length = self.length();
        let valid = length.gt(L::splat(0.0)) & length.lt(L::splat(f32::INFINITY));
        let unit = self.scale(L::splat(1.0) / L::select(valid, length, L::splat(1.0)));
        (Self::select(valid, unit, Self::zero()), length)
    }

    /// Every component times `s`.
    #[inline(always)]
    pub fn scale(self, s: L) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }

    /// Lane by lane: `on_true` where `mask`, else `on_false`.
    #[inline(always)]
    pub fn select(mask: L::Mask, on_true: Self, on_false: Self) -> Self {
        Self::new(
            L::select(mask, on_true.x, on_false.x),
            L::select(mask, on_true.y, on_false.y),
            L::select(mask, on_true.z, on_false.z),
        )
    }
}

impl<L: Lane> Add for Vec3<L> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<L: Lane> Sub for Vec3<L> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl<L: Lane> Neg for Vec3<L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}

impl<L: Lane> Mul<L> for Vec3<L> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: L) -> Self {
        self.scale(s)
    }
}

impl<L: Lane> AddAssign for Vec3<L> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl<L: Lane> SubAssign for Vec3<L> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

impl From<glam::Vec3> for Vec3<f32> {
    fn from(v: glam::Vec3) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}

impl From<Vec3<f32>> for glam::Vec3 {
    fn from(v: Vec3<f32>) -> Self {
        glam::Vec3::new(v.x, v.y, v.z)
    }
}
