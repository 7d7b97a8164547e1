//! The engine through the library: closed forms, conservation laws and independent derivations on simulated runs (impact laws on chains, uplift, collapse, loops, the temple and the 3D arch).
//!
//! One test binary per group (`tests/<group>/main.rs`), sharing `tests/common`.

#[path = "../common/mod.rs"]
mod common;

mod arch_3d;
mod certificate_audit;
mod collapse;
mod corner_order;
mod far_from_origin;
mod free_fall;
mod friction_on_loops;
mod impact_laws_on_chains;
mod impulse_tension;
mod initial_state_paths;
mod invariant;
mod loop_residual;
mod mirror_invariance;
mod opening_program;
mod order_invariance;
mod out_of_plane;
mod stack_planar_and_3d;
mod stop_at_violation;
mod streaming;
mod temple;
mod twist_closure;
mod unheld_seat;
mod uplift_at_a_jump;
mod uplift_at_multiplier;
mod uplift_fast_signals;
mod uplift_filter_in_loops;
mod uplift_in_loops;
mod uplift_time;
mod validation_two_block_stack;
