//! Every lane operation and polynomial on arbitrary floats: see `vertebra_fuzzing::math_backends`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| vertebra_fuzzing::math_backends(data));
