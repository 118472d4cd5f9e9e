//! `World::state_hash` covers what its documentation says: a change to any
//! piece of state a later step reads changes the hash.

use glam::{Quat, Vec3};
use vertebra_world::{
    AngularDrive, BodyDesc, BodyHandle, Contact, JointDesc, JointHandle, RodDesc, RodHandle,
    RodStiffness, Shape, SolverConfig, World,
};

struct Scene {
    world: World,
    ground: BodyHandle,
    a: BodyHandle,
    b: BodyHandle,
    socket: JointHandle,
    rod: RodHandle,
}

/// A fixed ground, two dynamic capsules (`tweak` changes the second's
/// description), a socket and a rod (not stepped:
/// a difference in what is stored must show, not its effect on motion).
fn scene(tweak: impl FnOnce(&mut BodyDesc)) -> Scene {
    let mut world = World::new(SolverConfig::default()).unwrap();
    let ground = world.add_body(BodyDesc::fixed()).unwrap();
    let shape = Shape::capsule(Vec3::new(0.0, -0.2, 0.0), Vec3::new(0.0, 0.2, 0.0), 0.05);
    let mass = shape.mass_properties_with_mass(2.0).unwrap();
    let a = world
        .add_body(BodyDesc::dynamic(mass).with_position(Vec3::new(0.0, -0.25, 0.0)))
        .unwrap();
    let mut desc_b = BodyDesc::dynamic(mass).with_position(Vec3::new(0.0, -0.75, 0.0));
    tweak(&mut desc_b);
    let b = world.add_body(desc_b).unwrap();
    let socket = JointDesc::socket_at_world_anchor(world.bodies(), ground, a, Vec3::ZERO, -Vec3::Y);
    let socket = world.add_joint(socket.unwrap()).unwrap();
    let rod = RodDesc::from_pose(world.bodies(), a, b, &[]).unwrap();
    let rod = world.add_rod(rod).unwrap();
    Scene {
        world,
        ground,
        a,
        b,
        socket,
        rod,
    }
}

fn base() -> Scene {
    scene(|_| {})
}

#[test]
fn identical_worlds_hash_alike() {
    assert_eq!(base().world.state_hash(), base().world.state_hash());
}

#[test]
fn every_piece_of_state_a_step_reads_changes_the_hash() {
    let expected = base().world.state_hash();
    type Change = fn(&mut Scene);
    let changes: &[(&str, Change)] = &[
        ("position", |s| {
            let q = s.world.body(s.a).unwrap().orientation;
            s.world
                .set_body_pose(s.a, Vec3::new(0.0, -0.3, 0.0), q)
                .unwrap();
        }),
        ("orientation", |s| {
            let p = s.world.body(s.a).unwrap().position;
            s.world
                .set_body_pose(s.a, p, Quat::from_rotation_x(0.1))
                .unwrap();
        }),
        ("linear velocity", |s| {
            let w = s.world.body(s.a).unwrap().angular_velocity;
            s.world.set_body_velocity(s.a, Vec3::X, w).unwrap();
        }),
        ("angular velocity", |s| {
            let v = s.world.body(s.a).unwrap().linear_velocity;
            s.world.set_body_velocity(s.a, v, Vec3::X).unwrap();
        }),
        ("pending force", |s| {
            s.world.add_force(s.a, Vec3::X).unwrap()
        }),
        ("pending torque", |s| {
            s.world.add_torque(s.a, Vec3::X).unwrap()
        }),
        ("socket drive", |s| {
            let drive = AngularDrive::rigid(Quat::from_rotation_x(0.2));
            s.world.set_joint_drive(s.socket, Some(drive)).unwrap();
        }),
        ("socket removed", |s| {
            s.world.remove_joint(s.socket).unwrap()
        }),
        ("rod stiffness", |s| {
            let rod = s.world.rod(s.rod).unwrap();
            let stiff = RodStiffness::Kirchhoff(10.0);
            s.world
                .set_rod(s.rod, rod.with_stiffness(stiff, stiff))
                .unwrap();
        }),
        ("rod rest bend velocity", |s| {
            let rod = s.world.rod(s.rod).unwrap();
            let moving = rod.with_rest_velocity(Vec3::Z * 0.1, 0.0);
            s.world.set_rod(s.rod, moving).unwrap();
        }),
        ("rod rest twist velocity", |s| {
            let rod = s.world.rod(s.rod).unwrap();
            let moving = rod.with_rest_velocity(Vec3::ZERO, -0.1);
            s.world.set_rod(s.rod, moving).unwrap();
        }),
        ("pending contacts", |s| {
            let contact = Contact {
                body_a: s.ground,
                body_b: s.b,
                point: Vec3::new(0.0, -0.9, 0.0),
                normal: Vec3::Y,
                depth: 0.01,
                friction: 0.5,
                restitution: 0.0,
            };
            s.world.set_contacts(&[contact]).unwrap();
        }),
        ("handle generations", |s| {
            let extra = s.world.add_body(BodyDesc::fixed()).unwrap();
            s.world.remove_body(extra).unwrap();
        }),
    ];
    for (what, change) in changes {
        let mut s = base();
        change(&mut s);
        assert_ne!(s.world.state_hash(), expected, "{what} is not hashed");
    }
    type Tweak = fn(&mut BodyDesc);
    let descriptions: &[(&str, Tweak)] = &[
        ("mass", |d| {
            let m = d.mass.unwrap();
            d.mass =
                Some(vertebra_world::MassProperties::new(m.mass * 2.0, m.inertia * 2.0).unwrap());
        }),
        ("damping", |d| *d = d.with_damping(0.5, 0.5)),
        ("kind", |d| {
            *d = BodyDesc::kinematic().with_position(d.position)
        }),
    ];
    for (what, tweak) in descriptions {
        assert_ne!(
            scene(*tweak).world.state_hash(),
            expected,
            "{what} is not hashed"
        );
    }
}
