//! # crr-kinematics
//!
//! Kinematics of coupled rocking rotations (CRR): the model of a rigid-block structure (bodies
//! with exact mass properties, hinges and rocking bases, the spanning tree from the ground and its
//! loop closures), the rotation operators Γ along each tree path for the active pivots (eq 1), body
//! positions and Jacobians, the γ inner products and the mass matrix M(q) (eq 2), the potential
//! U(q) (eq 3) and the loop-closure residuals Φ(q) with their Jacobian Φ_q.
//!
//! Pattern: an immutable [`Model`] built (and validated) once from a [`StructureSpec`]; a [`Data`]
//! workspace allocated once; the state (q, [`ActivePivots`]) passed to free functions
//! `algo(&model, &mut data, …)` that do not allocate.
//!
//! ```
//! use crr_kinematics::*;
//! let spec: StructureSpec = serde_json::from_str(r#"{
//!   "name": "block",
//!   "body": [{ "name": "block", "density": 2500.0,
//!              "box": { "center": [0, 0, 1], "size": [0.5, 0.5, 2] } }],
//!   "interface": [{ "name": "base", "parent": "ground", "child": "block", "axis": [0, 1, 0],
//!                   "pivot_positive": [0.25, 0, 0], "pivot_negative": [-0.25, 0, 0] }]
//! }"#).unwrap();
//! let model = Model::from_spec(&spec).unwrap();
//! let mut data = Data::new(&model);
//! let q = nalgebra::DVector::zeros(model.dof());
//! let pivots = ActivePivots::uniform(&model, Side::Positive);
//! forward_kinematics(&model, &mut data, &q, &pivots);
//! mass_matrix(&model, &mut data);
//! // Inertia about the pivot edge: I₀ = (4/3) m R², R² = b² + h².
//! let m = model.bodies[0].mass;
//! let i0 = 4.0 / 3.0 * m * (0.25f64.powi(2) + 1.0);
//! assert!((data.mass_matrix[(0, 0)] - i0).abs() < 1e-9 * i0);
//! ```

pub mod assembly;
pub mod closure;
pub mod contact_face;
pub mod contact_kinematics;
pub mod data;
pub mod disjoint_sets;
pub mod error;
pub mod fixtures;
pub mod gamma;
pub mod interpenetration;
pub mod kinematics;
pub mod mass_matrix;
pub mod model;
pub mod pivots;
pub mod potential;
pub mod rotation;
pub mod shapes;
pub mod short_copy;
pub mod spec;
pub mod velocity;

pub use closure::{
    closure_angles, constraint_jacobian, constraint_residual, interface_angles, relative_angles,
};
pub use contact_face::{ContactFace, contact_faces};
pub use contact_kinematics::{ContactKinematics, contact_bias, contact_geometry};
pub use data::Data;
pub use disjoint_sets::DisjointSets;
pub use error::ModelError;
pub use gamma::mass_matrix_gamma;
pub use kinematics::{body_point, body_points, body_rotation, forward_kinematics, jacobians};
pub use mass_matrix::{kinetic_energy, mass_matrix, mass_matrix_from_jacobians};
pub use model::{
    Body, Closure, Coordinate, GEOMETRY_TOLERANCE, Interface, InterfaceKind, MAX_COORDINATES,
    MIN_DIRAC_WIDTH, MOVED_BEYOND, Model, Parent, Parts, Role, Side, exact_reference,
};
pub use pivots::ActivePivots;
pub use potential::{generalized_gravity, potential_energy};
pub use spec::{
    BodySpec, ImpactLaw, InterfaceSpec, PivotSpec, RockingBaseSpec, StructureSpec,
    SymmetryRelation, SymmetrySpec,
};
pub use velocity::{body_kinetic_energy, constraint_bias, velocities, velocity_product};
