//! What one frame of a scene measured.

/// What one frame measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Frame {
    /// Sum over the ragdolls' joints of the linear error (cm): anchor
    /// separations, and the rod's `|C_len|`.
    pub eps_lin_cm: f32,
    /// Sum of the angular errors (rad): limit overshoot, and the rod's
    /// curve error.
    pub eps_ang_rad: f32,
    /// Controllability: summed distance of the bodies from the target (cm).
    pub deviation_cm: f32,
    /// Controllability: summed angle of the bodies from the target (rad).
    pub deviation_rad: f32,
    /// The largest limit violation of any one of the ragdolls' joints
    /// (rad): how far past its swing cone, twist or hinge range (the rod:
    /// its bend or twist limit), as in
    /// [`vertebra_world::JointResidual::limit_rad`].
    pub max_violation_rad: f32,
    /// The largest angular error of any one of the ragdolls' joints (rad):
    /// its limit violation plus the error of its held rotations (a
    /// hinge's angle between its axes, a fixed joint's angle, the rod's
    /// curve error), as in [`vertebra_world::JointResidual::angular_rad`].
    pub max_angular_error_rad: f32,
}
