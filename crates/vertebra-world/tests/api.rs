//! Bad input gets a clear error, never a panic, and a rejected call leaves
//! the world exactly as it was.

mod common;

use common::capsule;
use glam::{Mat3, Quat, Vec3};
use vertebra_world::{
    AngularDrive, BackendChoice, BodyDesc, Error, JointDesc, JointKind, LimitSoftness,
    MAX_DRIVE_DAMPING_RATIO, MIN_DRIVE_FREQUENCY, MassProperties, Shape, SolverConfig, Spring,
    SpringField, Swing, SwingTwist, World,
};

fn unit_mass() -> MassProperties {
    Shape::Sphere { radius: 0.1 }
        .mass_properties_with_mass(1.0)
        .unwrap()
}

/// A small world with two joined bodies, stepped once.
fn world() -> (
    World,
    vertebra_world::BodyHandle,
    vertebra_world::BodyHandle,
    vertebra_world::JointHandle,
) {
    let mut w = World::new(SolverConfig::default()).unwrap();
    let a = w.add_body(BodyDesc::fixed()).unwrap();
    let b = capsule(&mut w, Vec3::ZERO, -Vec3::Y * 0.4, 1.0);
    let s = w
        .add_joint(
            JointDesc::socket_at_world_anchor(w.bodies(), a, b, Vec3::ZERO, -Vec3::Y).unwrap(),
        )
        .unwrap();
    w.step(1.0 / 60.0).unwrap();
    (w, a, b, s)
}

/// Runs `bad`, expects `expected`, and checks nothing changed: the state
/// hash, the counts, and the next step's result.
fn rejected(expected: Error, bad: impl FnOnce(&mut World) -> Result<(), Error>) {
    rejected_after(|_| (), expected, |w, ()| bad(w));
}

/// [`rejected`], after `prepare` (adding the bodies the refused call
/// names, say) ran on the world and on the reference alike.
fn rejected_after<T>(
    prepare: impl Fn(&mut World) -> T,
    expected: Error,
    bad: impl FnOnce(&mut World, T) -> Result<(), Error>,
) {
    let (mut w, ..) = world();
    let (mut reference, ..) = world();
    let prepared = prepare(&mut w);
    prepare(&mut reference);
    let before = (w.state_hash(), w.bodies().len());
    assert_eq!(
        bad(&mut w, prepared),
        Err(expected.clone()),
        "expected {expected}"
    );
    assert_eq!(
        (w.state_hash(), w.bodies().len()),
        before,
        "a rejected call changed the world"
    );
    w.step(1.0 / 60.0).unwrap();
    reference.step(1.0 / 60.0).unwrap();
    assert_eq!(
        w.state_hash(),
        reference.state_hash(),
        "the world steps on as if nothing happened"
    );
    assert!(!expected.to_string().is_empty());
}

#[test]
fn bad_bodies_are_refused_with_the_field_named() {
    let nan = f32::NAN;
    rejected(Error::NonFinite("position"), |w| {
        w.add_body(BodyDesc::dynamic(unit_mass()).with_position(Vec3::new(nan, 0.0, 0.0)))
            .map(drop)
    });
    rejected(Error::NotNormalized("orientation"), |w| {
        w.add_body(
            BodyDesc::dynamic(unit_mass()).with_orientation(Quat::from_xyzw(0.0, 0.0, 0.0, 2.0)),
        )
        .map(drop)
    });
    rejected(Error::NonFinite("linear velocity"), |w| {
        w.add_body(
            BodyDesc::dynamic(unit_mass()).with_velocity(Vec3::splat(f32::INFINITY), Vec3::ZERO),
        )
        .map(drop)
    });
    rejected(Error::NonPositive("mass"), |w| {
        w.add_body(BodyDesc::dynamic(MassProperties {
            mass: -1.0,
            inertia: Mat3::IDENTITY,
        }))
        .map(drop)
    });
    rejected(Error::NonPositive("mass"), |w| {
        w.add_body(BodyDesc::dynamic(MassProperties {
            mass: 0.0,
            inertia: Mat3::IDENTITY,
        }))
        .map(drop)
    });
    rejected(Error::InvalidInertia, |w| {
        let inertia = Mat3::from_diagonal(Vec3::new(1.0, -1.0, 1.0));
        w.add_body(BodyDesc::dynamic(MassProperties { mass: 1.0, inertia }))
            .map(drop)
    });
    rejected(Error::InvalidInertia, |w| {
        let inertia = Mat3::from_cols(Vec3::X, Vec3::new(0.5, 1.0, 0.0), Vec3::Z);
        w.add_body(BodyDesc::dynamic(MassProperties { mass: 1.0, inertia }))
            .map(drop)
    });
    rejected(Error::NonPositive("linear damping"), |w| {
        w.add_body(BodyDesc::dynamic(unit_mass()).with_damping(-1.0, 0.0))
            .map(drop)
    });
    assert_eq!(
        Shape::Sphere { radius: 0.0 }.mass_properties(1.0),
        Err(Error::DegenerateShape("sphere radius"))
    );
    assert_eq!(
        Shape::Sphere { radius: nan }.mass_properties(1.0),
        Err(Error::NonFinite("sphere radius"))
    );
    assert!(matches!(
        Shape::Box {
            half_extents: Vec3::new(1.0, 0.0, 1.0)
        }
        .mass_properties(1.0),
        Err(Error::DegenerateShape(_))
    ));
    assert_eq!(
        Shape::capsule(Vec3::ZERO, Vec3::Y, -0.1).mass_properties(1.0),
        Err(Error::DegenerateShape("capsule radius"))
    );
    assert_eq!(
        Shape::Sphere { radius: 1.0 }.mass_properties(-5.0),
        Err(Error::NonPositive("density"))
    );
}

