//! Each joint's equality rows for the direct solve: the error `C` of every
//! row and its Jacobian `J = dC/dx` for each body, with `x = (p, theta)`
//! a body's displacement and rotation vector (world), so that the
//! linearised error after a correction is `C + J_a dx_a + J_b dx_b`.
//!
//! | joint | rows |
//! | --- | --- |
//! | socket, hinge and fixed point (3) | `C = d`, the anchors' separation; `J_b = [1, -[r_b]x]`, `J_a = [-1, [r_a]x]` |
//! | hinge axis (2) | `C = theta n` (the turn from `t_a` to `t_b`) along two axes `u` spanning the plane normal to `t_a + t_b`; `J_b = [0, u]`, `J_a = [0, -u]` |
//! | fixed lock (3) | `C = log((q_b F_b)(q_a F_a)*)`; `J_b = [0, 1]`, `J_a = [0, -1]` |
//! | rod curve (2) | `C = theta n` (the turn from the reflection `r` of `t_a` to `t_b`, `parts::rod::curve`) along two axes `u` normal to `r + t_b` (from a's +Y reflected likewise); `J_b = [g(u), u]`, `J_a = [-g(u), -(2 (u . o) o - u)]` |
//! | rod length (1) | `C = |p_b - p_a| - chord(l0, psi)`; `J_b = [o, -chord'(psi) n]`, `J_a = [-o, chord'(psi) n]` (`n` the bend axis: the paper's motion along the chord, and the chord's turn with the bend) |
//! | limits (socket swing: a cone's or an ellipse's 1, a pyramid's 2; socket twist, hinge range, rod bend and twist: 1 each) | the signed distance past the limit (positive beyond it, negative inside: how far its boundary is), `J_b = [0, j_b]`, `J_a = [0, -j_a]` with the axes the iterative parts turn about; which are held is the solve's active set (the solve's `settle`), and a row not held is zeroed (dropped) |
//! | drive (socket 3, hinge 1) | the drive's error rotation vector in a's body frame (`parts::drive`, `measure_in_a`) along a's axes (a socket's three, a hinge's axis): `C = e . log((q_a* q_b F_b)(F_a T)*)`, `J_b = [0, R_a e]`, `J_a = [0, -R_a e]`; held where the lane has a drive, its right-hand side and softness the drive's (`direct/drive.rs`) |
//!
//! The single angle the iterative parts correct (`hinge_axis`, `curve`)
//! has no direction where the error is zero: a row along `n` would vanish
//! exactly when the joint is right, and the solve would then leave other
//! joints free to turn it. Two rows across the whole plane the error lives
//! in keep it held at zero error too. Their Jacobians, and the lock's
//! (the identity: the rotation vector's derivative at zero), are exact
//! at zero error and first-order beyond, which the next iteration's
//! re-linearisation absorbs; the point's are exact everywhere. Derivations in `docs/direct.md`; every row
//! is checked against finite differences in `tests/direct.rs`.

use vertebra_math::{Lane, Quat, Vec3, poly};

use super::ldl::MAX;
use crate::body::{BodyLanes, PairStart, safe_ratio};
use crate::parts::limit::Softness;
use crate::parts::rod::{curve, length, twist as rod_twist};
use crate::parts::{
    axis_x, drive, ellipse, frames, lock, point, pyramid, swing, swing_direction, twist,
};

/// A limit row's error where the limit has no bound (a cone of pi, a
/// range of `[-pi, pi]`): far inside, so the row is never held and no
/// step is predicted to cross it.
pub const FREE: f32 = -1.0e3;

/// A socket's swing limit, as its rows see it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SwingRows {
    /// A circular cone (or none: a half-angle of pi), in radians.
    Cone,
    /// An elliptical cone, in swing sines (`parts::ellipse`).
    Ellipse,
    /// A pyramid: one row for each of its two angles.
    Pyramid,
}

/// What a joint holds, and so its rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum JointRows {
    /// A socket: the point, the swing limit (one row, two for a pyramid),
    /// the twist range (5 or 6 rows), and where `true` (some lane has a
    /// drive) the drive's 3.
    Socket(SwingRows, bool),
    /// A hinge: the point, the axis and the range (6 rows), and where
    /// `true` the drive's 1.
    Hinge(bool),
    /// A fixed joint: the point and the lock (6 rows).
    Fixed,
    /// A rod: the curve, the length and the bend and twist limits (5 rows).
    Rod,
}

