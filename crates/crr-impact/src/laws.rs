//! The impact maps (physics.md §5): at an impact the angle of one or more interfaces crosses 0
//! and their pivots switch (P⁺ ↔ P⁻). The configuration q is continuous; the body Jacobians change
//! from J⁻ (pivots `before`) to J⁺ (pivots `after`), and q̇ jumps from q̇⁻ to q̇⁺.
//!
//! Three laws:
//! * [`momentum_law`], the generalized Housner law (the physical default): plastic impact at the
//!   new pivots, M⁺ q̇⁺ = (J⁺)ᵀ 𝕄 J⁻ q̇⁻ + Φ_q⁺ᵀ Λ with Φ_q⁺ q̇⁺ = 0;
//! * [`restitution_law`]: ψ̇_s⁺ = r_s ψ̇_s⁻ for each impacting slot, the impulse along a_s only;
//! * [`dirac_law`], the paper's eq 5 integrated exactly, and its regularised form
//!   [`dirac_regularised_force`] with [`regularised_delta`] for straight-through integration.
//!
//! Loop closures are handled by the null-space method: q̇⁺ = N z with N an orthonormal basis of
//! ker Φ_q⁺ (rank-revealing SVD of the row-scaled Φ_q, so redundant closures are harmless), and the
//! balance of generalized momentum is projected on N (the closure impulses Φ_qᵀΛ drop out). This
//! only needs M to be positive definite on the mechanism's velocities, so a body of negligible mass
//! (a massless cap beam, γ → 0) does not make the system singular. The small projected systems are
//! solved with [`crr_dynamics::linalg::pinv_solve`] and their rank is checked: a singular system is
//! an [`ImpactError`], never a panic.

use crr_dynamics::eom::constraint_row_scale;
use crr_dynamics::linalg::{JacobiSvd, cholesky_in_place, cholesky_solve, pinv_solve};
use crr_kinematics::mass_matrix::world_inertia;
use crr_kinematics::{
    ActivePivots, Data, InterfaceKind, Model, Role, constraint_jacobian, forward_kinematics,
    jacobians, mass_matrix,
};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// Relative residual above which a solved impact system is reported as inconsistent.
const RESIDUAL_TOLERANCE: f64 = 1e-8;

/// The outcome of an impact map.
#[derive(Clone, Debug, PartialEq)]
pub struct ImpactResult {
    /// q̇⁺: the generalized velocity just after the impact (rad/s).
    pub qdot: DVector<f64>,
    /// T⁻ = ½ q̇⁻ᵀ M⁻ q̇⁻ with M⁻ the mass matrix of the `before` chain (J).
    pub kinetic_before: f64,
    /// T⁺ = ½ q̇⁺ᵀ M⁺ q̇⁺ with M⁺ the mass matrix of the `after` chain (J).
    pub kinetic_after: f64,
}

impl ImpactResult {
    /// T⁺ / T⁻ (NaN when T⁻ = 0).
    pub fn energy_ratio(&self) -> f64 {
        self.kinetic_after / self.kinetic_before
    }
}

/// Why an impact map could not be evaluated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// A vector or pivot set has the wrong length for the model.
    #[error("{what} has length {got}, the model needs {expected}")]
    Dimension {
        /// What was passed.
        what: &'static str,
        /// The length the model needs.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A slot index is not an angle slot of the model.
    #[error("slot {slot} does not exist: the model has {count} angle slots")]
    SlotOutOfRange {
        /// The slot given.
        slot: usize,
        /// The model's slot count.
        count: usize,
    },
    /// A state value or a law coefficient is not finite (or out of its domain).
    #[error("invalid input: {0}")]
    Invalid(String),
    /// The projected impact system is singular: e.g. the mass matrix is not positive definite on
    /// the mechanism's velocities, or an impacting slot's rate cannot be changed independently
    /// (it is locked by the closures or duplicated).
    #[error("{law}: the impact system is singular (rank {rank}, {needed} needed): {hint}")]
    Singular {
        /// The law being evaluated.
        law: &'static str,
        /// Numerical rank found.
        rank: usize,
        /// Rank needed for a unique solution.
        needed: usize,
        /// What the rank deficiency means.
        hint: &'static str,
    },
    /// The solved system does not satisfy its equations (inconsistent data).
    #[error("{law}: the solution leaves a relative residual {residual:.3e}")]
    Residual {
        /// The law being evaluated.
        law: &'static str,
        /// Relative residual.
        residual: f64,
    },
}

