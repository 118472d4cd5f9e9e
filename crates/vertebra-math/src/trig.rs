//! `sin`, `cos` and `atan2` of an `f32` with the same bits on every target,
//! for what builders, poses and mapping compute outside the kernels.
//!
//! `f32::sin` and its kin call the platform's C library: glibc on Linux
//! (whose x86-64 build even picks an FMA variant on CPUs that have it),
//! another libm on Apple targets, wasi-libc's on WebAssembly. Their last
//! bits differ (on this repository's x86-64 machine glibc's `sinf` and the
//! musl-derived `libm::sinf` differ for 28.7 million of the 2^32 inputs).
//! Here each is the `f64` function of the `libm` crate (pure Rust, so the
//! same arithmetic on every target; error below one `f64` ulp) rounded
//! once to `f32`: the correctly rounded result, but for inputs whose true
//! value lies within an `f64` ulp of a rounding boundary between two
//! `f32`s (none is known among the inputs the scenes and tests use; a
//! correctly rounded platform function, as glibc's `sinf`, `cosf` and
//! `atan2f` are on those inputs, gives the same bits: the golden hashes
//! say so on x86-64).

/// `sin(x)`, `x` in radians.
#[inline]
pub fn sin(x: f32) -> f32 {
    libm::sin(f64::from(x)) as f32
}

/// `cos(x)`, `x` in radians.
#[inline]
pub fn cos(x: f32) -> f32 {
    libm::cos(f64::from(x)) as f32
}

/// `(sin(x), cos(x))`, `x` in radians.
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    (sin(x), cos(x))
}

/// The angle of `(x, y)` from the +x axis, in `[-pi, pi]` (radians).
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    libm::atan2(f64::from(y), f64::from(x)) as f32
}
