//! Building a ragdoll in a world: standard (every body and joint) or
//! simplified (the spine chain replaced by one rod, paper section 6).

use std::collections::{HashMap, HashSet};
use std::sync::Arc;
use vertebra_math::PortableQuat;

use glam::{Quat, Vec3};
use vertebra_world::{
    BodyDesc, BodyHandle, JointDesc, JointHandle, MIN_TIME_STEP, MassProperties, RodDesc,
    RodHandle, RodStiffness, Shape, World,
};

use crate::error::RagdollError;
use crate::mapper::SkeletonMapper;
use crate::model::{RagdollDesc, SpineMode, rod_name};
use crate::pose::Pose;
use vertebra_math::DefaultFloatMode;

/// What a simplified ragdoll's rod takes its rest shape and limits from.
/// Either way the rod is made at the pose it is built at (its material
/// frames and rest length: paper section 6), so it holds exactly there.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RodRest {
    /// The paper's, and the default: the pose at the switch. The rod has
    /// no bending or twisting energy there (its stiffness keeps the spine
    /// in the shape the animation left it in), its twist range is centred
    /// on the switch's twist, and its bend limit caps the bend from the
    /// tangents made there. A spine twisted near its limit at the switch
    /// can twist that much further.
    #[default]
    Transition,
    /// As the sockets': measured from the bind pose, in the frames made at
    /// the switch. The rest bend and twist are the bind pose's (the
    /// stiffness pulls the spine back toward it), and the twist range is
    /// centred on the bind pose's twist (clamped to [-pi, pi]). The bend
    /// limit is a cone about the base's tangent (the kernel's), so it is
    /// widened by `psi_0`, the bind pose's bend in those frames (small for
    /// a spine bent evenly at the switch): every bend within the limit of
    /// the bind shape stays allowed. A switch pose beyond these limits is
    /// pulled inside them by the first step, as a socket's is.
    Bind,
}

/// Where each joint's pivot sits on its parent body. Either way the child
/// body's anchor is the description's pivot, and the joint's frames and
/// limits are measured from the bind pose.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum JointAnchors {
    /// The description's, and the default (as a physics asset's joints
    /// are): both bodies' anchors at the described pivot. A pose whose
    /// bodies are apart at a joint (an animation whose clavicle or neck
    /// bones, which have no body, moved the child off the parent's pivot)
    /// is pulled together by the first step.
    #[default]
    Bind,
    /// The switch's: the parent's anchor is put where the child's is at
    /// the pose the ragdoll is built at, so every joint holds exactly
    /// there, and the offset that the animation's bodiless bones (a turned
    /// clavicle, a bent neck) gave the child is kept for the ragdoll's
    /// life, as the mapper's [`Transition`](crate::Transition) keeps those
    /// bones' offsets. For the switch from animation: no body moves on the
    /// first step for a joint being apart. [`Ragdoll::recreate`] measures
    /// again at its pose. A gap larger than the two bodies' reach (each
    /// capsule's half segment and radius) is a broken pose, not an
    /// offset (a body torn off its parent by a teleported bone): the build
    /// is refused, naming the joint.
    Transition,
}

/// Options for [`Ragdoll::build`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildOptions {
    /// Standard or simplified.
    pub spine: SpineMode,
    /// Where a simplified ragdoll's rod takes its rest shape and limits
    /// from.
    pub rod_rest: RodRest,
    /// Where the joints' pivots sit on their parent bodies.
    pub anchors: JointAnchors,
    /// Opt-in stabilisation (after Jolt's `Ragdoll::Stabilize`, which
    /// follows Strunk): the largest allowed mass ratio across a joint, and
    /// between a body's largest and smallest principal inertia: finite and
    /// at least 1 (a ratio below 1 is no ratio of heavier to lighter).
    /// `None` keeps the file's masses.
    pub stabilise: Option<f32>,
}

impl BuildOptions {
    /// Standard or simplified, the rod's rest from the switch, the
    /// joints' anchors from the description, not stabilised.
    pub fn new(spine: SpineMode) -> Self {
        Self {
            spine,
            rod_rest: RodRest::Transition,
            anchors: JointAnchors::Bind,
            stabilise: None,
        }
    }

