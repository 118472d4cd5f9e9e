//! One step: for each substep, predict, iterate the coloured position
//! passes, derive velocities, run the velocity pass, damp (XPBD for rigid
//! bodies, Müller et al. 2020, algorithm 2).

use glam::{Quat, Vec3};
use vertebra_kernels::body::BodyRows;
use vertebra_kernels::contact::{self, ContactBlock};
use vertebra_kernels::driven::StartPass;
use vertebra_kernels::fixed::{self, FixedBlock};
use vertebra_kernels::hinge::{self, HingeBlock};
use vertebra_kernels::limited;
use vertebra_kernels::rod::{self, RodBlock};
use vertebra_kernels::socket::{PositionPass, SocketBlock};
use vertebra_math::Backend;
use vertebra_store::{BodyKind, BodyStore};

use crate::World;
use crate::islands::Islands;
use crate::joint::JointKind;
use crate::parallel::chunked;
use crate::tasks::TaskSystem;

pub(crate) fn step(world: &mut World, dt: f32) {
    let h = dt / world.config.substeps as f32;
    upload(&world.bodies, world.rows.get());
    world.layout.start_step(&world.bodies);
    world
        .previous
        .resize(world.bodies.capacity(), (Vec3::ZERO, Quat::IDENTITY));
    let substeps = world.config.substeps;
    for substep in 0..substeps {
        start_drives(world, h);
        predict(world, h);
        world
            .layout
            .sockets
            .blocks
            .iter_mut()
            .for_each(SocketBlock::reset_lambdas);
        world
            .layout
            .hinges
            .blocks
            .iter_mut()
            .for_each(HingeBlock::reset_lambdas);
        world
            .layout
            .rods
            .blocks
            .iter_mut()
            .for_each(RodBlock::reset_lambdas);
        // An overlap found at detection comes out evenly over the step
        // (docs/contacts.md, "The jammed pile").
        let remaining = (substeps - 1 - substep) as f32 / substeps as f32;
        world
            .contact_layout
            .blocks
            .iter_mut()
            .for_each(|b| b.start_substep(remaining));
        for _ in 0..world.config.iterations {
            solve_positions(world, h);
        }
        derive_velocities(world, h);
        solve_velocities(world, h);
        damp(&mut world.bodies, &world.islands, h);
        world.repaired += repair(world);
    }
    commit(world);
    keep_drive_targets(world);
    keep_rod_rests(world);
    let bodies = &mut world.bodies;
    bodies.force.iter_mut().for_each(|f| *f = Vec3::ZERO);
    bodies.torque.iter_mut().for_each(|t| *t = Vec3::ZERO);
}

/// The drives' substep start, before the bodies move: each drive's error
/// against the last substep's target, then the target advanced by `h`;
/// each rod's bend and twist error (its soft parts damp against them)
/// against the last substep's rest shape, then the rest advanced by `h`;
/// each shaped socket's and hinge's limit violations (`limited.rs`: a
/// damped limit's `C_0`).
/// Every driven block, one after another, on the world's backend (each
/// lane reads and writes only its own block).
fn start_drives(world: &mut World, h: f32) {
    let rows = &*world.rows.get();
    let layout = &mut world.layout;
    for group in layout
        .colours
        .iter()
        .chain(core::iter::once(&layout.overflow))
    {
        for range in [&group.driven, &group.shaped_driven] {
            world.backend.dispatch(StartPass {
                blocks: &mut layout.sockets.blocks[range.clone()],
                rows,
                h,
            });
        }
        world.backend.dispatch(StartPass {
            blocks: &mut layout.hinges.blocks[group.hinges_driven.clone()],
            rows,
            h,
        });
        for range in [&group.shaped_driven, &group.shaped_plain] {
            world.backend.dispatch(limited::StartPass {
                blocks: &mut layout.sockets.blocks[range.clone()],
                rows,
            });
        }
        for range in [&group.hinges_driven, &group.hinges_plain] {
            world.backend.dispatch(limited::StartPass {
                blocks: &mut layout.hinges.blocks[range.clone()],
                rows,
            });
        }
        world.backend.dispatch(rod::StartPass {
            blocks: &mut layout.rods.blocks[group.rods.clone()],
            rows,
            h,
        });
    }
}

