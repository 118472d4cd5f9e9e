//! A walking animation for the anatomical humanoid: [`Gait`]'s timing
//! turned into a pose at any time. The legs reach their feet by two-bone
//! inverse kinematics (hip and knee), so a planted foot stays where it is
//! while the hips pass over it (on a leg with an ankle the foot is kept
//! flat and ahead); the arms swing against the legs, the shoulders turn
//! against the hips, and the head keeps looking ahead.

use glam::{Quat, Vec3};
use vertebra_math::{DefaultFloatMode, PortableQuat, trig};
use vertebra_ragdoll::{Pose, RagdollDesc, RagdollError};

use crate::gait::Gait;

/// The anatomical humanoid walking along +Z: standing at its bind pose
/// before the start, then [`Gait`]'s walk. Every pose is placed by one
/// fixed turn and offset ([`Walk::placed`]), so a seeded start walks the
/// same walk moved.
#[derive(Clone, Debug)]
pub struct Walk {
    /// The timing.
    pub gait: Gait,
    /// When the walk starts (s): the bind pose before (infinity: it stands
    /// throughout).
    pub start: f32,
    joints: Joints,
    root_bind: Vec3,
    /// Per leg (left, right): the hip's anchor from the hips' centre, the
    /// foot (the ankle's pivot, or without ankles the end of the shin's
    /// capsule segment, the centre of the round end it stands on), the
    /// thigh's length (hip to knee), the shin's (knee to foot).
    legs: [Leg; 2],
    turn: Quat,
    offset: Vec3,
}

#[derive(Clone, Copy, Debug)]
struct Leg {
    hip: Vec3,
    foot: Vec3,
    thigh: f32,
    shin: f32,
}

/// The joints the walk moves, by index.
#[derive(Clone, Debug)]
struct Joints {
    count: usize,
    hips: [usize; 2],
    knees: [usize; 2],
    /// `ankle_l` and `ankle_r`, when the description has both.
    ankles: Option<[usize; 2]>,
    shoulders: [usize; 2],
    elbows: [usize; 2],
    spine: Vec<usize>,
    neck: usize,
}

