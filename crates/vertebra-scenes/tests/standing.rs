//! A powered ragdoll that stands with nothing kinematic: the anatomical
//! humanoid on flat ground, following a standing animation with its
//! joints' drives and capped world drives (`Ragdoll::follow`), whose force
//! caps together stay at half its weight: it stands by balancing on its
//! legs, a hard shove staggers it and it recovers, and a harder one fells
//! it (the caps hold).

use core::f32::consts::FRAC_PI_2;

use glam::{Quat, Vec3};
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_ragdoll::{
    BuildOptions, DriveSettings, PhysicalAnimation, Pose, Ragdoll, RagdollDesc, SpineMode, Upright,
    WorldDriveSettings,
};
use vertebra_world::{BodyDesc, BodyHandle, PinContacts, SolverConfig, Spring, World};

const DT: f32 = 1.0 / 60.0;
const G: f32 = 9.81;
/// The frame whose step a hit precedes.
const HIT_FRAME: usize = 120;

fn critical(frequency: f32) -> Spring {
    Spring::Frequency {
        frequency,
        damping_ratio: 1.0,
    }
}

/// The settings under test: joints at 8 Hz (300 N m caps), every body
/// pulled toward its pose at 2 Hz with a force cap of half its weight and
/// 20 N m, hips and chest kept upright (100 N m).
fn animation(desc: &RagdollDesc) -> PhysicalAnimation {
    let upright = |name: &str| Upright {
        body: desc.body_index(name).expect("a shipped body"),
        strength: critical(2.0),
        max_torque: 100.0,
    };
    PhysicalAnimation {
        joints: DriveSettings::uniform(critical(8.0)).with_max_torque(300.0),
        world: WorldDriveSettings {
            linear: Some(critical(2.0)),
            angular: Some(critical(2.0)),
            max_acceleration: 0.5 * G,
            max_torque: 20.0,
            uprights: vec![upright("hips"), upright("chest")],
        },
    }
}

struct Stand {
    world: World,
    collisions: Collisions,
    ragdoll: Ragdoll,
    pose: Pose,
    animation: PhysicalAnimation,
    hips: BodyHandle,
    chest: BodyHandle,
    start: Vec3,
}

impl Stand {
    /// The anatomical humanoid at its bind pose (standing, arms out), its
    /// lowest point 1 mm above the ground, at the default solver settings
    /// with a driven ragdoll's contacts with the ground pinned
    /// (`PinContacts::Driven`: its 1 kg feet need them).
    fn new(spine: SpineMode) -> Self {
        let desc = RagdollDesc::anatomical_humanoid();
        let config = SolverConfig {
            pin_contacts: PinContacts::Driven,
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
        let animation = animation(&desc);
        let body = |name| ragdoll.bodies[desc.body_index(name).unwrap()].unwrap();
        let (hips, chest) = (body("hips"), body("chest"));
        let start = world.body(hips).unwrap().position;
        Self {
            world,
            collisions,
            ragdoll,
            pose,
            animation,
            hips,
            chest,
            start,
        }
    }

    /// One frame: the standing animation followed, then the step.
    fn frame(&mut self) {
        let pose = (&self.pose, &self.pose);
        (self.ragdoll)
            .follow(&mut self.world, pose, DT, &self.animation)
            .unwrap();
        self.collisions.step(&mut self.world, DT).unwrap();
    }

    fn hips(&self) -> Vec3 {
        self.world.body(self.hips).unwrap().position
    }

    /// A hit of `impulse` (N s, world) on the chest before frame
    /// [`HIT_FRAME`]; then `seconds` more. Returns the hips' lowest height
    /// (m) after the hit and the time (s) from the hit until the hips stay
    /// within 2 cm of where they stood.
    fn hit(&mut self, impulse: Vec3, seconds: f32) -> (f32, Option<f32>) {
        for _ in 0..HIT_FRAME {
            self.frame();
        }
        self.world.apply_impulse(self.chest, impulse).unwrap();
        let (mut low, mut back) = (f32::MAX, None);
        for f in 0..(seconds / DT) as usize {
            self.frame();
            let hips = self.hips();
            low = low.min(hips.y);
            let near = (hips - self.start).length() < 0.02;
            back = match (near, back) {
                (false, _) => None,
                (true, None) => Some((f + 1) as f32 * DT),
                (true, kept) => kept,
            };
        }
        (low, back)
    }
}

#[test]
fn the_world_drives_caps_stay_under_the_ragdolls_weight() {
    let stand = Stand::new(SpineMode::Sockets);
    let world = &stand.world;
    let mass: f32 = (stand.ragdoll.bodies.iter().flatten())
        .map(|b| world.bodies().mass[b.index()])
        .sum();
    let mut stand = stand;
    stand.frame();
    let caps: f32 = (stand.ragdoll.bodies.iter().flatten())
        .map(|&b| stand.world.world_drive(b).unwrap().unwrap().max_force)
        .sum();
    eprintln!(
        "force caps {caps:.1} N against a weight of {:.1} N",
        mass * G
    );
    assert!(caps <= 0.5 * mass * G * 1.0001, "{caps} N");
}

#[test]
fn it_stands_for_a_minute_with_nothing_kinematic() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut stand = Stand::new(spine);
        let mut worst: f32 = 0.0;
        for _ in 0..60 * 60 {
            stand.frame();
            worst = worst.max((stand.hips() - stand.start).length());
        }
        eprintln!("{spine:?}: hips within {:.2} cm over 60 s", worst * 100.0);
        assert!(worst < 0.02, "{spine:?}: {worst} m");
    }
}

