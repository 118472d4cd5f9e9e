//! The joints' largest separation, for tests that step a ragdoll.

use vertebra_world::World;

/// The largest joint separation (cm) at the current poses, sockets and rod.
pub fn worst_separation(w: &mut World) -> f32 {
    let r = w.measure_residuals();
    let sockets = r.joints.iter().map(|j| j.linear_cm);
    sockets
        .chain(r.rods.iter().map(|j| j.linear_cm))
        .fold(0.0, f32::max)
}
