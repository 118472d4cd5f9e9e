//! Reading fuzz bytes as the values the targets need.

use arbitrary::Unstructured;
use glam::{Quat, Vec3};

/// Fuzz bytes as floats: each float either any bit pattern (NaN, infinity,
/// subnormals: "wild") or a tame value in `[-scale, scale]`.
pub struct Input<'a> {
    u: Unstructured<'a>,
    /// Whether any wild value was handed out.
    pub wild: bool,
}

impl<'a> Input<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Self {
            u: Unstructured::new(data),
            wild: false,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.u.is_empty()
    }

    /// An integer in `0..n` (0 once the bytes run out).
    pub fn pick(&mut self, n: usize) -> usize {
        self.u.choose_index(n.max(1)).unwrap_or(0)
    }

    pub fn flag(&mut self) -> bool {
        self.u.arbitrary().unwrap_or(false)
    }

    /// Wild one time in eight, else tame in `[-scale, scale]`.
    pub fn float(&mut self, scale: f32) -> f32 {
        if self.pick(8) == 0 {
            self.wild = true;
            f32::from_bits(self.u.arbitrary().unwrap_or(0))
        } else {
            self.tame(scale)
        }
    }

    /// Always tame: `[-scale, scale]` in 65536 steps.
    pub fn tame(&mut self, scale: f32) -> f32 {
        let k: u16 = self.u.arbitrary().unwrap_or(0);
        scale * (f32::from(k) / 32767.5 - 1.0)
    }

    /// A positive tame value in `(0, scale]`.
    pub fn positive(&mut self, scale: f32) -> f32 {
        self.tame(scale).abs().max(scale * 1e-4)
    }

    pub fn vec3(&mut self, scale: f32) -> Vec3 {
        Vec3::new(self.float(scale), self.float(scale), self.float(scale))
    }

    /// A unit quaternion, or (one time in eight) four arbitrary floats.
    pub fn quat(&mut self) -> Quat {
        if self.pick(8) == 0 {
            self.wild = true;
            Quat::from_xyzw(
                self.float(2.0),
                self.float(2.0),
                self.float(2.0),
                self.float(2.0),
            )
        } else {
            let q = Quat::from_xyzw(
                self.tame(1.0),
                self.tame(1.0),
                self.tame(1.0),
                self.tame(1.0),
            );
            if q.length_squared() > 1e-6 {
                q.normalize()
            } else {
                Quat::IDENTITY
            }
        }
    }
}
