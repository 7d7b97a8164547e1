//! # crr-impact
//!
//! Pivot switching, impact laws and the event-driven simulation of coupled rocking rotations.
//!
//! - [`laws`]: the impact maps q̇⁻ ↦ q̇⁺ when hinges switch pivot: the generalized Housner
//!   momentum law (default), restitution, and the paper's Dirac-delta force (eq 5),
//!   F = C ln(r) φ̇|φ̇| δ(φ), integrated exactly or regularised.
//! - [`simulation`]: interface states (seated, rocking about P⁺ or P⁻), impacts (simultaneous
//!   ones in loops), seating in the Zeno limit, uplift from rest, collapse, and the trajectory with
//!   its impact log and energy balance.
//! - [`monitor`]: the hypotheses monitor (compressive contacts, friction demand).
//! - [`face_forces`]: the most compressive distribution of a hyperstatic structure's contact
//!   forces on its faces in motion, one sparse linear program (the monitor's check).
//! - [`statics`]: the collapse multiplier at rest by the static theorem, one linear program on
//!   the contact faces, and its mechanism.
//!
//! ## Example: Housner's block released from half its slenderness
//!
//! ```
//! use std::collections::BTreeMap;
//! use crr_dynamics::ground_motion::GroundMotion;
//! use crr_dynamics::{solve_initial, InitialSpec};
//! use crr_impact::{Parameters, Simulation};
//! use crr_kinematics::{fixtures::single_block, Model};
//!
//! // A 0.4 m × 0.4 m × 2 m stone block (b = 0.2 m, h = 1 m).
//! let model = Model::from_spec(&single_block(0.2, 1.0, 2500.0)).unwrap();
//! let alpha = (0.2f64 / 1.0).atan();
//! let initial = solve_initial(&model, &InitialSpec {
//!     angles: BTreeMap::from([("base".to_string(), alpha / 2.0)]),
//!     ..Default::default()
//! }).unwrap();
//! let ground = GroundMotion::none();
//! let run = Simulation::new(&model, &ground, &initial, Parameters { duration: 3.0, ..Default::default() })
//!     .unwrap()
//!     .run()
//!     .map_err(|failure| failure.error)
//!     .unwrap();
//! // Every impact multiplies the rate by r = 1 − 1.5 sin²α (the momentum law).
//! let r = 1.0 - 1.5 * alpha.sin().powi(2);
//! let first = &run.impacts[0];
//! assert!((first.rates_after[0] / first.rates_before[0] - r).abs() < 1e-12);
//! assert!(run.collapse.is_none());
//! ```

pub mod face_forces;
pub mod laws;
pub mod least_distance;
pub mod least_norm;
pub mod monitor;
pub mod nnls;
pub mod simulation;
pub mod statics;

pub use simulation::{
    HeldOnSearch, Interrupted, Parameters, Sample, Samples, Simulation, SimulationError, SlotState,
    StopReason, Trajectory, UNDECIDED_GAP, UNDECIDED_UPLIFTS,
};
