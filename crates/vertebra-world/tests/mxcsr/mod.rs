//! MXCSR, read and written as a host does before it calls in: the one
//! place the tests that play such a host set a floating-point mode.

pub fn read_mxcsr() -> u32 {
    let mut value = 0u32;
    // SAFETY: stores MXCSR to a writable u32.
    unsafe {
        core::arch::asm!("stmxcsr [{}]", in(reg) &mut value, options(nostack, preserves_flags));
    }
    value
}

pub fn write_mxcsr(value: u32) {
    // SAFETY: loads MXCSR from a readable u32 holding only valid bits.
    unsafe {
        core::arch::asm!("ldmxcsr [{}]", in(reg) &value, options(nostack, preserves_flags, readonly));
    }
}
