//! Bodies as the kernels see them: three rows of eight floats per body,
//! gathered by index into lanes.
//!
//! | row | floats |
//! | --- | --- |
//! | pose | `p.x p.y p.z inv_mass q.x q.y q.z q.w` (m, 1/kg, unit quaternion) |
//! | inertia | `S.xx S.yy S.zz S.xy S.xz S.yz 0 0`: inverse inertia, body frame (1/(kg m^2)) |
//! | velocity | `v.x v.y v.z 0 w.x w.y w.z 0` (m/s, rad/s, world) |
//!
//! `p` is the body's *displacement* since the step began, not its
//! coordinate: everything the kernels compute from positions is a
//! difference between two bodies, and [`PairStart`] holds each pair's
//! difference at the start of the step, measured once in double precision.
//! So a correction or a velocity `dp / h` keeps the f32 precision of the
//! motion, however far from the origin the bodies are (Box2D v3 keeps a
//! per-body delta position for the same reason).
//!
//! Row 0 of every table is the *null row*: identity pose, zero inverse mass
//! and inertia. Padding lanes read it and write nothing, so they do nothing.
//! A body in slot `i` of the store has row `i + 1`.
//!
//! Generalised inverse masses (Müller et al. 2020, eqs. 2-3): a positional
//! correction along unit `n` at lever arm `r` sees
//! `w = 1/m + (r x n)^T I^-1 (r x n)`, a rotational one about `n` sees
//! `w = n^T I^-1 n`, with `I^-1 = R S R^T` the world-space inverse inertia.

use bytemuck::{Pod, Zeroable};
use vertebra_math::block::{BLOCK_LANES, Vec3Block};
use vertebra_math::row::{NO_WRITE, ROW_LEN, Row};
use vertebra_math::{Lane, Quat, Sym3, Vec3};

/// The solver's copy of every body, as rows.
#[derive(Clone, Debug, Default)]
pub struct BodyRows {
    /// Pose rows.
    pub pose: Vec<Row>,
    /// Inverse-inertia rows.
    pub inertia: Vec<Row>,
    /// Velocity rows.
    pub velocity: Vec<Row>,
}

