//! # crr-dynamics
//!
//! Equations of motion of coupled rocking rotations for multi-DOF chains, open and closed:
//! M(q) q̈ + h(q, q̇) = Q(q, t) + Φ_qᵀ λ with the ground motion as an effective gravity
//! ([`eom`]), on open chains also in O(DOF(1)) by the articulated-body algorithm
//! ([`articulated_body`]); ground motions, analytic and recorded ([`ground_motion`]); closed chains (mobility,
//! projection, consistent initial conditions, coordinate partitioning: [`closed_chain`]); the two
//! ODE forms that must agree, constrained and reduced ([`system`]); integrators of our own with
//! exact event location ([`integrator`]); and energy bookkeeping ([`energy`]).

pub mod analysis;
pub mod articulated_body;
pub mod cancel;
pub mod closed_chain;
pub mod energy;
pub mod eom;
pub mod ground_motion;
pub mod input;
pub mod integrator;
pub mod linalg;
pub mod mechanism;
pub mod roots;
pub mod run;
pub mod single_coordinate;
pub mod sparse_cholesky;
pub mod system;

pub use analysis::{AnalysisSpec, MethodName};
pub use articulated_body::ArticulatedBody;
pub use cancel::Cancel;
pub use closed_chain::{
    FiniteMobility, InitialSpec, InitialState, Mobility, Partition, mobility, mobility_after_step,
    partition, solve_initial,
};
pub use energy::{Energies, energies};
pub use eom::{ClosedChainSolve, Dynamics, DynamicsError, ForwardSolver, effective_gravity};
pub use mechanism::{
    EquivalentBlock, LagrangianParameters, equivalent_block, equivalent_block_on_side,
    horizontal_direction, lagrangian_parameters, lagrangian_parameters_on_side, reported_side,
};
pub use run::{Form, Sample, integrate_smooth};
pub use system::{ConstrainedSystem, ReducedSystem};
