//! Impulses change momentum at once, by the textbook amounts: linear
//! momentum by the impulse, angular momentum about the centre of mass by
//! `r x J`; held to the speed limits; refused on static and kinematic
//! bodies and for bad values, with the world unchanged.

use glam::{Mat3, Quat, Vec3};
use vertebra_world::{BodyDesc, BodyHandle, Error, SolverConfig, World};

const MASS: f32 = 3.0;
const HALF: Vec3 = Vec3::new(0.4, 0.1, 0.2);

/// The box's inertia (kg m^2, body frame) from the closed form for a
/// uniform box of half extents `a, b, c`: `m/3 (b^2 + c^2)` and so on.
fn box_inertia() -> Mat3 {
    let s = HALF * HALF;
    Mat3::from_diagonal(Vec3::new(s.y + s.z, s.x + s.z, s.x + s.y) * (MASS / 3.0))
}

/// A world without gravity holding a dynamic box turned by `turn`, moving
/// and spinning, a static body and a kinematic one.
fn world(turn: Quat) -> (World, BodyHandle, BodyHandle, BodyHandle) {
    let config = SolverConfig {
        gravity: Vec3::ZERO,
        ..SolverConfig::default()
    };
    let mut w = World::new(config).unwrap();
    let mass = vertebra_world::MassProperties::new(MASS, box_inertia()).unwrap();
    let body = w
        .add_body(
            BodyDesc::dynamic(mass)
                .with_position(Vec3::new(1.0, 2.0, -0.5))
                .with_orientation(turn)
                .with_velocity(Vec3::new(0.3, -0.2, 0.1), Vec3::new(0.5, 0.25, -1.0)),
        )
        .unwrap();
    let fixed = w.add_body(BodyDesc::fixed()).unwrap();
    let kinematic = w
        .add_body(BodyDesc::kinematic().with_velocity(Vec3::X, Vec3::Y))
        .unwrap();
    (w, body, fixed, kinematic)
}

/// Linear momentum `m v` (N s) and angular momentum about the centre of
/// mass `R I R^T w` (N m s) of the box.
fn momenta(w: &World, body: BodyHandle) -> (Vec3, Vec3) {
    let s = w.body(body).unwrap();
    let r = Mat3::from_quat(s.orientation);
    let inertia = r * box_inertia() * r.transpose();
    (s.linear_velocity * MASS, inertia * s.angular_velocity)
}

fn assert_close(a: Vec3, b: Vec3, what: &str) {
    let scale = a.abs().max(b.abs()).max_element().max(1.0);
    assert!(
        (a - b).abs().max_element() <= 2e-6 * scale,
        "{what}: {a} against {b}"
    );
}

#[test]
fn a_central_impulse_changes_linear_momentum_by_itself_and_leaves_the_spin() {
    let (mut w, body, ..) = world(Quat::from_rotation_y(0.7));
    let (p0, l0) = momenta(&w, body);
    let impulse = Vec3::new(4.0, -1.5, 2.5);
    w.apply_impulse(body, impulse).unwrap();
    let (p1, l1) = momenta(&w, body);
    assert_close(p1 - p0, impulse, "linear momentum change");
    assert_eq!(l1, l0, "no angular momentum about the centre of mass");
}

#[test]
fn an_impulse_at_a_point_changes_angular_momentum_by_r_cross_j() {
    let turn = Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.8, 1.1);
    let (mut w, body, ..) = world(turn);
    let centre = w.body(body).unwrap().position;
    let (p0, l0) = momenta(&w, body);
    let impulse = Vec3::new(-2.0, 3.0, 0.5);
    let point = centre + Vec3::new(0.15, -0.35, 0.25);
    w.apply_impulse_at(body, impulse, point).unwrap();
    let (p1, l1) = momenta(&w, body);
    assert_close(p1 - p0, impulse, "linear momentum change");
    assert_close(
        l1 - l0,
        (point - centre).cross(impulse),
        "angular momentum change",
    );
}

#[test]
fn an_angular_impulse_changes_angular_momentum_by_itself() {
    let (mut w, body, ..) = world(Quat::from_rotation_x(-0.4));
    let (p0, l0) = momenta(&w, body);
    let angular = Vec3::new(0.2, -0.7, 0.4);
    w.apply_angular_impulse(body, angular).unwrap();
    let (p1, l1) = momenta(&w, body);
    assert_eq!(p1, p0, "no linear momentum");
    assert_close(l1 - l0, angular, "angular momentum change");
}

