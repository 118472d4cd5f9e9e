//! Arbitrary call sequences on a world: see `vertebra_fuzzing::world_api`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| vertebra_fuzzing::world_api(data));
