//! Drive part: turns `b`'s joint frame toward a moving target orientation
//! relative to `a`'s, as a damped spring (3 degrees of freedom solved
//! together, as Jolt's `RotationEulerConstraintPart`), with a torque limit.
//!
//! Error. Desired frame `D = q_a F_a T`, current `B = q_b F_b`; the error
//! rotation `E = B D*` takes `D` to `B`, and `C = log(E)` is its rotation
//! vector (shortest arc). Turning `b` by a small `x` makes `E` into
//! `R(x) E`, so `dC/dtheta_b = 1` and `dC/dtheta_a = -1` to first order,
//! and the effective inverse inertia is the 3x3 `W = I_a^-1 + I_b^-1`
//! (world frame). Correcting one angle along `C`'s axis instead (the
//! `angle` part) converges slowly when the inertia is anisotropic: each
//! step is an oblique projection, removing only ~14% of the error per
//! iteration for a capsule whose inertias differ 13:1.
//!
//! Frame. The kernel measures and solves in a's body frame: `C` turned by
//! `R_a^T` is `log((q_a* q_b F_b) (F_a T)*)`, `W` turned is
//! `S_a + R S_b R^T` with `R` b's rotation relative to a's, and each
//! body's turn is applied in its own frame (`S_a dlambda`,
//! `S_b R^T dlambda`), so one inertia is rotated instead of two and no
//! turn is rotated back into the world (as the lock part, `lock.rs`). The
//! start error `C_0` and the accumulated `lambda` are held in the same
//! frame, so the damping's `C - C_0` is the change of the joint's own
//! error: a pair that turns rigidly keeps its error in a's frame and is
//! not damped, where in the world its error would turn with it and read
//! as a rate.
//!
//! Moving target. `T` turns at the target angular velocity `w_T` (rad/s,
//! in a's joint frame): substep `k` aims at `T_k = exp(w_T h) T_(k-1)`
//! ([`advance`]). The error at the substep's start, `C_0`, is measured
//! against `T_(k-1)` with the bodies where the previous substep left them
//! ([`start`]), so `(C - C_0) / h` is the rate of the error: the relative
//! angular velocity minus the target's.
//!
//! Spring. The drive is the damped spring `tau = -K C - D dC/dt` on the
//! error, solved by XPBD with damping (Macklin et al. 2016, eq. 26):
//!
//! `dlambda = -((1 + gamma) W + alpha~)^-1 (C + alpha~ lambda + gamma (C - C_0))`
//!
//! with `alpha~ = K^-1 / h^2` and `gamma = K^-1 D / h`. For a single
//! linear constraint one iteration lands on the implicit Euler step of the
//! spring-damper (each further iteration adds nothing), so the result
//! depends on neither the iteration count nor, to first order, the
//! substep. Two ways to give `K` and `D`, both held per lane as
//! `alpha = K^-1 = compliance 1 + period2 W` and `gamma h = damping_time`:
//!
//! - compliance `c` (rad/(N m)) and damping `d` (N m s/rad): `alpha = c 1`,
//!   `gamma = c d / h`, so `period2 = 0` and `damping_time = c d`. A rigid
//!   drive (`c = 0`) has no damping to speak of.
//! - frequency `f` (Hz) and damping ratio `zeta`, on the drive's own
//!   effective inertia `W^-1` (as Box2D v3's `b2MakeSoft` and Jolt's
//!   `SpringPart`, which work at the velocity level): with `omega = 2 pi
//!   f`, `K = W^-1 omega^2` and `D = 2 zeta omega W^-1`, so
//!   `alpha = W / omega^2` (`period2 = 1 / omega^2`, `compliance = 0`) and
//!   `gamma = 2 zeta / (omega h)` (`damping_time = 2 zeta / omega`). Then
//!   `(1 + gamma) W + alpha~ = W (1 + gamma + 1/(omega h)^2)` and the
//!   relative rotation one iteration applies, `W dlambda`, is
//!   `-(C + W lambda / (omega h)^2 + gamma (C - C_0)) / (1 + gamma +
//!   1/(omega h)^2)`: the bodies' masses cancel. From rest
//!   (`C_0 = C_prev`, the predicted `C~ = C_0 + h dC_0/dt`) this is
//!   `C_1 (1 + 2 zeta omega h + (omega h)^2) = C~ + 2 zeta omega h C_0`,
//!   the implicit Euler step of `C'' = -omega^2 C - 2 zeta omega C'`
//!   whatever the inertia: an oscillator at `f` with ratio `zeta`, whose
//!   implicit integration adds about `omega h / 2` to the damping ratio
//!   (0.013 at 5 Hz and 600 substeps per second).
//!
//! An infinite frequency or zero compliance makes `alpha = 0`, `gamma = 0`:
//! the target is a hard constraint (the paper's figure 7). A disabled
//! drive has `enabled = 0`, hence `C = C_0 = 0`, `lambda = 0`: no
//! correction.
//!
//! Torque limit. `lambda` accumulates the substep's angular impulse times
//! `h` (N m s^2): the torque is `lambda / h^2`. Where `|lambda + dlambda|`
//! would exceed `max_torque h^2` it is scaled back onto that sphere (a
//! select, per lane), and only the part of `dlambda` that gets there is
//! applied: a hit whose torque exceeds the limit turns the joint away, and
//! the capped drive brings it back afterwards.

use vertebra_math::{Lane, Quat, Sym3, Vec3};

use crate::body::BodyLanes;

