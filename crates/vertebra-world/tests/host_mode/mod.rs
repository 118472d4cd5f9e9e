//! The floating-point control register, read and written as a host does
//! before it calls in (MXCSR on x86-64, FPCR on AArch64): the one place the
//! tests that play such a host set a floating-point mode.
#![allow(dead_code)]

/// The register at a process's start: round to nearest, nothing flushed.
#[cfg(target_arch = "x86_64")]
pub const DEFAULT: u64 = 0x1F80;
/// Flush-to-zero with denormals-are-zero (MXCSR bits 15 and 6).
#[cfg(target_arch = "x86_64")]
pub const FLUSH: u64 = 0x8040;
/// The rounding field (bits 13-14): down, up, toward zero.
#[cfg(target_arch = "x86_64")]
pub const ROUNDING: [(&str, u64); 3] = [
    ("round down", 0x2000),
    ("round up", 0x4000),
    ("round toward zero", 0x6000),
];
/// The sticky status flags, which a call may set (bits 0-5).
#[cfg(target_arch = "x86_64")]
pub const STATUS: u64 = 0x3F;

/// FPCR at a Linux process's start: every control bit clear.
#[cfg(target_arch = "aarch64")]
pub const DEFAULT: u64 = 0;
/// Flush-to-zero (FPCR.FZ, bit 24: subnormal inputs and results are zero).
#[cfg(target_arch = "aarch64")]
pub const FLUSH: u64 = 1 << 24;
/// The rounding field RMode (bits 22-23): toward minus infinity, plus
/// infinity, zero.
#[cfg(target_arch = "aarch64")]
pub const ROUNDING: [(&str, u64); 3] = [
    ("round down", 2 << 22),
    ("round up", 1 << 22),
    ("round toward zero", 3 << 22),
];
/// FPCR holds no status flags (they are in FPSR).
#[cfg(target_arch = "aarch64")]
pub const STATUS: u64 = 0;

#[cfg(target_arch = "x86_64")]
pub fn read_mode() -> u64 {
    let mut value = 0u32;
    // SAFETY: stores MXCSR to a writable u32.
    unsafe {
        core::arch::asm!("stmxcsr [{}]", in(reg) &mut value, options(nostack, preserves_flags));
    }
    value.into()
}

#[cfg(target_arch = "x86_64")]
pub fn write_mode(value: u64) {
    let value = value as u32;
    // SAFETY: loads MXCSR from a readable u32 holding only valid bits.
    unsafe {
        core::arch::asm!("ldmxcsr [{}]", in(reg) &value, options(nostack, preserves_flags, readonly));
    }
}

#[cfg(target_arch = "aarch64")]
pub fn read_mode() -> u64 {
    let value: u64;
    // SAFETY: reads FPCR, which EL0 may read.
    unsafe {
        core::arch::asm!("mrs {}, fpcr", out(reg) value, options(nomem, nostack, preserves_flags));
    }
    value
}

#[cfg(target_arch = "aarch64")]
pub fn write_mode(value: u64) {
    // SAFETY: writes FPCR, which EL0 may write, with only control bits.
    unsafe {
        core::arch::asm!("msr fpcr, {}", in(reg) value, options(nomem, nostack, preserves_flags));
    }
}
