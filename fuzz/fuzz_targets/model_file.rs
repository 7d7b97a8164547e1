//! The model parser and validation: any text, as TOML and as JSON, must give a model or an error,
//! never a panic; a model that builds must inspect and report its mobility.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    crr::fuzzing::model_file(data);
});