impl BodyRows {
    /// Tables for `bodies` bodies plus the null row.
    pub fn with_bodies(bodies: usize) -> Self {
        let null_pose = Row::new([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
        let mut rows = Self {
            pose: vec![null_pose],
            inertia: vec![Row::default()],
            velocity: vec![Row::default()],
        };
        rows.pose.resize(
            bodies + 1,
            Row::new([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
        );
        rows.inertia.resize(bodies + 1, Row::default());
        rows.velocity.resize(bodies + 1, Row::default());
        rows
    }

    /// Tables from plain rows (pose, inverse inertia, velocity per body;
    /// entry 0 is the null row), as tests and fuzzing build them.
    pub fn from_raw(raw: &[[[f32; ROW_LEN]; 3]]) -> Self {
        let rows = Self::with_bodies(raw.len().saturating_sub(1));
        for (i, [pose, inertia, velocity]) in raw.iter().enumerate() {
            rows.pose[i].set(*pose);
            rows.inertia[i].set(*inertia);
            rows.velocity[i].set(*velocity);
        }
        rows
    }

    /// The null body's plain rows: at the origin, unrotated, no mass.
    pub fn null_raw() -> [[f32; ROW_LEN]; 3] {
        [
            Self::pose_row(glam::Vec3::ZERO, 0.0, glam::Quat::IDENTITY),
            [0.0; ROW_LEN],
            [0.0; ROW_LEN],
        ]
    }

    /// Packs a pose row.
    pub fn pose_row(
        position: glam::Vec3,
        inverse_mass: f32,
        orientation: glam::Quat,
    ) -> [f32; ROW_LEN] {
        let (p, q) = (position, orientation);
        [p.x, p.y, p.z, inverse_mass, q.x, q.y, q.z, q.w]
    }

    /// Packs an inverse-inertia row from a symmetric body-frame matrix.
    pub fn inertia_row(m: glam::Mat3) -> [f32; ROW_LEN] {
        [
            m.x_axis.x, m.y_axis.y, m.z_axis.z, m.y_axis.x, m.z_axis.x, m.z_axis.y, 0.0, 0.0,
        ]
    }

    /// Packs a velocity row.
    pub fn velocity_row(linear: glam::Vec3, angular: glam::Vec3) -> [f32; ROW_LEN] {
        [
            linear.x, linear.y, linear.z, 0.0, angular.x, angular.y, angular.z, 0.0,
        ]
    }
}

/// One body per lane: pose and body-frame inverse inertia.
#[derive(Clone, Copy, Debug)]
pub struct BodyLanes<L> {
    /// Displacement of the centre of mass since the step began (m, world).
    pub p: Vec3<L>,
    /// Inverse mass (1/kg).
    pub inv_mass: L,
    /// Orientation.
    pub q: Quat<L>,
    /// Inverse inertia, body frame.
    pub inv_inertia: Sym3<L>,
}

impl<L: Lane> BodyLanes<L> {
    /// Gathers the pose and inertia rows of `indices` (`L::WIDTH` of them).
    #[inline(always)]
    pub fn gather(rows: &BodyRows, indices: &[u32]) -> Self {
        let [px, py, pz, inv_mass, qx, qy, qz, qw] = L::gather_rows(&rows.pose, indices);
        let [xx, yy, zz, xy, xz, yz, _, _] = L::gather_rows(&rows.inertia, indices);
        let inv_inertia = Sym3::from_entries([xx, yy, zz, xy, xz, yz]);
        Self {
            p: Vec3::new(px, py, pz),
            inv_mass,
            q: Quat::new(qx, qy, qz, qw),
            inv_inertia,
        }
    }

    /// Writes the pose back to the rows named by `write` (`NO_WRITE` lanes
    /// are skipped).
    #[inline(always)]
    pub fn scatter_pose(&self, rows: &BodyRows, write: &[u32]) {
        let (p, q) = (self.p, self.q);
        L::scatter_rows(
            &[p.x, p.y, p.z, self.inv_mass, q.x, q.y, q.z, q.w],
            &rows.pose,
            write,
        );
    }

    /// `I^-1 v` with the world-space inverse inertia `R S R^T`.
    #[inline(always)]
    pub fn inv_inertia_mul(&self, v: Vec3<L>) -> Vec3<L> {
        self.q
            .rotate(self.inv_inertia.mul_vec(self.q.inverse_rotate(v)))
    }

    /// How this body answers a rotational correction about the world axis
    /// `n`: `u = R^T n` (the axis in the body frame), `S u` and
    /// `n^T I^-1 n = u . S u` (see [`Response`]).
    #[inline(always)]
    pub fn angular_response(&self, n: Vec3<L>) -> Response<L> {
        self.local_response(self.q.inverse_rotate(n))
    }

    /// As [`BodyLanes::angular_response`], for an axis `u` already in the
    /// body's own frame: `S u` and `u . S u`, with no rotation.
    #[inline(always)]
    pub fn local_response(&self, u: Vec3<L>) -> Response<L> {
        let turn = self.inv_inertia.mul_vec(u);
        Response {
            weight: u.dot(turn),
            turn,
        }
    }

    /// `1/m + (r x n)^T I^-1 (r x n)`: the generalised inverse mass of a
    /// positional correction along `n` at lever arm `r`.
    #[inline(always)]
    pub fn positional_weight(&self, r: Vec3<L>, n: Vec3<L>) -> L {
        self.positional_response(r, n).weight
    }

    /// How this body answers a positional correction along `n` at lever
    /// arm `r`: the angular response to `r x n`, with the weight
    /// `1/m + (r x n)^T I^-1 (r x n)`.
    #[inline(always)]
    pub fn positional_response(&self, r: Vec3<L>, n: Vec3<L>) -> Response<L> {
        let angular = self.angular_response(r.cross(n));
        Response {
            weight: self.inv_mass + angular.weight,
            ..angular
        }
    }

    /// Applies the positional impulse `dlambda n` (kg m) whose
    /// [`BodyLanes::positional_response`] is `response`:
    /// `p += dlambda n / m`, turned by `R (S R^T (r x n)) dlambda`.
    #[inline(always)]
    pub fn push(&mut self, n: Vec3<L>, response: &Response<L>, dlambda: L) {
        self.p += n.scale(dlambda * self.inv_mass);
        self.turn_local(response.turn, dlambda);
    }

    /// Applies a positional impulse `impulse` (kg m) at lever arm `r`:
    /// `p += impulse / m`, turned by `I^-1 (r x impulse)`.
    #[inline(always)]
    pub fn apply_impulse(&mut self, r: Vec3<L>, impulse: Vec3<L>) {
        self.p += impulse.scale(self.inv_mass);
        self.apply_angular_impulse(r.cross(impulse));
    }

    /// Turns the body by `I^-1 l` for the angular impulse `l` (kg m^2,
    /// world): `S R^T l` in its own frame ([`BodyLanes::turn_local`]).
    #[inline(always)]
    pub fn apply_angular_impulse(&mut self, l: Vec3<L>) {
        let turn = self.inv_inertia.mul_vec(self.q.inverse_rotate(l));
        self.turn_local(turn, L::splat(1.0));
    }

    /// Turns the body by the small rotation vector `theta = axis angle`
    /// (rad) given in its own frame: `q += 1/2 q (theta, 0)`,
    /// renormalised, which is `q += 1/2 (R theta, 0) q`: the world turn
    /// `R theta` ([`Quat::integrate_local`]).
    #[inline(always)]
    pub fn turn_local(&mut self, axis: Vec3<L>, angle: L) {
        self.q = self.q.integrate_local(axis, angle);
    }
}

/// One body's answer to a unit correction (Müller et al. 2020, eqs. 2-3):
/// the generalised inverse mass `w` and the turn per unit `dlambda` in the
/// body's own frame, `S R^T j` for the angular direction `j` (`n`, or
/// `r x n` for a positional one). The weight is `j^T R S R^T j =
/// (R^T j) . (S R^T j)`, so the one rotation of `j` into the body gives
/// both the weight and the turn, and the turn is applied in the body frame
/// (`q += 1/2 q (turn dlambda, 0)`), so it is never rotated back.
#[derive(Clone, Copy, Debug)]
pub struct Response<L> {
    /// `w` (1/kg for a positional correction, 1/(kg m^2) for a rotation).
    pub weight: L,
    /// `S R^T j` (rad per unit `dlambda`, body frame).
    pub turn: Vec3<L>,
}

/// One body per lane: velocities (for the velocity pass).
#[derive(Clone, Copy, Debug)]
pub struct VelocityLanes<L> {
    /// Linear velocity (m/s, world).
    pub v: Vec3<L>,
    /// Angular velocity (rad/s, world).
    pub w: Vec3<L>,
}

impl<L: Lane> VelocityLanes<L> {
    /// Gathers the velocity rows of `indices`.
    #[inline(always)]
    pub fn gather(rows: &BodyRows, indices: &[u32]) -> Self {
        let [vx, vy, vz, _, wx, wy, wz, _] = L::gather_rows(&rows.velocity, indices);
        Self {
            v: Vec3::new(vx, vy, vz),
            w: Vec3::new(wx, wy, wz),
        }
    }

    /// Writes the velocities back (`NO_WRITE` lanes are skipped).
    #[inline(always)]
    pub fn scatter(&self, rows: &BodyRows, write: &[u32]) {
        let z = L::splat(0.0);
        let (v, w) = (self.v, self.w);
        L::scatter_rows(&[v.x, v.y, v.z, z, w.x, w.y, w.z, z], &rows.velocity, write);
    }
}

/// `numerator / denominator` where the denominator is positive, else 0: a
/// correction between two bodies of infinite mass (or padding) is none.
#[inline(always)]
pub fn safe_ratio<L: Lane>(numerator: L, denominator: L) -> L {
    let valid = denominator.gt(L::splat(0.0));
    L::select(
        valid,
        numerator / L::select(valid, denominator, L::splat(1.0)),
        L::splat(0.0),
    )
}

/// The two bodies of eight joints: the rows each lane reads, and the rows
/// it writes (`NO_WRITE` for a static or kinematic body, or padding). Every
/// joint block starts with one.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C, align(32))]
pub struct BodyPairs {
    /// Row read for body a.
    pub body_a: [u32; BLOCK_LANES],
    /// Row read for body b.
    pub body_b: [u32; BLOCK_LANES],
    /// Row written for body a (`NO_WRITE` unless dynamic).
    pub write_a: [u32; BLOCK_LANES],
    /// Row written for body b (`NO_WRITE` unless dynamic).
    pub write_b: [u32; BLOCK_LANES],
    /// Each lane's [`PairStart`]: the points' separation when the step
    /// began (m, world).
    pub start_gap: Vec3Block,
    /// The world lever arm of a's point when the step began (m).
    pub start_arm_a: Vec3Block,
    /// The world lever arm of b's point when the step began (m).
    pub start_arm_b: Vec3Block,
    /// Bit `i` set: lane `i` is padding (reads the null row on both sides,
    /// writes no row), kept by [`BodyPairs::set`]; kernels skip slices of
    /// padding (`vertebra_math::block::for_live_slices`). Zero (a zeroed
    /// header) runs every lane.
    pub padding: u32,
    /// Nonzero: the direct solve (the `direct` module) solves the equality
    /// parts and the limits of every live lane (points, hinge axes, locks,
    /// swing and twist limits, the rod's curve and length), so the block's
    /// position pass leaves them out and solves only its drives and the
    /// rod's soft bend and twist. Zero (a zeroed
    /// header) solves every part. One flag per block, not per lane, so that
    /// every backend, whatever its slices, solves the same parts.
    pub direct: u32,
    /// Fills the header to its 32-byte alignment (`Pod` allows no implicit
    /// padding bytes).
    pub _align: [u32; 6],
}

/// The header of every constraint lane: the two bodies it joins, as rows
/// (slot + 1; row 0 is the null row), and whether each is dynamic (its
/// row written). [`BodyPairs`] holds eight.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PairLane {
    /// Row of body a.
    pub body_a: u32,
    /// Row of body b.
    pub body_b: u32,
    /// Whether body a is dynamic (written).
    pub dynamic_a: bool,
    /// Whether body b is dynamic (written).
    pub dynamic_b: bool,
}

impl PairLane {
    /// A padding lane's pair: the null row on both sides, no writes.
    pub const NULL: Self = Self {
        body_a: 0,
        body_b: 0,
        dynamic_a: false,
        dynamic_b: false,
    };

    /// The pair of rows `body_a` and `body_b`, both dynamic (both written).
    pub const fn dynamic(body_a: u32, body_b: u32) -> Self {
        Self {
            body_a,
            body_b,
            dynamic_a: true,
            dynamic_b: true,
        }
    }
}

/// Where a joint sits on its two bodies (one lane): an anchor on each
/// (m, its body's frame) and a joint frame on each (rotations from the
/// joint's axes to its body's). Sockets, hinges and fixed joints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointFrames {
    /// Anchor on a (m, a's body frame).
    pub anchor_a: glam::Vec3,
    /// Anchor on b (m, b's body frame).
    pub anchor_b: glam::Vec3,
    /// Joint frame in a's body frame.
    pub frame_a: glam::Quat,
    /// Joint frame in b's body frame.
    pub frame_b: glam::Quat,
}

impl JointFrames {
    /// A padding lane's: anchors at the origins, frames the bodies'.
    pub const NONE: Self = Self {
        anchor_a: glam::Vec3::ZERO,
        anchor_b: glam::Vec3::ZERO,
        frame_a: glam::Quat::IDENTITY,
        frame_b: glam::Quat::IDENTITY,
    };
}

/// A block of eight constraint lanes (AoSoA), written lane by lane from
/// its lane type; every block's first field is its [`BodyPairs`].
pub trait LaneBlock: Zeroable {
    /// One lane's data, whose header is a [`PairLane`].
    type Lane;
    /// What a padding lane holds: [`PairLane::NULL`], nothing enabled.
    const PADDING: Self::Lane;
    /// Writes `value` into `lane` (below `BLOCK_LANES`).
    fn set(&mut self, lane: usize, value: &Self::Lane);
    /// Makes `lane` a padding lane: null rows, no writes.
    fn clear(&mut self, lane: usize) {
        self.set(lane, &Self::PADDING);
    }
    /// A block of padding lanes.
    fn padding() -> Self
    where
        Self: Sized,
    {
        let mut block = Self::zeroed();
        for lane in 0..BLOCK_LANES {
            block.clear(lane);
        }
        block
    }
}

/// Where a pair of body points stood when the step began: their separation
/// `gap = (P_b + arm_b) - (P_a + arm_a)`, measured in double precision from
/// the bodies' coordinates `P`, and the lever arms `arm = q local` of that
/// moment. With the rows holding displacements `p` since then, the points'
/// separation now is
///
/// `d = gap + ((p_b + (r_b - arm_b)) - (p_a + (r_a - arm_a)))`
///
/// with every term the size of the motion or of the joint's error, never
/// the size of a coordinate; a body that has not turned has `r = arm`
/// exactly (the same rotation of the same numbers), so even a static body
/// whose anchor lies kilometres from its centre adds nothing.
#[derive(Clone, Copy, Debug)]
pub struct PairStart<L> {
    /// Separation of the points when the step began (m).
    pub gap: Vec3<L>,
    /// a's lever arm when the step began (m).
    pub arm_a: Vec3<L>,
    /// b's lever arm when the step began (m).
    pub arm_b: Vec3<L>,
}

impl<L: Lane> PairStart<L> {
    /// The points' separation now (m), from a's point to b's, for the
    /// current lever arms `ra`, `rb`.
    #[inline(always)]
    pub fn separation(
        &self,
        a: &BodyLanes<L>,
        b: &BodyLanes<L>,
        ra: Vec3<L>,
        rb: Vec3<L>,
    ) -> Vec3<L> {
        self.gap + ((b.p + (rb - self.arm_b)) - (a.p + (ra - self.arm_a)))
    }

    /// The chord between the centres of mass now (m), for pairs whose
    /// points are the centres (zero arms).
    #[inline(always)]
    pub fn chord(&self, a: &BodyLanes<L>, b: &BodyLanes<L>) -> Vec3<L> {
        self.gap + (b.p - a.p)
    }
}

/// One lane's [`PairStart`], as the world computes it from the bodies at
/// the start of a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StartLane {
    /// Separation of the points (m, world).
    pub gap: glam::Vec3,
    /// a's lever arm (m, world).
    pub arm_a: glam::Vec3,
    /// b's lever arm (m, world).
    pub arm_b: glam::Vec3,
}

impl StartLane {
    /// Both points at the origin, no lever arms.
    pub const ZERO: Self = Self {
        gap: glam::Vec3::ZERO,
        arm_a: glam::Vec3::ZERO,
        arm_b: glam::Vec3::ZERO,
    };