#[test]
fn bad_joints_are_refused() {
    rejected(Error::SameBody, |w| {
        let b = w.bodies().handle_at(1).unwrap();
        w.add_joint(JointDesc::socket_at_world_anchor(
            w.bodies(),
            b,
            b,
            Vec3::ZERO,
            Vec3::X,
        )?)
        .map(drop)
    });
    let kinematic = |w: &mut World| {
        let c = w.add_body(BodyDesc::fixed()).unwrap();
        w.remove_body(c).unwrap();
        w.add_body(BodyDesc::kinematic()).unwrap()
    };
    rejected_after(kinematic, Error::NoDynamicBody, |w, k| {
        let a = w.bodies().handle_at(0).unwrap();
        w.add_joint(JointDesc::socket_at_world_anchor(
            w.bodies(),
            a,
            k,
            Vec3::ZERO,
            Vec3::X,
        )?)
        .map(drop)
    });
    rejected(Error::InvalidLimit("swing"), |w| {
        let (a, b) = (
            w.bodies().handle_at(0).unwrap(),
            w.bodies().handle_at(1).unwrap(),
        );
        w.add_joint(
            JointDesc::socket_at_world_anchor(w.bodies(), a, b, Vec3::ZERO, Vec3::X)?
                .with_swing_limit(4.0),
        )
        .map(drop)
    });
    rejected(Error::InvalidLimit("twist"), |w| {
        let (a, b) = (
            w.bodies().handle_at(0).unwrap(),
            w.bodies().handle_at(1).unwrap(),
        );
        w.add_joint(
            JointDesc::socket_at_world_anchor(w.bodies(), a, b, Vec3::ZERO, Vec3::X)?
                .with_twist_limit(0.5, -0.5),
        )
        .map(drop)
    });
    rejected(Error::NotNormalized("twist axis"), |w| {
        let (a, b) = (
            w.bodies().handle_at(0).unwrap(),
            w.bodies().handle_at(1).unwrap(),
        );
        w.add_joint(JointDesc::socket_at_world_anchor(
            w.bodies(),
            a,
            b,
            Vec3::ZERO,
            Vec3::ZERO,
        )?)
        .map(drop)
    });
    rejected(Error::NonPositive("drive compliance"), |w| {
        let s = w.joints().next().expect("a joint").0;
        let drive = AngularDrive::compliant(Quat::IDENTITY, -1.0, 0.0);
        w.set_joint_drive(s, Some(drive))
    });
    rejected(Error::NotNormalized("drive target"), |w| {
        let s = w.joints().next().expect("a joint").0;
        let drive = AngularDrive::rigid(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0));
        w.set_joint_drive(s, Some(drive))
    });
}

/// A joint of `kind` between the world's two bodies, as the API refuses it.
fn add_kind(w: &mut World, kind: JointKind, drive: Option<AngularDrive>) -> Result<(), Error> {
    let (a, b) = (
        w.bodies().handle_at(0).unwrap(),
        w.bodies().handle_at(1).unwrap(),
    );
    let mut desc =
        JointDesc::socket_at_world_anchor(w.bodies(), a, b, Vec3::ZERO, Vec3::X)?.with_kind(kind);
    desc.drive = drive;
    w.add_joint(desc).map(drop)
}

