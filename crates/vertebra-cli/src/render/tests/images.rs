//! Rendered images against closed forms.

use glam::Vec3;

use super::{close, ray};
use crate::render::shade::BACKGROUND;
use crate::render::{Camera, Image, Light, Object, Paint, Primitive, Scene, render, sample};

/// An 8-bit sRGB channel back to linear, written out from IEC 61966-2-1
/// (not the renderer's own conversion).
fn linear(channel: u8) -> f32 {
    let c = f32::from(channel) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_pixel(image: &Image, x: u32, y: u32) -> Vec3 {
    let [r, g, b] = image.pixel(x, y);
    Vec3::new(linear(r), linear(g), linear(b))
}

const PAINT: Vec3 = Vec3::new(0.5, 0.4, 0.3);
const SIDE: u32 = 201;
const FOV_Y: f32 = 40.0;

fn plain(primitive: Primitive) -> Object {
    Object {
        primitive,
        paint: Paint::Plain(PAINT),
    }
}

/// The camera at (0, 0, 5) looking at the origin, `SIDE` pixels square.
fn camera() -> Camera {
    Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, FOV_Y, SIDE, SIDE).unwrap()
}

/// The focal length in pixels: half the image's height over the tangent
/// of half the field of view.
fn focal() -> f32 {
    0.5 * SIDE as f32 / (0.5 * FOV_Y).to_radians().tan()
}

/// Rendered `primitive` at the origin seen from +Z, lit from `towards`.
fn lit(primitive: Primitive, towards: Vec3, sun: f32, ambient: f32) -> Image {
    let scene = Scene::new(vec![plain(primitive)]).unwrap();
    render(
        &scene,
        &Light::new(towards, sun, ambient).unwrap(),
        &camera(),
    )
}

/// Within 1.5% of `expected` per channel (8-bit rounding and the four
/// samples' slightly different normals).
fn assert_near(got: Vec3, expected: Vec3) {
    assert!(
        close(got, expected, 0.015 * expected.max_element()),
        "{got} expected {expected}"
    );
}

#[test]
fn the_projected_centre_shows_lamberts_law_and_the_corners_the_background() {
    let towards = Vec3::new(0.0, 1.0, 1.0);
    let (sun, ambient) = (0.7, 0.2);
    let shapes = [
        Primitive::Sphere {
            centre: Vec3::ZERO,
            radius: 1.0,
        },
        Primitive::Capsule {
            a: Vec3::new(-1.0, 0.0, 0.0),
            b: Vec3::new(1.0, 0.0, 0.0),
            radius: 0.5,
        },
    ];
    for shape in shapes {
        let image = lit(shape, towards, sun, ambient);
        // At the image's centre the surface faces the eye: n = +Z, so
        // n . l = cos 45 degrees.
        let facing = std::f32::consts::FRAC_1_SQRT_2;
        let middle = SIDE / 2;
        assert_near(
            linear_pixel(&image, middle, middle),
            PAINT * (ambient + sun * facing),
        );
        for (x, y) in [(0, 0), (SIDE - 1, 0), (0, SIDE - 1), (SIDE - 1, SIDE - 1)] {
            assert_near(linear_pixel(&image, x, y), BACKGROUND);
        }
    }
    // On the sphere's lower part, turned from the light (n . l < 0): the
    // ambient term alone. The point n = (0, -0.8, 0.6) projects to
    // (centre, centre + f 0.8 / (5 - 0.6)).
    let sphere = lit(shapes[0], towards, sun, ambient);
    let y = 0.5 * SIDE as f32 + focal() * 0.8 / 4.4;
    assert_near(linear_pixel(&sphere, SIDE / 2, y as u32), PAINT * ambient);
}

/// The silhouette's area in pixels, under flat shading: each pixel's
/// coverage from its linear red between the background's (a corner's, as
/// 8-bit rounding left it) and the paint's (the centre's).
fn covered(image: &Image) -> f32 {
    let background = linear_pixel(image, 0, 0).x;
    let paint = linear_pixel(image, image.width / 2, image.height / 2).x;
    let mut area = 0.0;
    for y in 0..image.height {
        for x in 0..image.width {
            area += (linear_pixel(image, x, y).x - background) / (paint - background);
        }
    }
    area
}

#[test]
fn silhouettes_cover_their_projected_area() {
    // A ball of radius r at distance D: a disc of radius f r / sqrt(D^2 -
    // r^2) pixels.
    let sphere = Primitive::Sphere {
        centre: Vec3::ZERO,
        radius: 1.0,
    };
    let disc = focal() / 24f32.sqrt();
    let area = covered(&lit(sphere, Vec3::Y, 0.0, 1.0));
    let expected = std::f32::consts::PI * disc * disc;
    assert!(
        (area / expected - 1.0).abs() < 0.005,
        "{area} px, expected {expected}"
    );
    // A capsule across the view, far away through a narrow field (nearly
    // orthographic): 2 r L + pi r^2 at f / D pixels a metre.
    let far = Camera::look_at(Vec3::new(0.0, 0.0, 100.0), Vec3::ZERO, 2.0, SIDE, SIDE).unwrap();
    let capsule = Primitive::Capsule {
        a: Vec3::new(-0.5, 0.0, 0.0),
        b: Vec3::new(0.5, 0.0, 0.0),
        radius: 0.25,
    };
    let scene = Scene::new(vec![plain(capsule)]).unwrap();
    let image = render(&scene, &Light::new(Vec3::Y, 0.0, 1.0).unwrap(), &far);
    let per_metre = 0.5 * SIDE as f32 / 1f32.to_radians().tan() / 100.0;
    let expected = (2.0 * 0.25 * 1.0 + std::f32::consts::PI * 0.0625) * per_metre * per_metre;
    let area = covered(&image);
    assert!(
        (area / expected - 1.0).abs() < 0.01,
        "{area} px, expected {expected}"
    );
}

