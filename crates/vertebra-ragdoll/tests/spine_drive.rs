//! The rod spine driven as the socket spine is: drive damping damps a hit
//! on the chest, and at the same `DriveSettings` the two spines deflect
//! alike under a static torque (the mapping `k = l0 / (n c)`,
//! `d = l0 D / n` of sockets in series, `docs/ragdolls.md`, "Drives").
//!
//! The rig: the reference humanoid at its bind pose, hips held by a static
//! body and a rigid socket drive (as the controllability scene holds them),
//! no gravity, every joint driven to the bind pose. The chest's turn about
//! an axis is measured from its target orientation.

use core::f32::consts::TAU;

use glam::{Quat, Vec3};
use vertebra_ragdoll::{BuildOptions, DriveSettings, Pose, Ragdoll, RagdollDesc, SpineMode};
use vertebra_world::{AngularDrive, BodyDesc, BodyHandle, JointDesc, SolverConfig, Spring, World};

const DT: f32 = 1.0 / 60.0;
/// Compliance of every drive (rad / (N m)).
const COMPLIANCE: f32 = 0.01;
/// The spine's sockets, which the rod replaces.
const SPINE_JOINTS: f32 = 3.0;

struct Rig {
    world: World,
    chest: BodyHandle,
    target: Quat,
}

fn rig(spine: SpineMode, settings: &DriveSettings) -> Rig {
    let desc = RagdollDesc::reference_humanoid();
    let mut world = World::new(SolverConfig {
        substeps: 4,
        iterations: 20,
        gravity: Vec3::ZERO,
        // The oscillation is measured to its end (a small one would sleep).
        sleep: None,
        ..SolverConfig::default()
    })
    .unwrap();
    let pose = Pose::bind(&desc);
    let ragdoll = Ragdoll::build(&mut world, &desc, BuildOptions::new(spine), &pose, None).unwrap();
    let hips = ragdoll.bodies[desc.root].unwrap();
    let at = pose.bones[desc.root].0;
    let anchor = world.add_body(BodyDesc::fixed().with_position(at)).unwrap();
    let pin = JointDesc::socket_at_world_anchor(world.bodies(), anchor, hips, at, Vec3::Y).unwrap();
    world
        .add_joint(pin.with_drive(AngularDrive::rigid(Quat::IDENTITY)))
        .unwrap();
    ragdoll.drive_to(&mut world, &pose, settings).unwrap();
    let chest = desc.body_index("chest").unwrap();
    Rig {
        world,
        chest: ragdoll.bodies[chest].unwrap(),
        target: pose.bones[chest].1,
    }
}

impl Rig {
    /// The chest's turn from its target about `axis` (rad).
    fn turn(&self, axis: Vec3) -> f32 {
        let q = self.world.body(self.chest).unwrap().orientation * self.target.inverse();
        2.0 * Vec3::new(q.x, q.y, q.z).dot(axis).atan2(q.w)
    }

    /// The chest's turn about +X, frame by frame for `seconds`, after a hit
    /// of 10 N s along +Z on the chest.
    fn hit(mut self, seconds: f32) -> Vec<f32> {
        self.world
            .apply_impulse(self.chest, Vec3::new(0.0, 0.0, 10.0))
            .unwrap();
        (0..(seconds / DT) as usize)
            .map(|_| {
                self.world.step(DT).unwrap();
                self.turn(Vec3::X)
            })
            .collect()
    }
}

fn compliant(damping: f32) -> DriveSettings {
    DriveSettings::uniform(Spring::Compliance {
        compliance: COMPLIANCE,
        damping,
    })
}

/// The extremes (peaks and troughs, by magnitude) of an oscillation, in
/// order, with their frames.
fn extremes(x: &[f32]) -> Vec<(usize, f32)> {
    (1..x.len() - 1)
        .filter(|&k| x[k].abs() >= x[k - 1].abs() && x[k].abs() > x[k + 1].abs())
        .map(|k| (k, x[k].abs()))
        .collect()
}

/// The first frame after which `x` stays within `band` (rad).
fn settle(x: &[f32], band: f32) -> usize {
    x.iter().rposition(|v| v.abs() > band).map_or(0, |k| k + 1)
}

