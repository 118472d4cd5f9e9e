//! Choosing the instruction set once, at run time, and entering kernels
//! through it.
//!
//! A kernel is a [`LaneKernel`]: one generic body over [`Lane`]. Each SIMD
//! backend enters it through a `#[target_feature]` function, so the body
//! and every lane operation in it inline into code compiled for that
//! instruction set, while the binary itself stays built for the baseline
//! CPU (no `target-cpu` flags: the binary must not die on older machines).

use core::fmt;
use core::str::FromStr;

use crate::lane::Lane;

/// An instruction set that kernels can run on.
///
/// Every backend gives the same bits as [`Backend::Scalar`] for every
/// input (NaN payloads aside, see [`crate::lane`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Backend {
    /// One lane of plain `f32`: the reference.
    Scalar,
    /// Four lanes through `wide::f32x4`, for any target.
    Portable,
    /// Four lanes, explicit SSE4.1 intrinsics.
    Sse41,
    /// Four lanes, the SSE4.1 code entered with AVX2 and FMA enabled
    /// (VEX-encoded, three-operand instructions).
    Avx2x4,
    /// Eight lanes, explicit AVX2 intrinsics.
    Avx2,
    /// Four lanes, explicit AArch64 NEON intrinsics.
    Neon,
    /// Four lanes, explicit WebAssembly SIMD128 intrinsics (builds with
    /// the `simd128` target feature).
    Simd128,
}

/// The work a backend runs: one body, generic over the lane type.
///
/// Implementations mark [`LaneKernel::run`] `#[inline(always)]`: it is
/// instantiated once per backend inside that backend's `#[target_feature]`
/// entry, and only inlined there does it get that backend's instructions.
pub trait LaneKernel {
    /// What the kernel returns.
    type Output;
    /// Runs the kernel with lane type `L`.
    fn run<L: Lane>(self) -> Self::Output;
}

impl Backend {
    /// Every backend, scalar first.
    pub const ALL: [Backend; 7] = [
        Backend::Scalar,
        Backend::Portable,
        Backend::Sse41,
        Backend::Avx2x4,
        Backend::Avx2,
        Backend::Neon,
        Backend::Simd128,
    ];