    /// For the switch from animation (the mapper's
    /// [`map_to_ragdoll`](crate::SkeletonMapper::map_to_ragdoll)): the rod's
    /// rest and the joints' anchors both from the pose built at.
    pub fn at_switch(spine: SpineMode) -> Self {
        Self {
            anchors: JointAnchors::Transition,
            ..Self::new(spine)
        }
    }

    /// Checks the stabilisation ratio.
    pub fn validate(&self) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        match self.stabilise {
            Some(ratio) if !(ratio.is_finite() && ratio >= 1.0) => Err(RagdollError::OutOfRange {
                context: "build options".to_owned(),
                field: "stabilise",
                reason: format!("is {ratio}; a largest mass ratio must be finite and at least 1"),
            }),
            _ => Ok(()),
        }
    }
}

/// A ragdoll living in a [`World`]: the handles of its bodies and joints.
#[derive(Clone, Debug)]
pub struct Ragdoll {
    pub(crate) desc: RagdollDesc,
    pub(crate) options: BuildOptions,
    /// Per described body: its handle, or `None` for a spine interior body
    /// of a simplified ragdoll (an animation-only bone).
    pub bodies: Vec<Option<BodyHandle>>,
    /// Per described joint: its joint, or `None` for a spine joint of a
    /// simplified ragdoll.
    pub joints: Vec<Option<JointHandle>>,
    /// The spine rod of a simplified ragdoll.
    pub rod: Option<RodHandle>,
    /// The rod as created (its rest shape), to return to after driving.
    pub(crate) rod_rest: Option<RodDesc>,
    /// The mapper onto a skeleton of one bone per body, made once at the
    /// build for [`Ragdoll::skeleton_pose`] (shared by clones).
    pub(crate) as_bones: Arc<SkeletonMapper>,
}

/// Masses per described body for `options` (interior spine masses moved to
/// the ends in rod mode; stabilised if asked), total unchanged. Refused
/// for a description that fails [`RagdollDesc::validate`], options that
/// fail [`BuildOptions::validate`], and a rod spine of a description
/// without a `[spine]` ([`RagdollDesc::check_spine`]). For this
/// workspace's tests (the `harness` feature): a built ragdoll's bodies
/// carry these masses.
#[cfg(feature = "harness")]
pub fn body_masses(desc: &RagdollDesc, options: &BuildOptions) -> Result<Vec<f32>, RagdollError> {
    let _mode = DefaultFloatMode::enter();
    desc.validate()?;
    options.validate()?;
    desc.check_spine(options.spine)?;
    Ok(masses_of(desc, options))
}

/// Masses per described body of a checked description and options.
fn masses_of(desc: &RagdollDesc, options: &BuildOptions) -> Vec<f32> {
    let mut masses: Vec<f32> = desc.bodies.iter().map(|b| b.mass).collect();
    if let (SpineMode::Rod, Some(spine)) = (options.spine, &desc.spine) {
        let (first, last) = (spine.bodies[0], *spine.bodies.last().expect("a chain"));
        for &interior in &spine.bodies[1..spine.bodies.len() - 1] {
            let half = masses[interior] / 2.0;
            masses[first] += half;
            masses[last] += half;
            masses[interior] = 0.0;
        }
    }
    if let Some(ratio) = options.stabilise {
        stabilise_masses(desc, &mut masses, ratio);
    }
    masses
}

