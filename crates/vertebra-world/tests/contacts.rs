//! The contact solver with contacts fed by hand (as an engine with its own
//! collision detection would): boxes on the plane y = 0.

use glam::{Quat, Vec3};
use vertebra_world::{BodyDesc, BodyHandle, Contact, Error, Shape, SolverConfig, World};

const DT: f32 = 1.0 / 60.0;

/// Contacts of a box's corners that are below `margin` above the ground.
fn corner_contacts(
    w: &World,
    ground: BodyHandle,
    body: BodyHandle,
    half: Vec3,
    friction: f32,
    up: Vec3,
) -> Vec<Contact> {
    let s = w.body(body).unwrap();
    let mut out = Vec::new();
    for k in 0..8 {
        let corner = Vec3::new(
            if k & 1 == 0 { -half.x } else { half.x },
            if k & 2 == 0 { -half.y } else { half.y },
            if k & 4 == 0 { -half.z } else { half.z },
        );
        let p = s.position + s.orientation * corner;
        let height = p.dot(up);
        if height < 0.01 {
            out.push(Contact {
                body_a: ground,
                body_b: body,
                point: p - up * (0.5 * height),
                normal: up,
                depth: -height,
                friction,
                restitution: 0.0,
            });
        }
    }
    out
}

fn box_world(substeps: u32) -> (World, BodyHandle, BodyHandle, Vec3) {
    box_world_relaxed(substeps, false)
}

fn box_world_relaxed(substeps: u32, relax_contacts: bool) -> (World, BodyHandle, BodyHandle, Vec3) {
    let mut w = World::new(SolverConfig {
        substeps,
        iterations: 10,
        relax_contacts,
        ..SolverConfig::default()
    })
    .unwrap();
    let ground = w.add_body(BodyDesc::fixed()).unwrap();
    let half = Vec3::new(0.3, 0.2, 0.25);
    let props = Shape::Box { half_extents: half }
        .mass_properties(500.0)
        .unwrap();
    let body = w
        .add_body(BodyDesc::dynamic(props).with_position(Vec3::new(0.0, half.y + 0.05, 0.0)))
        .unwrap();
    (w, ground, body, half)
}

#[test]
fn a_box_rests_on_the_ground_without_sinking_drifting_or_jittering() {
    let (mut w, ground, body, half) = box_world(1);
    let mut worst_depth = 0.0f32;
    let mut positions = Vec::new();
    for frame in 0..600 {
        let contacts = corner_contacts(&w, ground, body, half, 0.6, Vec3::Y);
        w.set_contacts(&contacts).unwrap();
        w.step(DT).unwrap();
        let s = w.body(body).unwrap();
        let lowest = (0..8)
            .map(|k| {
                let c = Vec3::new(
                    if k & 1 == 0 { -half.x } else { half.x },
                    if k & 2 == 0 { -half.y } else { half.y },
                    if k & 4 == 0 { -half.z } else { half.z },
                );
                (s.position + s.orientation * c).y
            })
            .fold(f32::MAX, f32::min);
        if frame > 60 {
            worst_depth = worst_depth.max(-lowest);
            positions.push(s.position);
        }
    }
    let first = positions[0];
    let drift = positions
        .iter()
        .map(|p| (*p - first).length())
        .fold(0.0f32, f32::max);
    let speed = w.body(body).unwrap().linear_velocity.length();
    eprintln!(
        "box at rest: worst penetration {:.2} mm, drift {:.3} mm, final speed {speed:.2e} m/s",
        worst_depth * 1e3,
        drift * 1e3
    );
    assert!(worst_depth < 2e-3, "penetration {worst_depth}");
    assert!(drift < 1e-3, "drift {drift}");
    assert!(speed < 1e-2, "jitter {speed}");
}

#[test]
fn static_friction_holds_below_atan_mu_and_slides_above() {
    let mu = 0.5f32;
    for (angle_deg, slides) in [(20.0f32, false), (35.0, true)] {
        let (mut w, ground, body, half) = box_world(4);
        let tilt = Quat::from_rotation_z(angle_deg.to_radians());
        let up = tilt * Vec3::Y;
        w.set_body_pose(body, up * (half.y + 0.001), tilt).unwrap();
        for _ in 0..180 {
            let contacts = corner_contacts(&w, ground, body, half, mu, up);
            w.set_contacts(&contacts).unwrap();
            w.step(DT).unwrap();
        }
        let moved = w.body(body).unwrap().position - up * (half.y);
        let along = moved.length();
        eprintln!(
            "incline {angle_deg} deg (atan mu = {:.1}): moved {along:.4} m",
            mu.atan().to_degrees()
        );
        if slides {
            // Sliding from rest: s = 1/2 g (sin a - mu cos a) t^2, t = 3 s.
            let a = angle_deg.to_radians();
            let expected = 0.5 * 9.81 * (a.sin() - mu * a.cos()) * 9.0;
            assert!(
                (along - expected).abs() < 0.03 * expected,
                "slides above atan(mu): {along} m vs {expected} m"
            );
        } else {
            assert!(along < 1e-3, "holds below atan(mu): {along}");
        }
    }
}

