//! `Sym3<L>`: one symmetric 3x3 matrix per lane, for world-space inverse
//! inertia tensors `R diag(I_body^-1) R^T`.

use crate::lane::Lane;
use crate::quat::Quat;
use crate::vec3::Vec3;

/// A symmetric 3x3 matrix in every lane, stored as its six distinct
/// entries. Units are the caller's (kg^-1 m^-2 for an inverse inertia).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sym3<L> {
    /// Entry (0, 0).
    pub xx: L,
    /// Entry (1, 1).
    pub yy: L,
    /// Entry (2, 2).
    pub zz: L,
    /// Entries (0, 1) and (1, 0).
    pub xy: L,
    /// Entries (0, 2) and (2, 0).
    pub xz: L,
    /// Entries (1, 2) and (2, 1).
    pub yz: L,
}

impl<L: Lane> Sym3<L> {
    /// The matrix of the entries `[xx, yy, zz, xy, xz, yz]` (the order of
    /// the kernels' inertia rows).
    #[inline(always)]
    pub fn from_entries([xx, yy, zz, xy, xz, yz]: [L; 6]) -> Self {
        Self {
            xx,
            yy,
            zz,
            xy,
            xz,
            yz,
        }
    }

    /// The diagonal matrix `diag(d)`.
    #[inline(always)]
    pub fn diagonal(d: Vec3<L>) -> Self {
        let zero = L::splat(0.0);
        Self {
            xx: d.x,
            yy: d.y,
            zz: d.z,
            xy: zero,
            xz: zero,
            yz: zero,
        }
    }

    /// `R S R^T`, with `R` the rotation of the unit quaternion `q`: a
    /// body-frame tensor seen in the world frame. With the rows `r_i` of
    /// `R`, entry `(i, j)` is `(S r_i) . r_j`.
    #[inline(always)]
    pub fn rotated(self, q: Quat<L>) -> Self {
        let [r0, r1, r2] = rotation_rows(q);
        let (u0, u1, u2) = (self.mul_vec(r0), self.mul_vec(r1), self.mul_vec(r2));
        Self {
            xx: u0.dot(r0),
            yy: u1.dot(r1),
            zz: u2.dot(r2),
            xy: u0.dot(r1),
            xz: u0.dot(r2),
            yz: u1.dot(r2),
        }
    }

    /// `self + s 1`: the matrix with `s` added to the diagonal.
    #[inline(always)]
    pub fn add_diagonal(self, s: L) -> Self {
        Self {
            xx: self.xx + s,
            yy: self.yy + s,
            zz: self.zz + s,
            ..self
        }
    }

    /// The inverse by the adjugate, or the zero matrix in lanes whose
    /// determinant is not positive (a singular or indefinite matrix: two
    /// bodies of infinite mass, or padding), decided by a select.
    #[inline(always)]
    pub fn inverse_or_zero(self) -> Self {
        let (a, b, c, d, e, f) = (self.xx, self.yy, self.zz, self.xy, self.xz, self.yz);
        let (axx, ayy, azz) = (b * c - f * f, a * c - e * e, a * b - d * d);
        let (axy, axz, ayz) = (e * f - d * c, d * f - e * b, d * e - a * f);
        let det = a * axx + d * axy + e * axz;
        let valid = det.gt(L::splat(0.0));
        let inv = L::select(
            valid,
            L::splat(1.0) / L::select(valid, det, L::splat(1.0)),
            L::splat(0.0),
        );
        Self {
            xx: axx * inv,
            yy: ayy * inv,
            zz: azz * inv,
            xy: axy * inv,
            xz: axz * inv,
            yz: ayz * inv,
        }
    }

    /// The product `S v`.
    #[inline(always)]
    pub fn mul_vec(self, v: Vec3<L>) -> Vec3<L> {
        Vec3::new(
            self.xx * v.x + self.xy * v.y + self.xz * v.z,
            self.xy * v.x + self.yy * v.y + self.yz * v.z,
            self.xz * v.x + self.yz * v.y + self.zz * v.z,
        )
    }

    /// The quadratic form `v^T S v` (a generalised inverse mass when `S` is
    /// an inverse inertia and `v` a lever-arm cross product or an axis).
    #[inline(always)]
    pub fn quadratic(self, v: Vec3<L>) -> L {
        v.dot(self.mul_vec(v))
    }
}

/// The rows of the rotation matrix of the unit quaternion `q`.
#[inline(always)]
fn rotation_rows<L: Lane>(q: Quat<L>) -> [Vec3<L>; 3] {
    let one = L::splat(1.0);
    let two = L::splat(2.0);
    let (x, y, z, w) = (q.x, q.y, q.z, q.w);
    [
        Vec3::new(
            one - two * (y * y + z * z),
            two * (x * y - w * z),
            two * (x * z + w * y),
        ),
        Vec3::new(
            two * (x * y + w * z),
            one - two * (x * x + z * z),
            two * (y * z - w * x),
        ),
        Vec3::new(
            two * (x * z - w * y),
            two * (y * z + w * x),
            one - two * (x * x + y * y),
        ),
    ]
}

impl<L: Lane> core::ops::Add for Sym3<L> {
    type Output = Self;
    /// Entry-wise sum.
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            xx: self.xx + o.xx,
            yy: self.yy + o.yy,
            zz: self.zz + o.zz,
            xy: self.xy + o.xy,
            xz: self.xz + o.xz,
            yz: self.yz + o.yz,
        }
    }
}
