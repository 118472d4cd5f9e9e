//! Arbitrary call sequences on a world with arbitrary solver settings: see
//! `vertebra_fuzzing::world_settings`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| vertebra_fuzzing::world_settings(data));
