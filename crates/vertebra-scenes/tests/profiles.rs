//! Profile switches and blends on the standing anatomical humanoid, nothing
//! kinematic: the shipped profiles (`standing`, `hit`, `limp`) blended one
//! into another as a game would (a hit fading the drives out as it lands,
//! back in as the character recovers) move no body by more than 1 mm in a
//! frame because of the blend itself. That extra motion is measured
//! directly: each frame is stepped twice from the same state, once with
//! the profile as the blend stood a frame earlier and once as it stands
//! now, and the bodies' positions compared.

use core::f32::consts::FRAC_PI_2;

use glam::{Quat, Vec3};
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{
    BodyDriveSetting, BuildOptions, Pose, Profile, ProfileBlend, Ragdoll, RagdollDesc, SpineMode,
};
use vertebra_world::{BodyDesc, BodyHandle, PinContacts, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

struct Stand {
    desc: RagdollDesc,
    world: World,
    collisions: Collisions,
    ragdoll: Ragdoll,
    pose: Pose,
    blend: ProfileBlend,
    /// The profile the last frame used.
    last: Profile,
}

impl Stand {
    /// The anatomical humanoid at its bind pose, its lowest point 1 mm
    /// above the ground, following it with the `standing` profile; its
    /// contacts with the ground pinned (its 1 kg feet need them).
    fn new(spine: SpineMode) -> Self {
        Self::on(spine, PinContacts::Always)
    }

    /// As [`Self::new`], its contacts pinned as `pin_contacts` says.
    fn on(spine: SpineMode, pin_contacts: PinContacts) -> Self {
        let desc = RagdollDesc::anatomical_humanoid();
        let config = SolverConfig {
            pin_contacts,
            ..SolverConfig::default()
        };
        let mut world = World::new(config).unwrap();
        let mut collisions = Collisions::new();
        let ground = world.add_body(BodyDesc::fixed()).unwrap();
        collisions
            .add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
            .unwrap();
        let lift = vertebra_scenes::standing_lift(&desc);
        let pose = Pose::bind(&desc).moved(Vec3::ZERO, Quat::IDENTITY, lift);
        let options = BuildOptions::new(spine);
        let ragdoll = Ragdoll::build(&mut world, &desc, options, &pose, None).unwrap();
        collisions.add_ragdoll(&ragdoll).unwrap();
        let standing = desc.profile("standing").unwrap().clone();
        Self {
            desc,
            world,
            collisions,
            ragdoll,
            pose,
            blend: ProfileBlend::new(standing.clone()),
            last: standing,
        }
    }

    fn profile(&self, name: &str) -> Profile {
        self.desc.profile(name).unwrap().clone()
    }

    fn bodies(&self) -> Vec<Vec3> {
        (self.ragdoll.bodies.iter().flatten())
            .map(|&b| self.world.body(b).unwrap().position)
            .collect()
    }

    fn step_with(&mut self, profile: &Profile) {
        let poses = (&self.pose, &self.pose);
        (self.ragdoll)
            .follow_profile(&mut self.world, poses, DT, profile)
            .unwrap();
        self.collisions.step(&mut self.world, DT).unwrap();
    }

    /// One frame with the blend moved on; returns how far (m) the blend's
    /// change since the last frame moved any body in this frame.
    fn frame(&mut self) -> f32 {
        self.blend.advance(DT);
        let now = self.blend.current().unwrap();
        let (world, collisions) = (self.world.snapshot(), self.collisions.snapshot(&self.world));
        let last = self.last.clone();
        self.step_with(&last);
        let unchanged = self.bodies();
        self.world.restore(&world).unwrap();
        (self.collisions)
            .restore(&collisions.unwrap(), &self.world)
            .unwrap();
        self.step_with(&now);
        self.last = now;
        (self.bodies().iter().zip(&unchanged))
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f32::max)
    }

    /// Every body's linear velocity (m/s).
    fn velocities(&self) -> Vec<Vec3> {
        (self.ragdoll.bodies.iter().flatten())
            .map(|&b| self.world.body(b).unwrap().linear_velocity)
            .collect()
    }

    fn frames(&mut self, n: usize) -> f32 {
        (0..n).map(|_| self.frame()).fold(0.0, f32::max)
    }

    fn hips(&self) -> BodyHandle {
        self.ragdoll.bodies[self.desc.body_index("hips").unwrap()].unwrap()
    }

    fn chest(&self) -> BodyHandle {
        self.ragdoll.bodies[self.desc.body_index("chest").unwrap()].unwrap()
    }
}

#[test]
fn a_hit_fades_the_drives_out_and_back_in_without_a_pop() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        for k in 0..4 {
            let mut stand = Stand::new(spine);
            stand.frames(60);
            let start = stand.world.body(stand.hips()).unwrap().position;
            let turn = Quat::from_rotation_y(FRAC_PI_2 * k as f32);
            let chest = stand.chest();
            (stand.world)
                .apply_impulse(chest, turn * Vec3::new(40.0, 0.0, 0.0))
                .unwrap();
            let hit = stand.profile("hit");
            stand.blend.switch_to(hit, 0.2).unwrap();
            let out = stand.frames(30);
            let standing = stand.profile("standing");
            stand.blend.switch_to(standing, 0.5).unwrap();
            let back = stand.frames(120);
            let hips = stand.world.body(stand.hips()).unwrap().position;
            eprintln!(
                "{spine:?}, hit {k}: fading out moved a body {:.3} mm, back in {:.3} mm; \
                 hips {:.1} cm from the start",
                out * 1e3,
                back * 1e3,
                (hips - start).length() * 100.0
            );
            assert!(out < 1e-3 && back < 1e-3, "{spine:?} {k}: {out} {back} m");
            assert!((hips - start).length() < 0.05, "{spine:?} {k}: {hips}");
        }
    }
}

