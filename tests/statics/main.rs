//! Contact statics: the static multiplier and its mechanism against independent linear programs, duality and invariance under mirroring and reordering.
//!
//! One test binary per group (`tests/<group>/main.rs`), sharing `tests/common`.

#[path = "../common/mod.rs"]
mod common;

mod collapse_state;
mod duality;
mod exhaustive;
mod friction;
mod independent;
mod invariance;
mod out_of_plane;
mod rest_loads;
mod static_multiplier;
