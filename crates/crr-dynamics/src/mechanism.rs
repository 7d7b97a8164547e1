//! One-DOF mechanisms (a block, a trilithon, a four-hinge arch) reduced to their single
//! coordinate θ from the engine's own M, U and Q: the reduced equation
//! M(θ) θ̈ + ½ M′(θ) θ̇² + U′(θ) = −Q_h(θ) a_h / g, the activation (limit-analysis collapse)
//! multiplier λ = U′(0)/|Q_h(0)| and the equivalent single block.

use nalgebra::{DMatrix, DVector, Vector3};

use crr_kinematics::{
    ActivePivots, Data, Model, constraint_jacobian, forward_kinematics, generalized_gravity,
    mass_matrix,
};

use crate::closed_chain::project_positions;
use crate::eom::{DynamicsError, constraint_row_scale};
use crate::linalg::pinv_solve_in;

/// The reduced one-coordinate quantities at a closed configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct ReducedPoint {
    /// dq/dθ: the mechanism's velocity map (B, with `B[coordinate] = 1`).
    pub velocity_map: DVector<f64>,
    /// M(θ) = Bᵀ M B (kg m²).
    pub mass: f64,
    /// U′(θ) = −Bᵀ Q_gravity (N m).
    pub potential_slope: f64,
    /// Bᵀ Σ Mⁿ J_cᵀ (g d): the generalized force of a horizontal acceleration field of size g along
    /// the unit direction d (N m). The ground acceleration −g d produces it.
    pub horizontal_force: f64,
}

/// Evaluates the reduced quantities at configuration q (assumed closed) for the independent
/// coordinate `coordinate`. Errors when that coordinate does not drive a one-DOF mechanism.
pub fn reduce_at(
    model: &Model,
    q: &DVector<f64>,
    pivots: &ActivePivots,
    coordinate: usize,
    direction: &Vector3<f64>,
) -> Result<ReducedPoint, DynamicsError> {
    let n = model.dof();
    let mut kin = Data::new(model);
    forward_kinematics(model, &mut kin, q, pivots);
    mass_matrix(model, &mut kin);
    let mut b = DVector::zeros(n);
    b[coordinate] = 1.0;
    if model.constraint_rows > 0 {
        constraint_jacobian(model, &mut kin, pivots);
        let s = constraint_row_scale(model);
        let others: Vec<usize> = (0..n).filter(|&k| k != coordinate).collect();
        let jo = DMatrix::from_fn(model.constraint_rows, others.len(), |i, j| {
            s[i] * kin.phi_q[(i, others[j])]
        });
        let rhs = DVector::from_fn(model.constraint_rows, |i, _| {
            -s[i] * kin.phi_q[(i, coordinate)]
        });
        // Ranked against the whole scaled Jacobian, whose norm is |jo| and |rhs| together.
        let whole = (jo.norm_squared() + rhs.norm_squared()).sqrt();
        let (x, rank) = pinv_solve_in(&jo, &rhs, whole);
        if rank != others.len() || (&jo * &x - &rhs).amax() > 1e-9 {
            return Err(DynamicsError::Closure(format!(
                "coordinate \"{}\" does not drive a one-DOF mechanism here (DOF(2) ≠ 1 or it is locked)",
                model.coords[coordinate].name
            )));
        }
        for (j, &k) in others.iter().enumerate() {
            b[k] = x[j];
        }
    }
    let mut qg = DVector::zeros(n);
    generalized_gravity(
        model,
        &mut kin,
        &Vector3::new(0.0, 0.0, -model.gravity),
        &mut qg,
    );
    let mut qh = DVector::zeros(n);
    generalized_gravity(model, &mut kin, &(direction * model.gravity), &mut qh);
    Ok(ReducedPoint {
        mass: b.dot(&(&kin.mass_matrix * &b)),
        potential_slope: -b.dot(&qg),
        horizontal_force: b.dot(&qh),
        velocity_map: b,
    })
}

/// The closed configuration with coordinate `coordinate` = θ, others solved by Newton from `q0`.
pub fn configuration(
    model: &Model,
    q0: &DVector<f64>,
    pivots: &ActivePivots,
    coordinate: usize,
    theta: f64,
) -> Result<DVector<f64>, DynamicsError> {
    let mut q = q0.clone();
    q[coordinate] = theta;
    if model.constraint_rows > 0 {
        let free: Vec<usize> = (0..model.dof()).filter(|&k| k != coordinate).collect();
        let mut kin = Data::new(model);
        project_positions(model, &mut kin, pivots, &mut q, Some(&free))?;
    }
    Ok(q)
}

/// A one-DOF mechanism at rest seen as a single rocking block.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct EquivalentBlock {
    /// Independent coordinate.
    pub coordinate: String,
    /// M(0) = Bᵀ M B at rest (kg m²).
    pub mass: f64,
    /// U′(0⁺) for the active pivots (N m).
    pub potential_slope: f64,
    /// U″(0) (N m), by central differences of U′ along the mechanism.
    pub potential_curvature: f64,
    /// λ = U′(0)/|Q_h(0)|: the ground acceleration (in g) along the given horizontal direction
    /// that activates the mechanism, the limit-analysis collapse multiplier (tan α for a block).
    pub lambda: f64,
    /// Sign of the activating ground acceleration along the direction (+1 or −1).
    pub lambda_sign: f64,
    /// α_eq = atan(U′(0)/(−U″(0))): the equivalent block's slenderness (rad).
    pub alpha: f64,
    /// p_eq² = √(U′² + U″²)/M(0): the equivalent block's frequency parameter (1/s²); for a block
    /// it is p² = 3g/(4R), for the trilithon p̂² = p²(1 + 2γ)/(1 + 3γ).
    pub p_squared: f64,
    /// −U″(0)/M(0) = p_eq² cos α_eq: the linearised value (1/s²).
    pub p_squared_linearised: f64,
}

/// Reduces a one-DOF mechanism at rest (q = 0, the given pivots) to its equivalent block, driven
/// by a horizontal ground acceleration along `direction` (unit).
pub fn equivalent_block(
    model: &Model,
    pivots: &ActivePivots,
    coordinate: usize,
    direction: &Vector3<f64>,
) -> Result<EquivalentBlock, DynamicsError> {
    let zero = DVector::zeros(model.dof());
    let at = |theta: f64| -> Result<ReducedPoint, DynamicsError> {
        let q = configuration(model, &zero, pivots, coordinate, theta)?;
        reduce_at(model, &q, pivots, coordinate, direction)
    };
    let r0 = at(0.0)?;
    // U″ by central differences along the mechanism: h = 1e-5 rad, truncation h²U⁗ ~ 1e-10 relative.
    let h = 1e-5;
    let curvature = (at(h)?.potential_slope - at(-h)?.potential_slope) / (2.0 * h);
    let u1 = r0.potential_slope;
    Ok(EquivalentBlock {
        coordinate: model.coords[coordinate].name.clone(),
        mass: r0.mass,
        potential_slope: u1,
        potential_curvature: curvature,
        lambda: u1.abs() / r0.horizontal_force.abs(),
        lambda_sign: -(u1 * r0.horizontal_force).signum(),
        alpha: u1.atan2(-curvature),
        p_squared: u1.hypot(curvature) / r0.mass,
        p_squared_linearised: -curvature / r0.mass,
    })
}
