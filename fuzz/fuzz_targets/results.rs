//! `crr plot`'s reader of a results folder: summary.json, history.csv and impacts.csv.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    crr::fuzzing::results(data);
});
