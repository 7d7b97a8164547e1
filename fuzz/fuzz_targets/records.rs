//! The accelerogram readers: PEER `.AT2`, CSV and whitespace tables.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    crr::fuzzing::records(data);
});