#[test]
fn a_hard_shove_staggers_it_and_it_recovers_within_a_second() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        for k in 0..4 {
            let turn = Quat::from_rotation_y(FRAC_PI_2 * k as f32);
            let impulse = turn * Vec3::new(40.0, 0.0, 0.0);
            let mut stand = Stand::new(spine);
            let standing = stand.start.y;
            let (low, back) = stand.hit(impulse, 3.0);
            eprintln!(
                "{spine:?}, 40 N s toward {impulse}: hips down to {low:.3} m, back in {back:?} s"
            );
            assert!(low > 0.9 * standing, "{spine:?} {impulse}: fell to {low} m");
            assert!(
                back.is_some_and(|t| t < 1.0),
                "{spine:?} {impulse}: {back:?}"
            );
        }
    }
}

#[test]
fn a_hit_beyond_the_caps_fells_it() {
    let mut stand = Stand::new(SpineMode::Sockets);
    let (low, back) = stand.hit(Vec3::new(150.0, 0.0, 0.0), 3.0);
    eprintln!("150 N s: hips down to {low:.3} m, back in {back:?} s");
    assert!(
        low < 0.5,
        "held up at {low} m by drives that should give way"
    );
}

/// A standing ragdoll beside a pile of limp ones, in one world with a
/// driven ragdoll's contacts pinned (`PinContacts::Driven`), for 20 s:
/// the driven one's contacts are pins, so it stands on its 1 kg feet
/// (iterated, `Never`, they sink and slide, and it falls within 20 s); the
/// limp ones' stay iterated, so the pile holds its joints within 2
/// degrees of their limits as it lands and settles (`Always`: this pile's
/// rod spines go 15.7 degrees past; `docs/direct.md`, "Which trees take
/// pins").
#[test]
fn a_standing_ragdoll_and_a_landing_pile_share_one_world_on_driven_pins() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut stand = Stand::new(spine);
        let desc = RagdollDesc::anatomical_humanoid();
        for k in 0..8 {
            // Lying, each turned further about the vertical, one above
            // another: they land on each other.
            let turn = Quat::from_rotation_y(2.3 * k as f32) * Quat::from_rotation_x(FRAC_PI_2);
            let pivot = Vec3::new(0.0, 1.0, 0.0);
            let to = Vec3::new(2.0, 0.4 + 0.45 * k as f32, 0.0) - pivot;
            let pose = Pose::bind(&desc).moved(pivot, turn, to);
            let options = BuildOptions::new(spine);
            let limp = Ragdoll::build(&mut stand.world, &desc, options, &pose, None).unwrap();
            stand.collisions.add_ragdoll(&limp).unwrap();
        }
        let (mut worst, mut past) = (0.0f32, 0.0f32);
        for _ in 0..20 * 60 {
            stand.frame();
            worst = worst.max((stand.hips() - stand.start).length());
            let residuals = stand.world.measure_residuals();
            let joints = residuals.joints.iter().map(|j| j.limit_rad);
            let limits = joints.chain(residuals.rods.iter().map(|r| r.limit_rad));
            past = past.max(limits.fold(0.0, f32::max));
        }
        let past = past.to_degrees();
        eprintln!(
            "{spine:?}: hips within {:.2} cm; a joint at most {past:.2} degrees past its limit",
            worst * 100.0
        );
        assert!(
            worst < 0.02,
            "{spine:?}: the standing ragdoll's hips {worst} m off"
        );
        assert!(
            past < 2.0,
            "{spine:?}: a joint {past} degrees past its limit"
        );
    }
}