    /// The name used on command lines and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Scalar => "scalar",
            Backend::Portable => "portable",
            Backend::Sse41 => "sse4",
            Backend::Avx2x4 => "avx2x4",
            Backend::Avx2 => "avx2",
            Backend::Neon => "neon",
            Backend::Simd128 => "simd128",
        }
    }

    /// How many constraints one kernel call solves at once.
    pub fn lanes(self) -> usize {
        match self {
            Backend::Scalar => 1,
            Backend::Portable
            | Backend::Sse41
            | Backend::Avx2x4
            | Backend::Neon
            | Backend::Simd128 => 4,
            Backend::Avx2 => 8,
        }
    }

    /// Whether this CPU can run the backend: the x86 ones detected once
    /// (cached by std); NEON wherever the target has it (every AArch64
    /// CPU: it is the target's baseline); SIMD128 in a WebAssembly build
    /// with the `simd128` target feature (WebAssembly cannot detect it at
    /// run time: a module with SIMD does not load without it).
    pub fn is_available(self) -> bool {
        match self {
            Backend::Scalar | Backend::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Backend::Sse41 => std::arch::is_x86_feature_detected!("sse4.1"),
            #[cfg(target_arch = "x86_64")]
            Backend::Avx2x4 | Backend::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            Backend::Neon => cfg!(all(target_arch = "aarch64", target_feature = "neon")),
            Backend::Simd128 => cfg!(all(target_arch = "wasm32", target_feature = "simd128")),
            #[cfg(not(target_arch = "x86_64"))]
            Backend::Sse41 | Backend::Avx2x4 | Backend::Avx2 => false,
        }
    }

    /// The backends this CPU can run, scalar first.
    pub fn available() -> impl Iterator<Item = Backend> {
        Self::ALL.into_iter().filter(|b| b.is_available())
    }

    /// The fastest backend this CPU can run: 8-lane AVX2, else SSE4.1 (on
    /// x86-64), NEON (on AArch64), SIMD128 (on WebAssembly with SIMD), else
    /// the portable 4 lanes.
    pub fn best() -> Backend {
        [
            Backend::Avx2,
            Backend::Sse41,
            Backend::Neon,
            Backend::Simd128,
        ]
        .into_iter()
        .find(|b| b.is_available())
        .unwrap_or(Backend::Portable)
    }

    /// Runs `kernel` with this backend's lane type.
    ///
    /// A backend this CPU lacks runs as [`Backend::Scalar`] instead, which
    /// gives the same bits; [`BackendChoice::resolve`] is where a forced but
    /// unavailable backend is reported as an error.
    #[inline]
    pub fn dispatch<K: LaneKernel>(self, kernel: K) -> K::Output {
        if !self.is_available() {
            return kernel.run::<f32>();
        }
        match self {
            Backend::Scalar => kernel.run::<f32>(),
            Backend::Portable => kernel.run::<crate::lane::portable::F32x4Portable>(),
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `is_available` confirmed SSE4.1 on this CPU.
            Backend::Sse41 => unsafe { x86::enter_sse41(kernel) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `is_available` confirmed AVX2 and FMA on this CPU.
            Backend::Avx2x4 => unsafe { x86::enter_avx2x4(kernel) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `is_available` confirmed AVX2 and FMA on this CPU.
            Backend::Avx2 => unsafe { x86::enter_avx2(kernel) },
            // NEON and SIMD128 are the build's own instruction sets: no
            // entry with other target features is needed.
            #[cfg(all(target_arch = "aarch64", target_feature = "neon"))]
            Backend::Neon => kernel.run::<crate::lane::neon::F32x4Neon>(),
            #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
            Backend::Simd128 => kernel.run::<crate::lane::simd128::F32x4Wasm>(),
            // Unavailable here: handled above.
            #[allow(unreachable_patterns)]
            _ => kernel.run::<f32>(),
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::LaneKernel;
    use crate::lane::avx2::F32x8;
    use crate::lane::sse41::F32x4;

    #[target_feature(enable = "sse4.1")]
    pub(super) fn enter_sse41<K: LaneKernel>(kernel: K) -> K::Output {
        kernel.run::<F32x4>()
    }

    #[target_feature(enable = "avx2,fma")]
    pub(super) fn enter_avx2x4<K: LaneKernel>(kernel: K) -> K::Output {
        kernel.run::<F32x4>()
    }

    #[target_feature(enable = "avx2,fma")]
    pub(super) fn enter_avx2<K: LaneKernel>(kernel: K) -> K::Output {
        kernel.run::<F32x8>()
    }
}

impl fmt::Display for Backend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Which backend to use: the best available one, or a forced one (for
/// tests, benches and reproducing a run).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BackendChoice {
    /// [`Backend::best`].
    #[default]
    Auto,
    /// This backend, or an error if the CPU lacks it.
    Forced(Backend),
}

impl BackendChoice {
    /// The backend to run, or [`BackendError::Unavailable`] for a forced
    /// backend this CPU cannot run.
    pub fn resolve(self) -> Result<Backend, BackendError> {
        match self {
            BackendChoice::Auto => Ok(Backend::best()),
            BackendChoice::Forced(b) if b.is_available() => Ok(b),
            BackendChoice::Forced(b) => Err(BackendError::Unavailable(b)),
        }
    }
}

impl FromStr for BackendChoice {
    type Err = BackendError;
    /// `auto`, or a backend name: `scalar`, `portable`, `sse4`, `avx2x4`,
    /// `avx2`, `neon`, `simd128`.
    fn from_str(s: &str) -> Result<Self, BackendError> {
        if s == "auto" {
            return Ok(BackendChoice::Auto);
        }
        Backend::ALL
            .into_iter()
            .find(|b| b.name() == s)
            .map(BackendChoice::Forced)
            .ok_or_else(|| BackendError::Unknown(s.to_owned()))
    }
}

/// Why a backend cannot be used.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BackendError {
    /// The name is not one of `auto`, `scalar`, `portable`, `sse4`,
    /// `avx2x4`, `avx2`, `neon`, `simd128`.
    Unknown(String),
    /// This CPU lacks the instructions the forced backend needs.
    Unavailable(Backend),
}

impl fmt::Display for BackendError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BackendError::Unknown(s) => write!(
                f,
                "unknown backend `{s}` (expected auto, scalar, portable, sse4, avx2x4, avx2, neon or simd128)"
            ),
            BackendError::Unavailable(b) => {
                write!(f, "backend `{b}` is not supported by this CPU")
            }
        }
    }
}

impl std::error::Error for BackendError {}
