//! The calls a game makes on a whole ragdoll: its root transform and
//! bounds against the description's capsules, one velocity that moves it
//! rigidly, an impulse that changes its momentum by itself; refusals
//! change nothing.

use glam::{Quat, Vec3};
use vertebra_ragdoll::{BuildOptions, Pose, Ragdoll, RagdollDesc, RagdollError, SpineMode};
use vertebra_world::{Error, SolverConfig, World};

/// A world without gravity (momentum is then the ragdoll's own).
fn weightless() -> World {
    weightless_with(SolverConfig::default())
}

fn weightless_with(base: SolverConfig) -> World {
    World::new(SolverConfig {
        gravity: Vec3::ZERO,
        ..base
    })
    .unwrap()
}

const PIVOT: Vec3 = Vec3::new(0.0, 1.0, 0.0);
const SHIFT: Vec3 = Vec3::new(2.0, 0.5, -1.0);

fn turn() -> Quat {
    Quat::from_euler(glam::EulerRot::YXZ, 0.7, 0.4, -0.3)
}

/// The humanoid at its bind pose turned by `turn()` about `PIVOT` and
/// moved by `SHIFT`.
fn built(w: &mut World, spine: SpineMode) -> (RagdollDesc, Ragdoll, Pose) {
    let desc = RagdollDesc::reference_humanoid();
    let pose = Pose::bind(&desc).moved(PIVOT, turn(), SHIFT);
    let ragdoll = Ragdoll::build(w, &desc, BuildOptions::new(spine), &pose, None).unwrap();
    (desc, ragdoll, pose)
}

/// The ragdoll's linear momentum (N s): the sum of `m v` over its bodies.
fn momentum(w: &World, ragdoll: &Ragdoll) -> Vec3 {
    ragdoll
        .bodies
        .iter()
        .flatten()
        .map(|&b| w.body(b).unwrap().linear_velocity * w.bodies().mass[b.index()])
        .sum()
}

#[test]
fn the_root_transform_is_the_root_bone_of_the_pose_built() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut w = weightless();
        let (desc, ragdoll, pose) = built(&mut w, spine);
        assert_eq!(ragdoll.root_transform(&w).unwrap(), pose.bones[desc.root]);
    }
}

/// The box around every capsule, from the description's segments moved
/// rigidly as the pose was (endpoints, then the radius): interior spine
/// bones of the simplified ragdoll have no body and are left out.
#[test]
fn the_bounds_hold_every_capsule_and_no_more() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut w = weightless();
        let (desc, ragdoll, _) = built(&mut w, spine);
        let mut expected = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for (def, body) in desc.bodies.iter().zip(&ragdoll.bodies) {
            if body.is_none() {
                continue;
            }
            for end in def.segment {
                let moved = PIVOT + turn() * (end - PIVOT) + SHIFT;
                expected.0 = expected.0.min(moved - Vec3::splat(def.radius));
                expected.1 = expected.1.max(moved + Vec3::splat(def.radius));
            }
        }
        let (low, high) = ragdoll.bounds(&w).unwrap();
        let off = (low - expected.0).abs().max((high - expected.1).abs());
        assert!(off.max_element() < 1e-5, "{spine:?}: off by {off}");
    }
}

/// A velocity set on the whole ragdoll is a rigid motion: the root moves
/// at `linear`, every body spins at `angular`, no two bodies' centres
/// close in or draw apart (`(x_a - x_b) . (v_a - v_b) = 0`), and a step
/// later the joints still hold (nothing strained them).
#[test]
fn a_ragdoll_velocity_moves_it_as_one_rigid_body() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut w = weightless();
        let (desc, ragdoll, _) = built(&mut w, spine);
        let (linear, angular) = (Vec3::new(1.0, 2.0, -0.5), Vec3::new(0.3, -1.2, 0.8));
        ragdoll.set_velocity(&mut w, linear, angular).unwrap();
        let root = w.body(ragdoll.bodies[desc.root].unwrap()).unwrap();
        assert_eq!(
            (root.linear_velocity, root.angular_velocity),
            (linear, angular)
        );
        let states: Vec<_> = ragdoll
            .bodies
            .iter()
            .flatten()
            .map(|&b| w.body(b).unwrap())
            .collect();
        for (k, a) in states.iter().enumerate() {
            assert_eq!(a.angular_velocity, angular);
            for b in &states[k + 1..] {
                let rate = (a.position - b.position).dot(a.linear_velocity - b.linear_velocity);
                assert!(
                    rate.abs() < 1e-5,
                    "{spine:?}: two bodies part at {rate} m^2/s"
                );
            }
        }
        // A step later the joints hold (the default's direct solve: to
        // round-off whatever the velocity).
        w.step(1.0 / 60.0).unwrap();
        let held = w.measure_residuals().eps_lin_cm;
        assert!(held < 1e-4, "{spine:?}: {held} cm of joint error");
        // Iterated, against the same velocity given to the root alone,
        // which the joints must then drag the rest into: a step strains
        // the joints far less.
        let strain = |whole: bool| {
            let mut iterated = weightless_with(SolverConfig::paper());
            let (_, r, _) = built(&mut iterated, spine);
            if whole {
                r.set_velocity(&mut iterated, linear, angular).unwrap();
            } else {
                let root = r.bodies[desc.root].unwrap();
                iterated.set_body_velocity(root, linear, angular).unwrap();
            }
            iterated.step(1.0 / 60.0).unwrap();
            iterated.measure_residuals().eps_lin_cm
        };
        let (rigid, strained) = (strain(true), strain(false));
        assert!(
            rigid < 0.01 && rigid < strained / 20.0,
            "{spine:?}: {rigid} cm of joint error, {strained} cm from the root alone"
        );
    }
}