/// ψ̇ = aᵀq̇: the direction a whose product with q̇ is the rate of angle slot `slot`.
///
/// A tree coordinate k: a = eₖ. A closure slot: the relative angular velocity of the child frame
/// B with respect to the parent frame A, ω_B − ω_A, projected on the world axis of that angle: the
/// hinge axis Γ_A u; for a rocking base Γ_A e₁ for the first tilt and Γ_B e₂ for the second (with
/// Γ_AᵀΓ_B = R(e₁, θ₁)R(e₂, θ₂) these projections are exactly θ̇₁ and θ̇₂, since e₁ ⊥ R(e₁, θ₁)e₂;
/// for the hinge it is exact whenever the closure holds). Requires
/// [`crr_kinematics::forward_kinematics`] (the axes and Γ's, which do not depend on the pivots).
///
/// # Panics
/// If `slot ≥ model.slot_count` (the laws check this first and return an error).
pub fn slot_rate_direction(model: &Model, kin: &Data, slot: usize) -> DVector<f64> {
    let n = model.dof();
    let mut a = DVector::zeros(n);
    if slot < n {
        a[slot] = 1.0;
        return a;
    }
    let (idx, iface) = model
        .interfaces
        .iter()
        .enumerate()
        .find(|(_, i)| i.slots.contains(&slot))
        .expect("slot within slot_count belongs to an interface");
    debug_assert!(
        matches!(iface.role, Role::Closure { .. }),
        "interface {idx}"
    );
    let component = slot - iface.slots.start;
    let frame_a = model.frame_of(iface.parent);
    let frame_b = Some(model.body_coord[iface.child]);
    let rot = |k: Option<usize>| k.map_or_else(Matrix3::identity, |k| kin.rot_ops[k]);
    let w: Vector3<f64> = match &iface.kind {
        InterfaceKind::Hinge { axis, .. } => rot(frame_a) * axis,
        InterfaceKind::RockingBase { e1, e2, .. } => {
            if component == 0 {
                rot(frame_a) * e1
            } else {
                rot(frame_b) * e2
            }
        }
    };
    for (frame, sign) in [(frame_b, 1.0), (frame_a, -1.0)] {
        let mut j = frame;
        while let Some(jj) = j {
            a[jj] += sign * kin.axis[jj].dot(&w);
            j = model.coords[jj].parent;
        }
    }
    a
}

/// Everything an impact law needs of one dynamic chain at the impact configuration.
struct Chain {
    /// M(q) of this chain.
    mass: DMatrix<f64>,
    /// Orthonormal basis of ker Φ_q (n × DOF(2)); the identity for an open chain.
    null: DMatrix<f64>,
}

/// Evaluates the kinematics of the chain `pivots` into `kin` (forward kinematics, Jacobians, M,
/// Φ_q) and returns M and the null space of the row-scaled Φ_q.
fn evaluate_chain(model: &Model, kin: &mut Data, q: &DVector<f64>, pivots: &ActivePivots) -> Chain {
    forward_kinematics(model, kin, q, pivots);
    jacobians(model, kin);
    mass_matrix(model, kin);
    let n = model.dof();
    let null = if model.constraint_rows == 0 {
        DMatrix::identity(n, n)
    } else {
        constraint_jacobian(model, kin, pivots);
        let scale = constraint_row_scale(model);
        null_space(&kin.phi_q, &scale)
    };
    Chain {
        mass: kin.mass_matrix.clone(),
        null,
    }
}

/// Orthonormal basis of the null space of diag(scale) Φ (rank-revealing Jacobi SVD, the relative
/// threshold [`crr_dynamics::linalg::RANK_TOLERANCE`]).
fn null_space(phi: &DMatrix<f64>, scale: &DVector<f64>) -> DMatrix<f64> {
    let a = DMatrix::from_fn(phi.nrows(), phi.ncols(), |i, j| scale[i] * phi[(i, j)]);
    JacobiSvd::new(&a).null_space()
}