/// Two boxes side by side (slots 1 and 2), the second one deep in the
/// ground; `contact` says whether a contact is set between it and the
/// ground before it is removed.
fn removal_world(contact: bool) -> (World, BodyHandle, BodyHandle) {
    let (mut w, ground, first, half) = box_world(1);
    let props = Shape::Box { half_extents: half }
        .mass_properties(500.0)
        .unwrap();
    let sunk = BodyDesc::dynamic(props).with_position(Vec3::new(1.0, 0.0, 0.0));
    let doomed = w.add_body(sunk).unwrap();
    if contact {
        let mut contacts = corner_contacts(&w, ground, doomed, half, 0.6, Vec3::Y);
        contacts.push(Contact {
            body_a: first,
            body_b: doomed,
            point: Vec3::new(0.5, 0.1, 0.0),
            normal: Vec3::X,
            depth: 0.2,
            friction: 0.6,
            restitution: 0.0,
        });
        w.set_contacts(&contacts).unwrap();
    }
    w.remove_body(doomed).unwrap();
    let reborn = w.add_body(sunk).unwrap();
    assert_eq!(reborn.index(), doomed.index(), "the slot is reused");
    (w, first, reborn)
}

#[test]
fn removing_a_body_drops_its_pending_contacts() {
    // Kept, the contacts would name the removed body's slot: the step would
    // push the body that reused the slot up out of the ground and the
    // other box away from a ghost.
    let (mut w, first, reborn) = removal_world(true);
    let (mut reference, reference_first, reference_reborn) = removal_world(false);
    assert!(w.contacts().is_empty(), "no contact names a removed body");
    w.step(DT).unwrap();
    reference.step(DT).unwrap();
    assert_eq!(
        w.body(reborn),
        reference.body(reference_reborn),
        "the new body is not pushed"
    );
    assert_eq!(
        w.body(first),
        reference.body(reference_first),
        "nothing is pushed by a ghost"
    );
    assert_eq!(w.state_hash(), reference.state_hash());
}

/// The box of [`box_world`] pushed `depth` into the ground, one step at
/// `substeps`: its lowest corner's height, its velocity and its angular
/// velocity afterwards.
fn pushed_out(substeps: u32, depth: f32, relax: bool) -> (f32, Vec3, Vec3) {
    let (mut w, ground, body, half) = box_world_relaxed(substeps, relax);
    w.set_body_pose(body, Vec3::new(0.0, half.y - depth, 0.0), Quat::IDENTITY)
        .unwrap();
    let contacts = corner_contacts(&w, ground, body, half, 0.6, Vec3::Y);
    w.set_contacts(&contacts).unwrap();
    w.step(DT).unwrap();
    let s = w.body(body).unwrap();
    let height = s.position.y - half.y;
    (height, s.linear_velocity, s.angular_velocity)
}

#[test]
fn an_overlap_comes_out_at_the_same_speed_at_any_substep_count() {
    // A step removes an overlap found at detection evenly over its
    // substeps, so the body comes out at depth / dt whatever the substeps.
    // Removed in the first substep, a 2 cm overlap fired the box off at
    // depth / h: 24.6 m/s at 20 substeps, and a substepped pile of ragdolls
    // boiled (docs/contacts.md, "The jammed pile").
    let depth = 0.02;
    for substeps in [1, 4, 20] {
        let (height, velocity, _) = pushed_out(substeps, depth, false);
        let speed = velocity.length();
        eprintln!("{substeps} substeps: lowest corner {height:+.5} m, speed {speed:.3} m/s");
        assert!(height > -1e-3, "{substeps} substeps: still {height} m deep");
        assert!(
            speed < 1.1 * depth / DT,
            "{substeps} substeps: launched at {speed} m/s"
        );
    }
}

/// Relaxed (`SolverConfig::relax_contacts`), the contacts take back the
/// speed their push-out gave: the box comes out of the same overlap and
/// stays where it came out, where unrelaxed it leaves at `depth / dt`
/// (1.2 m/s). The four corners share the taking back: the box does not
/// spin (one pass of each corner in turn left it at 1.2 rad/s).
#[test]
fn a_relaxed_contact_pushes_an_overlap_out_without_launching_it() {
    let depth = 0.02;
    for substeps in [1, 4, 20] {
        let (height, velocity, spin) = pushed_out(substeps, depth, true);
        eprintln!("{substeps} substeps: lowest corner {height:+.5} m, v {velocity}, w {spin}");
        assert!(height > -1e-3, "{substeps} substeps: still {height} m deep");
        assert!(
            velocity.y.abs() < 0.01,
            "{substeps} substeps: left at {} m/s",
            velocity.y
        );
        assert!(
            spin.length() < 0.01,
            "{substeps} substeps: spins at {spin} rad/s"
        );
    }
}

