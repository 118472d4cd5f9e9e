//! Contacts found at the ends of the world's ranges are contacts the world
//! accepts.

use glam::Vec3;
use vertebra_collide::{Collider, ColliderShape, Collisions};
use vertebra_world::{BodyDesc, Shape, SolverConfig, World};

/// A body a million metres under a ground plane (a pose the world accepts)
/// gives a contact deeper than the world's depth range: it is held to the
/// range, so the whole list, the other body's contact included, is
/// accepted. (Found by an adversarial session: the world refused every
/// contact of the list, every frame.)
#[test]
fn a_body_far_under_the_ground_does_not_cost_the_others_their_contacts() {
    let mut w = World::new(SolverConfig::default()).unwrap();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    let ball = Shape::Sphere { radius: 0.5 };
    let mass = ball.mass_properties_with_mass(1.0).unwrap();
    let resting = w
        .add_body(BodyDesc::dynamic(mass).with_position(Vec3::new(0.0, 0.4, 0.0)))
        .unwrap();
    let lost = w
        .add_body(BodyDesc::dynamic(mass).with_position(Vec3::new(0.0, -1.0e6, 0.0)))
        .unwrap();
    let mut c = Collisions::new();
    c.add(Collider::new(ground, ColliderShape::Plane(Vec3::Y)))
        .unwrap();
    for body in [resting, lost] {
        c.add(Collider::new(body, ColliderShape::Solid(ball)))
            .unwrap();
    }
    let contacts = c.find_contacts(&w, 1.0 / 60.0).unwrap();
    assert!(
        contacts
            .iter()
            .any(|k| k.body_b == resting || k.body_a == resting)
    );
    w.set_contacts(&contacts)
        .expect("find_contacts' own output is accepted");
    w.step(1.0 / 60.0).unwrap();
    assert_eq!(w.repaired_bodies(), 0);
}