/// A box at rest, unturned, struck across its long axis at its end: the
/// centre moves at `J/m`, the box spins about z at `a J / I_zz` with
/// `I_zz = m/3 (a^2 + b^2)`, and the far end, at `v - a w`, moves
/// backwards (its centre of percussion is at `a/3` from the centre).
#[test]
fn a_box_struck_at_its_end_moves_and_spins_as_the_textbook_says() {
    let (mut w, body, ..) = world(Quat::IDENTITY);
    w.set_body_velocity(body, Vec3::ZERO, Vec3::ZERO).unwrap();
    let centre = w.body(body).unwrap().position;
    let j = 1.2;
    w.apply_impulse_at(body, Vec3::Y * j, centre + Vec3::X * HALF.x)
        .unwrap();
    let s = w.body(body).unwrap();
    let (a, b) = (HALF.x, HALF.y);
    let spin = a * j / (MASS / 3.0 * (a * a + b * b));
    assert_close(s.linear_velocity, Vec3::Y * (j / MASS), "velocity");
    assert_close(s.angular_velocity, Vec3::Z * spin, "angular velocity");
    let far_end = s.linear_velocity + s.angular_velocity.cross(-Vec3::X * a);
    assert!(far_end.y < 0.0, "the far end moves back: {far_end}");
    // The next step moves the box on at these velocities (no gravity, no
    // damping): the centre by v dt.
    w.step(0.01).unwrap();
    assert_close(
        w.body(body).unwrap().position - centre,
        s.linear_velocity * 0.01,
        "displacement",
    );
}

#[test]
fn impulses_are_held_to_the_speed_limits() {
    let (mut w, body, ..) = world(Quat::IDENTITY);
    let config = *w.config();
    w.apply_impulse(body, Vec3::new(0.0, 3.0e30, 4.0e30))
        .unwrap();
    w.apply_angular_impulse(body, Vec3::new(1.0e30, 0.0, 0.0))
        .unwrap();
    let s = w.body(body).unwrap();
    let speed = s.linear_velocity.length();
    assert!((speed - config.max_linear_speed).abs() <= 1e-3 * config.max_linear_speed);
    assert_close(
        s.linear_velocity.normalize(),
        Vec3::new(0.0, 0.6, 0.8),
        "the direction of the impulse",
    );
    let spin = s.angular_velocity.length();
    assert!((spin - config.max_angular_speed).abs() <= 1e-3 * config.max_angular_speed);
}

/// A call on the world.
type Call = dyn Fn(&mut World) -> Result<(), Error>;

/// Each refused call gives its error and leaves the state hash as it was.
#[test]
fn refused_impulses_change_nothing() {
    let (mut w, body, fixed, kinematic) = world(Quat::from_rotation_z(0.2));
    let removed = w.add_body(BodyDesc::fixed()).unwrap();
    w.remove_body(removed).unwrap();
    let (mut other, ..) = world(Quat::IDENTITY);
    let gone = other.add_body(BodyDesc::fixed()).unwrap();
    other.remove_body(gone).unwrap();
    let centre = w.body(body).unwrap().position;
    let nan = Vec3::new(0.0, f32::NAN, 0.0);
    let cases: Vec<(Error, Box<Call>)> = vec![
        (
            Error::NotDynamic("an impulse"),
            Box::new(move |w| w.apply_impulse(fixed, Vec3::X)),
        ),
        (
            Error::NotDynamic("an impulse"),
            Box::new(move |w| w.apply_impulse_at(kinematic, Vec3::X, Vec3::ZERO)),
        ),
        (
            Error::NotDynamic("an impulse"),
            Box::new(move |w| w.apply_angular_impulse(kinematic, Vec3::X)),
        ),
        (
            Error::NonFinite("impulse"),
            Box::new(move |w| w.apply_impulse(body, nan)),
        ),
        (
            Error::NonFinite("impulse"),
            Box::new(move |w| w.apply_impulse_at(body, Vec3::INFINITY, centre)),
        ),
        (
            Error::NonFinite("angular impulse"),
            Box::new(move |w| w.apply_angular_impulse(body, nan)),
        ),
        (
            Error::NonFinite("impulse point"),
            Box::new(move |w| w.apply_impulse_at(body, Vec3::X, nan)),
        ),
        (
            Error::OutOfRange("impulse point"),
            Box::new(move |w| w.apply_impulse_at(body, Vec3::X, Vec3::Z * 3.0e6)),
        ),
        (
            Error::NonFinite("angular impulse of the impulse at the point"),
            Box::new(move |w| w.apply_impulse_at(body, Vec3::Y * 3.0e38, Vec3::X * 1.5e6)),
        ),
        (
            Error::OutOfRange("impulse (its velocity change overflows f32)"),
            Box::new(move |w| w.apply_angular_impulse(body, Vec3::Z * 1.0e38)),
        ),
        (
            Error::StaleHandle("body"),
            Box::new(move |w| w.apply_impulse(removed, Vec3::X)),
        ),
        (
            Error::ForeignHandle("body"),
            Box::new(move |w| w.apply_impulse(gone, Vec3::X)),
        ),
    ];
    for (expected, call) in cases {
        let before = w.state_hash();
        assert_eq!(call(&mut w), Err(expected.clone()));
        assert_eq!(w.state_hash(), before, "{expected} changed the world");
        assert!(!expected.to_string().is_empty());
    }
}