impl JointRows {
    /// How many rows.
    pub const fn count(self) -> usize {
        match self {
            JointRows::Socket(_, true) => self.first_drive() + 3,
            JointRows::Hinge(true) => 7,
            _ => self.first_drive(),
        }
    }

    /// The first of the drive rows, which run to the last row (`count()`
    /// for none: a fixed joint, a rod, whose soft bend and twist stay
    /// iterated).
    pub const fn first_drive(self) -> usize {
        match self {
            JointRows::Socket(SwingRows::Pyramid, _) | JointRows::Hinge(_) | JointRows::Fixed => 6,
            JointRows::Socket(..) | JointRows::Rod => 5,
        }
    }

    /// How many limit rows.
    pub const fn limit_count(self) -> usize {
        self.first_drive() - self.first_limit()
    }

    /// The first of the limit rows, which run to the first drive row
    /// (`first_drive()` for none: a fixed joint).
    pub const fn first_limit(self) -> usize {
        match self {
            JointRows::Socket(..) | JointRows::Rod => 3,
            JointRows::Hinge(_) => 5,
            JointRows::Fixed => 6,
        }
    }

    /// Whether row `k` is a limit's.
    pub const fn is_limit(self, k: usize) -> bool {
        k >= self.first_limit() && k < self.first_drive()
    }

    /// How the softness of row `k` is scaled: a quarter for the ellipse's
    /// row, whose error is in swing sines (half a radian per radian for
    /// small swings: `parts::ellipse`), else one.
    pub const fn is_sine_row(self, k: usize) -> bool {
        matches!(self, JointRows::Socket(SwingRows::Ellipse, _)) && k == 3
    }
}

/// The most limit rows a joint has (a pyramid socket's two swing rows and
/// its twist).
pub const MAX_LIMITS: usize = 3;

/// The most drive rows a joint has (a socket's three).
pub const MAX_DRIVE_ROWS: usize = 3;

/// The most rows a joint holds or not ([`super::ldl::Held`]): its limits'
/// and its drive's.
pub const MAX_OPTIONAL: usize = MAX_LIMITS + MAX_DRIVE_ROWS;

/// Values the solve records of each limit row (a node scratch's `limits`):
/// `c`, the angular `J_a` and `J_b`, and `w`.
pub const LIMIT_RECORD: usize = 8;

/// A joint's rows: errors and both bodies' Jacobians (`[linear,
/// angular]`, world).
#[derive(Clone, Copy, Debug)]
pub struct Rows<L> {
    /// `dC/dx_a`, row by row.
    pub ja: [[L; 6]; MAX],
    /// `dC/dx_b`, row by row.
    pub jb: [[L; 6]; MAX],
    /// `C` (m for positional rows, rad for angular ones).
    pub c: [L; MAX],
}

/// What a joint is measured from: its anchors (m, body frames), frames
/// (body frames), the rod's rest length (m) and the pair's start of step.
#[derive(Clone, Copy, Debug)]
pub struct Geometry<L> {
    /// Anchor on a.
    pub anchor_a: Vec3<L>,
    /// Anchor on b.
    pub anchor_b: Vec3<L>,
    /// Joint (or material) frame on a.
    pub frame_a: Quat<L>,
    /// Joint (or material) frame on b.
    pub frame_b: Quat<L>,
    /// The rod's rest length.
    pub rest_length: L,
    /// The swing cone's half-angle (rad; the rod's bend limit; pi: none).
    pub swing_max: L,
    /// The elliptical cone's semi-axes `[sin(theta_y / 2), sin(theta_z /
    /// 2)]` (`[1, 1]`: none).
    pub ellipse: [L; 2],
    /// The pyramid's ranges about Y and Z (rad; `[-pi, pi]`: none).
    pub pyramid: [[L; 2]; 2],
    /// The twist range (rad; a hinge's range; the rod's twist limit;
    /// `[-pi, pi]`: none).
    pub twist: [L; 2],
    /// The limits' softness, scaled to the substep (all zero: hard).
    pub softness: Softness<L>,
    /// The drive's target this substep: b's joint frame relative to a's
    /// (the identity where the lane has no drive).
    pub drive_target: Quat<L>,
    /// Where the pair's points (a rod's centres) stood as the step began.
    pub start: PairStart<L>,
}