#[test]
fn bad_joint_kinds_are_refused_with_the_field_named() {
    let soft = |c| SwingTwist::FREE.with_softness(LimitSoftness::compliant(c));
    let drive = AngularDrive::rigid(Quat::IDENTITY);
    let hinge = |softness| JointKind::Hinge {
        range: Some([0.0, 1.0]),
        softness,
    };
    let spring = |frequency, damping_ratio| {
        LimitSoftness::Soft(Spring::Frequency {
            frequency,
            damping_ratio,
        })
    };
    let damped = |compliance, damping| {
        LimitSoftness::Soft(Spring::Compliance {
            compliance,
            damping,
        })
    };
    let cases = [
        (
            hinge(damped(0.1, -1.0)),
            None,
            Error::NonPositive("limit damping"),
        ),
        (
            hinge(damped(0.1, f32::INFINITY)),
            None,
            Error::NonFinite("limit damping"),
        ),
        (
            hinge(damped(1e4, 1e3)),
            None,
            Error::OutOfRange("limit damping (compliance times damping at most 1e6 s)"),
        ),
        (
            hinge(spring(f32::NAN, 1.0)),
            None,
            Error::NonFinite("limit frequency"),
        ),
        (
            hinge(spring(0.0, 1.0)),
            None,
            Error::OutOfRange("limit frequency (at least 1e-3 Hz)"),
        ),
        (
            hinge(spring(5.0, -0.5)),
            None,
            Error::NonPositive("limit damping ratio"),
        ),
        (
            JointKind::Socket(SwingTwist::FREE.with_softness(spring(5.0, 2e3))),
            None,
            Error::OutOfRange("limit damping ratio (at most 1e3)"),
        ),
        (
            JointKind::Socket(SwingTwist::FREE.with_swing(Swing::Ellipse { y: 0.5, z: 4.0 })),
            None,
            Error::InvalidLimit("swing ellipse z"),
        ),
        (
            JointKind::Socket(SwingTwist::FREE.with_swing(Swing::Ellipse {
                y: f32::NAN,
                z: 0.5,
            })),
            None,
            Error::NonFinite("swing ellipse y"),
        ),
        (
            JointKind::Socket(SwingTwist::FREE.with_swing(Swing::Pyramid {
                y: [-0.5, 0.5],
                z: [0.5, -0.5],
            })),
            None,
            Error::InvalidLimit("swing pyramid z"),
        ),
        (
            JointKind::Socket(soft(-1.0)),
            None,
            Error::NonPositive("limit compliance"),
        ),
        (
            JointKind::Socket(soft(f32::INFINITY)),
            None,
            Error::NonFinite("limit compliance"),
        ),
        (
            JointKind::Hinge {
                range: Some([0.0, 4.0]),
                softness: LimitSoftness::Hard,
            },
            None,
            Error::InvalidLimit("hinge range"),
        ),
        (
            JointKind::Fixed,
            Some(drive),
            Error::InvalidJoint("drive (a fixed joint has no rotation to drive)"),
        ),
    ];
    for (kind, drive, expected) in cases {
        rejected(expected, |w| add_kind(w, kind, drive));
    }
    // A drive set later on a fixed joint is refused too.
    let fixed = |w: &mut World| {
        add_kind(w, JointKind::Fixed, None).unwrap();
        w.joints().last().unwrap().0
    };
    rejected_after(
        fixed,
        Error::InvalidJoint("drive (a fixed joint has no rotation to drive)"),
        |w, j| w.set_joint_drive(j, Some(drive)),
    );
}

/// One spring serves a drive's strength and a soft limit: a value out of
/// range is refused by its one check wherever it is given (a drive set on
/// a joint, a joint added with it as its drive or as a hinge's or socket's
/// softness), the error naming the field (`drive ...` or `limit ...`) and
/// the number, and the refused call changes nothing.
#[test]
fn bad_springs_are_refused_as_drives_and_limits_naming_the_field() {
    let compliance = |compliance, damping| Spring::Compliance {
        compliance,
        damping,
    };
    let frequency = |frequency, damping_ratio| Spring::Frequency {
        frequency,
        damping_ratio,
    };
    // A bad spring, and the drive's and the limit's refusal of it.
    let cases = [
        (
            compliance(-1.0, 0.0),
            Error::NonPositive("drive compliance"),
            Error::NonPositive("limit compliance"),
        ),
        (
            compliance(f32::NAN, 0.0),
            Error::NonFinite("drive compliance"),
            Error::NonFinite("limit compliance"),
        ),
        (
            compliance(0.1, f32::INFINITY),
            Error::NonFinite("drive damping"),
            Error::NonFinite("limit damping"),
        ),
        (
            compliance(0.1, -2.0),
            Error::NonPositive("drive damping"),
            Error::NonPositive("limit damping"),
        ),
        (
            compliance(1e4, 1e3),
            Error::OutOfRange("drive damping (compliance times damping at most 1e6 s)"),
            Error::OutOfRange("limit damping (compliance times damping at most 1e6 s)"),
        ),
        (
            frequency(f32::NAN, 1.0),
            Error::NonFinite("drive frequency"),
            Error::NonFinite("limit frequency"),
        ),
        (
            frequency(5e-4, 1.0),
            Error::OutOfRange("drive frequency (at least 1e-3 Hz)"),
            Error::OutOfRange("limit frequency (at least 1e-3 Hz)"),
        ),
        (
            frequency(f32::NEG_INFINITY, 1.0),
            Error::OutOfRange("drive frequency (at least 1e-3 Hz)"),
            Error::OutOfRange("limit frequency (at least 1e-3 Hz)"),
        ),
        (
            frequency(5.0, -0.5),
            Error::NonPositive("drive damping ratio"),
            Error::NonPositive("limit damping ratio"),
        ),
        (
            frequency(5.0, f32::INFINITY),
            Error::NonFinite("drive damping ratio"),
            Error::NonFinite("limit damping ratio"),
        ),
        (
            frequency(5.0, 2e3),
            Error::OutOfRange("drive damping ratio (at most 1e3)"),
            Error::OutOfRange("limit damping ratio (at most 1e3)"),
        ),
    ];
    for (spring, as_drive, as_limit) in cases {
        assert_eq!(spring.check(SpringField::Drive), Err(as_drive.clone()));
        assert_eq!(spring.check(SpringField::Limit), Err(as_limit.clone()));
        let drive = AngularDrive::new(Quat::IDENTITY, spring);
        assert_eq!(drive.validate(), Err(as_drive.clone()));
        rejected(as_drive.clone(), |w| {
            let s = w.joints().next().expect("a joint").0;
            w.set_joint_drive(s, Some(drive))
        });
        let hinge = JointKind::Hinge {
            range: Some([0.0, 1.0]),
            softness: LimitSoftness::Hard,
        };
        rejected(as_drive, |w| add_kind(w, hinge, Some(drive)));
        let soft = LimitSoftness::Soft(spring);
        let kinds = [
            JointKind::Hinge {
                range: Some([0.0, 1.0]),
                softness: soft,
            },
            JointKind::Socket(SwingTwist::FREE.with_softness(soft)),
        ];
        for kind in kinds {
            rejected(as_limit.clone(), |w| add_kind(w, kind, None));
        }
    }
    // The ends of every range are taken, as a drive and as a limit.
    let taken = [
        Spring::RIGID,
        compliance(0.0, f32::MAX),
        compliance(1e3, 1e3),
        frequency(MIN_DRIVE_FREQUENCY, 0.0),
        frequency(f32::INFINITY, MAX_DRIVE_DAMPING_RATIO),
    ];
    for spring in taken {
        for field in [SpringField::Drive, SpringField::Limit] {
            assert_eq!(spring.check(field), Ok(()), "{spring:?} as {field:?}");
        }
        let (mut w, ..) = world();
        let kind = JointKind::Hinge {
            range: Some([0.0, 1.0]),
            softness: LimitSoftness::Soft(spring),
        };
        add_kind(
            &mut w,
            kind,
            Some(AngularDrive::new(Quat::IDENTITY, spring)),
        )
        .unwrap();
        w.step(1.0 / 60.0).unwrap();
    }
}

