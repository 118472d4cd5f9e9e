//! Arbitrary bytes as a ragdoll file: see `vertebra_fuzzing::ragdoll_loader`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| vertebra_fuzzing::ragdoll_loader(data));
