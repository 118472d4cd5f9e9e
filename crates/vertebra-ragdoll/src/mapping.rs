//! Writing the simulation back onto the animation skeleton (paper section
//! 6). Bones with a body follow it; in a simplified ragdoll the spine's
//! interior bones have none and are placed by one of three modes.
//!
//! | mode | bone lengths | chain end on the top body | source |
//! | --- | --- | --- | --- |
//! | `Orientation` | kept exactly | misses when bent | the paper |
//! | `PositionOrientation` | change | exact | the paper |
//! | `Arc` | kept along the arc; straight-line length shrinks by the chord factor `sin(x/2)/(x/2)` of the bone's share `x` of the bend (0.5% at 20 degrees per bone) | exact (to the rod's residual) | beyond the paper |
//!
//! Fractions `s_k` along the spine are the bones' shares of the bind-pose
//! polyline through the chain's centres.

use glam::{Quat, Vec3};
use vertebra_world::World;

use crate::error::RagdollError;
use crate::pose::Pose;
use crate::ragdoll::{Ragdoll, SpineMode, rod_name};

/// How a simplified ragdoll's interior spine bones are placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SpineMapping {
    /// The bones turn by shares of the top body's rotation relative to the
    /// base, and hang from each other at their bind offsets.
    Orientation,
    /// As `Orientation`, then each bone also moves by its share of the gap
    /// between the chain's end and the top body.
    PositionOrientation,
    /// The bones sit on the rod's arc at their fractions of its length,
    /// turned by the arc's natural frame and their share of the twist.
    Arc,
}

impl Ragdoll {
    /// The pose of every animation bone, from the bodies in `world`.
    pub fn skeleton_pose(
        &self,
        world: &World,
        mapping: SpineMapping,
    ) -> Result<Pose, RagdollError> {
        let mut bones = vec![(Vec3::ZERO, Quat::IDENTITY); self.desc.bodies.len()];
        for ((bone, body), def) in bones.iter_mut().zip(&self.bodies).zip(&self.desc.bodies) {
            if let Some(h) = body {
                let s = world
                    .body(*h)
                    .map_err(|e| RagdollError::world(&format!("body `{}`", def.name), e))?;
                *bone = (s.position, s.orientation);
            }
        }
        if let (SpineMode::Rod, Some(spine)) = (self.options.spine, &self.desc.spine) {
            let chain = &spine.bodies;
            let centres: Vec<Vec3> = chain
                .iter()
                .map(|&b| self.desc.bodies[b].centre())
                .collect();
            let fractions = fractions(&centres);
            let placed = match mapping {
                SpineMapping::Orientation | SpineMapping::PositionOrientation => interpolated(
                    &centres,
                    &fractions,
                    bones[chain[0]],
                    bones[chain[chain.len() - 1]],
                    mapping == SpineMapping::PositionOrientation,
                ),
                SpineMapping::Arc => {
                    let rod = world
                        .rod(self.rod.expect("a simplified ragdoll has its rod"))
                        .map_err(|e| RagdollError::world(&rod_name(&self.desc), e))?;
                    on_arc(
                        &fractions,
                        bones[chain[0]],
                        bones[chain[chain.len() - 1]],
                        rod.frame_a,
                        rod.frame_b,
                    )
                }
            };
            for (k, &b) in chain.iter().enumerate().skip(1).take(chain.len() - 2) {
                bones[b] = placed[k];
            }
        }
        Ok(Pose { bones })
    }
}

/// Each point's share of the polyline's length, from 0 to 1.
fn fractions(points: &[Vec3]) -> Vec<f32> {
    let mut acc = vec![0.0f32];
    for pair in points.windows(2) {
        acc.push(acc.last().expect("started") + (pair[1] - pair[0]).length());
    }
    let total = acc.last().copied().unwrap_or(1.0).max(f32::MIN_POSITIVE);
    acc.iter().map(|a| a / total).collect()
}

/// The paper's two interpolation modes.
fn interpolated(
    centres: &[Vec3],
    s: &[f32],
    base: (Vec3, Quat),
    top: (Vec3, Quat),
    move_positions: bool,
) -> Vec<(Vec3, Quat)> {
    let relative = base.1.inverse() * top.1;
    let relative = if relative.w < 0.0 {
        -relative
    } else {
        relative
    };
    let mut placed = vec![base];
    for k in 1..centres.len() {
        let (p, q) = placed[k - 1];
        placed.push((
            p + q * (centres[k] - centres[k - 1]),
            base.1 * Quat::IDENTITY.slerp(relative, s[k]),
        ));
    }
    if move_positions {
        let gap = top.0 - placed[centres.len() - 1].0;
        for (k, bone) in placed.iter_mut().enumerate() {
            bone.0 += gap * s[k];
        }
    }
    placed
}

/// Bones on the rod's arc. With `F(0) = q_a F_a`, tangents `t_a`, `t_b`,
/// bend `psi` about `n`, the arc's length `L = |d| / (2 sin(psi/2)/psi)` and
/// `m = n x t_a`: `gamma(s) = p_a + L s (2 h(x) cos(x/2) t_a + 2 x h(x)^2 m)`,
/// `x = psi s`, `h(x) = sin(x/2)/x` (smooth at `psi = 0`). The frame at `s`
/// is `R(t(s), tau s) M(s) F(0) G(s)`, with `M(s)` the turn by `psi s` about
/// `n`, `tau` the rod's twist and `G(s)` from `F_a^-1` to `F_b^-1`: so the
/// ends are exactly the two bodies' orientations.
fn on_arc(
    s: &[f32],
    a: (Vec3, Quat),
    b: (Vec3, Quat),
    frame_a: Quat,
    frame_b: Quat,
) -> Vec<(Vec3, Quat)> {
    let h = |x: f32| vertebra_math::poly::half_sinc(x);
    let (f0, f1) = (a.1 * frame_a, b.1 * frame_b);
    let (ta, tb) = (f0 * Vec3::X, f1 * Vec3::X);
    let cross = ta.cross(tb);
    let psi = cross.length().atan2(ta.dot(tb));
    let n = cross.normalize_or_zero();
    let length = (b.0 - a.0).length() / (2.0 * h(psi));
    let tau = vertebra_world::rod_twist(f0, f1);
    let (ga, gb) = (frame_a.inverse(), frame_b.inverse());
    s.iter()
        .map(|&s| {
            let x = psi * s;
            let along = ta * (2.0 * h(x) * (x / 2.0).cos()) + n.cross(ta) * (2.0 * x * h(x) * h(x));
            let turn = if n == Vec3::ZERO {
                Quat::IDENTITY
            } else {
                Quat::from_axis_angle(n, x)
            };
            let twist = Quat::from_axis_angle(turn * ta, tau * s);
            (
                a.0 + along * (length * s),
                (twist * turn * f0 * ga.slerp(gb, s)).normalize(),
            )
        })
        .collect()
}
