//! How a [`JointDesc`] is encoded (snapshots, the state hash): its bodies,
//! anchors and frames, then its kind, then its drive, the last two as
//! postcard enums (the variant's index, then its fields).
//!
//! The kind: a socket with hard limits and no swing limit is variant 0
//! (its twist range), one with a hard circular cone variant 1 (the cone's
//! half-angle, then the twist range), and every other kind variant 2 (the
//! whole [`JointKind`]). The drive: none is variant 0, a drive variant 1,
//! and breaking thresholds, with the drive if any, variant 2. So the plain
//! socket, the commonest joint, is a few bytes without a [`JointKind`]'s
//! tags and fields.
//!
//! The encoding is part of the state hash, which the golden hashes of
//! `crates/vertebra-scenes/tests/golden.rs` hold: a new kind or field is
//! encoded after the variants there are, so the bytes of every joint that
//! does not use it stay as they are.
//!
//! A [`LimitSoftness`] is one enum of three variants on the wire: `Hard`
//! (0), a compliance and damping (1), a frequency and damping ratio (2);
//! not `Soft` (1) with the [`Spring`]'s own tag after it, so a soft limit
//! is the same few bytes as every other tagged value of the encoding. A
//! drive's strength, a `Spring`, keeps its own two tags (compliance 0,
//! frequency 1).

use glam::{Quat, Vec3};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use vertebra_store::BodyHandle;

use crate::drive::AngularDrive;
use crate::joint::{JointBreaking, JointDesc, JointKind, LimitSoftness, Swing, SwingTwist};
use crate::spring::Spring;

#[derive(Serialize, Deserialize)]
pub(crate) struct JointWire {
    body_a: BodyHandle,
    body_b: BodyHandle,
    anchor_a: Vec3,
    anchor_b: Vec3,
    frame_a: Quat,
    frame_b: Quat,
    kind: KindWire,
    drive: DriveWire,
}

#[derive(Serialize, Deserialize)]
enum DriveWire {
    /// No drive, no thresholds (an `Option`'s `None`).
    Free,
    /// A drive, no thresholds (an `Option`'s `Some`).
    Driven(AngularDrive),
    /// Breaking thresholds, with the drive if any.
    Breaking(Option<AngularDrive>, JointBreaking),
}

#[derive(Serialize, Deserialize)]
enum KindWire {
    /// A plain socket without a swing limit, with its twist range.
    FreeSocket(Option<[f32; 2]>),
    /// A plain socket's cone half-angle and twist range.
    ConeSocket(f32, Option<[f32; 2]>),
    /// Any other kind.
    Kind(JointKind),
}

impl From<JointKind> for KindWire {
    fn from(kind: JointKind) -> Self {
        match kind {
            JointKind::Socket(SwingTwist {
                swing: Swing::Free,
                twist,
                softness: LimitSoftness::Hard,
            }) => Self::FreeSocket(twist),
            JointKind::Socket(SwingTwist {
                swing: Swing::Cone(half),
                twist,
                softness: LimitSoftness::Hard,
            }) => Self::ConeSocket(half, twist),
            other => Self::Kind(other),
        }
    }
}

impl From<KindWire> for JointKind {
    fn from(wire: KindWire) -> Self {
        let plain = |swing, twist| {
            JointKind::Socket(SwingTwist {
                swing,
                twist,
                softness: LimitSoftness::Hard,
            })
        };
        match wire {
            KindWire::FreeSocket(twist) => plain(Swing::Free, twist),
            KindWire::ConeSocket(half, twist) => plain(Swing::Cone(half), twist),
            KindWire::Kind(kind) => kind,
        }
    }
}

impl From<JointDesc> for JointWire {
    fn from(d: JointDesc) -> Self {
        Self {
            body_a: d.body_a,
            body_b: d.body_b,
            anchor_a: d.anchor_a,
            anchor_b: d.anchor_b,
            frame_a: d.frame_a,
            frame_b: d.frame_b,
            kind: d.kind.into(),
            drive: match (d.drive, d.breaking) {
                (None, None) => DriveWire::Free,
                (Some(drive), None) => DriveWire::Driven(drive),
                (drive, Some(breaking)) => DriveWire::Breaking(drive, breaking),
            },
        }
    }
}

impl From<JointWire> for JointDesc {
    fn from(w: JointWire) -> Self {
        let (drive, breaking) = match w.drive {
            DriveWire::Free => (None, None),
            DriveWire::Driven(drive) => (Some(drive), None),
            DriveWire::Breaking(drive, breaking) => (drive, Some(breaking)),
        };
        Self {
            body_a: w.body_a,
            body_b: w.body_b,
            anchor_a: w.anchor_a,
            anchor_b: w.anchor_b,
            frame_a: w.frame_a,
            frame_b: w.frame_b,
            kind: w.kind.into(),
            drive,
            breaking,
        }
    }
}

/// Serde's traits for `$ty`, through its wire form `$wire` (`From` each
/// way).
macro_rules! through_wire {
    ($ty:ty, $wire:ty) => {
        impl Serialize for $ty {
            fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                <$wire>::from(*self).serialize(serializer)
            }
        }

        impl<'de> Deserialize<'de> for $ty {
            fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                <$wire>::deserialize(deserializer).map(Self::from)
            }
        }
    };
}

through_wire!(JointDesc, JointWire);
through_wire!(LimitSoftness, SoftnessWire);

/// A [`LimitSoftness`] as it is encoded: the spring's variants beside
/// `Hard`, field for field.
#[derive(Serialize, Deserialize)]
enum SoftnessWire {
    Hard,
    Compliance { compliance: f32, damping: f32 },
    Spring { frequency: f32, damping_ratio: f32 },
}

impl From<LimitSoftness> for SoftnessWire {
    fn from(s: LimitSoftness) -> Self {
        match s {
            LimitSoftness::Hard => Self::Hard,
            LimitSoftness::Soft(Spring::Compliance {
                compliance,
                damping,
            }) => Self::Compliance {
                compliance,
                damping,
            },
            LimitSoftness::Soft(Spring::Frequency {
                frequency,
                damping_ratio,
            }) => Self::Spring {
                frequency,
                damping_ratio,
            },
        }
    }
}

impl From<SoftnessWire> for LimitSoftness {
    fn from(w: SoftnessWire) -> Self {
        match w {
            SoftnessWire::Hard => Self::Hard,
            SoftnessWire::Compliance {
                compliance,
                damping,
            } => Self::Soft(Spring::Compliance {
                compliance,
                damping,
            }),
            SoftnessWire::Spring {
                frequency,
                damping_ratio,
            } => Self::Soft(Spring::Frequency {
                frequency,
                damping_ratio,
            }),
        }
    }
}
