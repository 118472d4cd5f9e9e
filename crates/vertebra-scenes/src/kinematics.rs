//! Figure 6: where the end of the spine can go, a rod against chains of
//! sockets, in the plane of bending (kinematics only).

use vertebra_math::trig;

/// End-point loci in the bending plane (m): x forward, y up from the base.
#[derive(Clone, Debug, PartialEq)]
pub struct Locus {
    /// The rod's end for bends from 0 to the limit.
    pub rod: Vec<[f32; 2]>,
    /// `(name, points, largest gap to the rod's end at the same total bend)`
    /// for chains of 2, 3, 4 and 8 equal-angle sockets and one chain whose
    /// angles are shared 60/30/10.
    pub chains: Vec<(String, Vec<[f32; 2]>, f32)>,
}

/// The end of a chain of links of `length / n` whose joints turn by
/// `angles` (rad), each link turned by its joints' half-turns either side,
/// as the arc's tangent turns along it.
fn chain_end(length: f32, angles: &[f32]) -> [f32; 2] {
    let n = angles.len() as f32;
    let (mut heading, mut x, mut y) = (0.0f32, 0.0f32, 0.0f32);
    for &a in angles {
        heading += a / 2.0;
        x += trig::sin(heading) * length / n;
        y += trig::cos(heading) * length / n;
        heading += a / 2.0;
    }
    [x, y]
}

/// The loci for a spine of `length` (m) bent up to `limit` (rad), sampled
/// at `samples` bends.
pub fn kinematics(length: f32, limit: f32, samples: usize) -> Locus {
    let bends: Vec<f32> = (0..samples)
        .map(|k| limit * k as f32 / (samples - 1).max(1) as f32)
        .collect();
    let rod: Vec<[f32; 2]> = bends
        .iter()
        .map(|&psi| {
            let chord = 2.0 * length * vertebra_math::poly::half_sinc(psi);
            [chord * trig::sin(psi / 2.0), chord * trig::cos(psi / 2.0)]
        })
        .collect();
    let mut chains = Vec::new();
    let shapes: Vec<(String, Vec<f32>)> = [2usize, 3, 4, 8]
        .into_iter()
        .map(|n| (format!("{n} equal sockets"), vec![1.0 / n as f32; n]))
        .chain(std::iter::once((
            "3 sockets 60/30/10".to_owned(),
            vec![0.6, 0.3, 0.1],
        )))
        .collect();
    for (name, shares) in shapes {
        let points: Vec<[f32; 2]> = bends
            .iter()
            .map(|&psi| chain_end(length, &shares.iter().map(|s| s * psi).collect::<Vec<_>>()))
            .collect();
        let gap = points
            .iter()
            .zip(&rod)
            .map(|(p, r)| ((p[0] - r[0]).powi(2) + (p[1] - r[1]).powi(2)).sqrt())
            .fold(0.0, f32::max);
        chains.push((name, points, gap));
    }
    Locus { rod, chains }
}