/// Fading to limp over half a second moves no body by more than 1 mm in a
/// frame by the blend itself; neither does fading back in to standing
/// from two thirds of the way out, before it has fallen. (Once it has
/// fallen, a blend back to standing drives its stiff legs straight from
/// a heap and throws it: getting up is a get-up clip's work,
/// `docs/ragdolls.md`.)
#[test]
fn fading_to_limp_and_back_before_it_falls_has_no_pop() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut stand = Stand::new(spine);
        stand.frames(30);
        stand.blend.switch_to(stand.profile("limp"), 0.5).unwrap();
        let out = stand.frames(45);
        let mut stand = Stand::new(spine);
        stand.frames(30);
        stand.blend.switch_to(stand.profile("limp"), 0.5).unwrap();
        stand.frames(20);
        let standing = stand.profile("standing");
        stand.blend.switch_to(standing, 0.5).unwrap();
        let back = stand.frames(60);
        eprintln!(
            "{spine:?}: fading to limp moved a body {:.3} mm, back from two thirds out {:.3} mm",
            out * 1e3,
            back * 1e3
        );
        assert!(out < 1e-3 && back < 1e-3, "{spine:?}: {out} {back} m");
    }
}

/// A drive exerts at most its cap, also where the step it would take
/// uncapped turns a limb through the ground: a fallen limp ragdoll whose
/// every joint is driven toward standing at a zero cap settles as the
/// limp one does, never thrown. (Were a drive capped only after its uncapped step is taken,
/// the contacts would push out of the ground what that step pushed in,
/// and keep the push as speed.) On plain contacts and on pins, where a
/// heap's pins may never settle while the drives are uncapped.
#[test]
fn a_drive_capped_at_zero_does_not_throw_a_fallen_ragdoll() {
    let pins = [PinContacts::Never, PinContacts::Always];
    for (spine, pins) in [SpineMode::Sockets, SpineMode::Rod]
        .into_iter()
        .flat_map(|spine| pins.map(|pins| (spine, pins)))
    {
        let mut stand = Stand::on(spine, pins);
        let limp = stand.profile("limp");
        for _ in 0..150 {
            stand.step_with(&limp);
        }
        let mut capped = stand.profile("standing");
        for joint in &mut capped.joints {
            joint.max_torque = 0.0;
        }
        capped.bodies.fill(BodyDriveSetting::NONE);
        let (world, collisions) = (
            stand.world.snapshot(),
            stand.collisions.snapshot(&stand.world),
        );
        let mut runs = Vec::new();
        for profile in [&limp, &capped] {
            stand.world.restore(&world).unwrap();
            (stand.collisions)
                .restore(collisions.as_ref().unwrap(), &stand.world)
                .unwrap();
            let mut frames = Vec::new();
            for _ in 0..10 {
                stand.step_with(profile);
                frames.push(stand.velocities());
            }
            runs.push(frames);
        }
        let apart = (runs[0].iter().flatten().zip(runs[1].iter().flatten()))
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f32::max);
        let [limp, fastest] = [&runs[0], &runs[1]].map(|run| {
            (run.iter().flatten())
                .map(|v| v.length())
                .fold(0.0, f32::max)
        });
        eprintln!(
            "{spine:?}, pins {pins:?}: driven at a zero cap, fastest body {fastest:.3} m/s \
             (limp {limp:.3}), {apart:.2e} m/s from the limp ragdoll's"
        );
        // The capped rows change the solve's round-off and the passes its
        // limits take, and a heap's contacts carry that on (a heap on pins
        // may still be sliding off itself at 0.7 m/s): a throw is metres a
        // second more than the limp ragdoll's.
        assert!(
            fastest < limp + 0.5,
            "{spine:?}, pins {pins:?}: {fastest} m/s, limp {limp} m/s"
        );
    }
}

#[test]
fn switching_at_once_is_measured_against_the_blend() {
    // A switch with no blend puts the whole change of force in one frame:
    // the measure above sees it (this is why the profiles blend).
    let mut stand = Stand::new(SpineMode::Sockets);
    stand.frames(60);
    let chest = stand.chest();
    stand
        .world
        .apply_impulse(chest, Vec3::new(40.0, 0.0, 0.0))
        .unwrap();
    stand.blend.switch_to(stand.profile("limp"), 0.0).unwrap();
    let limp = stand.frames(30);
    stand
        .blend
        .switch_to(stand.profile("standing"), 0.0)
        .unwrap();
    let at_once = stand.frame();
    eprintln!(
        "at once: to limp {:.3} mm, back to standing {:.3} mm",
        limp * 1e3,
        at_once * 1e3
    );
    assert!(
        at_once > 1e-3,
        "{at_once} m: the measure does not see a switch"
    );
}
