//! A ragdoll's world drives (`Ragdoll::world_drive_following`,
//! `Ragdoll::follow`): rigid ones put every body on the animation's pose
//! as each step ends, uprights hold the axis the animation has up, and a
//! refused call names the field and changes nothing.

mod common;

use glam::{Quat, Vec3};
use vertebra_ragdoll::{
    BuildOptions, DriveSettings, PhysicalAnimation, Ragdoll, RagdollDesc, RagdollError, SpineMode,
    Upright, WorldDriveSettings,
};
use vertebra_world::{SolverConfig, Spring, World};

const DT: f32 = 1.0 / 60.0;

fn settings(desc: &RagdollDesc) -> WorldDriveSettings {
    WorldDriveSettings {
        linear: Some(Spring::RIGID),
        angular: Some(Spring::RIGID),
        max_acceleration: f32::INFINITY,
        max_torque: f32::INFINITY,
        uprights: vec![Upright {
            body: desc.body_index("chest").unwrap(),
            strength: Spring::RIGID,
            max_torque: 50.0,
        }],
    }
}

#[test]
fn rigid_world_drives_put_every_body_on_the_animation_as_each_step_ends() {
    let desc = RagdollDesc::reference_humanoid();
    for spine in [SpineMode::Sockets, SpineMode::Rod] {
        let mut world = World::new(SolverConfig {
            gravity: Vec3::ZERO,
            ..SolverConfig::default()
        })
        .unwrap();
        let first = common::walking(&desc, 0.0);
        let options = BuildOptions::new(spine);
        let ragdoll = Ragdoll::build(&mut world, &desc, options, &first, None).unwrap();
        let animation = PhysicalAnimation {
            joints: DriveSettings::uniform(Spring::RIGID),
            world: settings(&desc),
        };
        let mut prev = first;
        let mut worst: (f32, f32) = (0.0, 0.0);
        for k in 1..=60 {
            let pose = common::walking(&desc, k as f32 * DT);
            ragdoll
                .follow(&mut world, (&prev, &pose), DT, &animation)
                .unwrap();
            world.step(DT).unwrap();
            for (b, body) in ragdoll.bodies.iter().enumerate() {
                let Some(body) = body else { continue };
                let state = world.body(*body).unwrap();
                let (at, turn) = pose.bones[b];
                worst.0 = worst.0.max((state.position - at).length());
                worst.1 = worst.1.max(common::angle(state.orientation, turn));
            }
            prev = pose;
        }
        eprintln!(
            "{spine:?}: within {:.1e} m and {:.1e} rad of the walk",
            worst.0, worst.1
        );
        assert!(worst.0 < 1e-4 && worst.1 < 1e-3, "{spine:?}: {worst:?}");
    }
}

#[test]
fn an_upright_holds_the_axis_the_animation_has_up() {
    let desc = RagdollDesc::reference_humanoid();
    let mut world = World::new(SolverConfig::default()).unwrap();
    let pose = common::walking(&desc, 0.3);
    let options = BuildOptions::new(SpineMode::Sockets);
    let ragdoll = Ragdoll::build(&mut world, &desc, options, &pose, None).unwrap();
    ragdoll
        .world_drive_to(&mut world, &pose, &settings(&desc))
        .unwrap();
    let chest = desc.body_index("chest").unwrap();
    for (b, body) in ragdoll.bodies.iter().enumerate() {
        let upright = world.upright_drive(body.unwrap()).unwrap();
        assert_eq!(upright.is_some(), b == chest, "body {b}");
        if let Some(u) = upright {
            let up = pose.bones[b].1 * u.axis;
            assert!((up - Vec3::Y).length() < 1e-5, "{up}");
        }
    }
    ragdoll.release_world_drives(&mut world).unwrap();
    for body in ragdoll.bodies.iter().flatten() {
        assert_eq!(world.world_drive(*body).unwrap(), None);
        assert_eq!(world.upright_drive(*body).unwrap(), None);
    }
}

#[test]
fn refused_world_drives_name_the_field_and_change_nothing() {
    let desc = RagdollDesc::reference_humanoid();
    let mut world = World::new(SolverConfig::default()).unwrap();
    let pose = common::walking(&desc, 0.0);
    let options = BuildOptions::new(SpineMode::Sockets);
    let ragdoll = Ragdoll::build(&mut world, &desc, options, &pose, None).unwrap();
    let good = settings(&desc);
    ragdoll.world_drive_to(&mut world, &pose, &good).unwrap();
    let hash = world.state_hash();
    let upright = good.uprights[0];
    let cases = [
        (
            WorldDriveSettings {
                max_acceleration: f32::NAN,
                ..good.clone()
            },
            "max_acceleration",
        ),
        (
            WorldDriveSettings {
                max_torque: -1.0,
                ..good.clone()
            },
            "max_torque",
        ),
        (
            WorldDriveSettings {
                linear: Some(Spring::Frequency {
                    frequency: 0.0,
                    damping_ratio: 1.0,
                }),
                ..good.clone()
            },
            "linear",
        ),
        (
            WorldDriveSettings {
                uprights: vec![Upright {
                    body: 99,
                    ..upright
                }],
                ..good.clone()
            },
            "body",
        ),
        (
            WorldDriveSettings {
                uprights: vec![upright, upright],
                ..good.clone()
            },
            "body",
        ),
    ];
    let far = common::walking(&desc, 0.0).moved(Vec3::ZERO, Quat::IDENTITY, Vec3::X * 1e5);
    for (settings, field) in cases {
        let refused = ragdoll.world_drive_following(&mut world, &pose, &far, DT, &settings);
        let Err(RagdollError::OutOfRange { field: named, .. }) = refused else {
            panic!("{field}: {refused:?}");
        };
        assert_eq!(named, field);
        assert_eq!(world.state_hash(), hash, "{field}");
    }
    // A target too fast for the world: every body's drive is made and
    // checked before any is set.
    let refused = ragdoll.world_drive_following(&mut world, &pose, &far, 1e-6, &good);
    assert!(
        matches!(refused, Err(RagdollError::World { .. })),
        "{refused:?}"
    );
    assert_eq!(world.state_hash(), hash);
    // `follow` makes and checks the bodies' drives before it drives the
    // joints: the same refusal leaves the joints' drives as they were.
    let animation = PhysicalAnimation {
        joints: DriveSettings::uniform(Spring::RIGID),
        world: good.clone(),
    };
    let refused = ragdoll.follow(&mut world, (&pose, &far), 1e-6, &animation);
    assert!(
        matches!(refused, Err(RagdollError::World { .. })),
        "{refused:?}"
    );
    assert_eq!(world.state_hash(), hash);
    let zero_dt = ragdoll.world_drive_following(&mut world, &pose, &pose, 0.0, &good);
    assert!(matches!(
        zero_dt,
        Err(RagdollError::OutOfRange { field: "dt", .. })
    ));
    assert_eq!(world.state_hash(), hash);
}
