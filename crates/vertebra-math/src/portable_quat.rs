//! glam's quaternion operations whose bits glam leaves to the target, as
//! plain `f32` arithmetic in one fixed order: the same bits on every
//! target.
//!
//! glam stores a `Quat` in a SIMD register where it can and computes with
//! each target's instructions: SSE2 on x86-64, NEON on AArch64, scalar
//! code elsewhere (and whenever its `scalar-math` feature is on, as this
//! crate turns it on for every target but x86-64, so that the collision
//! layer's glam, parry's, computes one way there). Element-wise operations
//! and `Quat * Vec3` give the same bits on all of them (the rotation's
//! formula is written in the same order; `tests/portable_quat.rs` checks
//! it), but these do not:
//!
//! | operation | SSE2 (x86-64) | scalar | NEON |
//! | --- | --- | --- | --- |
//! | `dot`, `length` | `(x x + z z) + (y y + w w)` | `((x x + y y) + z z) + w w` | `(x x + y y) + (z z + w w)` |
//! | `normalize` | `q / length` | `q * (1 / length)` | `q * (1 / length)` |
//! | `a * b` | each component `(p + q) + (r + s)` (rtm's order) | `((p + q) + r) - s` | rtm's |
//!
//! Everything that enters a world (bodies' orientations, joint frames,
//! the step's integration, contacts' relative poses) goes through these
//! instead, written in the order of glam's SSE2 code: x86-64's results
//! are glam's own, and every other target computes the same bits. So do
//! rotations made from an angle: glam takes their sine and cosine from
//! the platform's C library, these from [`crate::trig`].
//! (Nothing refuses glam's own at compile time: tests use them freely,
//! and clippy could not refuse the `*` operator anyway. The golden hashes
//! checked under emulation on AArch64 and WebAssembly are the check.)

use glam::{Quat, Vec3};

/// glam's `Quat` operations with the same bits on every target.
pub trait PortableQuat: Sized {
    /// `self * rhs` (the rotation `rhs`, then `self`).
    fn mul_portable(self, rhs: Self) -> Self;
    /// `self.dot(rhs)`: the four products summed as `(x + z) + (y + w)`.
    fn dot_portable(self, rhs: Self) -> f32;
    /// `self.length()`.
    fn length_portable(self) -> f32;
    /// `self.normalize()`: each component divided by the length.
    fn normalize_portable(self) -> Self;
    /// `Quat::from_rotation_arc(from, to)` for unit vectors: the shortest
    /// turn taking `from` to `to`.
    fn from_rotation_arc_portable(from: Vec3, to: Vec3) -> Self;
    /// `Quat::from_axis_angle(axis, angle)`: `angle` radians about the unit
    /// `axis`, its sine and cosine from [`crate::trig`].
    fn from_axis_angle_portable(axis: Vec3, angle: f32) -> Self;
    /// `Quat::from_rotation_x(angle)`: `angle` radians about +x.
    fn from_rotation_x_portable(angle: f32) -> Self;
    /// `Quat::from_rotation_y(angle)`: `angle` radians about +y.
    fn from_rotation_y_portable(angle: f32) -> Self;
    /// `self.slerp(end, w)` for unit quaternions: `self` turned toward
    /// `end` by the fraction `w` of the shorter turn between them, about
    /// that turn's fixed axis (the angle from `self` is `w` times the
    /// whole turn's, to rounding). The turn's angle comes from
    /// [`crate::trig::atan2`], which resolves small turns; glam's takes it
    /// from an approximate `acos` and its sines from a per-target
    /// polynomial or the C library, so its bits differ between targets
    /// (and from these on x86-64).
    fn slerp_portable(self, end: Self, w: f32) -> Self;
    /// The angle (radians, in `[0, pi]`) of the turn from `self` to `rhs`:
    /// glam's `angle_between`, from [`crate::trig::atan2`] of the turn's
    /// half sine and cosine rather than glam's `acos` of a per-target dot
    /// product (and exact for small turns, where `acos` is not).
    fn angle_between_portable(self, rhs: Self) -> f32;
    /// `self` turned at angular velocity `w` (rad/s, world) for `t`
    /// seconds exactly: `exp(w t / 2) self`, renormalised, through the
    /// lane math's polynomials. The first-order `q + t/2 (w, 0) q` turns by
    /// `2 atan(|w| t / 2)` instead, and together with deriving `w` from the
    /// quaternion difference it bleeds spin at `(|w| t)^2 / 8` per step.
    fn turned_portable(self, w: Vec3, t: f32) -> Self;
}