/// Writes each moving drive's advanced target (a nonzero
/// `target_velocity`) back to its joint's description, and lays the joint
/// out again from the description: the next step then starts from the
/// description, bit for bit as a rebuilt layout (a restored snapshot, a
/// joint added or removed) starts from it. The lane holds the target
/// normalised (`AngularDrive::lane`), and normalising an advanced target
/// again moves it by an ulp in some steps, so the lane kept as it was
/// would differ from what the description lays out. A still target is
/// left alone: its description is as given and its lane is the layout's
/// (the kernel's advance returns it bit for bit). The same rule as
/// [`keep_rod_rests`].
fn keep_drive_targets(world: &mut World) {
    let layout = &mut world.layout;
    for (slot, desc) in world.joints.iter_mut().enumerate() {
        let Some(desc) = desc.as_mut() else { continue };
        if world.islands.holds_asleep(desc.body_a, desc.body_b) {
            continue; // not laid out
        }
        let Some(drive) = desc.drive.as_mut() else {
            continue;
        };
        if drive.target_velocity == Vec3::ZERO {
            continue;
        }
        drive.target = match desc.kind {
            JointKind::Socket(_) => {
                let (block, lane) = layout.sockets.place[slot];
                layout.sockets.blocks[block].drive.target.get(lane)
            }
            JointKind::Hinge { .. } => {
                let (block, lane) = layout.hinges.place[slot];
                layout.hinges.blocks[block].drive.target.get(lane)
            }
            JointKind::Fixed => continue,
        };
        layout.update_joint(slot, desc, &world.bodies);
    }
}

/// Writes each moving rod's advanced rest shape back to its description
/// and lays the rod out again from it, as [`keep_drive_targets`] does for
/// drives (and for the same reason: the lane holds the rest normalised).
/// A still rest is left alone (its description and lane are as they
/// were).
fn keep_rod_rests(world: &mut World) {
    let layout = &mut world.layout;
    for (slot, desc) in world.rods.iter_mut().enumerate() {
        let Some(desc) = desc.as_mut() else { continue };
        if world.islands.holds_asleep(desc.body_a, desc.body_b) {
            continue; // not laid out
        }
        let (bend, twist) = (
            desc.bend_rest_velocity != Vec3::ZERO,
            desc.twist_rest_velocity != 0.0,
        );
        if !(bend || twist) {
            continue;
        }
        let (block, lane) = layout.rods.place[slot];
        let block = &layout.rods.blocks[block];
        if bend {
            desc.bend_rest = block.bend_rest.get(lane);
        }
        if twist {
            desc.twist_rest = block.twist_rest[lane];
        }
        layout.update_rod(slot, desc, &world.bodies);
    }
}

/// Rows for every slot (stale slots hold harmless old data: no joint
/// references them), every body at zero displacement: the rows hold each
/// body's motion since the step began (see `vertebra_kernels::body`).
pub(crate) fn upload(bodies: &BodyStore, rows: &mut BodyRows) {
    if rows.pose.len() != bodies.capacity() + 1 {
        *rows = BodyRows::with_bodies(bodies.capacity());
    }
    for i in 0..bodies.capacity() {
        rows.inertia[i + 1].set(BodyRows::inertia_row(bodies.inverse_inertia[i]));
        rows.velocity[i + 1].set(BodyRows::velocity_row(
            bodies.linear_velocity[i],
            bodies.angular_velocity[i],
        ));
        rows.pose[i + 1].set(BodyRows::pose_row(
            Vec3::ZERO,
            bodies.inverse_mass[i],
            bodies.orientation[i],
        ));
    }
}

/// A body's displacement since the step began and its orientation, as the
/// rows hold them.
fn pose(rows: &BodyRows, i: usize) -> (Vec3, Quat) {
    let [px, py, pz, _, qx, qy, qz, qw] = rows.pose[i + 1].get();
    (Vec3::new(px, py, pz), Quat::from_xyzw(qx, qy, qz, qw))
}

