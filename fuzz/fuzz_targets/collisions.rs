//! Removal, snapshots and detection on a world with a collision set and
//! ragdolls: see `vertebra_fuzzing::collisions`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| vertebra_fuzzing::collisions(data));