impl Walk {
    /// `gait` on `desc`, starting at `start` (s), the bind pose standing at
    /// the origin with its hips at their bind place. Refused when `desc`
    /// lacks a joint the walk moves (the anatomical humanoid's `hip_l`,
    /// `knee_l`, `shoulder_l`, `elbow_l`, their right twins, `spine_1` to
    /// `spine_3` and `neck`), or when a leg's joints are not one chain (a
    /// knee's parent body must be its hip's child). With `ankle_l` and
    /// `ankle_r` (feet below the shins: each ankle's parent is its knee's
    /// child, or it is refused, as is one ankle without the other) the
    /// legs reach the ankles, the ankles keep the feet flat and ahead, and
    /// a planted foot does not roll (`gait.foot_radius` is taken as 0).
    pub fn new(desc: &RagdollDesc, mut gait: Gait, start: f32) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let joint = |name: &str| {
            desc.joint_index(name).ok_or_else(|| {
                RagdollError::BadPose(format!(
                    "the walk moves joint `{name}` (the anatomical humanoid's); `{}` has none",
                    desc.name
                ))
            })
        };
        let pair = |stem: &str| -> Result<[usize; 2], RagdollError> {
            Ok([joint(&format!("{stem}_l"))?, joint(&format!("{stem}_r"))?])
        };
        let ankles = match ["ankle_l", "ankle_r"].map(|name| desc.joint_index(name)) {
            [Some(l), Some(r)] => Some([l, r]),
            [None, None] => None,
            _ => {
                return Err(RagdollError::BadPose(format!(
                    "the walk reaches both ankles (`ankle_l`, `ankle_r`) or neither; `{}` has one",
                    desc.name
                )));
            }
        };
        let joints = Joints {
            count: desc.joints.len(),
            hips: pair("hip")?,
            knees: pair("knee")?,
            ankles,
            shoulders: pair("shoulder")?,
            elbows: pair("elbow")?,
            spine: ["spine_1", "spine_2", "spine_3"]
                .into_iter()
                .map(joint)
                .collect::<Result<_, _>>()?,
            neck: joint("neck")?,
        };
        for side in 0..2 {
            chained(desc, joints.hips[side], joints.knees[side])?;
            if let Some(ankles) = joints.ankles {
                chained(desc, joints.knees[side], ankles[side])?;
            }
        }
        let root_bind = desc.bodies[desc.root].centre();
        let leg = |side: usize| {
            let (hip, knee) = (
                &desc.joints[joints.hips[side]],
                &desc.joints[joints.knees[side]],
            );
            let shin = &desc.bodies[knee.child];
            // The ankle, or the end of the shin's segment farther from the
            // knee.
            let [a, b] = shin.segment;
            let far = if (a - knee.anchor).length() > (b - knee.anchor).length() {
                a
            } else {
                b
            };
            let foot = joints
                .ankles
                .map_or(far, |ankles| desc.joints[ankles[side]].anchor);
            Leg {
                hip: hip.anchor - root_bind,
                foot,
                thigh: (knee.anchor - hip.anchor).length(),
                shin: (foot - knee.anchor).length(),
            }
        };
        let legs = [leg(0), leg(1)];
        if joints.ankles.is_some() {
            gait.foot_radius = 0.0;
        }
        Ok(Self {
            gait,
            start,
            joints,
            root_bind,
            legs,
            turn: Quat::IDENTITY,
            offset: Vec3::ZERO,
        })
    }

    /// This walk with every pose turned by `turn` about the hips' bind
    /// place, then moved by `offset` (world).
    pub fn placed(mut self, turn: Quat, offset: Vec3) -> Self {
        self.turn = turn;
        self.offset = offset;
        self
    }

    /// The hips' place in [`Walk::pose`] at `t` (s), without building the
    /// pose.
    pub fn hips(&self, t: f32) -> Vec3 {
        let _mode = DefaultFloatMode::enter();
        let (root, _) = self.root(t - self.start);
        self.place(root)
    }

    /// The pose at `t` (s).
    pub fn pose(&self, desc: &RagdollDesc, t: f32) -> Result<Pose, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        let g = &self.gait;
        let t = t - self.start;
        let (root, hips_turn) = self.root(t);
        let mut rotations = vec![Quat::IDENTITY; self.joints.count];
        for side in 0..2 {
            let leg = &self.legs[side];
            let foot = g.foot(side, t);
            let at = leg.foot + Vec3::new(0.0, foot.lift, foot.forward);
            let hip = root + hips_turn * leg.hip;
            let (thigh, knee) = reach(hip, at, hips_turn * Vec3::X, leg.thigh, leg.shin);
            let knee = Quat::from_rotation_x_portable(knee);
            rotations[self.joints.hips[side]] = hips_turn.conjugate().mul_portable(thigh);
            rotations[self.joints.knees[side]] = knee;
            if let Some(ankles) = self.joints.ankles {
                // The foot flat and ahead: the shin's turn undone.
                rotations[ankles[side]] = thigh.mul_portable(knee).conjugate();
            }
        }
        let grown = g.speed_fraction(t);
        let (_, _, turn) = g.hips(t);
        // The shoulders turn half as far the other way; the head looks
        // ahead again.
        let n = self.joints.spine.len() as f32;
        let spine = Quat::from_rotation_y_portable(-1.5 * turn / n);
        for &j in &self.joints.spine {
            rotations[j] = spine;
        }
        rotations[self.joints.neck] = Quat::from_rotation_y_portable(0.5 * turn);
        // Each arm swings with the other side's leg.
        let swing = g.arms(t);
        for (side, forward) in [(0, swing), (1, -swing)] {
            rotations[self.joints.shoulders[side]] = Quat::from_rotation_x_portable(-forward);
            let bend = grown * (g.elbow + 0.5 * forward.max(0.0));
            rotations[self.joints.elbows[side]] = Quat::from_rotation_x_portable(-bend);
        }
        let pose = Pose::from_joint_rotations(desc, (root, hips_turn), &rotations)?;
        Ok(pose.moved(self.root_bind, self.turn, self.offset))
    }

    /// The hips' centre and orientation at `t` (s since the start), before
    /// the placement.
    fn root(&self, t: f32) -> (Vec3, Quat) {
        let g = &self.gait;
        let (side, up, turn) = g.hips(t);
        let at = self.root_bind + Vec3::new(side, up, g.distance(t));
        let lean = g.speed_fraction(t) * g.lean;
        let orientation =
            Quat::from_rotation_y_portable(turn).mul_portable(Quat::from_rotation_x_portable(lean));
        (at, orientation)
    }

    fn place(&self, at: Vec3) -> Vec3 {
        self.root_bind + self.turn * (at - self.root_bind) + self.offset
    }
}