    /// Points `local_a` on a and `local_b` on b (m, body frames) of bodies
    /// at coordinates `pa`, `pb` (m, world, double precision) turned by
    /// `qa`, `qb`. The arms are rotated by the kernels' own rotation (the
    /// scalar twin of every backend), so an unturned body's arm cancels
    /// exactly.
    pub fn new(
        pa: glam::DVec3,
        qa: glam::Quat,
        local_a: glam::Vec3,
        pb: glam::DVec3,
        qb: glam::Quat,
        local_b: glam::Vec3,
    ) -> Self {
        let (arm_a, arm_b) = (lever_arm(qa, local_a), lever_arm(qb, local_b));
        let gap = (pb + arm_b.as_dvec3()) - (pa + arm_a.as_dvec3());
        Self {
            gap: gap.as_vec3(),
            arm_a,
            arm_b,
        }
    }
}

/// `q local` by the kernels' own rotation (the scalar twin of every
/// backend's), so that it cancels exactly against a kernel's `q.rotate`.
fn lever_arm(q: glam::Quat, local: glam::Vec3) -> glam::Vec3 {
    glam::Vec3::from(Quat::<f32>::from(q).rotate(Vec3::<f32>::from(local)))
}

impl BodyPairs {
    /// Sets lane `lane`: rows `a` and `b`, written where dynamic.
    pub fn set(&mut self, lane: usize, pair: &PairLane) {
        let PairLane {
            body_a: a,
            body_b: b,
            dynamic_a,
            dynamic_b,
        } = *pair;
        self.body_a[lane] = a;
        self.body_b[lane] = b;
        self.write_a[lane] = if dynamic_a { a } else { NO_WRITE };
        self.write_b[lane] = if dynamic_b { b } else { NO_WRITE };
        let bit = 1 << lane;
        if a == 0 && b == 0 && !dynamic_a && !dynamic_b {
            self.padding |= bit;
        } else {
            self.padding &= !bit;
        }
    }

