//! Arbitrary socket, rod and contact lanes through every backend: see `vertebra_fuzzing::kernels`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| vertebra_fuzzing::kernels(data));
