//! x
pub mod integrator;