/// The box resting on its corners, for the next step: contacts both ways.
fn resting_box() -> (World, Vec<Contact>) {
    let (mut w, ground, body, half) = box_world(1);
    let pose = Vec3::new(0.0, half.y, 0.0);
    w.set_body_pose(body, pose, Quat::IDENTITY).unwrap();
    let contacts = corner_contacts(&w, ground, body, half, 0.6, Vec3::Y);
    assert_eq!(contacts.len(), 4);
    (w, contacts)
}

#[test]
fn swapped_contacts_step_as_copied_ones_and_the_world_gives_its_list_back() {
    let (mut copied, contacts) = resting_box();
    // The same box in another world (handles are each world's own).
    let (mut swapped, own) = resting_box();
    copied.set_contacts(&contacts).unwrap();
    let mut list = own.clone();
    swapped.swap_contacts(&mut list).unwrap();
    assert!(list.is_empty(), "the world's previous list, emptied");
    assert_eq!(swapped.contacts(), own.as_slice());
    copied.step(DT).unwrap();
    swapped.step(DT).unwrap();
    assert_eq!(copied.state_hash(), swapped.state_hash());
    // The world's list comes back to the caller at the next swap, its
    // capacity kept: the two vectors change places frame after frame.
    let mut list = own.clone();
    swapped.swap_contacts(&mut list).unwrap();
    assert!(list.is_empty() && list.capacity() >= own.len());
}

#[test]
fn a_refused_swap_leaves_both_lists_as_they_were() {
    let (mut w, contacts) = resting_box();
    w.set_contacts(&contacts[..2]).unwrap();
    let mut bad = contacts.clone();
    bad[3].normal = Vec3::new(0.0, 2.0, 0.0);
    let before = w.state_hash();
    assert!(w.swap_contacts(&mut bad).is_err());
    assert_eq!(w.state_hash(), before);
    assert_eq!(w.contacts(), &contacts[..2]);
    assert_eq!(bad.len(), 4);
    assert_eq!(bad[..3], contacts[..3]);
}

/// A refused list names its first wrong contact by its index in the list,
/// whichever way it is handed over, and leaves the world's list as it was.
#[test]
fn a_refused_contact_is_named_by_its_index_in_the_list() {
    let (mut w, contacts) = resting_box();
    w.set_contacts(&contacts[..1]).unwrap();
    let mut bad = contacts.clone();
    bad[2].point = Vec3::NAN;
    bad[3].friction = -1.0;
    let named = Err(Error::Contact {
        index: 2,
        reason: Box::new(Error::NonFinite("contact point")),
    });
    assert_eq!(w.set_contacts(&bad), named);
    assert_eq!(w.swap_contacts(&mut bad.clone()), named);
    assert_eq!(
        w.set_contacts(&bad).unwrap_err().to_string(),
        "contact 2: contact point is not finite"
    );
    assert_eq!(w.contacts(), &contacts[..1]);
    // A body removed since: the same, by index.
    let (mut w, contacts) = resting_box();
    let gone = w
        .add_body(BodyDesc::dynamic(
            Shape::Sphere { radius: 0.1 }.mass_properties(1.0).unwrap(),
        ))
        .unwrap();
    w.remove_body(gone).unwrap();
    let mut stale = contacts.clone();
    stale[1].body_b = gone;
    let error = w.set_contacts(&stale).unwrap_err();
    assert!(
        matches!(&error, Error::Contact { index: 1, reason } if matches!(**reason, Error::StaleHandle(_))),
        "{error:?}"
    );
}

/// The box of [`box_world`] dropped 5 cm onto the ground for a second,
/// each frame's corner contacts passed through `convention`: its lowest
/// corner's height at the end (m), or when the world first refused a
/// frame's contacts.
fn dropped_with(convention: impl Fn(Contact) -> Contact) -> f32 {
    let (mut w, ground, body, half) = box_world(1);
    for _ in 0..60 {
        let contacts: Vec<Contact> = corner_contacts(&w, ground, body, half, 0.6, Vec3::Y)
            .into_iter()
            .map(&convention)
            .collect();
        if w.set_contacts(&contacts).is_err() {
            break;
        }
        w.step(DT).unwrap();
    }
    w.body(body).unwrap().position.y - half.y
}

/// The normal's sign is the contact's meaning: a contact reversed (bodies
/// exchanged, normal flipped) holds the box up as the original does; the
/// bodies exchanged alone pull it into the ground, deeper each frame, which
/// no check of the world can see (it does not know the bodies' shapes).
#[test]
fn a_reversed_contact_pushes_as_the_original_and_its_bodies_alone_exchanged_do_not() {
    let original = dropped_with(|c| c);
    let reversed = dropped_with(Contact::reversed);
    let exchanged = dropped_with(|c| Contact {
        body_a: c.body_b,
        body_b: c.body_a,
        ..c
    });
    eprintln!(
        "lowest corner: {original:+.5} m, reversed {reversed:+.5} m, exchanged {exchanged:+.5} m"
    );
    assert!(original.abs() < 2e-3 && reversed.abs() < 2e-3);
    assert!((reversed - original).abs() < 1e-4);
    assert!(
        exchanged < -1.0,
        "the exchanged contacts sank it {exchanged} m"
    );
}
