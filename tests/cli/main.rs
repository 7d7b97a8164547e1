//! The command line `crr`: every command run as a user runs it, its files, its messages and its exit codes on good and hostile inputs.
//!
//! One test binary per group (`tests/<group>/main.rs`), sharing `tests/common`.

#[path = "../common/mod.rs"]
mod common;

mod animate;
mod assemble;
mod check;
mod fuzz_corpus;
mod hops;
mod hostile_inputs;
mod input_checks;
mod inspect;
mod interrupt;
mod mechanism;
mod outputs;
mod plot;
mod poincare_limits;
mod record_file;
mod simulate;
mod warnings;