#[test]
fn stale_handles_are_refused() {
    let (mut w, a, b, s) = world();
    w.remove_joint(s).unwrap();
    assert_eq!(w.remove_joint(s), Err(Error::StaleHandle("joint")));
    assert_eq!(w.joint(s), Err(Error::StaleHandle("joint")));
    w.remove_body(b).unwrap();
    assert_eq!(w.body(b), Err(Error::StaleHandle("body")));
    assert_eq!(
        w.set_body_pose(b, Vec3::ZERO, Quat::IDENTITY),
        Err(Error::StaleHandle("body"))
    );
    assert_eq!(w.add_force(b, Vec3::X), Err(Error::StaleHandle("body")));
    // The slot is reused, but the old handle stays stale.
    let c = w.add_body(BodyDesc::dynamic(unit_mass())).unwrap();
    assert_eq!(c.index(), b.index());
    assert_ne!(c, b);
    assert_eq!(w.body(b), Err(Error::StaleHandle("body")));
    assert!(JointDesc::socket_at_world_anchor(w.bodies(), a, b, Vec3::ZERO, Vec3::X).is_err());
    w.step(1.0 / 60.0).unwrap();
}

#[test]
fn a_body_in_use_cannot_be_removed_and_bad_steps_are_refused() {
    rejected(Error::BodyInUse, |w| {
        w.remove_body(w.bodies().handle_at(1).unwrap())
    });
    rejected(Error::NonPositive("time step"), |w| w.step(0.0));
    rejected(Error::NonFinite("time step"), |w| w.step(f32::NAN));
    rejected(Error::NonFinite("force"), |w| {
        w.add_force(w.bodies().handle_at(1).unwrap(), Vec3::splat(f32::NAN))
    });
    rejected(Error::NotNormalized("orientation"), |w| {
        w.set_body_pose(
            w.bodies().handle_at(1).unwrap(),
            Vec3::ZERO,
            Quat::from_xyzw(1.0, 1.0, 0.0, 0.0),
        )
    });
}

