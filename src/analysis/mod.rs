//! The analysis layer: what crr computes from a model, in memory. A simulation ([`simulation`],
//! behind [`crate::run`]), the `crr check` report and its static multiplier, energy levels, size
//! sweeps, Poincaré sections and studies. Nothing here writes a results folder or draws a plot;
//! those are the output layer's.

pub mod assemble;
pub mod check;
pub mod inspect;
pub mod levels;
pub mod poincare;
pub mod simulation;
pub mod size_sweep;
pub mod static_multiplier;
pub mod study;
pub mod summary;