/// Moves every body by its displacement over the step, in double
/// precision (`BodyStore::displace`: the coordinate keeps what an `f32`
/// cannot hold, and the world's edge holds bodies in).
fn commit(world: &mut World) {
    let (b, islands) = (&mut world.bodies, &world.islands);
    for i in 0..b.capacity() {
        if b.is_live(i) && b.kind[i] != BodyKind::Static && !islands.is_asleep(i) {
            let (displacement, orientation) = pose(world.rows.get(), i);
            b.displace(i, displacement);
            b.orientation[i] = orientation;
        }
    }
}

/// Integration of velocities (gravity, forces, the implicit gyroscopic
/// term in the body frame) and of the rows' displacements and
/// orientations; the previous ones are kept for deriving velocities
/// afterwards.
fn predict(world: &mut World, h: f32) {
    let g = world.config.gravity;
    let (max_linear, max_angular) = (
        world.config.max_linear_speed,
        world.config.max_angular_speed,
    );
    let (b, islands) = (&mut world.bodies, &world.islands);
    for i in 0..b.capacity() {
        if !b.is_live(i) || b.kind[i] == BodyKind::Static || islands.is_asleep(i) {
            continue;
        }
        // The speed limits, before and after the forces: huge but finite
        // velocities or forces would overflow `|w|^2` in the exponential map
        // (or `w x I w`) and poison the world.
        let w = limit(b.angular_velocity[i], max_angular);
        if b.kind[i] == BodyKind::Dynamic {
            let v = b.linear_velocity[i] + (g + b.force[i] * b.inverse_mass[i]) * h;
            b.linear_velocity[i] = limit(v, max_linear);
            let q = b.orientation[i];
            let w_body = gyroscopic(q.inverse() * w, b.inertia[i], h);
            let torque_body = q.inverse() * b.torque[i];
            let w_body = limit(w_body + b.inverse_inertia[i] * torque_body * h, max_angular);
            b.angular_velocity[i] = q * w_body;
        } else {
            b.linear_velocity[i] = limit(b.linear_velocity[i], max_linear);
            b.angular_velocity[i] = w;
        }
        let (displacement, orientation) = pose(world.rows.get(), i);
        world.previous[i] = (displacement, orientation);
        world.rows.get().pose[i + 1].set(BodyRows::pose_row(
            displacement + b.linear_velocity[i] * h,
            b.inverse_mass[i],
            integrate(orientation, b.angular_velocity[i], h),
        ));
    }
}

/// Holds every moving body's velocities to the speed limits, as the step
/// begins: the contacts measure their approach speed from them before any
/// substep has held them (an accepted spin of 1e38 rad/s overflowed
/// `w x r` there and turned both bodies NaN).
pub(crate) fn hold_speeds(b: &mut BodyStore, islands: &Islands, max_linear: f32, max_angular: f32) {
    for i in 0..b.capacity() {
        if b.is_live(i) && b.kind[i] != BodyKind::Static && !islands.is_asleep(i) {
            b.linear_velocity[i] = limit(b.linear_velocity[i], max_linear);
            b.angular_velocity[i] = limit(b.angular_velocity[i], max_angular);
        }
    }
}

