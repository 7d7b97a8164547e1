//! Pivot switching, impact laws and the event-driven simulation of coupled rocking rotations.

pub mod laws;
pub mod monitor;
pub mod simulation;

pub use simulation::{
    Interrupted, Parameters, Simulation, SimulationError, SlotState, StopReason, Trajectory,
};
