//! `Quat<L>`: one rotation quaternion per lane.

use core::ops::Mul;

use crate::lane::Lane;
use crate::poly;
use crate::vec3::Vec3;

/// A rotation quaternion `w + xi + yj + zk` in every lane (Hamilton
/// convention, as glam: `q * p` applies `p` first, then `q`; a vector is
/// rotated by `q v q*`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quat<L> {
    /// i components.
    pub x: L,
    /// j components.
    pub y: L,
    /// k components.
    pub z: L,
    /// Real parts.
    pub w: L,
}

impl<L: Lane> Quat<L> {
    /// From components.
    #[inline(always)]
    pub fn new(x: L, y: L, z: L, w: L) -> Self {
        Self { x, y, z, w }
    }

    /// The identity rotation.
    #[inline(always)]
    pub fn identity() -> Self {
        Self::splat(glam::Quat::IDENTITY)
    }

    /// The same quaternion in every lane.
    #[inline(always)]
    pub fn splat(q: glam::Quat) -> Self {
        Self::new(L::splat(q.x), L::splat(q.y), L::splat(q.z), L::splat(q.w))
    }

    /// Loads lanes from four component arrays (`WIDTH` values each).
    #[inline(always)]
    pub fn load(x: &[f32], y: &[f32], z: &[f32], w: &[f32]) -> Self {
        Self::new(L::load(x), L::load(y), L::load(z), L::load(w))
    }

    /// Stores lanes into four component arrays (`WIDTH` values each).
    #[inline(always)]
    pub fn store(self, x: &mut [f32], y: &mut [f32], z: &mut [f32], w: &mut [f32]) {
        self.x.store(x);
        self.y.store(y);
        self.z.store(z);
        self.w.store(w);
    }

    /// The vector (imaginary) part.
    #[inline(always)]
    pub fn vector(self) -> Vec3<L> {
        Vec3::new(self.x, self.y, self.z)
    }

    /// From a vector part and a real part.
    #[inline(always)]
    pub fn from_parts(v: Vec3<L>, w: L) -> Self {
        Self::new(v.x, v.y, v.z, w)
    }

    /// The conjugate, which is the inverse of a unit quaternion.
    #[inline(always)]
    pub fn conjugate(self) -> Self {
        Self::new(-self.x, -self.y, -self.z, self.w)
    }