/// One drive's settings, per lane (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct Drive<L> {
    /// This substep's target `T_k`: b's joint frame relative to a's.
    pub target: Quat<L>,
    /// Compliance `c` (rad / (N m)).
    pub compliance: L,
    /// `1 / omega^2` (s^2): compliance in units of the effective inverse
    /// inertia.
    pub period2: L,
    /// `gamma h` (s).
    pub damping_time: L,
    /// The largest torque (N m), infinity for none.
    pub max_torque: L,
    /// 1 where the drive is on, 0 where off.
    pub enabled: L,
    /// The error `C_0` at the substep's start (rad, a's body frame).
    pub start: Vec3<L>,
}

/// The error rotation vector in a's body frame, `R_a^T log(B D*) =
/// log((q_a* q_b F_b) (F_a T)*)` (rad; the conjugate by `q_a` of the
/// world error rotation, whose rotation vector is the world one turned by
/// `R_a^T`), and b's orientation relative to a's, `q_a* q_b`.
#[inline(always)]
pub fn measure_in_a<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
    target: Quat<L>,
) -> (Vec3<L>, Quat<L>) {
    let relative = a.q.conjugate() * b.q;
    let desired = frame_a * target;
    (
        ((relative * frame_b) * desired.conjugate()).to_rotation_vector(),
        relative,
    )
}

/// The error at the substep's start, `C_0` (rad, a's body frame), against
/// the previous substep's target, zero where the drive is off.
#[inline(always)]
pub fn start<L: Lane>(
    a: &BodyLanes<L>,
    b: &BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
    target: Quat<L>,
    enabled: L,
) -> Vec3<L> {
    measure_in_a(a, b, frame_a, frame_b, target)
        .0
        .scale(enabled)
}

/// The turn `exp(velocity h)` that `h` seconds at `velocity` (rad/s) make,
/// and where it moves anything at all (a nonzero speed): what every moving
/// target advances by, the drives' here and the rod's rest shape
/// (`parts::rod::drive::advance_direction`).
#[inline(always)]
pub fn turn<L: Lane>(velocity: Vec3<L>, h: L) -> (Quat<L>, L::Mask) {
    let (axis, speed) = velocity.normalize_or_zero();
    (
        Quat::from_axis_angle(axis, speed * h),
        speed.gt(L::splat(0.0)),
    )
}

/// The target advanced by `h` seconds at `velocity` (rad/s, a's joint
/// frame): `exp(velocity h) T`, renormalised. A still target is returned
/// as it is, bit for bit.
#[inline(always)]
pub fn advance<L: Lane>(target: Quat<L>, velocity: Vec3<L>, h: L) -> Quat<L> {
    let (turn, moving) = turn(velocity, h);
    Quat::select(moving, (turn * target).normalize(), target)
}

/// One XPBD iteration of the drive; returns the new accumulated `lambda`
/// (N m s^2, a's body frame). `inv_h` and `inv_h2` are `1/h` and `1/h^2`.
/// Solved in a's body frame, as the lock part (`lock.rs`): `W = S_a +
/// R S_b R^T` (`R` b's rotation relative to a's), a turns by `-S_a dlambda`
/// in its own frame and b by `S_b R^T dlambda` in its own: one inertia
/// rotated instead of two, nothing rotated back into the world.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn solve<L: Lane>(
    a: &mut BodyLanes<L>,
    b: &mut BodyLanes<L>,
    frame_a: Quat<L>,
    frame_b: Quat<L>,
    d: &Drive<L>,
    inv_h: L,
    inv_h2: L,
    lambda: Vec3<L>,
) -> Vec3<L> {
    let (c, relative) = measure_in_a(a, b, frame_a, frame_b, d.target);
    let c = c.scale(d.enabled);
    let w = a.inv_inertia + b.inv_inertia.rotated(relative);
    let gamma = d.damping_time * inv_h;
    let spring = d.period2 * inv_h2;
    let alpha = d.compliance * inv_h2;
    let m = scale(w, L::splat(1.0) + gamma + spring).add_diagonal(alpha);
    // A drive by compliance alone gives the plain XPBD step's bits.
    let rhs = c + lambda.scale(alpha);
    let sprung = rhs + w.mul_vec(lambda).scale(spring) + (c - d.start).scale(gamma);
    let rhs = Vec3::select((spring + gamma).gt(L::splat(0.0)), sprung, rhs);
    let dlambda = -m.inverse_or_zero().mul_vec(rhs);
    let (lambda, dlambda) = cap(lambda, dlambda, d.max_torque / inv_h2);
    let turn_b = b.inv_inertia.mul_vec(relative.inverse_rotate(dlambda));
    b.turn_local(turn_b, L::splat(1.0));
    a.turn_local(a.inv_inertia.mul_vec(dlambda), L::splat(-1.0));
    lambda
}

/// `s S`.
#[inline(always)]
fn scale<L: Lane>(m: Sym3<L>, s: L) -> Sym3<L> {
    Sym3 {
        xx: m.xx * s,
        yy: m.yy * s,
        zz: m.zz * s,
        xy: m.xy * s,
        xz: m.xz * s,
        yz: m.yz * s,
    }
}

/// The accumulated `lambda + dlambda` held to length `limit`, and the step
/// that gets there: `dlambda` itself, bit for bit, where within the limit.
#[inline(always)]
fn cap<L: Lane>(lambda: Vec3<L>, dlambda: Vec3<L>, limit: L) -> (Vec3<L>, Vec3<L>) {
    let total = lambda + dlambda;
    let length = total.length();
    let over = length.gt(limit);
    let held = total.scale(limit / L::select(over, length, L::splat(1.0)));
    (
        Vec3::select(over, held, total),
        Vec3::select(over, held - lambda, dlambda),
    )
}
