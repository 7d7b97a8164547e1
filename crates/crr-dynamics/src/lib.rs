//! x
pub mod ground_motion;
pub mod integrator;