    /// The 4-dimensional dot product.
    #[inline(always)]
    pub fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z + self.w * o.w
    }

    /// Scaled to unit length; a lane of zero, NaN or infinite length
    /// becomes the identity (the safe zero case, by a select). As for
    /// [`Vec3::normalize_or_zero`], the length comes from its square.
    #[inline(always)]
    pub fn normalize(self) -> Self {
        let length = self.dot(self).sqrt();
        let valid = length.gt(L::splat(0.0)) & length.lt(L::splat(f32::INFINITY));
        let inv = L::splat(1.0) / L::select(valid, length, L::splat(1.0));
        let unit = Self::new(self.x * inv, self.y * inv, self.z * inv, self.w * inv);
        Self::select(valid, unit, Self::identity())
    }

    /// Rotates `v` by this unit quaternion: `q v q*`, as
    /// `v + w t + q.xyz x t` with `t = 2 q.xyz x v`.
    #[inline(always)]
    pub fn rotate(self, v: Vec3<L>) -> Vec3<L> {
        let u = self.vector();
        let t = u.cross(v);
        let t = t + t;
        v + t.scale(self.w) + u.cross(t)
    }

    /// Rotates `v` by the inverse of this unit quaternion.
    #[inline(always)]
    pub fn inverse_rotate(self, v: Vec3<L>) -> Vec3<L> {
        self.conjugate().rotate(v)
    }

    /// The orientation after turning at world-space angular velocity
    /// `omega` (rad/s) for `dt` seconds: `q + dt/2 (omega, 0) q`,
    /// renormalised (the first-order update of XPBD rigid bodies).
    #[inline(always)]
    pub fn integrate(self, omega: Vec3<L>, dt: L) -> Self {
        let h = dt * L::splat(0.5);
        let spin = Self::from_parts(omega, L::splat(0.0)) * self;
        Self::new(
            self.x + spin.x * h,
            self.y + spin.y * h,
            self.z + spin.z * h,
            self.w + spin.w * h,
        )
        .normalize()
    }

    /// The orientation after turning by the small rotation vector
    /// `theta = axis angle` (rad) given in the frame this quaternion rotates
    /// *from* (a body's own frame): `q + 1/2 q (theta, 0)`, renormalised.
    /// The same turn as [`Quat::integrate`] by the world vector `R theta`
    /// over one second, since `(R theta, 0) q = q (theta, 0) q* q`, without
    /// rotating `theta` into the world (and with a product whose real part
    /// is known zero). `axis` need not be unit: the split only lets the
    /// half be taken of the scalar.
    #[inline(always)]
    pub fn integrate_local(self, axis: Vec3<L>, angle: L) -> Self {
        let v = axis.scale(angle * L::splat(0.5));
        let (x, y, z, w) = (self.x, self.y, self.z, self.w);
        Self::new(
            x + (w * v.x + y * v.z - z * v.y),
            y + (w * v.y + z * v.x - x * v.z),
            z + (w * v.z + x * v.y - y * v.x),
            w - (x * v.x + y * v.y + z * v.z),
        )
        .normalize_turned()
    }

    /// [`Quat::normalize`] for a unit quaternion plus a perpendicular
    /// step (as [`Quat::integrate_local`] makes): its length is at least
    /// one, never zero, so only a non-finite length (an overflowing or NaN
    /// step) needs the identity, and one comparison finds it.
    #[inline(always)]
    fn normalize_turned(self) -> Self {
        let length = self.dot(self).sqrt();
        let finite = length.lt(L::splat(f32::INFINITY));
        let inv = L::splat(1.0) / length;
        let unit = Self::new(self.x * inv, self.y * inv, self.z * inv, self.w * inv);
        Self::select(finite, unit, Self::identity())
    }

    /// The rotation by `angle` radians about the unit vector `axis`.
    #[inline(always)]
    pub fn from_axis_angle(axis: Vec3<L>, angle: L) -> Self {
        let (s, c) = poly::sin_cos(angle * L::splat(0.5));
        Self::from_parts(axis.scale(s), c)
    }

    /// The rotation vector (axis times angle, radians) of the shortest arc:
    /// the angle is in [0, pi]. The identity gives the zero vector.
    #[inline(always)]
    pub fn to_rotation_vector(self) -> Vec3<L> {
        let flip = self.w.lt(L::splat(0.0));
        let v = Vec3::select(flip, -self.vector(), self.vector());
        let w = self.w.abs();
        let sin_half = v.length();
        let angle = L::splat(2.0) * poly::atan2(sin_half, w);
        // angle / sin(angle / 2) -> 2 as the angle -> 0.
        let has_axis = sin_half.gt(L::splat(0.0));
        let factor = L::select(
            has_axis,
            angle / L::select(has_axis, sin_half, L::splat(1.0)),
            L::splat(2.0),
        );
        v.scale(factor)
    }

    /// The rotation angle in [0, pi] of the shortest arc.
    #[inline(always)]
    pub fn angle(self) -> L {
        L::splat(2.0) * poly::atan2(self.vector().length(), self.w.abs())
    }

    /// Splits this unit quaternion into `(swing, twist)` with
    /// `self = swing * twist`: `twist` turns about the unit vector `axis`
    /// (in the frame `self` acts on), `swing` about an axis perpendicular to
    /// `axis`. When the rotation swings `axis` half a turn the twist is
    /// undefined; it is then the identity.
    #[inline(always)]
    pub fn swing_twist(self, axis: Vec3<L>) -> (Self, Self) {
        let p = self.vector().dot(axis);
        let length = (p * p + self.w * self.w).sqrt();
        let defined = length.gt(L::splat(1e-12));
        let inv = L::splat(1.0) / L::select(defined, length, L::splat(1.0));
        let twist = Self::select(
            defined,
            Self::from_parts(axis.scale(p * inv), self.w * inv),
            Self::identity(),
        );
        (self * twist.conjugate(), twist)
    }

    /// The signed twist angle in [-pi, pi] about the unit vector `axis`:
    /// the angle of the `twist` from [`Quat::swing_twist`].
    #[inline(always)]
    pub fn twist_angle(self, axis: Vec3<L>) -> L {
        let p = self.vector().dot(axis);
        let sign = L::splat(1.0).copysign(self.w);
        L::splat(2.0) * poly::atan2(p * sign, self.w * sign)
    }

    /// Lane by lane: `on_true` where `mask`, else `on_false`.
    #[inline(always)]
    pub fn select(mask: L::Mask, on_true: Self, on_false: Self) -> Self {
        Self::new(
            L::select(mask, on_true.x, on_false.x),
            L::select(mask, on_true.y, on_false.y),
            L::select(mask, on_true.z, on_false.z),
            L::select(mask, on_true.w, on_false.w),
        )
    }
}

impl<L: Lane> Mul for Quat<L> {
    type Output = Self;
    /// The Hamilton product: `self * o` applies `o` first, then `self`.
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self::new(
            self.w * o.x + self.x * o.w + self.y * o.z - self.z * o.y,
            self.w * o.y - self.x * o.z + self.y * o.w + self.z * o.x,
            self.w * o.z + self.x * o.y - self.y * o.x + self.z * o.w,
            self.w * o.w - self.x * o.x - self.y * o.y - self.z * o.z,
        )
    }
}

impl From<glam::Quat> for Quat<f32> {
    fn from(q: glam::Quat) -> Self {
        Self::new(q.x, q.y, q.z, q.w)
    }
}

impl From<Quat<f32>> for glam::Quat {
    fn from(q: Quat<f32>) -> Self {
        glam::Quat::from_xyzw(q.x, q.y, q.z, q.w)
    }
}