#[test]
fn bad_configs_are_refused() {
    let bad = |c: SolverConfig| World::new(c).err();
    assert_eq!(
        bad(SolverConfig {
            iterations: 0,
            ..SolverConfig::default()
        }),
        Some(Error::InvalidConfig("iterations must be at least 1"))
    );
    assert_eq!(
        bad(SolverConfig {
            substeps: 0,
            ..SolverConfig::default()
        }),
        Some(Error::InvalidConfig("substeps must be at least 1"))
    );
    assert_eq!(
        bad(SolverConfig {
            threads: 0,
            ..SolverConfig::default()
        }),
        Some(Error::InvalidConfig("threads must be at least 1"))
    );
    assert_eq!(
        bad(SolverConfig {
            gravity: Vec3::NAN,
            ..SolverConfig::default()
        }),
        Some(Error::NonFinite("gravity"))
    );
    for speed in [-1.0, f32::NAN] {
        assert!(matches!(
            bad(SolverConfig {
                max_push_out_speed: speed,
                ..SolverConfig::default()
            }),
            Some(Error::InvalidConfig(_))
        ));
    }
    for speed in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let limits = [
            SolverConfig {
                max_linear_speed: speed,
                ..SolverConfig::default()
            },
            SolverConfig {
                max_angular_speed: speed,
                ..SolverConfig::default()
            },
        ];
        for config in limits {
            assert!(matches!(bad(config), Some(Error::InvalidConfig(_))));
        }
    }
    for backend in vertebra_math::Backend::ALL {
        let result = World::new(SolverConfig {
            backend: BackendChoice::Forced(backend),
            ..SolverConfig::default()
        });
        assert_eq!(result.is_ok(), backend.is_available(), "{backend}");
    }
}

#[test]
fn bad_rods_are_refused() {
    use vertebra_world::{RodDesc, RodStiffness};
    // A rod between the first dynamic body and a new one (added first,
    // to the reference too) above it, or where it is.
    let new_body = |offset: Vec3| {
        move |w: &mut World| {
            let b = w.bodies().handle_at(1).unwrap();
            let at = w.body(b).unwrap().position + offset;
            let c = w.add_body(BodyDesc::dynamic(unit_mass()).with_position(at));
            (b, c.unwrap())
        }
    };
    let above = new_body(Vec3::new(0.0, 0.5, 0.0));
    let rod = |w: &World, (b, c)| RodDesc::from_pose(w.bodies(), b, c, &[]);
    rejected_after(above, Error::NotNormalized("rod frame a"), |w, ends| {
        let mut r = rod(w, ends)?;
        r.frame_a = Quat::from_xyzw(0.0, 0.0, 0.0, 3.0);
        w.add_rod(r).map(drop)
    });
    rejected_after(above, Error::NonPositive("rod rest length"), |w, ends| {
        let mut r = rod(w, ends)?;
        r.rest_length = -0.1;
        w.add_rod(r).map(drop)
    });
    rejected_after(
        above,
        Error::OutOfRange("rod relaxation factor (0 to 1)"),
        |w, ends| {
            let r = rod(w, ends)?
                .with_stiffness(RodStiffness::Relaxation(1.5), RodStiffness::Kirchhoff(1.0));
            w.add_rod(r).map(drop)
        },
    );
    rejected_after(above, Error::NonPositive("rod bending"), |w, ends| {
        let r = rod(w, ends)?
            .with_stiffness(RodStiffness::Kirchhoff(-2.0), RodStiffness::Kirchhoff(1.0));
        w.add_rod(r).map(drop)
    });
    rejected_after(above, Error::NonPositive("rod max torque"), |w, ends| {
        w.add_rod(rod(w, ends)?.with_max_torque(-1.0)).map(drop)
    });
    rejected_after(above, Error::NonFinite("rod max torque"), |w, ends| {
        w.add_rod(rod(w, ends)?.with_max_torque(f32::NAN)).map(drop)
    });
    rejected_after(
        above,
        Error::NonFinite("rod twisting damping"),
        |w, ends| {
            let damped = RodStiffness::Damped {
                stiffness: 1.0,
                damping: f32::INFINITY,
            };
            let r = rod(w, ends)?.with_stiffness(RodStiffness::Kirchhoff(1.0), damped);
            w.add_rod(r).map(drop)
        },
    );
    rejected_after(
        above,
        Error::OutOfRange("rod damping (damping over stiffness at most 1e6 s)"),
        |w, ends| {
            let damped = RodStiffness::Damped {
                stiffness: 1e-9,
                damping: 1.0,
            };
            w.add_rod(rod(w, ends)?.with_stiffness(damped, damped))
                .map(drop)
        },
    );
    rejected_after(
        above,
        Error::OutOfRange("rod frequency (at least 1e-3 Hz)"),
        |w, ends| {
            let spring = RodStiffness::Spring {
                frequency: 0.0,
                damping_ratio: 1.0,
            };
            w.add_rod(rod(w, ends)?.with_stiffness(spring, spring))
                .map(drop)
        },
    );
    rejected_after(
        above,
        Error::NonPositive("rod bending damping ratio"),
        |w, ends| {
            let spring = RodStiffness::Spring {
                frequency: 2.0,
                damping_ratio: -1.0,
            };
            w.add_rod(rod(w, ends)?.with_stiffness(spring, spring))
                .map(drop)
        },
    );
    rejected_after(above, Error::InvalidLimit("bend"), |w, ends| {
        let r = rod(w, ends)?.with_bend_limit(4.0);
        w.add_rod(r).map(drop)
    });
    // A bone far to the side of the chord puts the rod on the major arc.
    let bent = Error::DegenerateShape("the rod's bones bend its arc by pi or more");
    assert_eq!(
        bent.to_string(),
        "degenerate shape: the rod's bones bend its arc by pi or more"
    );
    rejected_after(above, bent, |w, (b, c)| {
        let side = w.body(b)?.position + Vec3::new(1.0, -0.1, 0.0);
        RodDesc::from_pose(w.bodies(), b, c, &[side]).map(drop)
    });
    rejected_after(
        new_body(Vec3::ZERO),
        Error::DegenerateShape("the rod's ends coincide"),
        |w, ends| rod(w, ends).map(drop),
    );
}

