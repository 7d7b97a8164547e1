//! Data: every intermediate result of the kinematics, allocated once per model.
//!
//! Fields are grouped by the function that fills them (as MuJoCo's `mjData`). All vectors are in
//! world coordinates of the current configuration unless a field says "rest".

use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Vector3, Vector6};

use crate::model::Model;

/// Workspace of the kinematic algorithms for one model. Create once, reuse for every evaluation.
#[derive(Clone, Debug)]
pub struct Data {
    // --- filled by `forward_kinematics` ---
    /// Γᵏ (`rot_ops`): rotation of the frame after coordinate k, Γᵏ = R₁R₂…Rₖ along its tree path
    /// (eq 1). A body moving with frame k maps a rest point X to Γᵏ X + tᵏ.
    pub rot_ops: Vec<Matrix3<f64>>,
    /// tᵏ: translation of frame k (m).
    pub frame_translation: Vec<Vector3<f64>>,
    /// wₖ = Γᵖ uₖ: world axis of coordinate k (p its parent frame).
    pub axis: Vec<Vector3<f64>>,
    /// Pₖ: active pivot of coordinate k at rest (m).
    pub pivot_rest: Vec<Vector3<f64>>,
    /// pₖ: world position of the active pivot of coordinate k (m).
    pub pivot: Vec<Vector3<f64>>,
    /// cₙ: world centre of mass of each body (m).
    pub com: Vec<Vector3<f64>>,

    // --- filled by `jacobians` ---
    /// J_c: centre-of-mass Jacobians, rows 3n..3n+3 for body n (m/rad), DOF(1) columns (0 × 0
    /// until the first `jacobians` call).
    pub com_jacobian: DMatrix<f64>,
    /// J_ω: angular-velocity Jacobians, rows 3n..3n+3 for body n (1/rad → rad/s per rad/s).
    pub angular_jacobian: DMatrix<f64>,

    // --- filled by `mass_matrix` ---
    /// Composite spatial inertia about the world origin of the subtree of each coordinate
    /// ([ω; v₀] ordering), kg m², kg m, kg.
    pub composite_inertia: Vec<Matrix6<f64>>,
    /// M(q): the generalized mass matrix (eq 2), DOF(1) × DOF(1).
    pub mass_matrix: DMatrix<f64>,

    // --- filled by `generalized_gravity` ---
    /// Subtree mass of each coordinate (kg).
    pub subtree_mass: Vec<f64>,
    /// Subtree first moment Σ m c of each coordinate (kg m).
    pub subtree_moment: Vec<Vector3<f64>>,

    // --- filled by `velocities` ---
    /// Vₖ = [ωₖ; v₀ₖ]: spatial velocity of frame k (rad/s; m/s of the frame point at the origin).
    pub spatial_velocity: Vec<Vector6<f64>>,
    /// Aₖ: spatial bias acceleration J̇q̇ of frame k (the acceleration when q̈ = 0).
    pub bias_acceleration: Vec<Vector6<f64>>,

    // --- filled by `velocity_product` ---
    /// Fₖ: spatial force of the subtree of coordinate k (N m about the origin; N).
    pub subtree_force: Vec<Vector6<f64>>,
    /// h(q, q̇): velocity-product generalized forces (N m), M q̈ + h = Q.
    pub velocity_product: DVector<f64>,

    // --- filled by `constraint_bias` ---
    /// Φ̇_q q̇: constraint bias, so that Φ_q q̈ + Φ̇_q q̇ = 0.
    pub phi_bias: DVector<f64>,

    // --- filled by `constraint_residual` / `constraint_jacobian` ---
    /// Φ(q): loop-closure residuals (m for point rows, dimensionless for axis rows).
    pub phi: DVector<f64>,
    /// Φ_q: Jacobian of Φ, rows × DOF(1).
    pub phi_q: DMatrix<f64>,
}

impl Data {
    /// Allocates the workspace for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.dof();
        Self {
            rot_ops: vec![Matrix3::identity(); n],
            frame_translation: vec![Vector3::zeros(); n],
            axis: vec![Vector3::zeros(); n],
            pivot_rest: vec![Vector3::zeros(); n],
            pivot: vec![Vector3::zeros(); n],
            com: model.bodies.iter().map(|b| b.com).collect(),
            // Allocated by the first `jacobians` call: the hot path never reads them.
            com_jacobian: DMatrix::zeros(0, 0),
            angular_jacobian: DMatrix::zeros(0, 0),
            composite_inertia: vec![Matrix6::zeros(); n],
            mass_matrix: DMatrix::zeros(n, n),
            subtree_mass: vec![0.0; n],
            subtree_moment: vec![Vector3::zeros(); n],
            spatial_velocity: vec![Vector6::zeros(); n],
            bias_acceleration: vec![Vector6::zeros(); n],
            subtree_force: vec![Vector6::zeros(); n],
            velocity_product: DVector::zeros(n),
            phi_bias: DVector::zeros(model.constraint_rows),
            phi: DVector::zeros(model.constraint_rows),
            phi_q: DMatrix::zeros(model.constraint_rows, n),
        }
    }
}
