//! Pivot switching, impact laws and the event-driven simulation of coupled rocking rotations.

pub mod laws;