impl PortableQuat for Quat {
    #[inline]
    fn mul_portable(self, rhs: Quat) -> Quat {
        // glam's SSE2 `mul_quat` (after rtm's `quat_mul`): per component,
        // `w_l * r` plus a signed `x_l * r'`, and a signed `y_l * r''`
        // plus a signed `z_l * r'''`, the two sums added. A product's
        // sign is flipped after rounding (a multiplication by -1 there).
        let ([lx, ly, lz, lw], [rx, ry, rz, rw]) = (self.to_array(), rhs.to_array());
        Quat::from_xyzw(
            (lx * rw + lw * rx) + (-(lz * ry) + ly * rz),
            (-(lx * rz) + lw * ry) + (lz * rx + ly * rw),
            (lx * ry + lw * rz) + (lz * rw + -(ly * rx)),
            (-(lx * rx) + lw * rw) + (-(lz * rz) + -(ly * ry)),
        )
    }

    #[inline]
    fn dot_portable(self, rhs: Quat) -> f32 {
        let ([ax, ay, az, aw], [bx, by, bz, bw]) = (self.to_array(), rhs.to_array());
        (ax * bx + az * bz) + (ay * by + aw * bw)
    }

    #[inline]
    fn length_portable(self) -> f32 {
        self.dot_portable(self).sqrt()
    }

    #[inline]
    fn normalize_portable(self) -> Quat {
        let length = self.length_portable();
        let [x, y, z, w] = self.to_array();
        Quat::from_xyzw(x / length, y / length, z / length, w / length)
    }

    #[inline]
    fn from_rotation_arc_portable(from: Vec3, to: Vec3) -> Quat {
        // glam's, with its normalisation made portable.
        const ONE_MINUS_EPS: f32 = 1.0 - 2.0 * f32::EPSILON;
        let dot = from.dot(to);
        if dot > ONE_MINUS_EPS {
            Quat::IDENTITY
        } else if dot < -ONE_MINUS_EPS {
            // Half a turn about any axis normal to `from`: sin(pi/2) and
            // cos(pi/2) as f32 computes them (1 and -4.371139e-8), without
            // the platform's sin and cos.
            let axis = from.any_orthonormal_vector();
            let (s, c) = (1.0, -4.371_139e-8_f32);
            Quat::from_xyzw(axis.x * s, axis.y * s, axis.z * s, c)
        } else {
            let c = from.cross(to);
            Quat::from_xyzw(c.x, c.y, c.z, 1.0 + dot).normalize_portable()
        }
    }

    #[inline]
    fn from_axis_angle_portable(axis: Vec3, angle: f32) -> Quat {
        let (s, c) = crate::trig::sin_cos(angle * 0.5);
        let v = axis * s;
        Quat::from_xyzw(v.x, v.y, v.z, c)
    }

    #[inline]
    fn from_rotation_x_portable(angle: f32) -> Quat {
        let (s, c) = crate::trig::sin_cos(angle * 0.5);
        Quat::from_xyzw(s, 0.0, 0.0, c)
    }

    #[inline]
    fn from_rotation_y_portable(angle: f32) -> Quat {
        let (s, c) = crate::trig::sin_cos(angle * 0.5);
        Quat::from_xyzw(0.0, s, 0.0, c)
    }

    #[inline]
    fn slerp_portable(self, end: Quat, w: f32) -> Quat {
        let turn = self.conjugate().mul_portable(end);
        let turn = if turn.w < 0.0 { -turn } else { turn };
        let sin_half = turn.xyz().length();
        if sin_half == 0.0 {
            return self;
        }
        let angle = 2.0 * crate::trig::atan2(sin_half, turn.w);
        self.mul_portable(Quat::from_axis_angle_portable(
            turn.xyz() / sin_half,
            angle * w,
        ))
        .normalize_portable()
    }

    #[inline]
    fn angle_between_portable(self, rhs: Quat) -> f32 {
        let turn = self.conjugate().mul_portable(rhs);
        2.0 * crate::trig::atan2(turn.xyz().length(), turn.w.abs())
    }

    #[inline]
    fn turned_portable(self, w: Vec3, t: f32) -> Quat {
        let (axis, speed) = crate::Vec3::<f32>::from(w).normalize_or_zero();
        let turn = crate::Quat::<f32>::from_axis_angle(axis, speed * t);
        Quat::from(turn * self.into()).normalize_portable()
    }
}
