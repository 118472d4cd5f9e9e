//! The rod's soft bend and twist as drives, against the damped oscillator
//! they claim to be: a spring at `f` Hz oscillates at `f` in bending and in
//! twisting whatever the masses; damping decays each period as the closed
//! form says; a torque cap lets a hit through and the rod recovers.
//!
//! The rig: a static base and a ball 0.4 m above it on a straight rod, no
//! gravity. Bending turns the ball about +Z and carries it round the arc
//! (the rod's effective inertia in bending is `I + m l0^2 / 4`,
//! `vertebra_kernels::parts::rod::drive`); twisting turns it about +Y, the
//! rod's axis (effective inertia `I`).

use core::f32::consts::TAU;

use glam::Vec3;
use vertebra_world::{BodyDesc, BodyHandle, RodDesc, RodStiffness, Shape, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;
const SUBSTEPS: u32 = 10;
const LENGTH: f32 = 0.4;
const RADIUS: f32 = 0.08;

/// The base, the ball of `mass` kg on a rod of `stiffness` (bending and
/// twisting) capped at `max_torque`.
fn rig(mass: f32, stiffness: RodStiffness, max_torque: f32) -> (World, BodyHandle) {
    let mut w = World::new(SolverConfig {
        substeps: SUBSTEPS,
        iterations: 10,
        gravity: Vec3::ZERO,
        // The spring's own response: a 0.2 rad twist of the ball moves its
        // mass by 1 cm, and it would sleep.
        sleep: None,
        ..SolverConfig::default()
    })
    .unwrap();
    let base = w.add_body(BodyDesc::fixed()).unwrap();
    let props = Shape::Sphere { radius: RADIUS }
        .mass_properties_with_mass(mass)
        .unwrap();
    let ball = w
        .add_body(BodyDesc::dynamic(props).with_position(Vec3::Y * LENGTH))
        .unwrap();
    let rod = RodDesc::from_pose(w.bodies(), base, ball, &[])
        .unwrap()
        .with_stiffness(stiffness, stiffness)
        .with_max_torque(max_torque);
    w.add_rod(rod).unwrap();
    (w, ball)
}

/// The ball's turn about `axis` (rad).
fn angle(w: &World, ball: BodyHandle, axis: Vec3) -> f32 {
    let q = w.body(ball).unwrap().orientation;
    2.0 * Vec3::new(q.x, q.y, q.z).dot(axis).atan2(q.w)
}

/// Effective inertia of bending (`I + m l0^2 / 4`, held base) and of
/// twisting (`I`), kg m^2.
fn inertia(mass: f32, axis: Vec3) -> f32 {
    let i = 0.4 * mass * RADIUS * RADIUS;
    if axis == Vec3::Z {
        i + mass * LENGTH * LENGTH / 4.0
    } else {
        i
    }
}

/// The turn about `axis` after an angular impulse about it that would swing
/// a `frequency` Hz oscillator of inertia `j` by 0.2 rad, frame by frame for
/// `seconds`.
fn response(
    mut w: World,
    ball: BodyHandle,
    axis: Vec3,
    [frequency, j]: [f32; 2],
    seconds: f32,
) -> Vec<f32> {
    w.apply_angular_impulse(ball, axis * 0.2 * TAU * frequency * j)
        .unwrap();
    (0..(seconds / DT) as usize)
        .map(|_| {
            w.step(DT).unwrap();
            angle(&w, ball, axis)
        })
        .collect()
}

/// The mean period (s) between upward zero crossings, interpolated.
fn period(x: &[f32]) -> f32 {
    let ups: Vec<f32> = (1..x.len())
        .filter(|&k| x[k - 1] < 0.0 && x[k] >= 0.0)
        .map(|k| (k - 1) as f32 + x[k - 1] / (x[k - 1] - x[k]))
        .collect();
    assert!(ups.len() >= 3, "oscillates: {} crossings", ups.len());
    (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f32 * DT
}

/// The positive peaks, in order.
fn peaks(x: &[f32]) -> Vec<f32> {
    (1..x.len() - 1)
        .filter(|&k| x[k] > 0.0 && x[k] >= x[k - 1] && x[k] > x[k + 1])
        .map(|k| x[k])
        .collect()
}

#[test]
fn a_sprung_rod_oscillates_at_its_frequency_in_bending_and_twisting() {
    for axis in [Vec3::Z, Vec3::Y] {
        for mass in [0.5, 5.0, 50.0] {
            for frequency in [1.0f32, 3.0] {
                let spring = RodStiffness::Spring {
                    frequency,
                    damping_ratio: 0.0,
                };
                let (w, ball) = rig(mass, spring, f32::INFINITY);
                let hit = [frequency, inertia(mass, axis)];
                let measured = 1.0 / period(&response(w, ball, axis, hit, 4.0));
                eprintln!("{axis} {mass} kg {frequency} Hz: {measured:.4} Hz");
                assert!(
                    (measured / frequency - 1.0).abs() < 0.02,
                    "{axis}, {mass} kg: {measured} Hz for {frequency} Hz"
                );
            }
        }
    }
}

/// The decay per period of a damped oscillator of ratio `zeta`.
fn decay(zeta: f32) -> f32 {
    (-TAU * zeta / (1.0 - zeta * zeta).sqrt()).exp()
}

#[test]
fn damping_decays_each_period_as_the_damped_oscillator() {
    // Kirchhoff stiffness and damping: K = k / l0, D = d / l0 on the
    // effective inertia J give zeta = D / (2 sqrt(K J)). Implicit Euler
    // adds about omega h / 2 = 0.006 at 2 Hz and 600 substeps/s.
    let mass = 5.0;
    for axis in [Vec3::Z, Vec3::Y] {
        let j = inertia(mass, axis);
        let stiffness = j * (TAU * 2.0f32).powi(2) * LENGTH;
        for zeta in [0.0f32, 0.05, 0.2] {
            let damping = 2.0 * zeta * (stiffness / LENGTH * j).sqrt() * LENGTH;
            let (w, ball) = rig(
                mass,
                RodStiffness::Damped { stiffness, damping },
                f32::INFINITY,
            );
            let p = peaks(&response(w, ball, axis, [2.0, j], 2.0));
            let measured = p[2] / p[1];
            eprintln!(
                "{axis} zeta {zeta}: {measured:.4} per period, closed form {:.4}",
                decay(zeta)
            );
            assert!(
                measured <= decay(zeta) && measured >= decay(zeta + 0.015),
                "{axis} zeta {zeta}: {measured} per period, closed form {}",
                decay(zeta)
            );
        }
        // The frequency form's ratio is the same oscillator's.
        let spring = RodStiffness::Spring {
            frequency: 2.0,
            damping_ratio: 0.2,
        };
        let (w, ball) = rig(mass, spring, f32::INFINITY);
        let p = peaks(&response(w, ball, axis, [2.0, j], 2.0));
        let measured = p[2] / p[1];
        assert!(
            measured <= decay(0.2) && measured >= decay(0.215),
            "{axis} spring zeta 0.2: {measured} per period"
        );
    }
}

#[test]
fn a_torque_cap_lets_a_hit_through_and_the_rod_recovers() {
    // A 5 Hz critically damped rod; on the ball for 0.25 s a torque of
    // 20 rad/s^2 times the part's effective inertia J; the cap at half.
    for axis in [Vec3::Z, Vec3::Y] {
        let j = inertia(5.0, axis);
        let torque = 20.0 * j;
        let mut largest = Vec::new();
        for cap in [f32::INFINITY, torque / 2.0] {
            let spring = RodStiffness::Spring {
                frequency: 5.0,
                damping_ratio: 1.0,
            };
            let (mut w, ball) = rig(5.0, spring, cap);
            let mut peak = 0.0f32;
            for frame in 0..240 {
                if frame < 15 {
                    w.add_torque(ball, axis * torque).unwrap();
                }
                w.step(DT).unwrap();
                peak = peak.max(angle(&w, ball, axis).abs());
            }
            let after = angle(&w, ball, axis).abs();
            eprintln!("{axis} cap {cap} N m: peak {peak:.4} rad, 3.75 s later {after:.2e}");
            assert!(after < 1e-3, "{axis} cap {cap}: recovers ({after} rad)");
            largest.push(peak);
        }
        // Uncapped, the critically damped spring turns no further than the
        // static torque / K (K = J omega^2: 0.020 rad); capped at half the
        // torque, the net half turns the ball by at least half of what it
        // would turn a free ball over 0.25 s, 1/2 (10 rad/s^2) t^2 = 0.31 rad.
        let still = torque / (j * (TAU * 5.0).powi(2));
        let free = 0.5 * 10.0 * 0.25f32.powi(2);
        assert!(
            largest[0] < 1.02 * still,
            "{axis}: uncapped {largest:?}, static {still}"
        );
        assert!(
            largest[1] > 0.5 * free,
            "{axis}: capped {largest:?}, free {free}"
        );
    }
}