/// Solves, for q̇ = N z and the impulses Π (one per column of `a`):
/// Nᵀ M N z − Nᵀ A Π = Nᵀ b (momentum balance projected on the mechanism's velocities, the
/// closure impulses Φ_qᵀΛ drop out) and Aᵀ N z = t (the prescribed slot rates).
fn solve_projected(
    law: &'static str,
    chain: &Chain,
    b: &DVector<f64>,
    a: &DMatrix<f64>,
    t: &DVector<f64>,
) -> Result<DVector<f64>, ImpactError> {
    let nn = &chain.null;
    let d = nn.ncols();
    let k = a.ncols();
    let n = nn.nrows();
    let mr = nn.transpose() * &chain.mass * nn;
    // Balance the two blocks: Π is solved as μ Π' with μ a typical reduced inertia.
    let mu = (0..d).map(|i| mr[(i, i)].abs()).fold(0.0, f64::max);
    let mu = if mu > 0.0 && mu.is_finite() { mu } else { 1.0 };
    let na = nn.transpose() * a;
    let mut sys = DMatrix::zeros(d + k, d + k);
    let mut rhs = DVector::zeros(d + k);
    sys.view_mut((0, 0), (d, d)).copy_from(&mr);
    sys.view_mut((0, d), (d, k)).copy_from(&(-&na * mu));
    sys.view_mut((d, 0), (k, d))
        .copy_from(&(na.transpose() * mu));
    let ntb = nn.transpose() * b;
    rhs.rows_mut(0, d).copy_from(&ntb);
    rhs.rows_mut(d, k).copy_from(&(t * mu));
    if d + k == 0 {
        return Ok(DVector::zeros(n));
    }
    let (x, rank) = pinv_solve(&sys, &rhs);
    if rank < d + k {
        return Err(ImpactError::Singular {
            law,
            rank,
            needed: d + k,
            hint: if k == 0 {
                "the mass matrix is not positive definite on the mechanism's velocities"
            } else {
                "the mass matrix is not positive definite on the mechanism's velocities, or an \
                 impacting slot's rate is locked by the closures or depends on another's"
            },
        });
    }
    let res = (&sys * &x - &rhs).norm();
    let size = rhs.norm().max(f64::MIN_POSITIVE) + (sys.norm() * x.norm());
    if res.is_nan() || res > RESIDUAL_TOLERANCE * size {
        return Err(ImpactError::Residual {
            law,
            residual: res / size,
        });
    }
    Ok(nn * x.rows(0, d))
}

fn check_inputs(
    model: &Model,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
) -> Result<(), ImpactError> {
    let n = model.dof();
    let dims = [
        ("q", n, q.len()),
        ("qdot_minus", n, qdot.len()),
        ("before pivots", model.slot_count, before.sides.len()),
        ("after pivots", model.slot_count, after.sides.len()),
    ];
    for (what, expected, got) in dims {
        if expected != got {
            return Err(ImpactError::Dimension {
                what,
                expected,
                got,
            });
        }
    }
    if !q.iter().chain(qdot.iter()).all(|x| x.is_finite()) {
        return Err(ImpactError::Invalid("q and q̇⁻ must be finite".to_string()));
    }
    Ok(())
}

fn check_slot(model: &Model, slot: usize) -> Result<(), ImpactError> {
    if slot < model.slot_count {
        Ok(())
    } else {
        Err(ImpactError::SlotOutOfRange {
            slot,
            count: model.slot_count,
        })
    }
}

fn kinetic(m: &DMatrix<f64>, v: &DVector<f64>) -> f64 {
    0.5 * v.dot(&(m * v))
}

/// The slot directions as the columns of A (n × slots).
fn directions(model: &Model, kin: &Data, slots: impl Iterator<Item = usize>) -> DMatrix<f64> {
    let cols: Vec<DVector<f64>> = slots.map(|s| slot_rate_direction(model, kin, s)).collect();
    if cols.is_empty() {
        DMatrix::zeros(model.dof(), 0)
    } else {
        DMatrix::from_columns(&cols)
    }
}