impl<L: Lane> Rows<L> {
    /// Measures the rows of a joint of kind `kind` between `a` and `b`.
    #[inline(always)]
    pub fn measure(kind: JointRows, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) -> Self {
        let mut rows = Self::zero();
        rows.equalities(kind, a, b, g);
        rows.limits(kind, a, b, g);
        rows
    }

    /// Measures only the limit rows (from `kind.first_limit()`; the rest
    /// zero), each as [`Rows::measure`] measures it, bit for bit.
    #[inline(always)]
    pub fn measure_limits(
        kind: JointRows,
        a: &BodyLanes<L>,
        b: &BodyLanes<L>,
        g: &Geometry<L>,
    ) -> Self {
        let mut rows = Self::zero();
        rows.limits(kind, a, b, g);
        rows
    }

    /// Measures only the drive rows (from `kind.first_drive()`; the rest
    /// zero); each row's error, and `J_b`'s angular part (`J_a`'s is its
    /// negative), the axis it is measured along turned into the world.
    #[inline(always)]
    pub fn measure_drive(
        kind: JointRows,
        a: &BodyLanes<L>,
        b: &BodyLanes<L>,
        g: &Geometry<L>,
    ) -> Self {
        let mut rows = Self::zero();
        let (c, _) = drive::measure_in_a(a, b, g.frame_a, g.frame_b, g.drive_target);
        let zero = Vec3::zero();
        for (k, e) in (kind.first_drive()..kind.count()).zip(drive_axes(kind, g.frame_a)) {
            let j = a.q.rotate(e);
            rows.set(k, c.dot(e), (zero, j), j);
        }
        rows
    }

    #[inline(always)]
    fn zero() -> Self {
        let zero = L::splat(0.0);
        Self {
            ja: [[zero; 6]; MAX],
            jb: [[zero; 6]; MAX],
            c: [zero; MAX],
        }
    }

    /// The equality rows: the point (a rod's curve and length), a hinge's
    /// axis, a fixed joint's lock.
    #[inline(always)]
    fn equalities(&mut self, kind: JointRows, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        match kind {
            JointRows::Socket(..) => self.point(0, a, b, g),
            JointRows::Hinge(_) => {
                self.point(0, a, b, g);
                self.axis(3, a, b, g);
            }
            JointRows::Fixed => {
                self.point(0, a, b, g);
                self.lock(3, a, b, g);
            }
            JointRows::Rod => {
                self.curve(0, a, b, g);
                self.length(2, a, b, g);
            }
        }
    }

    /// The limit rows, from `kind.first_limit()`.
    #[inline(always)]
    fn limits(&mut self, kind: JointRows, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        match kind {
            JointRows::Socket(SwingRows::Cone, _) => {
                self.swing(3, a, b, g);
                self.twist(4, a, b, g);
            }
            JointRows::Socket(SwingRows::Ellipse, _) => {
                self.ellipse(3, a, b, g);
                self.twist(4, a, b, g);
            }
            JointRows::Socket(SwingRows::Pyramid, _) => {
                self.pyramid(3, a, b, g);
                self.twist(5, a, b, g);
            }
            JointRows::Hinge(_) => self.twist(5, a, b, g),
            JointRows::Fixed => {}
            JointRows::Rod => self.rod_limits(3, a, b, g),
        }
    }

    /// Row `k`: error `c`, `J_b = [lb, ab]`, `J_a = [-lb, -aa]`.
    #[inline(always)]
    fn set(&mut self, k: usize, c: L, (lb, ab): (Vec3<L>, Vec3<L>), aa: Vec3<L>) {
        self.c[k] = c;
        self.jb[k] = [lb.x, lb.y, lb.z, ab.x, ab.y, ab.z];
        self.ja[k] = [-lb.x, -lb.y, -lb.z, -aa.x, -aa.y, -aa.z];
    }

    /// A limit's row: its signed distance `c` past the limit grows as b
    /// turns about `jb` and as a turns against `ja` (world). Which rows
    /// are held is the solve's active set (the solve's `settle`).
    #[inline(always)]
    fn limit(&mut self, k: usize, c: L, ja: Vec3<L>, jb: Vec3<L>) {
        self.set(k, c, (Vec3::zero(), jb), ja);
    }

