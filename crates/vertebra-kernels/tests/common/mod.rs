//! Random and adversarial scenes shared by the kernels' cross-backend tests.
#![allow(dead_code)]

use glam::{Mat3, Quat, Vec3};
use rand::RngExt;
use rand::rngs::StdRng;
use vertebra_kernels::body::{BodyRows, PairLane, StartLane};
use vertebra_kernels::driven::DriveLane;
use vertebra_kernels::limited::LimitLane;
use vertebra_math::block::BLOCK_LANES;
use vertebra_math::check::same_bits;
use vertebra_math::{Backend, PortableQuat};

/// Body rows as plain floats: pose, inverse inertia, velocity.
pub type RawRows = Vec<[[f32; 8]; 3]>;

pub fn unit_quat(r: &mut StdRng) -> Quat {
    Quat::from_xyzw(
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
        r.random_range(-1.0..1.0),
    )
    .normalize_portable()
}

pub fn vec(r: &mut StdRng, scale: f32) -> Vec3 {
    Vec3::new(
        r.random_range(-scale..scale),
        r.random_range(-scale..scale),
        r.random_range(-scale..scale),
    )
}

/// A random symmetric positive definite inverse inertia.
pub fn inverse_inertia(r: &mut StdRng) -> Mat3 {
    let q = Mat3::from_quat(unit_quat(r));
    let d = Vec3::new(
        r.random_range(0.1..50.0),
        r.random_range(0.1..50.0),
        r.random_range(0.1..50.0),
    );
    q * Mat3::from_diagonal(d) * q.transpose()
}

/// Rows for `lanes` joints with two own bodies each, plus `statics` fixed
/// bodies at the end (row 0 is the null row). `adversarial` adds zero
/// masses and identity orientations.
pub fn rows(r: &mut StdRng, lanes: usize, statics: usize, adversarial: bool) -> RawRows {
    let bodies = lanes * 2 + statics;
    let mut rows = vec![BodyRows::null_raw(); bodies + 1];
    for (i, row) in rows.iter_mut().enumerate().skip(1) {
        let fixed = i > bodies - statics || (adversarial && r.random_bool(0.1));
        let inv_mass = if fixed {
            0.0
        } else {
            r.random_range(0.01..10.0)
        };
        let inertia = if fixed {
            Mat3::ZERO
        } else {
            inverse_inertia(r)
        };
        let q = if adversarial && r.random_bool(0.2) {
            Quat::IDENTITY
        } else {
            unit_quat(r)
        };
        *row = [
            BodyRows::pose_row(vec(r, 3.0), inv_mass, q),
            BodyRows::inertia_row(inertia),
            BodyRows::velocity_row(vec(r, 5.0), vec(r, 5.0)),
        ];
    }
    rows
}

/// The two body rows of joint `lane` (its own, or a static one on one
/// side), as the colouring allows: a written row is used by one lane only.
pub fn lane_bodies(r: &mut StdRng, rows: &RawRows, lane: usize, statics: usize) -> (u32, u32) {
    let own = |k: usize| (1 + lane * 2 + k) as u32;
    let static_row = (rows.len() - 1 - r.random_range(0..statics)) as u32;
    match r.random_range(0..4) {
        0 => (static_row, own(1)),
        1 => (own(0), static_row),
        _ => (own(0), own(1)),
    }
}

/// Whether a row's body is dynamic.
pub fn dynamic(rows: &RawRows, row: u32) -> bool {
    rows[row as usize][0][3] > 0.0
}

/// The lane header of a constraint between rows `a` and `b`, each written
/// where its body is dynamic.
pub fn pair(rows: &RawRows, a: u32, b: u32) -> PairLane {
    PairLane {
        body_a: a,
        body_b: b,
        dynamic_a: dynamic(rows, a),
        dynamic_b: dynamic(rows, b),
    }
}

pub fn to_rows(raw: &RawRows) -> BodyRows {
    BodyRows::from_raw(raw)
}

/// Every row's pose and velocity, flattened.
pub fn flatten(rows: &BodyRows) -> Vec<f32> {
    let mut out = Vec::new();
    for i in 0..rows.pose.len() {
        out.extend(rows.pose[i].get());
        out.extend(rows.velocity[i].get());
    }
    out
}

/// Runs `run` on every backend and compares with the scalar reference.
pub fn assert_backends_agree(seed: u64, run: impl Fn(Backend) -> Vec<f32>) {
    let expected = run(Backend::Scalar);
    assert!(
        expected.iter().all(|x| x.is_finite()),
        "seed {seed}: the scalar reference produced a non-finite value"
    );
    for backend in Backend::available() {
        let actual = run(backend);
        if let Some(k) = (0..expected.len()).find(|&k| !same_bits(expected[k], actual[k])) {
            panic!(
                "seed {seed}: {backend} differs at float {k}: {:e} vs scalar {:e}",
                actual[k], expected[k]
            );
        }
    }
}

/// Builds a scene per seed (random, or adversarial) and checks that every
/// backend runs it to the scalar reference's bits.
pub fn agree_over_seeds<B>(
    seeds: core::ops::Range<u64>,
    adversarial: bool,
    scene: fn(u64, usize, bool) -> (RawRows, Vec<B>),
    run: fn(Backend, &RawRows, &[B]) -> Vec<f32>,
) {
    for seed in seeds {
        let (rows, blocks) = scene(seed, 6, adversarial);
        assert_backends_agree(seed, |b| run(b, &rows, &blocks));
    }
}