/// The generalized Housner law (plastic impact at the new pivots, every other hinge persisting):
/// M⁺ q̇⁺ = (J⁺)ᵀ 𝕄 J⁻ q̇⁻ + Φ_q⁺ᵀ Λ with Φ_q⁺ q̇⁺ = 0, 𝕄 = blockdiag(mₙ I₃, Iₙ world) per body and
/// J = [J_c; J_ω]. The angular momentum of every subtree about its new pivot is conserved; kinetic
/// energy never increases. `kin` is left evaluated for the `after` chain.
pub fn momentum_law(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
) -> Result<ImpactResult, ImpactError> {
    check_inputs(model, q, qdot_minus, before, after)?;
    let minus = evaluate_chain(model, kin, q, before);
    let vc = &kin.com_jacobian * qdot_minus;
    let wv = &kin.angular_jacobian * qdot_minus;
    let plus = evaluate_chain(model, kin, q, after);
    // Body momenta before the impact (linear m ċ, angular I ω), projected with (J⁺)ᵀ.
    let mut lin = DVector::zeros(vc.len());
    let mut ang = DVector::zeros(wv.len());
    for (bi, body) in model.bodies.iter().enumerate() {
        let i_w = world_inertia(body, &kin.rot_ops[model.body_coord[bi]]);
        let w = i_w * Vector3::new(wv[3 * bi], wv[3 * bi + 1], wv[3 * bi + 2]);
        for r in 0..3 {
            lin[3 * bi + r] = body.mass * vc[3 * bi + r];
            ang[3 * bi + r] = w[r];
        }
    }
    let b = kin.com_jacobian.tr_mul(&lin) + kin.angular_jacobian.tr_mul(&ang);
    let qdot = solve_projected(
        "momentum law",
        &plus,
        &b,
        &DMatrix::zeros(model.dof(), 0),
        &DVector::zeros(0),
    )?;
    Ok(ImpactResult {
        kinetic_before: kinetic(&minus.mass, qdot_minus),
        kinetic_after: kinetic(&plus.mass, &qdot),
        qdot,
    })
}

/// Classical restitution: for each impacting slot s with coefficient r_s, ψ̇_s⁺ = r_s ψ̇_s⁻
/// (ψ̇ = aᵀq̇, [`slot_rate_direction`]); the generalized impulse acts only along the a_s:
/// M⁺ (q̇⁺ − q̇⁻) = Σ a_s Π_s + Φ_q⁺ᵀ Λ with Φ_q⁺ q̇⁺ = 0, M⁺ the mass matrix of the `after` chain.
/// Errors when the system for the Π_s is singular (a slot listed twice, or locked by the
/// closures). `kin` is left evaluated for the `after` chain.
pub fn restitution_law(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
    slots: &[(usize, f64)],
) -> Result<ImpactResult, ImpactError> {
    check_inputs(model, q, qdot_minus, before, after)?;
    for &(s, r) in slots {
        check_slot(model, s)?;
        if !r.is_finite() {
            return Err(ImpactError::Invalid(format!(
                "restitution coefficient {r} of slot {s} is not finite"
            )));
        }
    }
    let minus = evaluate_chain(model, kin, q, before);
    let plus = evaluate_chain(model, kin, q, after);
    let a = directions(model, kin, slots.iter().map(|x| x.0));
    let rates = a.tr_mul(qdot_minus);
    let t = DVector::from_iterator(
        slots.len(),
        slots.iter().zip(rates.iter()).map(|(s, v)| s.1 * v),
    );
    let b = &plus.mass * qdot_minus;
    let qdot = solve_projected("restitution law", &plus, &b, &a, &t)?;
    Ok(ImpactResult {
        kinetic_before: kinetic(&minus.mass, qdot_minus),
        kinetic_after: kinetic(&plus.mass, &qdot),
        qdot,
    })
}

