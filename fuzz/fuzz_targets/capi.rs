//! Arbitrary call sequences through the C ABI: see `vertebra_fuzzing::capi`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| vertebra_fuzzing::capi(data));