/// A random start of step for one lane (adversarial: zero, as for a pair
/// whose points coincided when the step began and whose rows hold absolute
/// positions).
pub fn start(r: &mut StdRng, adversarial: bool) -> StartLane {
    if adversarial && r.random_bool(0.3) {
        return StartLane::default();
    }
    StartLane {
        gap: vec(r, 0.5),
        arm_a: vec(r, 0.5),
        arm_b: vec(r, 0.5),
    }
}

/// A limit's softness of every kind: hard, compliance (with damping or
/// without), a spring at any frequency and damping ratio, and extremes.
pub fn limit_softness(r: &mut StdRng, compliance: f32) -> LimitLane {
    let omega = match r.random_range(0..3) {
        0 => 1e-2,
        1 => 1e4,
        _ => r.random_range(1.0..200.0f32),
    };
    let damping_time = match r.random_range(0..4) {
        0 => 0.0,
        1 => 1e6,
        _ => r.random_range(0.0..1.0),
    };
    match r.random_range(0..4) {
        0 => LimitLane::HARD,
        1 => LimitLane {
            compliance,
            ..LimitLane::HARD
        },
        2 => LimitLane {
            compliance,
            damping_time,
            ..LimitLane::HARD
        },
        _ => LimitLane {
            period2: 1.0 / (omega * omega),
            damping_time,
            ..LimitLane::HARD
        },
    }
}

/// A violation at the substep's start (rad): zero, small or large.
pub fn limit_start(r: &mut StdRng) -> f32 {
    match r.random_range(0..3) {
        0 => 0.0,
        1 => r.random_range(0.0..0.1),
        _ => r.random_range(0.0..4.0),
    }
}

/// Which lanes of a block hold joints in [`padded_blocks_agree`] (bit `i`:
/// lane `i` live): the first 1 to 8 lanes (as the layout fills a colour's
/// last block), the upper half alone, one lane of the upper half, every
/// other lane.
pub const LIVE_PATTERNS: [u32; 11] = [
    0b1, 0b11, 0b111, 0xF, 0x1F, 0x3F, 0x7F, 0xFF, 0xF0, 0x20, 0x55,
];

/// A scene's blocks with only the lanes of each [`LIVE_PATTERNS`] entry
/// kept (`clear` makes the others padding): every backend runs them to the
/// scalar reference's bits, whichever slices and lane widths it skips or
/// narrows to.
pub fn padded_blocks_agree<B: Clone>(
    seeds: core::ops::Range<u64>,
    scene: fn(u64, usize, bool) -> (RawRows, Vec<B>),
    clear: fn(&mut B, usize),
    run: fn(Backend, &RawRows, &[B]) -> Vec<f32>,
) {
    for seed in seeds {
        let (rows, blocks) = scene(seed, 3, seed % 2 == 1);
        for live in LIVE_PATTERNS {
            let mut padded = blocks.clone();
            for block in &mut padded {
                for lane in (0..BLOCK_LANES).filter(|lane| live & (1 << lane) == 0) {
                    clear(block, lane);
                }
            }
            assert_backends_agree(seed, |b| run(b, &rows, &padded));
        }
    }
}

/// Turns a body by the world rotation vector `v`, exactly (the gradient
/// tests' finite differences).
pub fn turned(
    mut b: vertebra_kernels::body::BodyLanes<f32>,
    v: Vec3,
) -> vertebra_kernels::body::BodyLanes<f32> {
    b.q = (Quat::from_scaled_axis(v) * Quat::from(b.q))
        .normalize()
        .into();
    b
}

/// Moves a body by `v` (m, world).
pub fn moved(
    mut b: vertebra_kernels::body::BodyLanes<f32>,
    v: Vec3,
) -> vertebra_kernels::body::BodyLanes<f32> {
    b.p = (Vec3::from(b.p) + v).into();
    b
}

/// A drive of either strength (compliance, or `1 / omega^2` with
/// compliance 0), moving or still, with or without a torque limit.
pub fn random_drive(r: &mut StdRng, compliance: f32) -> DriveLane {
    let spring = r.random_bool(0.5);
    let omega = match r.random_range(0..3) {
        0 => 1e-2,
        1 => 1e4,
        _ => r.random_range(1.0..200.0),
    };
    DriveLane {
        target: unit_quat(r),
        velocity: if r.random_bool(0.5) {
            glam::Vec3::new(
                r.random_range(-20.0..20.0),
                r.random_range(-20.0..20.0),
                r.random_range(-20.0..20.0),
            )
        } else {
            glam::Vec3::ZERO
        },
        compliance: if spring { 0.0 } else { compliance },
        period2: if spring { 1.0 / (omega * omega) } else { 0.0 },
        damping_time: match r.random_range(0..3) {
            0 => 0.0,
            1 => 1e6,
            _ => r.random_range(0.0..1.0),
        },
        max_torque: match r.random_range(0..4) {
            0 => 0.0,
            1 => r.random_range(0.0..50.0),
            _ => f32::INFINITY,
        },
    }
}