/// The paper's eq 5, F = C ln(r) ψ̇|ψ̇| δ(ψ) on each listed slot `(s, r, C)`, integrated exactly
/// across ψ = 0: ψ̇_s is multiplied by r^C, the change distributed along M⁻¹a_s (C normalised by
/// the effective inertia 1/(a_sᵀM⁻¹a_s), so that C = 1 gives r).
///
/// The δ straddles the pivot switch, so the map is the limit of a symmetric regularised δ: half
/// the impulse (factor r^(C/2)) with the `before` chain's M⁻ and Φ_q⁻, then the pivot switch
/// (q̇ unchanged), then the other half with the `after` chain's M⁺ and Φ_q⁺. On each side the
/// impulse is projected with closure multipliers so that Φ_q q̇ = 0 holds there. Several slots
/// impact simultaneously (their impulses are solved together). `kin` is left evaluated for the
/// `after` chain.
pub fn dirac_law(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
    slots: &[(usize, f64, f64)],
) -> Result<ImpactResult, ImpactError> {
    check_inputs(model, q, qdot_minus, before, after)?;
    for &(s, r, c) in slots {
        check_slot(model, s)?;
        if !(r.is_finite() && r > 0.0 && c.is_finite()) {
            return Err(ImpactError::Invalid(format!(
                "slot {s}: the Dirac law needs r > 0 and a finite C (got r = {r}, C = {c})"
            )));
        }
    }
    let half: Vec<f64> = slots.iter().map(|&(_, r, c)| r.powf(0.5 * c)).collect();
    let targets = |a: &DMatrix<f64>, v: &DVector<f64>| {
        DVector::from_iterator(
            half.len(),
            a.tr_mul(v).iter().zip(&half).map(|(x, f)| x * f),
        )
    };
    let minus = evaluate_chain(model, kin, q, before);
    let a = directions(model, kin, slots.iter().map(|x| x.0));
    let b = &minus.mass * qdot_minus;
    let mid = solve_projected(
        "Dirac law (before the switch)",
        &minus,
        &b,
        &a,
        &targets(&a, qdot_minus),
    )?;
    let plus = evaluate_chain(model, kin, q, after);
    let b = &plus.mass * &mid;
    let qdot = solve_projected(
        "Dirac law (after the switch)",
        &plus,
        &b,
        &a,
        &targets(&a, &mid),
    )?;
    Ok(ImpactResult {
        kinetic_before: kinetic(&minus.mass, qdot_minus),
        kinetic_after: kinetic(&plus.mass, &qdot),
        qdot,
    })
}

/// The regularised δ_ε: a unit-area raised cosine (1/ε)(1 + cos(2πx/ε)) on |x| < ε/2, 0
/// elsewhere (continuous with its first derivative). `width` = ε > 0.
pub fn regularised_delta(x: f64, width: f64) -> f64 {
    if x.abs() < 0.5 * width {
        (1.0 + (2.0 * std::f64::consts::PI * x / width).cos()) / width
    } else {
        0.0
    }
}

/// Generalized force of the regularised eq 5 for the listed slots `(s, r, C, ε)` at the current
/// state: F = Σ_s a_s C ln(r) ψ̇_s|ψ̇_s| δ_ε(ψ_s) / (a_sᵀ M⁻¹ a_s), ψ̇_s = a_sᵀq̇, written into `out`
/// (overwritten). `angles[s]` are the slot angles (q, then the closure angles). `kin` must hold
/// the forward kinematics and M of the current chain. A slot outside its δ support costs nothing.
///
/// Note: the normalisation uses the unconstrained M⁻¹; in a closed chain integrated with
/// closure multipliers the crossing then multiplies ψ̇_s by r^(Cκ), κ = a_sᵀ P a_s / a_sᵀM⁻¹a_s ≤ 1
/// (P the constrained inverse), whereas [`dirac_law`] imposes r^C.
///
/// # Panics
/// If a slot index is out of range of `angles` or of the model's slots.
pub fn dirac_regularised_force(
    model: &Model,
    kin: &Data,
    qdot: &DVector<f64>,
    angles: &[f64],
    slots: &[(usize, f64, f64, f64)],
    out: &mut DVector<f64>,
) {
    out.fill(0.0);
    let mut factor: Option<Option<DMatrix<f64>>> = None;
    for &(s, r, c, width) in slots {
        let d = regularised_delta(angles[s], width);
        if d == 0.0 {
            continue;
        }
        let a = slot_rate_direction(model, kin, s);
        let rate = a.dot(qdot);
        let l = factor.get_or_insert_with(|| {
            let mut l = kin.mass_matrix.clone();
            cholesky_in_place(&mut l).ok().map(|_| l)
        });
        let minv_a = match l {
            Some(l) => {
                let mut x = a.clone();
                cholesky_solve(l, x.as_mut_slice());
                x
            }
            None => pinv_solve(&kin.mass_matrix, &a).0,
        };
        let denom = a.dot(&minv_a);
        if denom.is_nan() || denom <= 0.0 {
            continue;
        }
        *out += a * (c * r.ln() * rate * rate.abs() * d / denom);
    }
}
