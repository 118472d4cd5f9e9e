//! Every lane operation and polynomial on arbitrary floats.

use vertebra_math::check::backends_agree;
use vertebra_math::map::LaneMap;
use vertebra_math::{Lane, poly};

struct Everything;

impl LaneMap for Everything {
    const INPUTS: usize = 3;
    const OUTPUTS: usize = 12;
    #[inline(always)]
    fn apply<L: Lane>(&self, i: &[L], o: &mut [L]) {
        let (a, b, c) = (i[0], i[1], i[2]);
        let (s, co) = poly::sin_cos(a);
        let outputs = [
            s,
            co,
            poly::asin(a),
            poly::acos(a),
            poly::atan2(a, b),
            poly::half_sinc(a),
            (a + b) * c - a / b,
            a.sqrt().min(b).max(c),
            a.round().copysign(b),
            L::select(a.lt(b) | c.ge(a), a.abs(), -b),
            a.mul_add(b, c),
            a.clamp(b, c),
        ];
        o.copy_from_slice(&outputs);
    }
}

/// Arbitrary floats (little-endian, three columns) through every lane
/// operation and polynomial: each backend equals the scalar reference bit
/// for bit, and finite input gives finite output wherever the math defines
/// one.
pub fn math_backends(data: &[u8]) {
    let floats: Vec<f32> = data
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let n = floats.len() / 3;
    let columns: Vec<&[f32]> = floats.chunks_exact(n.max(1)).take(3).collect();
    if n == 0 || columns.len() < 3 {
        return;
    }
    let out = backends_agree(&Everything, &columns).unwrap_or_else(|m| panic!("{m}"));
    for k in 0..n {
        let (a, b) = (columns[0][k], columns[1][k]);
        if a.is_finite() {
            for (j, name) in [
                (0, "sin"),
                (1, "cos"),
                (2, "asin"),
                (3, "acos"),
                (5, "half_sinc"),
            ] {
                assert!(out[j][k].is_finite(), "{name}({a:e}) = {}", out[j][k]);
            }
            if b.is_finite() {
                assert!(out[4][k].is_finite(), "atan2({a:e}, {b:e})");
            }
        }
    }
}