/// A rod's rest rates: finite and at most `MAX_ANGULAR_SPEED_LIMIT`, each
/// refusal (by `add_rod` and by `set_rod`) naming the field and leaving the
/// world, a moving rod in it included, as it was.
#[test]
fn bad_rest_rates_are_refused_by_name_and_change_nothing() {
    use vertebra_world::{MAX_ANGULAR_SPEED_LIMIT, RodDesc, RodStiffness};
    let (mut w, _, b, _) = world();
    let c = w
        .add_body(BodyDesc::dynamic(unit_mass()).with_position(Vec3::new(0.0, 0.5, 0.0)))
        .unwrap();
    let spring = RodStiffness::Spring {
        frequency: 2.0,
        damping_ratio: 1.0,
    };
    let rod = RodDesc::from_pose(w.bodies(), b, c, &[])
        .unwrap()
        .with_stiffness(spring, spring)
        .with_rest_velocity(Vec3::Z, 0.5);
    let handle = w.add_rod(rod).unwrap();
    w.step(1.0 / 60.0).unwrap();
    let fast = MAX_ANGULAR_SPEED_LIMIT * 1.01;
    let bend = |v: Vec3| rod.with_rest_velocity(v, 0.0);
    let twist = |v: f32| rod.with_rest_velocity(Vec3::ZERO, v);
    let cases = [
        (
            bend(Vec3::new(0.0, f32::NAN, 0.0)),
            Error::NonFinite("rod rest bend velocity"),
        ),
        (
            bend(Vec3::new(f32::INFINITY, 0.0, 0.0)),
            Error::NonFinite("rod rest bend velocity"),
        ),
        (
            bend(Vec3::new(0.0, fast, 0.0)),
            Error::OutOfRange("rod rest bend velocity (at most MAX_ANGULAR_SPEED_LIMIT)"),
        ),
        (twist(f32::NAN), Error::NonFinite("rod rest twist velocity")),
        (
            twist(f32::NEG_INFINITY),
            Error::NonFinite("rod rest twist velocity"),
        ),
        (
            twist(-fast),
            Error::OutOfRange("rod rest twist velocity (at most MAX_ANGULAR_SPEED_LIMIT)"),
        ),
    ];
    for (desc, error) in cases {
        let before = (w.snapshot(), w.state_hash());
        assert_eq!(w.set_rod(handle, desc), Err(error.clone()));
        assert_eq!(w.add_rod(desc).err(), Some(error));
        assert_eq!((w.snapshot(), w.state_hash()), before);
    }
    let limit = Vec3::new(0.6, 0.0, 0.8) * MAX_ANGULAR_SPEED_LIMIT;
    w.set_rod(
        handle,
        rod.with_rest_velocity(limit, -MAX_ANGULAR_SPEED_LIMIT),
    )
    .unwrap();
    w.step(1.0 / 60.0).unwrap();
}

/// `set_rod` with other bodies is refused naming the rod and saying its
/// bodies cannot change (not as an invalid solver setting), with the world as it was; the same bodies in the
/// other order are other bodies too (`body_a` is the rod's base).
#[test]
fn set_rod_refuses_other_bodies_naming_the_rod() {
    use vertebra_world::RodDesc;
    let (mut w, a, b, _) = world();
    let c = w
        .add_body(BodyDesc::dynamic(unit_mass()).with_position(Vec3::new(0.0, 0.5, 0.0)))
        .unwrap();
    let rod = RodDesc::from_pose(w.bodies(), b, c, &[]).unwrap();
    let handle = w.add_rod(rod).unwrap();
    let expected = Error::InvalidJoint(
        "rod bodies (body_a, body_b) cannot change; remove the rod and add one between the new bodies",
    );
    for (body_a, body_b) in [(a, c), (b, a), (c, b)] {
        let before = (w.snapshot(), w.state_hash());
        let moved = RodDesc {
            body_a,
            body_b,
            ..rod
        };
        assert_eq!(w.set_rod(handle, moved), Err(expected.clone()));
        assert_eq!((w.snapshot(), w.state_hash()), before);
    }
    assert_eq!(
        expected.to_string(),
        "invalid joint: rod bodies (body_a, body_b) cannot change; remove the rod and add one \
         between the new bodies"
    );
    w.set_rod(handle, rod.with_bend_limit(0.5)).unwrap();
}