/// `v` shortened to at most `max` (`v` itself when it is no longer), and
/// finite even when a component overflowed to infinity.
pub(crate) fn limit(v: Vec3, max: f32) -> Vec3 {
    if v.length_squared() <= max * max {
        return v;
    }
    let v = v.clamp(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
    let scaled = v / v.abs().max_element();
    scaled.normalize() * max
}

/// The gyroscopic term, implicitly: `I (w' - w) + h w' x I w' = 0` in the
/// body frame, solved by one Newton step from `w` (as Bullet's implicit
/// gyroscopic body solver). The explicit term `-h I^-1 (w x I w)` gains
/// energy and lets the angular momentum drift; this does not blow up.
fn gyroscopic(w: Vec3, inertia: glam::Mat3, h: f32) -> Vec3 {
    let skew = |v: Vec3| {
        glam::Mat3::from_cols(
            Vec3::new(0.0, v.z, -v.y),
            Vec3::new(-v.z, 0.0, v.x),
            Vec3::new(v.y, -v.x, 0.0),
        )
    };
    let residual = w.cross(inertia * w) * h;
    let jacobian = inertia + (skew(w) * inertia - skew(inertia * w)) * h;
    let turned = w - jacobian.inverse() * residual;
    // A singular Jacobian, or an inertia so large the product overflowed:
    // no gyroscopic correction this substep.
    if jacobian.determinant().abs() > f32::MIN_POSITIVE && turned.is_finite() {
        turned
    } else {
        w
    }
}

/// Turns `q` at angular velocity `w` for `h` seconds exactly:
/// `exp(w h / 2) q`. The first-order `q + h/2 (w, 0) q` turns by
/// `2 atan(|w| h / 2)` instead, and together with deriving `w` from the
/// quaternion difference it bleeds spin at `(|w| h)^2 / 8` per substep.
/// Through the math layer's polynomials, so every platform agrees.
fn integrate(q: Quat, w: Vec3, h: f32) -> Quat {
    let (axis, speed) = vertebra_math::Vec3::<f32>::from(w).normalize_or_zero();
    let turn = vertebra_math::Quat::<f32>::from_axis_angle(axis, speed * h);
    glam::Quat::from(turn * q.into()).normalize()
}

/// The angular velocity that turns `q0` into `q` in `h` seconds, exactly
/// (the inverse of [`integrate`]): `log(q q0*) / h`, shortest arc.
pub(crate) fn angular_velocity(q: Quat, q0: Quat, h: f32) -> Vec3 {
    let turn = vertebra_math::Quat::<f32>::from(q * q0.conjugate());
    Vec3::from(turn.to_rotation_vector()) / h
}

/// Which socket blocks: with drives or not, plain or shaped path.
#[derive(Clone, Copy)]
struct SocketBlocks {
    driven: bool,
    shaped: bool,
}

/// One kind of pass over one group's blocks of one type.
trait Pass: Sync {
    /// Sockets (`driven` and `shaped` say which blocks).
    fn sockets(
        &self,
        blocks: &mut [SocketBlock],
        kind: SocketBlocks,
        rows: &BodyRows,
        backend: Backend,
    );
    /// Hinges (`driven` says which blocks).
    fn hinges(&self, blocks: &mut [HingeBlock], driven: bool, rows: &BodyRows, backend: Backend);
    /// Fixed joints.
    fn fixed(&self, blocks: &mut [FixedBlock], rows: &BodyRows, backend: Backend);
    /// Rods.
    fn rods(&self, blocks: &mut [RodBlock], rows: &BodyRows, backend: Backend);
    /// Contacts.
    fn contacts(&self, blocks: &mut [ContactBlock], rows: &BodyRows, backend: Backend);
}

/// Runs `pass` over this step's contacts, then the joints: each colour in
/// order, then its overflow set with the scalar kernel. Inside a colour,
/// constraints share no dynamic body, so blocks go to the task system (in
/// ranges) when there are enough of them.
///
/// Joints come last so that what an iteration leaves behind is contact
/// error, not joint error: joint error is what the animation skeleton
/// shows, and what the paper's figure 8 measures. In the 30-ragdoll drop
/// this order cut the mean joint error 2.4x (sockets) and 3.4x (rods),
/// while ragdolls met the floor less deeply (10 mm against 25 mm at
/// impact, 1.4 mm against 0.5 mm at rest); see docs/contacts.md.
fn for_each_colour(world: &mut World, pass: &impl Pass) {
    // The whole step runs inside the task system (World::step), so a split
    // colour is a fork-join among its workers, not a wake-up from outside.
    let tasks: &dyn TaskSystem = &*world.tasks;
    let min_blocks = world.config.parallel_min_blocks;
    let rows = &*world.rows.get();
    // This step's contacts first, coloured on their own; the joints after.
    let contacts = &mut world.contact_layout;
    let groups = contacts.colours.iter().map(|r| (r.clone(), world.backend));
    let overflow = core::iter::once((contacts.overflow.clone(), Backend::Scalar));
    for (range, backend) in groups.chain(overflow) {
        let parallel = (backend != Backend::Scalar).then_some(tasks);
        let blocks = &mut contacts.blocks[range];
        chunked(
            parallel,
            min_blocks,
            contacts.disjoint,
            blocks,
            rows,
            |c, rows| pass.contacts(c, rows, backend),
        );
    }
    // The groups are read in place (no copy per iteration): they and the
    // blocks are disjoint fields of the layout.
    let layout = &mut world.layout;
    let groups = layout.colours.iter().map(|g| (g, world.backend));
    for (group, backend) in groups.chain(core::iter::once((&layout.overflow, Backend::Scalar))) {
        let parallel = (backend != Backend::Scalar).then_some(tasks);
        for (range, driven, shaped) in group.socket_ranges() {
            let blocks = &mut layout.sockets.blocks[range.clone()];
            let kind = SocketBlocks { driven, shaped };
            chunked(
                parallel,
                min_blocks,
                layout.disjoint,
                blocks,
                rows,
                |c, rows| pass.sockets(c, kind, rows, backend),
            );
        }
        for (range, driven) in group.hinge_ranges() {
            let blocks = &mut layout.hinges.blocks[range.clone()];
            chunked(
                parallel,
                min_blocks,
                layout.disjoint,
                blocks,
                rows,
                |c, rows| pass.hinges(c, driven, rows, backend),
            );
        }
        let blocks = &mut layout.fixed.blocks[group.fixed.clone()];
        chunked(
            parallel,
            min_blocks,
            layout.disjoint,
            blocks,
            rows,
            |c, rows| pass.fixed(c, rows, backend),
        );
        let blocks = &mut layout.rods.blocks[group.rods.clone()];
        chunked(
            parallel,
            min_blocks,
            layout.disjoint,
            blocks,
            rows,
            |c, rows| pass.rods(c, rows, backend),
        );
    }
}

/// The position iteration.
struct Positions {
    inv_h: f32,
    inv_h2: f32,
}

impl Pass for Positions {
    fn sockets(
        &self,
        blocks: &mut [SocketBlock],
        kind: SocketBlocks,
        rows: &BodyRows,
        backend: Backend,
    ) {
        let (inv_h, inv_h2) = (self.inv_h, self.inv_h2);
        match (kind.driven, kind.shaped) {
            (true, false) => backend.dispatch(PositionPass::<true, false> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            }),
            (false, false) => backend.dispatch(PositionPass::<false, false> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            }),
            (true, true) => backend.dispatch(PositionPass::<true, true> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            }),
            (false, true) => backend.dispatch(PositionPass::<false, true> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            }),
        }
    }
    fn hinges(&self, blocks: &mut [HingeBlock], driven: bool, rows: &BodyRows, backend: Backend) {
        let (inv_h, inv_h2) = (self.inv_h, self.inv_h2);
        if driven {
            backend.dispatch(hinge::PositionPass::<true> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            });
        } else {
            backend.dispatch(hinge::PositionPass::<false> {
                blocks,
                rows,
                inv_h,
                inv_h2,
            });
        }
    }
    fn fixed(&self, blocks: &mut [FixedBlock], rows: &BodyRows, backend: Backend) {
        backend.dispatch(fixed::PositionPass { blocks, rows });
    }
    fn rods(&self, blocks: &mut [RodBlock], rows: &BodyRows, backend: Backend) {
        backend.dispatch(rod::PositionPass {
            blocks,
            rows,
            inv_h: self.inv_h,
            inv_h2: self.inv_h2,
        });
    }
    fn contacts(&self, blocks: &mut [ContactBlock], rows: &BodyRows, backend: Backend) {
        backend.dispatch(contact::PositionPass { blocks, rows });
    }
}

