//! x
pub mod ground_motion;