#[test]
fn a_point_behind_an_occluder_along_the_light_is_in_shadow() {
    let floor = Object {
        primitive: Primitive::Plane {
            normal: Vec3::Y,
            offset: 0.0,
        },
        paint: Paint::Plain(PAINT),
    };
    let ball = plain(Primitive::Sphere {
        centre: Vec3::new(0.0, 1.0, 0.0),
        radius: 0.5,
    });
    let scene = Scene::new(vec![floor, ball]).unwrap();
    let light = Light::new(Vec3::Y, 0.7, 0.2).unwrap();
    // Seen from the side (the ball out of the way), the floor under the
    // ball gets the ambient light only, the floor 2 m off the full sun.
    let under = sample(
        &scene,
        &light,
        &ray(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, -1.0, -3.0)),
    );
    let open = sample(
        &scene,
        &light,
        &ray(Vec3::new(2.0, 1.0, 3.0), Vec3::new(0.0, -1.0, -3.0)),
    );
    assert_eq!(under.object, open.object, "both on the floor");
    assert!(close(under.colour, PAINT * 0.2, 1e-6), "{under:?}");
    assert!(close(open.colour, PAINT * 0.9, 1e-6), "{open:?}");
}

#[test]
fn non_finite_or_degenerate_input_is_refused_by_name() {
    let nan = Vec3::new(f32::NAN, 0.0, 0.0);
    let refused = [
        Camera::look_at(nan, Vec3::ZERO, 40.0, 10, 10).err(),
        Camera::look_at(Vec3::ONE, Vec3::ONE, 40.0, 10, 10).err(),
        Camera::look_at(Vec3::Y, Vec3::ZERO, 40.0, 10, 10).err(),
        Camera::look_at(Vec3::Z, Vec3::ZERO, f32::NAN, 10, 10).err(),
        Camera::look_at(Vec3::Z, Vec3::ZERO, 180.0, 10, 10).err(),
        Camera::look_at(Vec3::Z, Vec3::ZERO, 40.0, 0, 10).err(),
        Camera::look_at(Vec3::Z, Vec3::ZERO, 40.0, 10, 9000).err(),
        Light::new(Vec3::ZERO, 1.0, 0.1).err(),
        Light::new(Vec3::Y, f32::INFINITY, 0.1).err(),
        Light::new(Vec3::Y, 1.0, -0.1).err(),
    ];
    for (k, error) in refused.iter().enumerate() {
        let error = error.as_ref().unwrap_or_else(|| panic!("case {k} refused"));
        assert!(
            error.starts_with("camera: ") || error.starts_with("light: "),
            "{error}"
        );
    }
    let good = plain(Primitive::Sphere {
        centre: Vec3::ZERO,
        radius: 1.0,
    });
    let bad = [
        Primitive::Sphere {
            centre: nan,
            radius: 1.0,
        },
        Primitive::Capsule {
            a: Vec3::ZERO,
            b: Vec3::ONE,
            radius: f32::INFINITY,
        },
        Primitive::Box {
            centre: Vec3::ZERO,
            rotation: glam::Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0),
            half_extents: Vec3::ONE,
        },
        Primitive::Plane {
            normal: Vec3::new(0.0, 2.0, 0.0),
            offset: 0.0,
        },
    ];
    for primitive in bad {
        let error = Scene::new(vec![good, plain(primitive)])
            .err()
            .expect("refused");
        assert!(error.starts_with("render: object 1 "), "{error}");
    }
    let red = Object {
        paint: Paint::Plain(Vec3::new(f32::NAN, 0.0, 0.0)),
        ..good
    };
    assert!(Scene::new(vec![red]).is_err());
}

#[test]
fn the_image_is_the_same_bytes_on_one_thread_or_two() {
    let objects = (0..40)
        .map(|k| {
            let x = k as f32 * 0.13 - 2.5;
            plain(Primitive::Capsule {
                a: Vec3::new(x, -1.0, (k % 7) as f32 * 0.2),
                b: Vec3::new(-x, 1.0, 0.0),
                radius: 0.1,
            })
        })
        .collect();
    let scene = Scene::new(objects).unwrap();
    let light = Light::new(Vec3::new(-1.0, 2.0, 1.0), 0.7, 0.2).unwrap();
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&scene, &light, &camera()).rgba)
    };
    assert_eq!(on(1), on(2));
}