    /// The swing cone: the angle between the twist axes past its
    /// half-angle, about `n = t_a x t_b / |t_a x t_b|` (`parts::swing`).
    #[inline(always)]
    fn swing(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let (n, theta) = swing::measure(a, b, g.frame_a, g.frame_b);
        self.limit(at, bounded(theta - g.swing_max, g.swing_max), n, n);
    }

    /// The elliptical cone, in swing sines (`parts::ellipse`): outside,
    /// the distance to its nearest point along the ellipse's normal there.
    #[inline(always)]
    fn ellipse(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let dir = swing_direction::measure(a, b, g.frame_a, g.frame_b);
        let [semi_y, semi_z] = g.ellipse;
        let (n, c) = ellipse::signed(&dir, semi_y, semi_z, L::splat(FREE));
        let n = a.q.rotate(n);
        self.limit(at, c, n, n);
    }

    /// The pyramid's two swing angles (`parts::pyramid`).
    #[inline(always)]
    fn pyramid(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let dir = swing_direction::measure(a, b, g.frame_a, g.frame_b);
        let [y, z] = g.pyramid;
        for (k, (n, c)) in pyramid::signed(&dir, y, z, L::splat(FREE))
            .into_iter()
            .enumerate()
        {
            let n = a.q.rotate(n);
            self.limit(at + k, c, n, n);
        }
    }

    /// The twist range (a hinge's range): the signed distance past the
    /// nearer end (`parts::twist`). The swing-twist decomposition's twist
    /// is the rod's (`parts::rod::twist`): its swing is the shortest arc
    /// from `t_a` to `t_b`, the rod's minimal rotation, so its exact
    /// gradient is the rod's twist axes, `t_b + t_b x k` for b with
    /// `k = t_a x t_b / (1 + t_a . t_b)`. Turning about `t_b` alone (the
    /// iterative part's axis) is exact only without swing: one solve of a
    /// swung socket left up to 55% of its twist.
    #[inline(always)]
    fn twist(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let [lo, hi] = g.twist;
        let (_, phi) = twist::measure_local(a, b, g.frame_a, g.frame_b);
        let (c, sign) = twist::signed(phi, lo, hi, L::splat(FREE));
        let (ja, jb) = rod_twist::axes(&frames(a, b, g.frame_a, g.frame_b));
        self.limit(at, c, ja.scale(sign), jb.scale(sign));
    }

    /// The rod's bend limit and twist range (`parts::rod::bend`,
    /// `parts::rod::twist`), in the world frames.
    #[inline(always)]
    fn rod_limits(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let f = frames(a, b, g.frame_a, g.frame_b);
        let (n, psi) = crate::parts::rod::bend_angle(f.ta, f.tb);
        self.limit(at, bounded(psi - g.swing_max, g.swing_max), n, n);
        let [lo, hi] = g.twist;
        let (c, sign) = twist::signed(rod_twist::measure(&f), lo, hi, L::splat(FREE));
        let (na, nb) = rod_twist::axes(&f);
        self.limit(at + 1, c, na.scale(sign), nb.scale(sign));
    }

    /// The point: `d` along the world axes; moving b along `e` moves its
    /// anchor by `e`, turning it by `w` moves it by `w x r_b`, so
    /// `dd_k/dtheta_b = r_b x e_k`.
    #[inline(always)]
    fn point(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let (ra, rb, d) = point::separation(a, b, g.anchor_a, g.anchor_b, &g.start);
        for (k, (e, c)) in world_axes().into_iter().zip([d.x, d.y, d.z]).enumerate() {
            self.set(at + k, c, (e, rb.cross(e)), ra.cross(e));
        }
    }

    /// The hinge axis: `theta n` across the plane normal to `t_a + t_b`.
    #[inline(always)]
    fn axis(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let (fa, fb) = (a.q * g.frame_a, b.q * g.frame_b);
        let (ta, tb) = (axis_x(fa), axis_x(fb));
        let (n, sin) = ta.cross(tb).normalize_or_zero();
        let turn = n.scale(poly::atan2(sin, ta.dot(tb)));
        let zero = Vec3::zero();
        for (k, u) in plane(ta + tb, axis_y(fa)).into_iter().enumerate() {
            self.set(at + k, turn.dot(u), (zero, u), u);
        }
    }

    /// The lock: the rotation vector between the joint frames.
    #[inline(always)]
    fn lock(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let c = lock::measure(a, b, g.frame_a, g.frame_b);
        for (k, (e, c)) in world_axes().into_iter().zip([c.x, c.y, c.z]).enumerate() {
            self.set(at + k, c, (Vec3::zero(), e), e);
        }
    }

