//! Crafted snapshots restored and stepped: see `vertebra_fuzzing::snapshot`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| vertebra_fuzzing::snapshot(data));