/// An impulse on the chest of a ragdoll at rest gives the whole ragdoll
/// exactly that momentum, which its joints then share out without
/// changing it (they are internal forces).
#[test]
fn an_impulse_on_a_named_body_is_the_ragdolls_momentum() {
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut w = weightless();
        let (desc, ragdoll, _) = built(&mut w, spine);
        let chest = desc.bodies.iter().position(|b| b.name == "chest").unwrap();
        let at = w.body(ragdoll.bodies[chest].unwrap()).unwrap().position + Vec3::Y * 0.1;
        let impulse = Vec3::new(30.0, 0.0, -12.0);
        ragdoll
            .apply_impulse(&mut w, "chest", impulse, Some(at))
            .unwrap();
        ragdoll
            .apply_impulse(&mut w, "head", impulse, None)
            .unwrap();
        let scale = 2.0 * impulse.length();
        let off = (momentum(&w, &ragdoll) - 2.0 * impulse).length();
        assert!(off < 1e-5 * scale, "{spine:?}: {off} N s off at once");
        for _ in 0..30 {
            w.step(1.0 / 60.0).unwrap();
        }
        let off = (momentum(&w, &ragdoll) - 2.0 * impulse).length();
        assert!(
            off < 1e-3 * scale,
            "{spine:?}: {off} N s off after the joints"
        );
    }
}

/// Each refused call gives its error and changes nothing (the world's
/// state hash).
#[test]
fn refused_ragdoll_calls_change_nothing() {
    let mut w = weightless();
    let (desc, ragdoll, _) = built(&mut w, SpineMode::Rod);
    let interior = &desc.bodies[desc.spine.as_ref().unwrap().bodies[1]].name;
    let before = w.state_hash();
    let nan = Vec3::new(f32::NAN, 0.0, 0.0);
    let unknown = |name: &str, context: &str| RagdollError::UnknownBody {
        context: context.to_owned(),
        field: "body",
        name: name.to_owned(),
    };
    assert_eq!(
        ragdoll.apply_impulse(&mut w, "tail", Vec3::X, None),
        Err(unknown("tail", "impulse"))
    );
    assert_eq!(
        ragdoll.apply_impulse(&mut w, interior, Vec3::X, None),
        Err(unknown(
            interior,
            "impulse (an interior spine bone of a simplified ragdoll has no body)"
        ))
    );
    assert_eq!(
        ragdoll.apply_impulse(&mut w, "head", nan, None),
        Err(RagdollError::World {
            context: "body `head`".to_owned(),
            error: Error::NonFinite("impulse"),
        })
    );
    assert_eq!(
        ragdoll.set_velocity(&mut w, Vec3::X, nan),
        Err(RagdollError::NonFinite {
            context: "ragdoll velocity".to_owned(),
            field: "angular velocity",
        })
    );
    // A velocity so large that a body's, the root's plus its spin about
    // the root (a leg's is 1e38 times at least 0.1 m), overflows: no body,
    // the root included, takes any of it.
    let refused = ragdoll.set_velocity(&mut w, Vec3::splat(3.3e38), Vec3::splat(1.0e38));
    assert!(
        matches!(
            &refused,
            Err(RagdollError::OutOfRange {
                field: "velocity",
                ..
            })
        ),
        "{refused:?}"
    );
    assert_eq!(w.state_hash(), before);
    // A removed ragdoll has no root, no bounds and no velocity to set.
    let mut gone = ragdoll.clone();
    gone.remove(&mut w).unwrap();
    let removed = w.state_hash();
    let no_root = RagdollError::Removed {
        ragdoll: "reference-humanoid".to_owned(),
    };
    assert_eq!(gone.root_transform(&w), Err(no_root.clone()));
    assert_eq!(gone.bounds(&w), Err(no_root.clone()));
    assert_eq!(gone.set_velocity(&mut w, Vec3::X, Vec3::ZERO), Err(no_root));
    // The ragdoll whose bodies went behind its back names the root.
    assert!(ragdoll.set_velocity(&mut w, Vec3::X, Vec3::ZERO).is_err());
    assert_eq!(w.state_hash(), removed);
}
