//! The documentation stays true: its commands and examples run, it stands alone, and the crate keeps its layers.
//!
//! One test binary per group (`tests/<group>/main.rs`), sharing `tests/common`.

#[path = "../common/mod.rs"]
mod common;

mod commands;
mod constants;
mod examples;
mod layers;
mod self_contained;
