//! One-DOF mechanisms (a block, a trilithon, a four-hinge arch) reduced to their single
//! coordinate θ from the engine's own M, U and Q: the reduced equation
//! M(θ) θ̈ + ½ M′(θ) θ̇² + U′(θ) = −Q_h(θ) a_h / g, the activation (limit-analysis collapse)
//! multiplier λ = U′(0)/|Q_h(0)| and the equivalent single block.

use nalgebra::{DMatrix, DVector, Vector3};

use crr_kinematics::{
    ActivePivots, Data, Model, Side, constraint_jacobian, forward_kinematics, generalized_gravity,
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

/// Angle (rad) of the coordinate at which [`reported_side`] reads each side's pivots: the
/// pivots a state opened that far settles on.
pub const SIDE_PROBE_ANGLE: f64 = 0.01;

/// Relative difference below which the two sides' multipliers (or slendernesses) count as equal:
/// the geometry and densities of masonry are known to no better than this, so sides whose λ
/// differ by less are the same to an engineer (a symmetric arch with one voussoir's density off
/// by 1e-6 has sides 4e-8 apart, and a tolerance of 1e-9 reported its other side, α_eq 0.107
/// for 0.302).
pub const SIDE_TIE: f64 = 1e-3;

/// The unit horizontal direction perpendicular to coordinate `coordinate`'s axis (x when the
/// axis is vertical): the direction of ground acceleration a mechanism of that coordinate is
/// reported along.
pub fn horizontal_direction(model: &Model, coordinate: usize) -> Vector3<f64> {
    let d = model.coords[coordinate].axis.cross(&Vector3::z());
    if d.norm() < 1e-9 {
        Vector3::x()
    } else {
        d.normalize()
    }
}

/// The side of `coordinate` on which a one-DOF mechanism is reported, with its pivots and its
/// equivalent block: decided by the physics of the two sides, not by the sense the file gives
/// the coordinate (a hinge written with its axis and pivots exchanged gives the same report).
/// A side that opens under its own weight (α_eq < 0) first; else the side with the smaller
/// activation multiplier λ (the mechanism that opens first under a growing horizontal load);
/// on equal λ (within [`SIDE_TIE`], as for a symmetric arch, whose two sides are mirror images
/// read in one coordinate) the larger α_eq, a choice with no physics behind it but that the
/// same structure always gets the same one (the two sides are then one motion read in two
/// coordinates); on equal α_eq too, θ > 0. A side whose state cannot be solved is skipped; both
/// failing is the error of θ > 0.
pub fn reported_side(
    model: &Model,
    coordinate: usize,
    direction: &Vector3<f64>,
) -> Result<(Side, ActivePivots, EquivalentBlock), DynamicsError> {
    let name = &model.coords[coordinate].name;
    let side = |side: Side| -> Result<(Side, ActivePivots, EquivalentBlock), DynamicsError> {
        let spec = crate::InitialSpec {
            angles: [(name.clone(), side.sign() * SIDE_PROBE_ANGLE)]
                .into_iter()
                .collect(),
            rates: Default::default(),
        };
        let pivots = crate::solve_initial(model, &spec)?.pivots;
        let eq = equivalent_block_on_side(model, &pivots, coordinate, direction, side)?;
        Ok((side, pivots, eq))
    };
    let (plus, minus) = (side(Side::Positive), side(Side::Negative));
    let (a, b) = match (plus, minus) {
        (Ok(a), Ok(b)) => (a, b),
        (Ok(a), Err(_)) => return Ok(a),
        (Err(_), Ok(b)) => return Ok(b),
        (Err(e), Err(_)) => return Err(e),
    };
    let tie = |x: f64, y: f64| (x - y).abs() <= SIDE_TIE * x.abs().max(y.abs());
    let take_b = if a.2.alpha < 0.0 || b.2.alpha < 0.0 {
        b.2.alpha < a.2.alpha
    } else if !tie(a.2.lambda, b.2.lambda) {
        b.2.lambda < a.2.lambda
    } else {
        !tie(a.2.alpha, b.2.alpha) && b.2.alpha > a.2.alpha
    };
    Ok(if take_b { b } else { a })
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
/// by a horizontal ground acceleration along `direction` (unit). The mechanism opens with the
/// coordinate increasing (θ > 0); [`equivalent_block_on_side`] for either side.
pub fn equivalent_block(
    model: &Model,
    pivots: &ActivePivots,
    coordinate: usize,
    direction: &Vector3<f64>,
) -> Result<EquivalentBlock, DynamicsError> {
    equivalent_block_on_side(model, pivots, coordinate, direction, Side::Positive)
}

/// [`equivalent_block`] of the mechanism opening on `side` of the coordinate (θ > 0 or θ < 0),
/// `pivots` those of that side. It is read in the opening angle s = σθ (σ = ±1), so that a
/// mechanism written with its coordinate's sense reversed (axis and pivots exchanged) gives the
/// same block: U′ and the generalized force change sign with σ, M and U″ do not.
pub fn equivalent_block_on_side(
    model: &Model,
    pivots: &ActivePivots,
    coordinate: usize,
    direction: &Vector3<f64>,
    side: Side,
) -> Result<EquivalentBlock, DynamicsError> {
    let sigma = side.sign();
    let zero = DVector::zeros(model.dof());
    let at = |s: f64| -> Result<ReducedPoint, DynamicsError> {
        let q = configuration(model, &zero, pivots, coordinate, sigma * s)?;
        reduce_at(model, &q, pivots, coordinate, direction)
    };
    let r0 = at(0.0)?;
    // U″ by central differences along the mechanism: h = 1e-5 rad, truncation h²U⁗ ~ 1e-10 relative.
    // d²U/ds² = d²U/dθ², and dU/ds = σ dU/dθ at both ends.
    let h = 1e-5;
    let curvature = sigma * (at(h)?.potential_slope - at(-h)?.potential_slope) / (2.0 * h);
    let u1 = sigma * r0.potential_slope;
    Ok(EquivalentBlock {
        coordinate: model.coords[coordinate].name.clone(),
        mass: r0.mass,
        potential_slope: u1,
        potential_curvature: curvature,
        lambda: u1.abs() / r0.horizontal_force.abs(),
        // σU′ · σQ_h: the activating direction does not depend on the side's sign.
        lambda_sign: -(r0.potential_slope * r0.horizontal_force).signum(),
        alpha: u1.atan2(-curvature),
        p_squared: u1.hypot(curvature) / r0.mass,
        p_squared_linearised: -curvature / r0.mass,
    })
}

/// The parameters of the paper's one-DOF Lagrangian (eq 4) for a mechanism at rest, with the
/// generalized Housner frequency's χ and ε (eq 6).
///
/// Eq 4 is read as the second-order expansion about θ = 0 of the Lagrangian per unit of the
/// reduced inertia at rest, on the side σ = sgn θ (σ = +1 on the opening side the pivots are
/// given for, mirrored on the other):
///
/// ```text
/// L / M(0) = ½ (1 + σνθ + ξθ²) θ̇² − σηθ + ½χθ² + O(θ³)
/// ```
///
/// so that M(θ) = M(0)(1 + σνθ + ξθ²) and U(θ) − U(0) = M(0)(σηθ − ½χθ²). The text of eq 4 as
/// extracted puts dots on the last two θ's; dimensions (L/M(0) in 1/s², ν and ξ in 1/rad and
/// 1/rad², η and χ in 1/s²) and eq 6, whose χ and ε are the same block's p² and 1/α, require this
/// form (NOTATION.md). The mechanism's linearised equation is θ̈ = −σ η + χθ, the block's
/// θ̈ = −p²(σα − θ) with η = p² sin α ≈ p²α and χ = p² cos α ≈ p².
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LagrangianParameters {
    /// ν = M′(0)/M(0) (1/rad): the first-order change of the reduced inertia; 0 when M is
    /// constant along the mechanism (a block, a frame of identical columns).
    pub nu: f64,
    /// ξ = M″(0)/(2M(0)) (1/rad²).
    pub xi: f64,
    /// η = U′(0)/M(0) (1/s²): the restoring term, p_eq² sin α_eq.
    pub eta: f64,
    /// χ = −U″(0)/M(0) (1/s²): the overturning term, p_eq² cos α_eq.
    pub chi: f64,
    /// χ of eq 6: p_eq² = √(η² + χ²) (1/s²).
    pub chi_housner: f64,
    /// ε of eq 6: 1/α_eq = 1/atan(η/χ) (1/rad).
    pub epsilon: f64,
}

/// [`LagrangianParameters`] of the mechanism driven by `coordinate` on `pivots` (the opening
/// side), from the engine's M and U along the mechanism: U′ and U″ as in [`equivalent_block`],
/// M′ and M″ by central differences of the reduced inertia Bᵀ M B of closed configurations.
pub fn lagrangian_parameters(
    model: &Model,
    pivots: &ActivePivots,
    coordinate: usize,
    direction: &Vector3<f64>,
) -> Result<LagrangianParameters, DynamicsError> {
    lagrangian_parameters_on_side(model, pivots, coordinate, direction, Side::Positive)
}

/// [`lagrangian_parameters`] of the mechanism opening on `side`, read in the opening angle
/// s = σθ as [`equivalent_block_on_side`] (ν = M′(0)/M(0) changes sign with σ, ξ does not).
pub fn lagrangian_parameters_on_side(
    model: &Model,
    pivots: &ActivePivots,
    coordinate: usize,
    direction: &Vector3<f64>,
    side: Side,
) -> Result<LagrangianParameters, DynamicsError> {
    let eq = equivalent_block_on_side(model, pivots, coordinate, direction, side)?;
    let sigma = side.sign();
    let zero = DVector::zeros(model.dof());
    let mass_at = |s: f64| -> Result<f64, DynamicsError> {
        let q = configuration(model, &zero, pivots, coordinate, sigma * s)?;
        Ok(reduce_at(model, &q, pivots, coordinate, direction)?.mass)
    };
    // M′ with h = 1e-4 rad: truncation h²M‴/6 ~ 1e-9 M, round-off ~1e-16 M/h ~ 1e-12 M. M″ with
    // h = 1e-3 rad: truncation h²M⁗/12 ~ 1e-7 M, round-off of the closed configurations (~1e-14 M)
    // over h² ~ 1e-8 M.
    let (h1, h2) = (1e-4, 1e-3);
    let m0 = eq.mass;
    let nu = (mass_at(h1)? - mass_at(-h1)?) / (2.0 * h1 * m0);
    let xi = (mass_at(h2)? - 2.0 * m0 + mass_at(-h2)?) / (2.0 * h2 * h2 * m0);
    Ok(LagrangianParameters {
        nu,
        xi,
        eta: eq.potential_slope / m0,
        chi: -eq.potential_curvature / m0,
        chi_housner: eq.p_squared,
        epsilon: 1.0 / eq.alpha,
    })
}