#[test]
fn drive_damping_damps_a_chest_hit_on_the_rod_spine() {
    // The chest's bending on the rod spine is a damped oscillator of
    // stiffness K = 1 / (n c) and damping D / n (n sockets of compliance c
    // and damping D in series), so zeta = c D omega0 / 2 whatever the
    // inertia, omega0 the undamped frequency. Measured undamped, the
    // closed form gives the damped run's decay per half period,
    // exp(-pi zeta / sqrt(1 - zeta^2)).
    let free = rig(SpineMode::Rod, &compliant(0.0)).hit(3.0);
    let e = extremes(&free);
    let half_period = (e[3].0 - e[1].0) as f32 / 2.0 * DT;
    let omega0 = TAU / (2.0 * half_period);
    let zeta = 0.3f32;
    let damping = 2.0 * zeta / (COMPLIANCE * omega0);
    let damped = rig(SpineMode::Rod, &compliant(damping)).hit(3.0);
    let d = extremes(&damped);
    let undamped_decay = e[2].1 / e[1].1;
    let decay = d[2].1 / d[1].1;
    let closed = (-core::f32::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp();
    let peak = |x: &[f32]| x.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    eprintln!(
        "rod spine, chest hit: omega0 {omega0:.2} rad/s; damping 0: peak {:.4} rad, \
         decay per half period {undamped_decay:.3}; damping {damping:.2} N m s/rad \
         (zeta {zeta}): peak {:.4} rad, decay {decay:.3}, closed form {closed:.3}",
        peak(&free),
        peak(&damped)
    );
    assert!(
        undamped_decay > 0.85,
        "undamped keeps swinging: {undamped_decay}"
    );
    assert!(
        (decay / closed - 1.0).abs() < 0.25,
        "damped decay {decay} per half period, closed form {closed}"
    );
    assert!(
        peak(&damped) < 0.9 * peak(&free),
        "damping lowers the peak: {} vs {}",
        peak(&damped),
        peak(&free)
    );
}

impl Rig {
    /// The chest's turn about `axis` after `seconds` under a constant
    /// `torque` (N m) about it.
    fn held(mut self, axis: Vec3, torque: f32, seconds: f32) -> f32 {
        for _ in 0..(seconds / DT) as usize {
            self.world.add_torque(self.chest, axis * torque).unwrap();
            self.world.step(DT).unwrap();
        }
        self.turn(axis)
    }
}

#[test]
fn rod_and_socket_spines_driven_alike_deflect_alike() {
    // Under a static torque tau on the chest every spine socket carries
    // tau and turns by c tau, the chain by n c tau; the rod, of stiffness
    // k = l0 / (n c), turns by (l0 / k) tau: the same. Twisting alike (the
    // spine's sockets twist about nearly one axis). Damped near critical
    // to settle; 5 N m, 4 s.
    let torque = 5.0;
    let settings = compliant(50.0);
    let closed = SPINE_JOINTS * COMPLIANCE * torque;
    for (axis, what) in [(Vec3::X, "bend"), (Vec3::Y, "twist")] {
        let sockets = rig(SpineMode::Sockets, &settings).held(axis, torque, 4.0);
        let rod = rig(SpineMode::Rod, &settings).held(axis, torque, 4.0);
        eprintln!("{what}: sockets {sockets:.4} rad, rod {rod:.4} rad, n c tau {closed:.4} rad");
        for (spine, turn) in [("sockets", sockets), ("rod", rod)] {
            assert!(
                (turn / closed - 1.0).abs() < 0.2,
                "{what}, {spine}: {turn} rad, n c tau {closed}"
            );
        }
        assert!(
            (rod / sockets - 1.0).abs() < 0.2,
            "{what}: rod {rod} vs sockets {sockets}"
        );
    }
    // The same chest hit at zeta ~ 0.3 (on the rod's mode): figures only,
    // for docs/ragdolls.md.
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let x = rig(spine, &compliant(15.76)).hit(4.0);
        let peak = x.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        let settled = settle(&x, 0.01) as f32 * DT;
        eprintln!("{spine:?} hit: peak {peak:.4} rad, within 0.01 rad after {settled:.2} s");
    }
}