/// The velocity pass (contact friction and restitution; joints have none:
/// drives damp at the position level).
struct Velocities {
    h: f32,
    resting_speed: f32,
}

impl Pass for Velocities {
    fn sockets(&self, _: &mut [SocketBlock], _: SocketBlocks, _: &BodyRows, _: Backend) {}
    fn hinges(&self, _: &mut [HingeBlock], _: bool, _: &BodyRows, _: Backend) {}
    fn fixed(&self, _: &mut [FixedBlock], _: &BodyRows, _: Backend) {}
    fn rods(&self, _: &mut [RodBlock], _: &BodyRows, _: Backend) {}
    fn contacts(&self, blocks: &mut [ContactBlock], rows: &BodyRows, backend: Backend) {
        let (h, resting_speed) = (self.h, self.resting_speed);
        backend.dispatch(contact::VelocityPass {
            blocks,
            rows,
            h,
            resting_speed,
        });
    }
}

fn solve_positions(world: &mut World, h: f32) {
    for_each_colour(
        world,
        &Positions {
            inv_h: 1.0 / h,
            inv_h2: 1.0 / (h * h),
        },
    );
}

fn solve_velocities(world: &mut World, h: f32) {
    let resting_speed = 2.0 * world.config.gravity.length() * h;
    for_each_colour(world, &Velocities { h, resting_speed });
    let (max_linear, max_angular) = (
        world.config.max_linear_speed,
        world.config.max_angular_speed,
    );
    let (b, islands) = (&mut world.bodies, &world.islands);
    for i in 0..b.capacity() {
        if b.is_live(i) && b.kind[i] == BodyKind::Dynamic && !islands.is_asleep(i) {
            let [vx, vy, vz, _, wx, wy, wz, _] = world.rows.get().velocity[i + 1].get();
            b.linear_velocity[i] = limit(Vec3::new(vx, vy, vz), max_linear);
            b.angular_velocity[i] = limit(Vec3::new(wx, wy, wz), max_angular);
        }
    }
}