    /// Sets lane `lane`'s start of step.
    pub fn set_start(&mut self, lane: usize, s: &StartLane) {
        self.start_gap.set(lane, s.gap);
        self.start_arm_a.set(lane, s.arm_a);
        self.start_arm_b.set(lane, s.arm_b);
    }

    /// The start of step of lanes `start .. start + L::WIDTH`.
    #[inline(always)]
    pub fn start<L: Lane>(&self, start: usize) -> PairStart<L> {
        PairStart {
            gap: self.start_gap.load(start),
            arm_a: self.start_arm_a.load(start),
            arm_b: self.start_arm_b.load(start),
        }
    }

    /// Gathers both bodies of lanes `start .. start + L::WIDTH`.
    #[inline(always)]
    pub fn gather<L: Lane>(&self, rows: &BodyRows, start: usize) -> (BodyLanes<L>, BodyLanes<L>) {
        (
            BodyLanes::gather(rows, &self.body_a[start..]),
            BodyLanes::gather(rows, &self.body_b[start..]),
        )
    }

    /// Writes both bodies' poses back.
    #[inline(always)]
    pub fn scatter<L: Lane>(
        &self,
        rows: &BodyRows,
        start: usize,
        a: &BodyLanes<L>,
        b: &BodyLanes<L>,
    ) {
        a.scatter_pose(rows, &self.write_a[start..]);
        b.scatter_pose(rows, &self.write_b[start..]);
    }
}
