//! The floating-point mode the solver computes in, whatever its caller set.
//!
//! Rust, and every bit-for-bit promise of this crate, assumes the default
//! floating-point environment: round to nearest, subnormals kept (no
//! flush-to-zero, no denormals-are-zero), exceptions masked. A host may run
//! with another: game engines and audio code often set FTZ and DAZ on their
//! threads for speed, and threads they create inherit it. Then a subnormal
//! that the default mode keeps becomes zero, and the same world steps to
//! other bits on that host than on a thread pool's workers (which start
//! from whatever their creator had).
//!
//! [`DefaultFloatMode`] sets the default mode on the current thread for as
//! long as it lives and gives the caller its own mode back when dropped
//! (the x64 calling conventions treat these bits the same way: callee-saved,
//! standard values expected across calls). A step holds one on the thread
//! that enters it and one on every worker for each chunk it solves; every
//! other public call of the world, ragdoll, collision and scene layers
//! that computes what enters a world, or what a game reads back, holds
//! one for its length (`docs/robustness.md`, "Soundness and numerics").
//!
//! | target | register | what is set |
//! | --- | --- | --- |
//! | x86-64 | MXCSR | `0x1F80`: all exceptions masked, round to nearest, FTZ and DAZ off (status flags cleared; the caller's come back) |
//! | AArch64 | FPCR | `0`: round to nearest, FZ and FZ16 (flush-to-zero) off, DN (default NaN) off, AH and FIZ (FEAT_AFP's alternate handling and input flushing) off, no trap enabled: the register's value at a Linux process's start |
//! | WebAssembly | none | nothing to set: the standard fixes round to nearest and keeps subnormals |
//! | other | | nothing: a host that sets another target's flush or rounding bits changes results there |
//!
//! Bits change only in `stmxcsr`/`ldmxcsr` (`mrs`/`msr fpcr`), each its
//! own `asm!` block, at the guard's creation and drop; the solver's
//! arithmetic runs in the functions called in between. (FPSR, AArch64's
//! status flags, is left alone: nothing reads it.)

use core::marker::PhantomData;

/// MXCSR at reset (Intel SDM vol. 1, 10.2.3): exceptions masked, round to
/// nearest, FTZ and DAZ off.
#[cfg(target_arch = "x86_64")]
const DEFAULT_MXCSR: u32 = 0x1F80;

/// FPCR as Linux starts a process (Arm ARM, D19.2.51 FPCR): every control
/// bit clear.
#[cfg(target_arch = "aarch64")]
const DEFAULT_FPCR: u64 = 0;

/// While alive, the current thread computes in the default floating-point
/// mode; dropping it restores the mode it found. Not `Send`: it must be
/// dropped on the thread that made it.
#[must_use = "the default mode holds only while the guard lives"]
#[derive(Debug)]
pub struct DefaultFloatMode {
    #[cfg(target_arch = "x86_64")]
    previous: u32,
    #[cfg(target_arch = "aarch64")]
    previous: u64,
    _this_thread: PhantomData<*const ()>,
}

impl DefaultFloatMode {
    /// Saves the current thread's mode and sets the default one.
    #[inline]
    pub fn enter() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            let previous = read_mxcsr();
            write_mxcsr(DEFAULT_MXCSR);
            Self {
                previous,
                _this_thread: PhantomData,
            }
        }
        #[cfg(target_arch = "aarch64")]
        {
            let previous = read_fpcr();
            write_fpcr(DEFAULT_FPCR);
            Self {
                previous,
                _this_thread: PhantomData,
            }
        }
        #[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
        {
            Self {
                _this_thread: PhantomData,
            }
        }
    }
}

impl Default for DefaultFloatMode {
    fn default() -> Self {
        Self::enter()
    }
}

impl Drop for DefaultFloatMode {
    #[inline]
    fn drop(&mut self) {
        #[cfg(target_arch = "x86_64")]
        write_mxcsr(self.previous);
        #[cfg(target_arch = "aarch64")]
        write_fpcr(self.previous);
    }
}

#[cfg(target_arch = "x86_64")]
#[inline]
fn read_mxcsr() -> u32 {
    let mut value = 0u32;
    // SAFETY: `stmxcsr` stores the 4-byte MXCSR to `value`, which is
    // writable; SSE is part of the x86-64 baseline.
    unsafe {
        core::arch::asm!("stmxcsr [{}]", in(reg) &mut value, options(nostack, preserves_flags));
    }
    value
}

#[cfg(target_arch = "x86_64")]
#[inline]
fn write_mxcsr(value: u32) {
    // SAFETY: `ldmxcsr` loads MXCSR from `value` (readable); `value` was read
    // from MXCSR or is its reset value, so no reserved bit is set (which
    // would fault).
    unsafe {
        core::arch::asm!("ldmxcsr [{}]", in(reg) &value, options(nostack, preserves_flags, readonly));
    }
}

#[cfg(target_arch = "aarch64")]
#[inline]
fn read_fpcr() -> u64 {
    let value: u64;
    // SAFETY: `mrs` reads FPCR into a register; EL0 may read it.
    unsafe {
        core::arch::asm!("mrs {}, fpcr", out(reg) value, options(nomem, nostack, preserves_flags));
    }
    value
}

#[cfg(target_arch = "aarch64")]
#[inline]
fn write_fpcr(value: u64) {
    // SAFETY: `msr` writes FPCR, which EL0 may write; `value` was read
    // from FPCR or is its reset value, so every RES0 bit is zero.
    unsafe {
        core::arch::asm!("msr fpcr, {}", in(reg) value, options(nomem, nostack, preserves_flags));
    }
}

#[cfg(all(test, target_arch = "aarch64"))]
mod fpcr_tests {
    use super::*;

    #[test]
    fn sets_the_default_mode_and_restores_the_callers() {
        const FZ: u64 = 1 << 24;
        let original = read_fpcr();
        write_fpcr(DEFAULT_FPCR | FZ);
        // Each product from its own opaque operand: the compiler assumes
        // one floating-point mode and would compute the two as one.
        let half_tiny = || core::hint::black_box(1.0e-38f32) * 0.5;
        assert_eq!(half_tiny(), 0.0, "the host's FZ flushes a subnormal result");
        {
            let _mode = DefaultFloatMode::enter();
            assert_eq!(read_fpcr(), DEFAULT_FPCR);
            assert!(half_tiny() > 0.0, "a subnormal result is kept");
        }
        assert_eq!(read_fpcr(), DEFAULT_FPCR | FZ);
        write_fpcr(original);
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    #[test]
    fn sets_the_default_mode_and_restores_the_callers() {
        const FTZ_DAZ: u32 = 0x8040;
        let original = read_mxcsr();
        write_mxcsr(DEFAULT_MXCSR | FTZ_DAZ);
        {
            let _mode = DefaultFloatMode::enter();
            assert_eq!(read_mxcsr() & !0x3F, DEFAULT_MXCSR);
            let tiny = core::hint::black_box(1.0e-38f32);
            assert!(tiny * 0.5 > 0.0, "a subnormal result is kept");
        }
        assert_eq!(read_mxcsr() & !0x3F, DEFAULT_MXCSR | FTZ_DAZ);
        write_mxcsr(original);
    }
}