/// Derives velocities from the solved motion: `v = (d - d0) / h` from the
/// displacements since the step began (exact to the precision of the
/// motion, wherever the body is), `w = log(q q0*) / h` (shortest arc);
/// both held to the speed limits, which a hard correction can exceed.
fn derive_velocities(world: &mut World, h: f32) {
    let (max_linear, max_angular) = (
        world.config.max_linear_speed,
        world.config.max_angular_speed,
    );
    let (b, islands) = (&mut world.bodies, &world.islands);
    for i in 0..b.capacity() {
        if !b.is_live(i) || b.kind[i] != BodyKind::Dynamic || islands.is_asleep(i) {
            continue;
        }
        let (d, q) = pose(world.rows.get(), i);
        let (d0, q0) = world.previous[i];
        b.orientation[i] = q;
        b.linear_velocity[i] = limit((d - d0) / h, max_linear);
        b.angular_velocity[i] = limit(angular_velocity(q, q0, h), max_angular);
        world.rows.get().velocity[i + 1].set(BodyRows::velocity_row(
            b.linear_velocity[i],
            b.angular_velocity[i],
        ));
    }
}

/// The last line of defence: a body whose motion is no longer finite goes
/// back to its pose before the substep, at rest, and is counted. Validated
/// input keeps every body finite: it never fired in any test, scene or in
/// 390,000 fuzzed call sequences run with it made to panic
/// (docs/robustness.md). It stays so that a case nobody found yet costs a
/// body a substep, not the world.
fn repair(world: &mut World) -> u64 {
    let b = &mut world.bodies;
    let mut repaired = 0;
    for (i, &(displacement, orientation)) in world.previous.iter().enumerate().take(b.capacity()) {
        let (d, q) = pose(world.rows.get(), i);
        let finite = b.is_finite(i) && d.is_finite() && q.is_finite();
        if b.is_live(i) && b.kind[i] != BodyKind::Static && !finite {
            b.orientation[i] = orientation;
            b.linear_velocity[i] = Vec3::ZERO;
            b.angular_velocity[i] = Vec3::ZERO;
            world.rows.get().pose[i + 1].set(BodyRows::pose_row(
                displacement,
                b.inverse_mass[i],
                orientation,
            ));
            repaired += 1;
        }
    }
    repaired
}

/// Linear and angular damping: `v /= 1 + h c`.
fn damp(b: &mut BodyStore, islands: &Islands, h: f32) {
    for i in 0..b.capacity() {
        if b.is_live(i) && b.kind[i] == BodyKind::Dynamic && !islands.is_asleep(i) {
            b.linear_velocity[i] /= 1.0 + h * b.linear_damping[i];
            b.angular_velocity[i] /= 1.0 + h * b.angular_damping[i];
        }
    }
}