/// Moves mass across joints until no joint's heavier side outweighs its
/// lighter side by more than `ratio` (total mass unchanged). Joints whose
/// child was removed (mass 0) are skipped.
fn stabilise_masses(desc: &RagdollDesc, masses: &mut [f32], ratio: f32) {
    for _ in 0..64 {
        let mut changed = false;
        for j in &desc.joints {
            let (a, b) = (masses[j.parent], masses[j.child]);
            if a <= 0.0 || b <= 0.0 {
                continue;
            }
            let (heavy, light) = if a > b {
                (j.parent, j.child)
            } else {
                (j.child, j.parent)
            };
            if masses[heavy] > ratio * masses[light] * (1.0 + 1e-4) {
                let sum = masses[heavy] + masses[light];
                masses[light] = sum / (1.0 + ratio);
                masses[heavy] = sum - masses[light];
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
}

impl Ragdoll {
    /// Creates the ragdoll at `pose`, at rest, or moving as the animation
    /// did from `previous` (a pose `dt` seconds earlier) to `pose`. Every
    /// joint holds exactly at creation; the rod is instantiated from the
    /// pose and the spine bones between its ends. On error the world is
    /// put back as it was (its state, and so its state hash: the world
    /// restores a snapshot taken before the first body went in); only the
    /// handles the refused build drew are never issued again. A description
    /// that fails [`RagdollDesc::validate`] (one edited by hand), or asked
    /// for a rod spine without a `[spine]` ([`RagdollDesc::check_spine`]),
    /// is refused before anything is built. With a collision layer, `vertebra_collide::Collisions::build_ragdoll`
    /// builds it and adds its colliders in one call.
    pub fn build(
        world: &mut World,
        desc: &RagdollDesc,
        options: BuildOptions,
        pose: &Pose,
        previous: Option<(&Pose, f32)>,
    ) -> Result<Self, RagdollError> {
        let _mode = DefaultFloatMode::enter();
        options.validate()?;
        desc.validate()?;
        desc.check_spine(options.spine)?;
        pose.validate(desc)?;
        if let Some((p, dt)) = previous {
            p.validate(desc)?;
            // Velocities are motion divided by dt, as in the step: below
            // the world's shortest time step they overflow.
            if !(dt.is_finite() && dt >= MIN_TIME_STEP) {
                return Err(RagdollError::BadPose(format!(
                    "the time between the two poses is {dt} s; it must be at least {MIN_TIME_STEP} s"
                )));
            }
        }
        let as_bones = SkeletonMapper::bodies_as_bones(desc, options.spine)?;
        let mut ragdoll = Self {
            desc: desc.clone(),
            options,
            bodies: vec![None; desc.bodies.len()],
            joints: vec![None; desc.joints.len()],
            rod: None,
            rod_rest: None,
            as_bones: Arc::new(as_bones),
        };
        // Removing what went in would leave the slots it took behind (a
        // longer table, a free list): the snapshot puts them back too.
        let before = world.snapshot();
        match ragdoll.populate(world, pose, previous) {
            Ok(()) => Ok(ragdoll),
            Err(e) => {
                world.restore(&before)?;
                Err(e)
            }
        }
    }

    fn populate(
        &mut self,
        world: &mut World,
        pose: &Pose,
        previous: Option<(&Pose, f32)>,
    ) -> Result<(), RagdollError> {
        let desc = &self.desc;
        let masses = masses_of(desc, &self.options);
        let removed_joint = |k: usize| {
            self.options.spine == SpineMode::Rod
                && desc.spine.as_ref().is_some_and(|s| s.joints.contains(&k))
        };
        for (i, b) in desc.bodies.iter().enumerate() {
            if masses[i] <= 0.0 {
                continue; // an interior spine body of the simplified ragdoll
            }
            let in_body = |e| RagdollError::world(&format!("body `{}`", b.name), e);
            let mut props = b
                .shape()
                .mass_properties_with_mass(masses[i])
                .map_err(in_body)?;
            if let Some(ratio) = self.options.stabilise {
                props = MassProperties::new(props.mass, clamp_inertia(props.inertia, ratio))
                    .map_err(in_body)?;
            }
            let (p, q) = pose.bones[i];
            let (v, w) = previous.map_or((Vec3::ZERO, Vec3::ZERO), |(prev, dt)| {
                velocities(prev.bones[i], (p, q), dt)
            });
            let body = BodyDesc::dynamic(props)
                .with_position(p)
                .with_orientation(q)
                .with_velocity(v, w);
            self.bodies[i] = Some(world.add_body(body).map_err(in_body)?);
        }
        for (k, j) in desc.joints.iter().enumerate() {
            if removed_joint(k) {
                continue;
            }
            let (a, b) = (
                self.bodies[j.parent].expect("built"),
                self.bodies[j.child].expect("built"),
            );
            // Joint frames from bind pose (bodies unrotated there): both are
            // the described frame, so limits are measured from bind pose.
            let anchor_b = j.anchor - desc.bodies[j.child].centre();
            let described = j.anchor - desc.bodies[j.parent].centre();
            let anchor_a = match self.options.anchors {
                JointAnchors::Bind => described,
                JointAnchors::Transition => {
                    let at_switch =
                        pivot_on_parent(pose.bones[j.parent], pose.bones[j.child], anchor_b);
                    within_reach(desc, k, at_switch.distance(described))?;
                    at_switch
                }
            };
            let socket = JointDesc {
                body_a: a,
                body_b: b,
                anchor_a,
                anchor_b,
                frame_a: j.frame,
                frame_b: j.frame,
                kind: j.kind,
                drive: None,
                breaking: j.breaking,
            };
            self.joints[k] = Some(
                world
                    .add_joint(socket)
                    .map_err(|e| RagdollError::world(&format!("joint `{}`", j.name), e))?,
            );
        }
        if let (SpineMode::Rod, Some(spine)) = (self.options.spine, &desc.spine) {
            let (first, last) = (spine.bodies[0], *spine.bodies.last().expect("a chain"));
            let in_rod = |e| RagdollError::world(&rod_name(desc), e);
            let bones: Vec<Vec3> = spine.bodies[1..spine.bodies.len() - 1]
                .iter()
                .map(|&b| pose.bones[b].0)
                .collect();
            let rod = RodDesc::from_pose(
                world.bodies(),
                self.bodies[first].expect("built"),
                self.bodies[last].expect("built"),
                &bones,
            )
            .map_err(in_rod)?
            .with_stiffness(
                RodStiffness::Kirchhoff(spine.bend_stiffness),
                RodStiffness::Kirchhoff(spine.twist_stiffness),
            )
            .with_bend_limit(spine.bend_limit)
            .with_twist_limit(spine.twist_limit[0], spine.twist_limit[1]);
            let rod = match self.options.rod_rest {
                RodRest::Transition => rod,
                RodRest::Bind => measured_from_bind(rod),
            };
            self.rod = Some(world.add_rod(rod).map_err(in_rod)?);
            self.rod_rest = Some(rod);
        }
        Ok(())
    }

    /// Removes every joint and body of the ragdoll from `world` (with the
    /// contacts set for the next step that name them); the ragdoll is left
    /// with no handles. All or nothing: refused with nothing removed
    /// ([`RagdollError::NotRemovable`], naming the item) when one of its
    /// bodies or joints is no longer in the world (removed by hand, or a
    /// world restored to before the ragdoll was built) or a joint that is
    /// not the ragdoll's still holds one of its bodies (remove that joint
    /// first). A collision layer's colliders on its bodies are the layer's
    /// (`vertebra_collide::Collisions::remove_ragdoll` removes both). A
    /// ragdoll already removed is refused ([`RagdollError::Removed`]), as
    /// every later call on it is.
    pub fn remove(&mut self, world: &mut World) -> Result<(), RagdollError> {
        self.check_not_removed()?;
        self.check_removable(world)?;
        if let Some(rod) = self.rod.take() {
            world
                .remove_rod(rod)
                .map_err(|e| RagdollError::world(&rod_name(&self.desc), e))?;
        }
        for (socket, j) in self.joints.iter_mut().zip(&self.desc.joints) {
            if let Some(socket) = socket.take() {
                world
                    .remove_joint(socket)
                    .map_err(|e| RagdollError::world(&format!("joint `{}`", j.name), e))?;
            }
        }
        for (body, b) in self.bodies.iter_mut().zip(&self.desc.bodies) {
            if let Some(body) = body.take() {
                world
                    .remove_body(body)
                    .map_err(|e| RagdollError::world(&format!("body `{}`", b.name), e))?;
            }
        }
        Ok(())
    }

    /// Whether [`Ragdoll::remove`] would remove everything: every handle
    /// live, and no other joint on a body of the ragdoll.
    fn check_removable(&self, world: &World) -> Result<(), RagdollError> {
        let refuse = |item: String, reason| RagdollError::NotRemovable { item, reason };
        const GONE: &str = "is no longer in the world";
        if let Some(rod) = self.rod {
            world
                .rod(rod)
                .map_err(|_| refuse("the spine rod".to_owned(), GONE))?;
        }
        for (joint, socket) in self.desc.joints.iter().zip(&self.joints) {
            if let Some(socket) = *socket {
                world
                    .joint(socket)
                    .map_err(|_| refuse(format!("joint `{}`", joint.name), GONE))?;
            }
        }
        let mut owner = HashMap::new();
        for (def, body) in self.desc.bodies.iter().zip(&self.bodies) {
            if let Some(body) = *body {
                world
                    .body(body)
                    .map_err(|_| refuse(format!("body `{}`", def.name), GONE))?;
                owner.insert(body, def);
            }
        }
        let own_joints: HashSet<_> = self.joints.iter().flatten().collect();
        let foreign = world
            .joints()
            .filter(|(h, _)| !own_joints.contains(h))
            .map(|(_, d)| (d.body_a, d.body_b))
            .chain(
                world
                    .rods()
                    .filter(|(h, _)| Some(*h) != self.rod)
                    .map(|(_, d)| (d.body_a, d.body_b)),
            );
        for (a, b) in foreign {
            if let Some(def) = owner.get(&a).or_else(|| owner.get(&b)) {
                return Err(refuse(
                    format!("body `{}`", def.name),
                    "is held by a joint that is not the ragdoll's (remove that joint first)",
                ));
            }
        }
        Ok(())
    }

    /// Re-creates the ragdoll at `pose` (the transition from animation to
    /// physics): the old bodies and joints go, new ones come, the rod
    /// re-instantiated to hold exactly at the new pose. On error (a bad
    /// pose, a world refusal, an old ragdoll that [`Ragdoll::remove`] would
    /// refuse, a removed one: build a new one) the ragdoll and the world
    /// are unchanged.
    pub fn recreate(
        &mut self,
        world: &mut World,
        pose: &Pose,
        previous: Option<(&Pose, f32)>,
    ) -> Result<(), RagdollError> {
        let _mode = DefaultFloatMode::enter();
        self.check_not_removed()?;
        pose.validate(&self.desc)?;
        self.check_removable(world)?;
        let fresh = Self::build(world, &self.desc.clone(), self.options, pose, previous)?;
        let mut old = core::mem::replace(self, fresh);
        old.remove(world)
    }

    /// Its first body (the first described body it has): the name the
    /// collision layer gives it in hits and events
    /// (`vertebra_collide::RagdollPart::ragdoll`). `None` once removed. A
    /// handle is never issued twice, so no other ragdoll of the world is
    /// ever named so; [`Ragdoll::recreate`] moves the name to the new
    /// first body (and the collision layer with it).
    pub fn first_body(&self) -> Option<BodyHandle> {
        self.bodies.iter().flatten().next().copied()
    }

    /// Which of its described bodies `body` is (its index in
    /// `description().bodies`, whose `name` is the bone's), or `None` for
    /// a body that is not the ragdoll's.
    pub fn bone_of(&self, body: BodyHandle) -> Option<usize> {
        self.bodies.iter().position(|&b| b == Some(body))
    }

    /// The description it was built from.
    pub fn description(&self) -> &RagdollDesc {
        &self.desc
    }

    /// How it was built.
    pub fn options(&self) -> BuildOptions {
        self.options
    }

    /// Each body's capsule (its body frame, centred on its centre of mass),
    /// for a collision layer.
    pub fn collision_shapes(&self) -> Vec<(BodyHandle, Shape)> {
        self.desc
            .bodies
            .iter()
            .zip(&self.bodies)
            .filter_map(|(def, body)| body.map(|b| (b, def.shape())))
            .collect()
    }

    /// Pairs of bodies that must never collide: every joint's (and the
    /// rod's) two bodies.
    pub fn non_colliding_pairs(&self) -> Vec<(BodyHandle, BodyHandle)> {
        let mut pairs: Vec<_> = self
            .desc
            .joints
            .iter()
            .zip(&self.joints)
            .filter(|(_, s)| s.is_some())
            .map(|(j, _)| {
                (
                    self.bodies[j.parent].expect("built"),
                    self.bodies[j.child].expect("built"),
                )
            })
            .collect();
        if let (Some(rest), Some(_)) = (self.rod_rest, self.rod) {
            pairs.push((rest.body_a, rest.body_b));
        }
        pairs
    }
}

/// Refuses a joint `k` whose bodies are `gap` (m) apart at the pivot at
/// the switch by more than the two bodies' reach (each capsule's half
/// segment and radius): an offset that bones without bodies give a joint
/// is a few centimetres, a gap larger than the bodies is a broken pose (a
/// teleported body), which `JointAnchors::Transition` would keep.
fn within_reach(desc: &RagdollDesc, k: usize, gap: f32) -> Result<(), RagdollError> {
    let j = &desc.joints[k];
    let reach = |b: usize| {
        let body = &desc.bodies[b];
        0.5 * body.segment[0].distance(body.segment[1]) + body.radius
    };
    let most = reach(j.parent) + reach(j.child);
    if gap <= most {
        return Ok(());
    }
    Err(RagdollError::BadPose(format!(
        "joint `{}`: its bodies are {gap} m apart at its pivot at the pose built at, more than the two bodies' reach ({most} m): a broken pose, which JointAnchors::Transition would keep",
        j.name
    )))
}

/// The child's anchor `anchor_b` (its body frame) at the child's pose, in
/// the parent's body frame at the parent's: the relative offset first, so
/// that far from the origin only the bodies' separation is rounded.
fn pivot_on_parent(
    (parent, parent_q): (Vec3, Quat),
    (child, child_q): (Vec3, Quat),
    anchor_b: Vec3,
) -> Vec3 {
    parent_q.inverse() * ((child - parent) + child_q * anchor_b)
}

impl RagdollDesc {
    /// Whether a ragdoll of this description can be built (or mapped) with
    /// `spine`: a rod spine ([`SpineMode::Rod`]) replaces the `[spine]`
    /// chain, so a description without one is refused, naming it and the
    /// missing table (it would otherwise build the standard ragdoll, with
    /// no rod, and say nothing). Sockets always can.
    pub fn check_spine(&self, spine: SpineMode) -> Result<(), RagdollError> {
        match (spine, &self.spine) {
            (SpineMode::Rod, None) => Err(RagdollError::OutOfRange {
                context: format!("ragdoll `{}`", self.name),
                field: "spine",
                reason: "is a rod (SpineMode::Rod), but the description has no [spine] for one to replace; build it with SpineMode::Sockets, or give it a [spine]".to_owned(),
            }),
            _ => Ok(()),
        }
    }
}

/// `rod`'s rest shape and limits measured from the bind pose
/// ([`RodRest::Bind`]), in its frames. At bind the bodies are unrotated, so
/// the material frames are `F_a` and `F_b` themselves: the rest direction
/// is `F_a^-1 t_b`, the rest twist theirs; the twist range moves onto it
/// and the bend limit widens by their bend.
fn measured_from_bind(mut rod: RodDesc) -> RodDesc {
    use core::f32::consts::PI;
    let (ta, tb) = (rod.frame_a * Vec3::X, rod.frame_b * Vec3::X);
    let bend = vertebra_math::trig::atan2(ta.cross(tb).length(), ta.dot(tb));
    let twist = vertebra_world::rod_twist(rod.frame_a, rod.frame_b);
    rod.bend_rest = (rod.frame_a.inverse() * tb).normalize();
    rod.twist_rest = twist;
    rod.bend_limit = rod.bend_limit.map(|max| (max + bend).min(PI));
    rod.twist_limit = rod
        .twist_limit
        .map(|[lo, hi]| [(twist + lo).max(-PI), (twist + hi).min(PI)]);
    rod
}

/// Velocities that carry `from` to `to` in `dt` seconds.
fn velocities(from: (Vec3, Quat), to: (Vec3, Quat), dt: f32) -> (Vec3, Vec3) {
    let turn = vertebra_math::Quat::<f32>::from(to.1.mul_portable(from.1.conjugate()));
    (
        (to.0 - from.0) / dt,
        Vec3::from(turn.to_rotation_vector()) / dt,
    )
}

/// Raises the smaller principal moments of a diagonal inertia to at least
/// the largest divided by `ratio` (capsules along a body axis are
/// diagonal; a tilted capsule's tensor is left as it is).
fn clamp_inertia(inertia: glam::Mat3, ratio: f32) -> glam::Mat3 {
    let off = [inertia.x_axis.y, inertia.x_axis.z, inertia.y_axis.z];
    if off.iter().any(|x| x.abs() > 1e-6 * inertia.x_axis.x) {
        return inertia;
    }
    let d = inertia.diagonal();
    glam::Mat3::from_diagonal(d.max(Vec3::splat(d.max_element() / ratio)))
}