#[test]
fn a_body_with_a_rod_cannot_be_removed_until_the_rod_is() {
    use vertebra_world::RodDesc;
    let (mut w, _, b, _) = world();
    let c = w
        .add_body(BodyDesc::dynamic(unit_mass()).with_position(Vec3::new(0.0, 0.5, 0.0)))
        .unwrap();
    let rod = w
        .add_rod(RodDesc::from_pose(w.bodies(), b, c, &[]).unwrap())
        .unwrap();
    assert_eq!(w.remove_body(c), Err(Error::BodyInUse));
    w.remove_rod(rod).unwrap();
    assert_eq!(w.remove_rod(rod), Err(Error::StaleHandle("rod")));
    assert_eq!(w.rod(rod), Err(Error::StaleHandle("rod")));
    w.remove_body(c).unwrap();
    w.step(1.0 / 60.0).unwrap();
}

/// Huge but finite velocities and forces are accepted, and the solver's
/// speed limits keep the world finite (the fuzzer found `|w| = 3.6e28`
/// overflowing `|w|^2` in the exponential map, and `|w| = 1e34` overflowing
/// the gyroscopic term); a force that would overflow the accumulator is
/// refused.
#[test]
fn huge_finite_velocities_are_clamped_to_the_speed_limits() {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let config = *world.config();
    let shape = Shape::Sphere { radius: 0.1 };
    let body = world
        .add_body(BodyDesc::dynamic(shape.mass_properties(1000.0).unwrap()))
        .unwrap();
    let spinner = world.add_body(BodyDesc::kinematic()).unwrap();
    world
        .set_body_velocity(
            body,
            Vec3::new(3e30, 0.0, 0.0),
            Vec3::new(0.0, -3.6e28, 0.0),
        )
        .unwrap();
    world
        .set_body_velocity(spinner, Vec3::ZERO, Vec3::new(-3.6e28, 5.0, 6.0))
        .unwrap();
    world.add_force(body, Vec3::new(0.0, 3e38, 0.0)).unwrap();
    assert_eq!(
        world.add_force(body, Vec3::new(0.0, 3e38, 0.0)),
        Err(Error::NonFinite("accumulated force"))
    );
    world.add_torque(body, Vec3::new(3e38, 0.0, 0.0)).unwrap();
    world.step(1.0 / 60.0).unwrap();
    for handle in [body, spinner] {
        let state = world.body(handle).unwrap();
        assert!(state.position.is_finite() && state.orientation.is_finite());
        assert!(state.linear_velocity.length() <= config.max_linear_speed * 1.0001);
        assert!(state.angular_velocity.length() <= config.max_angular_speed * 1.0001);
    }
}

/// Coordinates beyond `MAX_COORDINATE` and steps outside `MIN_TIME_STEP`
/// to `MAX_TIME_STEP` are refused with the world unchanged (the fuzzer
/// stepped a world by 1e30 s into infinities, and by subnormal steps into
/// infinite derived velocities).
#[test]
fn coordinates_and_time_steps_out_of_range_are_refused() {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let far = Vec3::new(0.0, 2.0 * vertebra_world::MAX_COORDINATE, 0.0);
    assert_eq!(
        world.add_body(BodyDesc::fixed().with_position(far)),
        Err(Error::OutOfRange("position"))
    );
    let shape = Shape::Sphere { radius: 0.1 };
    let body = world
        .add_body(BodyDesc::dynamic(shape.mass_properties(1000.0).unwrap()))
        .unwrap();
    let before = world.state_hash();
    assert_eq!(
        world.set_body_pose(body, far, glam::Quat::IDENTITY),
        Err(Error::OutOfRange("position"))
    );
    assert_eq!(
        world.step(2.0 * vertebra_world::MAX_TIME_STEP),
        Err(Error::OutOfRange("time step (at most 1 s)"))
    );
    // A subnormal step: velocities derived as motion / h would overflow.
    assert_eq!(
        world.step(1e-40),
        Err(Error::OutOfRange(
            "time step (each substep at least 1e-6 s)"
        ))
    );
    assert_eq!(world.state_hash(), before);
    world.step(vertebra_world::MAX_TIME_STEP).unwrap();
    assert!(world.body(body).unwrap().position.is_finite());
}