/// Two-bone inverse kinematics: the thigh's orientation (world) and the
/// knee's bend (rad, about the thigh's +X, which turns the shin back)
/// that put the foot at `foot` from a hip at `hip`, the knee bending
/// forward about `lateral` (the hips' +X). Out of reach, the leg is
/// straight toward the foot (as it is at the bind pose: the walk's
/// standing start is the bind pose exactly).
fn reach(hip: Vec3, foot: Vec3, lateral: Vec3, thigh: f32, shin: f32) -> (Quat, f32) {
    let to = foot - hip;
    let length = to.length();
    let down = to / length;
    // Within rounding of full reach the law of cosines loses the angles
    // (they go as the square root of the shortfall): straight. Otherwise
    // the knee's bend and the thigh's angle from the line to the foot.
    let (ahead, knee) = if length >= (thigh + shin) * (1.0 - 1e-6) {
        (0.0, 0.0)
    } else {
        let d = length.max((thigh - shin).abs() + 1e-4);
        let inner = acos((thigh * thigh + shin * shin - d * d) / (2.0 * thigh * shin));
        let ahead = acos((thigh * thigh + d * d - shin * shin) / (2.0 * thigh * d));
        (ahead, core::f32::consts::PI - inner)
    };
    let knee_axis = (lateral - down * down.dot(lateral)).normalize();
    let along = Quat::from_axis_angle_portable(knee_axis, -ahead) * down;
    // Down the thigh, with its +X on the knee's axis.
    let arc = Quat::from_rotation_arc_portable(Vec3::NEG_Y, along);
    let x = arc * Vec3::X;
    let twist = trig::atan2(x.cross(knee_axis).dot(along), x.dot(knee_axis));
    let thigh_turn = Quat::from_axis_angle_portable(along, twist)
        .mul_portable(arc)
        .normalize_portable();
    (thigh_turn, knee)
}

fn acos(c: f32) -> f32 {
    let c = c.clamp(-1.0, 1.0);
    trig::atan2((1.0 - c * c).max(0.0).sqrt(), c)
}

/// Refuses, naming both joints, a leg whose joint `lower` does not hang
/// from joint `upper`'s child body.
fn chained(desc: &RagdollDesc, upper: usize, lower: usize) -> Result<(), RagdollError> {
    let (upper, lower) = (&desc.joints[upper], &desc.joints[lower]);
    if lower.parent == upper.child {
        return Ok(());
    }
    Err(RagdollError::BadPose(format!(
        "the walk bends joint `{}` below `{}`, but its parent body `{}` is not `{}`'s child `{}`",
        lower.name,
        upper.name,
        desc.bodies[lower.parent].name,
        upper.name,
        desc.bodies[upper.child].name
    )))
}
