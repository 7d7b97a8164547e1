//! The analyses on top of a run: energy levels, size sweeps, Poincaré sections and sweeps, studies and their folders and products.
//!
//! One test binary per group (`tests/<group>/main.rs`), sharing `tests/common`.

#[path = "../common/mod.rs"]
mod common;

mod cancel;
mod levels;
mod overturning_map;
mod poincare;
mod size_sweep;
mod study;
mod study_folders;
mod study_inputs;
mod study_products;