/// Kind changes to or from static, a kinematic body without mass made
/// dynamic, and `move_kinematic` on a body that is not kinematic or with
/// a bad pose, time step or a move faster than the speed limits: each
/// refused by name, the world as it was.
#[test]
fn bad_kind_changes_and_kinematic_moves_are_refused() {
    use vertebra_world::BodyKind;
    let ground = |w: &mut World| w.bodies().handle_at(0).unwrap();
    let bob = |w: &mut World| w.bodies().handle_at(1).unwrap();
    for kind in [BodyKind::Dynamic, BodyKind::Kinematic, BodyKind::Static] {
        rejected_after(
            ground,
            Error::WrongKind(
                "kind: a static body stays static (only dynamic and kinematic bodies switch)",
            ),
            |w, g| w.set_body_kind(g, kind),
        );
    }
    rejected_after(
        bob,
        Error::WrongKind(
            "kind: no body becomes static at run time (remove it and add a static body)",
        ),
        |w, b| w.set_body_kind(b, BodyKind::Static),
    );
    let massless = |w: &mut World| w.add_body(BodyDesc::kinematic()).unwrap();
    rejected_after(
        massless,
        Error::WrongKind(
            "kind: a kinematic body without mass cannot become dynamic \
             (create it with BodyDesc::with_mass)",
        ),
        |w, k| w.set_body_kind(k, BodyKind::Dynamic),
    );
    rejected_after(
        bob,
        Error::WrongKind(
            "move_kinematic needs a kinematic body (switch it with World::set_body_kind)",
        ),
        |w, b| w.move_kinematic(b, Vec3::ZERO, Quat::IDENTITY, 1.0 / 60.0),
    );
    let kinematic = |w: &mut World| {
        let b = w.bodies().handle_at(1).unwrap();
        w.set_body_kind(b, BodyKind::Kinematic).unwrap();
        b
    };
    let (dt, q) = (1.0 / 60.0, Quat::IDENTITY);
    let nan = f32::NAN;
    let cases: [(Error, Vec3, Quat, f32); 9] = [
        (
            Error::NonFinite("position"),
            Vec3::new(nan, 0.0, 0.0),
            q,
            dt,
        ),
        (
            Error::OutOfRange("position"),
            Vec3::new(2.0e6, 0.0, 0.0),
            q,
            dt,
        ),
        (
            Error::NotNormalized("orientation"),
            Vec3::ZERO,
            Quat::from_xyzw(0.0, 0.0, 0.0, 2.0),
            dt,
        ),
        (
            Error::NonFinite("orientation"),
            Vec3::ZERO,
            Quat::from_xyzw(nan, 0.0, 0.0, 1.0),
            dt,
        ),
        (Error::NonFinite("time step"), Vec3::ZERO, q, nan),
        (Error::NonPositive("time step"), Vec3::ZERO, q, 0.0),
        (
            Error::OutOfRange("time step (1e-6 s to 1 s)"),
            Vec3::ZERO,
            q,
            2.0,
        ),
        (
            Error::OutOfRange("position (reaching it in dt needs more than max_linear_speed)"),
            Vec3::new(100.0, 0.0, 0.0),
            q,
            dt,
        ),
        (
            Error::OutOfRange("orientation (reaching it in dt needs more than max_angular_speed)"),
            Vec3::new(0.0, -0.2, 0.0),
            Quat::from_rotation_z(3.0),
            1e-3,
        ),
    ];
    for (expected, position, orientation, dt) in cases {
        rejected_after(kinematic, expected, |w, b| {
            w.move_kinematic(b, position, orientation, dt)
        });
    }
}

/// A pendulum swinging from rest at 45 degrees, measuring its residuals
/// every step or not.
fn pendulum(measure_residuals: bool) -> World {
    let mut w = World::new(SolverConfig {
        iterations: 2,
        measure_residuals,
        ..SolverConfig::default()
    })
    .unwrap();
    let a = w.add_body(BodyDesc::fixed()).unwrap();
    let down = Quat::from_rotation_z(0.8) * -Vec3::Y;
    let b = capsule(&mut w, Vec3::ZERO, down * 0.4, 1.0);
    w.add_joint(JointDesc::socket_at_world_anchor(w.bodies(), a, b, Vec3::ZERO, down).unwrap())
        .unwrap();
    w
}

#[test]
fn residuals_are_measured_when_asked_for_and_never_shown_stale() {
    let (mut off, mut on) = (pendulum(false), pendulum(true));
    assert!(off.residuals().is_none() && on.residuals().is_none());
    for _ in 0..30 {
        off.step(1.0 / 60.0).unwrap();
        on.step(1.0 / 60.0).unwrap();
        assert!(off.residuals().is_none(), "not measured by the step");
        let each_step = on.residuals().expect("measured by the step");
        assert_eq!(each_step.joints.len(), 1);
        // Two iterations leave the swinging joint apart: a real error.
        assert!(each_step.eps_lin_cm > 0.0);
        // Measuring changes nothing a step reads.
        assert_eq!(off.state_hash(), on.state_hash());
    }
    let on_demand = off.measure_residuals().clone();
    assert_eq!(off.residuals(), Some(&on_demand));
    // The same poses, measured from the committed pose instead of the
    // step's rows: the same error to rounding.
    let each_step = on.residuals().unwrap();
    let close = (on_demand.eps_lin_cm - each_step.eps_lin_cm).abs();
    assert!(
        close <= 1e-4 * each_step.eps_lin_cm,
        "{on_demand:?} {each_step:?}"
    );
    off.step(1.0 / 60.0).unwrap();
    assert!(
        off.residuals().is_none(),
        "the measurement is of the last poses"
    );
}