    /// The rod's curve: the turn from `r` to `t_b` across the plane normal
    /// to `r + t_b`, with the chord's turn as b moves (`curve.rs`'s `g`,
    /// for any axis `u`: `e = u x r`).
    #[inline(always)]
    fn curve(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let f = frames(a, b, g.frame_a, g.frame_b);
        let measured = curve::measure(a, b, &f, &g.start);
        let turn = measured.n_b.scale(measured.theta);
        let two = L::splat(2.0);
        let (o, distance) = g.start.chord(a, b).normalize_or_zero();
        let apart = distance.gt(L::splat(0.0));
        let ta_o = f.ta.dot(o);
        let r = o.scale(two * ta_o) - f.ta;
        let scale = -safe_ratio(two, distance);
        // The hint is a's +Y reflected as t_a is: normal to r, as a's +Y is
        // to t_a, so never along `r + t_b` near zero error (a's own +Y is
        // along r for a rod bent 90 degrees in its XY plane).
        let y = axis_y(f.fa);
        let hint = o.scale(two * y.dot(o)) - y;
        for (k, u) in plane(r + f.tb, hint).into_iter().enumerate() {
            let e = u.cross(r);
            let along = f.ta.scale(e.dot(o)) + e.scale(ta_o);
            let across = (along - o.scale(along.dot(o))).scale(scale);
            let across = Vec3::select(apart, across, Vec3::zero());
            let reflected = o.scale(two * u.dot(o)) - u;
            self.set(at + k, turn.dot(u), (across, u), reflected);
        }
    }

    /// The rod's length: along the chord as the bodies move, and against
    /// the chord's turn as the rod bends (`length::chord_turn`).
    #[inline(always)]
    fn length(&mut self, at: usize, a: &BodyLanes<L>, b: &BodyLanes<L>, g: &Geometry<L>) {
        let f = frames(a, b, g.frame_a, g.frame_b);
        let (o, c) = length::measure(a, b, &f, g.rest_length, &g.start);
        let turn = -length::chord_turn(g.rest_length, &f);
        self.set(at, c, (o, turn), turn);
    }
}

/// The axes a joint's drive rows are measured along, in a's body frame:
/// a socket's three, a hinge's axis (its joint frame's X; the axis rows
/// hold the other two), as many as `kind` has drive rows.
#[inline(always)]
pub fn drive_axes<L: Lane>(kind: JointRows, frame_a: Quat<L>) -> [Vec3<L>; MAX_DRIVE_ROWS] {
    match kind {
        JointRows::Hinge(_) => {
            let zero = Vec3::zero();
            [axis_x(frame_a), zero, zero]
        }
        _ => world_axes(),
    }
}

/// A cone's (a rod bend's) signed distance `c` past the half-angle
/// `max`, or [`FREE`] where the half-angle is pi or more (no bound).
#[inline(always)]
fn bounded<L: Lane>(c: L, max: L) -> L {
    L::select(max.ge(L::splat(core::f32::consts::PI)), L::splat(FREE), c)
}

/// The world's axes: the rows of a vector error measured along them (the
/// point's separation, the lock's rotation vector).
#[inline(always)]
fn world_axes<L: Lane>() -> [Vec3<L>; 3] {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    [
        Vec3::new(one, zero, zero),
        Vec3::new(zero, one, zero),
        Vec3::new(zero, zero, one),
    ]
}

/// A frame's +Y axis (its rotation matrix's second column).
#[inline(always)]
fn axis_y<L: Lane>(q: Quat<L>) -> Vec3<L> {
    q.rotate(Vec3::new(L::splat(0.0), L::splat(1.0), L::splat(0.0)))
}

/// Two orthonormal axes spanning the plane normal to `s`: `hint` with its
/// part along `s` removed, and `s` crossed with that. Zero where they are
/// undefined (`s = 0`: axes exactly opposed; `hint` along `s`), which
/// drops the row ([`super::ldl`]).
#[inline(always)]
fn plane<L: Lane>(s: Vec3<L>, hint: Vec3<L>) -> [Vec3<L>; 2] {
    let along = safe_ratio(hint.dot(s), s.dot(s));
    let (u, _) = (hint - s.scale(along)).normalize_or_zero();
    let (v, _) = s.cross(u).normalize_or_zero();
    [u, v]
}
