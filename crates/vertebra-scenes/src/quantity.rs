//! The quantities a frame measures, and a run's mean, peak and final value
//! of each.

use core::fmt;

use crate::{Frame, Scene, SceneRun};

/// One quantity of a [`Frame`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// Summed linear joint error (cm): figure 8's `eps_lin`.
    EpsLin,
    /// Summed angular joint error (rad): figure 8's `eps_ang`.
    EpsAng,
    /// Summed distance of the bodies from the target pose (cm): figure 7.
    DeviationCm,
    /// Summed angle of the bodies from the target pose (rad): figure 7.
    DeviationRad,
    /// The largest limit violation of any one joint (rad).
    MaxViolation,
    /// The largest angular error of any one joint (rad): limit violation
    /// plus the held rotations' error.
    MaxAngularError,
}

impl Quantity {
    /// Every quantity, in the order of [`Frame`]'s fields.
    pub const ALL: [Quantity; 6] = [
        Quantity::EpsLin,
        Quantity::EpsAng,
        Quantity::DeviationCm,
        Quantity::DeviationRad,
        Quantity::MaxViolation,
        Quantity::MaxAngularError,
    ];

    /// The quantity's value in `frame`.
    pub fn of(self, frame: &Frame) -> f32 {
        match self {
            Quantity::EpsLin => frame.eps_lin_cm,
            Quantity::EpsAng => frame.eps_ang_rad,
            Quantity::DeviationCm => frame.deviation_cm,
            Quantity::DeviationRad => frame.deviation_rad,
            Quantity::MaxViolation => frame.max_violation_rad,
            Quantity::MaxAngularError => frame.max_angular_error_rad,
        }
    }

    /// The field name with its unit, as in the CSV and JSON files
    /// (`eps_lin_cm`, ...).
    pub fn key(self) -> &'static str {
        match self {
            Quantity::EpsLin => "eps_lin_cm",
            Quantity::EpsAng => "eps_ang_rad",
            Quantity::DeviationCm => "deviation_cm",
            Quantity::DeviationRad => "deviation_rad",
            Quantity::MaxViolation => "max_violation_rad",
            Quantity::MaxAngularError => "max_angular_error_rad",
        }
    }

    /// The two quantities a scene's figure compares: the joint errors
    /// (figure 8), or for controllability the deviation from the target
    /// pose (figure 7).
    pub fn compared(scene: Scene) -> [Quantity; 2] {
        match scene {
            Scene::Controllability | Scene::HitReaction => {
                [Quantity::DeviationCm, Quantity::DeviationRad]
            }
            _ => [Quantity::EpsLin, Quantity::EpsAng],
        }
    }
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.key())
    }
}

/// A run's mean, largest and final value of one quantity.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Mean over the frames.
    pub mean: f32,
    /// Largest frame.
    pub max: f32,
    /// The last frame.
    pub last: f32,
}

impl SceneRun {
    /// `quantity`'s mean, largest and final value over this run.
    pub fn stats(&self, quantity: Quantity) -> Stats {
        let values = self.frames.iter().map(|f| quantity.of(f));
        Stats {
            mean: values.clone().sum::<f32>() / self.frames.len().max(1) as f32,
            max: values.fold(0.0, f32::max),
            last: self.frames.last().map_or(0.0, |f| quantity.of(f)),
        }
    }
}
