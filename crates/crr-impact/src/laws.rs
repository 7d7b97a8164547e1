//! The impact maps (docs/physics.md §5): at an impact the angle of one or more interfaces crosses 0
//! and their pivots switch (P⁺ ↔ P⁻). The configuration q is continuous; the body Jacobians change
//! from J⁻ (pivots `before`) to J⁺ (pivots `after`), and q̇ jumps from q̇⁻ to q̇⁺.
//!
//! Three laws (their derivation on chains: docs/simulation.md, "Impact laws on chains"):
//! * [`momentum_law`], the generalized Housner law (the physical default): plastic impact at the
//!   new pivots, M⁺ q̇⁺ = (J⁺)ᵀ 𝕄 J⁻ q̇⁻ + Φ_q⁺ᵀ Λ with Φ_q⁺ q̇⁺ = 0;
//! * [`restitution_law`]: the momentum of every motion that leaves the impacting slots' rates
//!   unchanged is conserved (from the bodies' real velocities, as in the momentum law), and the
//!   impact mode keeps r² of its kinetic energy, with the slot rates in the ratio r ψ̇⁻;
//! * [`dirac_law`], the paper's eq 5 integrated exactly (restitution with r^C), and its
//!   regularised form [`dirac_regularised_force`] with [`regularised_delta`] for
//!   straight-through integration.
//!
//! Loop closures are handled by the null-space method: q̇⁺ = N z with N an orthonormal basis of
//! ker Φ_q⁺ (rank-revealing SVD of the row-scaled Φ_q, so redundant closures are harmless), and the
//! balance of generalized momentum is projected on N (the closure impulses Φ_qᵀΛ drop out). This
//! only needs M to be positive definite on the mechanism's velocities, so a body of negligible mass
//! (a massless cap beam, γ → 0) does not make the system singular. Slots whose rates the closures
//! tie together (a trilithon's four hinges) form one impact mode: the laws are posed on the
//! mechanism's velocities and are never over-determined. A singular system is an [`ImpactError`],
//! never a panic.

use crr_dynamics::eom::{Dynamics, constraint_row_scale, slot_row};
use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::linalg::{
    JacobiSvd, back_substitute_transposed, cholesky_in_place, cholesky_solve, forward_substitute,
    pinv_solve,
};
use crr_kinematics::mass_matrix::world_inertia;
use crr_kinematics::short_copy::assign;
use crr_kinematics::{
    ActivePivots, Data, InterfaceKind, Model, Role, constraint_jacobian, forward_kinematics,
    jacobians, mass_matrix,
};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

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
#[derive(Clone, Debug, Default)]
struct Chain {
    /// M(q) of this chain.
    mass: DMatrix<f64>,
    /// Orthonormal basis of ker Φ_q (n × DOF(2)); None for an open chain, where it is the
    /// identity.
    null: Option<DMatrix<f64>>,
}

/// Evaluates the kinematics of the chain `pivots` into `kin` (forward kinematics, Jacobians, M,
/// Φ_q) and leaves M and the null space of the row-scaled Φ_q in `chain`.
fn evaluate_chain(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    pivots: &ActivePivots,
    chain: &mut Chain,
) {
    forward_kinematics(model, kin, q, pivots);
    jacobians(model, kin);
    mass_matrix(model, kin);
    chain.null = (model.constraint_rows > 0).then(|| {
        constraint_jacobian(model, kin, pivots);
        let scale = constraint_row_scale(model);
        null_space(&kin.phi_q, &scale)
    });
    copy_matrix(&mut chain.mass, &kin.mass_matrix);
}

/// [`evaluate_chain`] with the slots `held` kept at rate 0 through the impact (seated joints: a
/// rocking base's seated tilt): the chain's mechanism is then the null space of Φ_q (row-scaled)
/// and the held slots' rate rows aᵀ together, also on an open chain.
fn evaluate_chain_holding(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    pivots: &ActivePivots,
    held: &[usize],
    chain: &mut Chain,
) {
    evaluate_chain(model, kin, q, pivots, chain);
    if held.is_empty() {
        return;
    }
    let n = model.dof();
    let closure_rows = model.constraint_rows;
    let mut rows = DMatrix::zeros(closure_rows + held.len(), n);
    if closure_rows > 0 {
        let scale = constraint_row_scale(model);
        for i in 0..closure_rows {
            for j in 0..n {
                rows[(i, j)] = scale[i] * kin.phi_q[(i, j)];
            }
        }
    }
    let mut row = DVector::zeros(n);
    for (i, &s) in held.iter().enumerate() {
        slot_row(model, kin, s, &mut row);
        rows.row_mut(closure_rows + i).copy_from(&row.transpose());
    }
    chain.null = Some(crr_dynamics::linalg::null_space(&rows));
}

/// `dst` = `src`, reusing `dst`'s storage when the shapes agree.
fn copy_matrix(dst: &mut DMatrix<f64>, src: &DMatrix<f64>) {
    if dst.shape() == src.shape() {
        dst.copy_from(src);
    } else {
        *dst = src.clone();
    }
}

/// `v` with `len` entries (their values are to be overwritten), reusing its storage if it has.
fn with_len(v: &mut DVector<f64>, len: usize) {
    if v.len() != len {
        *v = DVector::zeros(len);
    }
}

/// Buffers the impact laws reuse from one impact to the next (a simulation keeps one, so that
/// an impact on a chain allocates only its result): both chains' M, the bodies' momenta and the
/// metric's factor. The products written into them are the ones the allocating forms make:
/// nalgebra's `mul_to` / `tr_mul_to` run the same gemm / dot loops as `*` / `tr_mul`.
#[derive(Clone, Debug, Default)]
pub(crate) struct LawWorkspace {
    /// The `before` chain.
    minus: Chain,
    /// The `after` chain.
    plus: Chain,
    /// J_c⁻ q̇⁻, then the linear momenta m ċ (3 per body).
    linear: DVector<f64>,
    /// J_ω⁻ q̇⁻, then the angular momenta I ω (3 per body).
    angular: DVector<f64>,
    /// (J⁺)ᵀ 𝕄 J⁻ q̇⁻, the generalized momentum on the `after` chain.
    momentum: DVector<f64>,
    /// J_ω⁺ᵀ I ω, the angular part of `momentum`; then M q̇ for the kinetic energies.
    part: DVector<f64>,
    /// The metric of the `after` chain.
    metric: Metric,
    /// w of the momentum.
    w: DVector<f64>,
}

/// Orthonormal basis of the null space of diag(scale) Φ (rank-revealing Jacobi SVD, the relative
/// threshold [`crr_dynamics::linalg::RANK_TOLERANCE`]).
fn null_space(phi: &DMatrix<f64>, scale: &DVector<f64>) -> DMatrix<f64> {
    let a = DMatrix::from_fn(phi.nrows(), phi.ncols(), |i, j| scale[i] * phi[(i, j)]);
    crr_dynamics::linalg::null_space(&a)
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

/// The listed slots must be distinct: one slot cannot take two prescriptions.
fn check_distinct(slots: impl Iterator<Item = usize>) -> Result<(), ImpactError> {
    let mut seen: Vec<usize> = slots.collect();
    seen.sort_unstable();
    match seen.windows(2).find(|w| w[0] == w[1]) {
        Some(w) => Err(ImpactError::Invalid(format!(
            "slot {} is listed twice",
            w[0]
        ))),
        None => Ok(()),
    }
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
    let mut mv = DVector::zeros(v.len());
    kinetic_with(m, v, &mut mv)
}

/// ½ vᵀ M v, with M v written into `mv`.
fn kinetic_with(m: &DMatrix<f64>, v: &DVector<f64>, mv: &mut DVector<f64>) -> f64 {
    with_len(mv, m.nrows());
    m.mul_to(v, mv);
    0.5 * v.dot(mv)
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
    let mut ws = LawWorkspace::default();
    momentum_law_with(model, kin, &mut ws, q, qdot_minus, before, after)
}

/// [`momentum_law`] with the buffers `ws` (the same results to the last bit).
pub(crate) fn momentum_law_with(
    model: &Model,
    kin: &mut Data,
    ws: &mut LawWorkspace,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
) -> Result<ImpactResult, ImpactError> {
    check_inputs(model, q, qdot_minus, before, after)?;
    pre_impact_momentum(model, kin, q, qdot_minus, before, after, &[], ws);
    ws.metric.refactor("momentum law", &ws.plus)?;
    ws.metric.w_of_momentum_into(&ws.momentum, &mut ws.w);
    let qdot = ws.metric.qdot_of_w(&ws.w);
    Ok(ImpactResult {
        kinetic_before: kinetic_with(&ws.minus.mass, qdot_minus, &mut ws.part),
        kinetic_after: kinetic_with(&ws.plus.mass, &qdot, &mut ws.part),
        qdot,
    })
}

/// [`momentum_law`] posed in the range of the constraints instead of their null space: the
/// generalized momentum p = (J⁺)ᵀ 𝕄 J⁻ q̇⁻ is projected by Gauss' principle of impulsive motion,
/// M⁺ q̇⁺ = p + Φ_q⁺ᵀ Λ with Φ_q⁺ q̇⁺ = 0 ([`Dynamics::solve_impulse`]: the factor of M on its tree
/// pattern and the selected independent closure rows), which is the same minimisation as
/// q̇⁺ = N (NᵀM⁺N)⁻¹ Nᵀ p with N a basis of ker Φ_q⁺, without the Jacobi SVD of Φ_q⁺ that gives N.
/// T⁻ is the bodies' kinetic energy before the impact (from their velocities J⁻q̇⁻). When M is
/// not positive definite on the whole tree (a massless body: the null-space form only needs it
/// on the mechanism's velocities) the null-space law [`momentum_law_with`] answers instead.
/// `work` is a workspace for `model` (its pivots and seated slots are overwritten); `kin` is
/// left evaluated for the `before` chain.
#[allow(clippy::too_many_arguments)]
pub(crate) fn momentum_law_projected(
    model: &Model,
    kin: &mut Data,
    ws: &mut LawWorkspace,
    work: &mut Dynamics,
    ground: &GroundMotion,
    t: f64,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
) -> Result<ImpactResult, ImpactError> {
    check_inputs(model, q, qdot_minus, before, after)?;
    // The bodies' velocities before: V⁻ = J⁻q̇⁻, and T⁻ from them.
    forward_kinematics(model, kin, q, before);
    jacobians(model, kin);
    crr_kinematics::velocities(model, kin, qdot_minus);
    let kinetic_before = crr_kinematics::body_kinetic_energy(model, kin);
    body_velocities(kin, qdot_minus, ws);
    // The `after` chain: M⁺, Φ_q⁺ and J⁺ at the same q.
    work.pivots.clone_from(after);
    work.seated.clear();
    work.evaluate(model, ground, t, q, qdot_minus);
    jacobians(model, &mut work.kin);
    generalized_momentum(model, &work.kin, ws);
    let qdot = match work.solve_impulse(model, t, &ws.momentum) {
        Ok(qdot) => qdot.clone(),
        Err(_) => return momentum_law_with(model, kin, ws, q, qdot_minus, before, after),
    };
    Ok(ImpactResult {
        kinetic_before,
        kinetic_after: kinetic_with(&work.kin.mass_matrix, &qdot, &mut ws.part),
        qdot,
    })
}

/// The momentum of the bodies' real motion before the impact, V⁻ = J⁻q̇⁻ (linear m ċ, angular
/// I ω), as a generalized momentum of the `after` chain: (J⁺)ᵀ 𝕄 J⁻ q̇⁻. Evaluates both chains
/// into `ws.minus` and `ws.plus` and the momentum into `ws.momentum`; `kin` is left evaluated
/// for the `after` chain.
fn pre_impact_momentum(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
    held: &[usize],
    ws: &mut LawWorkspace,
) {
    evaluate_chain_holding(model, kin, q, before, held, &mut ws.minus);
    body_velocities(kin, qdot_minus, ws);
    evaluate_chain_holding(model, kin, q, after, held, &mut ws.plus);
    generalized_momentum(model, kin, ws);
}

/// The bodies' velocities V = J q̇ (J of the chain evaluated in `kin`) into `ws.linear` (ċ) and
/// `ws.angular` (ω).
fn body_velocities(kin: &Data, qdot: &DVector<f64>, ws: &mut LawWorkspace) {
    let (vc, wv) = (&mut ws.linear, &mut ws.angular);
    with_len(vc, kin.com_jacobian.nrows());
    with_len(wv, kin.angular_jacobian.nrows());
    kin.com_jacobian.mul_to(qdot, vc);
    kin.angular_jacobian.mul_to(qdot, wv);
}

/// The bodies' momenta (m ċ, I ω) from the velocities in `ws.linear`, `ws.angular` (in place),
/// as a generalized momentum Jᵀ𝕄V of the chain evaluated in `kin` (its Jacobians and Γ's), into
/// `ws.momentum`.
fn generalized_momentum(model: &Model, kin: &Data, ws: &mut LawWorkspace) {
    let (vc, wv) = (&mut ws.linear, &mut ws.angular);
    // In place: body bi's entries are read before they are overwritten.
    for (bi, body) in model.bodies.iter().enumerate() {
        let i_w = world_inertia(body, &kin.rot_ops[model.body_coord[bi]]);
        let w = i_w * Vector3::new(wv[3 * bi], wv[3 * bi + 1], wv[3 * bi + 2]);
        for r in 0..3 {
            vc[3 * bi + r] *= body.mass;
            wv[3 * bi + r] = w[r];
        }
    }
    let n = kin.com_jacobian.ncols();
    with_len(&mut ws.momentum, n);
    with_len(&mut ws.part, n);
    kin.com_jacobian.tr_mul_to(vc, &mut ws.momentum);
    kin.angular_jacobian.tr_mul_to(wv, &mut ws.part);
    ws.momentum += &ws.part;
}

/// Classical restitution on a chain: each impacting slot s with coefficient r_s has its rate
/// multiplied by r_s, in the energy norm of the impact (docs/simulation.md, "Impact laws on
/// chains"):
///
/// * the momentum conjugate to every motion of the `after` chain that leaves the impacting slots'
///   rates unchanged is conserved, computed from the bodies' real velocities, J⁻q̇⁻ before and
///   J⁺q̇⁺ after (as in [`momentum_law`]: the persisting hinges carry no moment about their
///   axes);
/// * the rest of the motion, the impact mode, has its slot rates ψ̇ = aᵀq̇
///   ([`slot_rate_direction`]) set to r_s ψ̇_s⁻, scaled by the one factor that makes the mode's
///   kinetic energy r² times its value before: E⁺ = r² E⁻. For one slot this is
///   ψ̇⁺ = r √(κ⁺/κ⁻) ψ̇⁻ with κ = aᵀM⁻¹a (on the mechanism's velocities); κ⁺ = κ⁻ for one
///   block and for symmetric mechanisms, where ψ̇⁺ = r ψ̇⁻ exactly.
///
/// Hence T⁻ − T⁺ = (1 − r²) E⁻ ≥ 0 for r ≤ 1, and r = 1 is an elastic pivot switch. In loops the
/// law is posed on the mechanism's velocities (null space of Φ_q⁺), so slots tied by the closures
/// (a trilithon's four hinges) are one impact mode, never an over-determined system. With
/// different r_s in one simultaneous impact, E⁺ is the energy of the slot rates r_s ψ̇_s⁻ on the
/// `before` chain, capped at r_max² E⁻. `kin` is left evaluated for the `after` chain.
pub fn restitution_law(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
    slots: &[(usize, f64)],
) -> Result<ImpactResult, ImpactError> {
    restitution_law_holding(model, kin, q, qdot_minus, before, after, slots, &[])
}

/// [`restitution_law`] with the slots `held` (seated joints) kept at rate 0 through the impact,
/// like the closures: the law is posed on the motions that leave them seated. A rocking base
/// that rocks about one tilt with the other seated (a block on an edge of its base) then keeps
/// exactly r of its rate; posed on every motion, part of the impact mode would go into the seated
/// tilt and be taken out afterwards by the plastic impulse that keeps it seated.
#[allow(clippy::too_many_arguments)]
pub fn restitution_law_holding(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
    slots: &[(usize, f64)],
    held: &[usize],
) -> Result<ImpactResult, ImpactError> {
    check_inputs(model, q, qdot_minus, before, after)?;
    for &(s, r) in slots {
        check_slot(model, s)?;
        if !(r.is_finite() && r >= 0.0) {
            return Err(ImpactError::Invalid(format!(
                "restitution coefficient {r} of slot {s} must be finite and ≥ 0"
            )));
        }
    }
    check_distinct(slots.iter().map(|s| s.0))?;
    for &s in held {
        check_slot(model, s)?;
    }
    rate_law(
        "restitution law",
        model,
        kin,
        q,
        qdot_minus,
        before,
        after,
        slots,
        held,
    )
}

/// The paper's eq 5, F = C ln(r) ψ̇|ψ̇| δ(ψ) on each listed slot `(s, r, C)`, integrated exactly
/// across ψ = 0: ψ̇_s is multiplied by r^C (C normalised by the effective inertia 1/(aᵀM⁻¹a), so
/// that C = 1 gives r and one block gives θ̇⁺ = r^C θ̇⁻ exactly).
///
/// The δ straddles the pivot switch. The switch itself moves no momentum about the persisting
/// hinges and, like the rest of the motion away from the δ, dissipates nothing (hypothesis 3:
/// energy is lost only by the impulsive force); the force then takes the impact mode's rates
/// by r^C. Both together are [`restitution_law`] with r_s^(C_s): T⁺ = T⁻ − (1 − r^(2C)) E⁻.
/// `kin` is left evaluated for the `after` chain.
pub fn dirac_law(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
    slots: &[(usize, f64, f64)],
) -> Result<ImpactResult, ImpactError> {
    dirac_law_holding(model, kin, q, qdot_minus, before, after, slots, &[])
}

/// [`dirac_law`] with the slots `held` (seated joints) kept at rate 0 through the impact (see
/// [`restitution_law_holding`]).
#[allow(clippy::too_many_arguments)]
pub fn dirac_law_holding(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
    slots: &[(usize, f64, f64)],
    held: &[usize],
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
    check_distinct(slots.iter().map(|s| s.0))?;
    for &s in held {
        check_slot(model, s)?;
    }
    let factors: Vec<(usize, f64)> = slots.iter().map(|&(s, r, c)| (s, r.powf(c))).collect();
    rate_law(
        "Dirac law",
        model,
        kin,
        q,
        qdot_minus,
        before,
        after,
        &factors,
        held,
    )
}

/// The kinetic metric of one chain on its mechanism's velocities: q̇ = N z, T = ½ zᵀ(NᵀMN)z
/// = ½|w|² with w = Lᵀz, L the Cholesky factor of NᵀMN.
///
/// On an open chain N = I and z = q̇: the products with N are skipped (each entry of a product
/// with I is one entry times 1 plus zeros, so the results are the same to the last bit; for n
/// coordinates this saves the O(n³) products NᵀMN and NᵀA at every impact).
#[derive(Clone, Debug, Default)]
struct Metric {
    /// N, None for the identity (an open chain).
    null: Option<DMatrix<f64>>,
    chol: DMatrix<f64>,
}

impl Metric {
    fn new(law: &'static str, chain: &Chain) -> Result<Self, ImpactError> {
        let mut metric = Self::default();
        metric.refactor(law, chain)?;
        Ok(metric)
    }

    /// Makes this the metric of `chain`, reusing the factor's storage (an open chain's metric
    /// allocates nothing once the sizes are set).
    fn refactor(&mut self, law: &'static str, chain: &Chain) -> Result<(), ImpactError> {
        match &chain.null {
            Some(null) => self.chol = null.transpose() * &chain.mass * null,
            None => copy_matrix(&mut self.chol, &chain.mass),
        }
        let d = self.chol.nrows();
        cholesky_in_place(&mut self.chol).map_err(|col| ImpactError::Singular {
            law,
            rank: col,
            needed: d,
            hint: "the mass matrix is not positive definite on the mechanism's velocities",
        })?;
        // cholesky_in_place leaves scratch in the strict upper triangle: clear it, Lᵀ is used.
        self.chol.fill_upper_triangle(0.0, 1);
        self.null.clone_from(&chain.null);
        Ok(())
    }

    /// w = Lᵀ Nᵀ q̇ for a velocity q̇ of this chain (Φ_q q̇ = 0).
    fn w_of_qdot(&self, qdot: &DVector<f64>) -> DVector<f64> {
        match &self.null {
            Some(null) => self.chol.tr_mul(&null.tr_mul(qdot)),
            None => self.chol.tr_mul(qdot),
        }
    }

    /// w = L⁻¹ Nᵀ p for a generalized momentum p (the momentum's components along the
    /// mechanism's motions, in the energy-normalised coordinates).
    fn w_of_momentum(&self, p: &DVector<f64>) -> DVector<f64> {
        let mut w = DVector::zeros(0);
        self.w_of_momentum_into(p, &mut w);
        w
    }

    /// [`Self::w_of_momentum`] written into `w` (its storage reused on an open chain).
    fn w_of_momentum_into(&self, p: &DVector<f64>, w: &mut DVector<f64>) {
        match &self.null {
            Some(null) => *w = null.tr_mul(p),
            None => assign(w, p.as_slice()),
        }
        forward_substitute(&self.chol, w.as_mut_slice());
    }

    /// q̇ = N L⁻ᵀ w.
    fn qdot_of_w(&self, w: &DVector<f64>) -> DVector<f64> {
        let mut z = w.clone();
        back_substitute_transposed(&self.chol, z.as_mut_slice());
        match &self.null {
            Some(null) => null * z,
            None => z,
        }
    }

    /// C = L⁻¹ Nᵀ A, so that the slot rates are ψ̇ = Aᵀq̇ = Cᵀw.
    fn slot_map(&self, a: &DMatrix<f64>) -> DMatrix<f64> {
        let mut c = match &self.null {
            Some(null) => null.tr_mul(a),
            None => a.clone(),
        };
        for mut col in c.column_iter_mut() {
            let mut v = col.clone_owned();
            forward_substitute(&self.chol, v.as_mut_slice());
            col.copy_from(&v);
        }
        c
    }
}

/// Orthonormal basis of the range of C (d × k): the directions of w that change the slot rates
/// (the impact modes). Its complement, ker Cᵀ, holds the motions that leave them unchanged.
fn range_basis(c: &DMatrix<f64>) -> DMatrix<f64> {
    if c.nrows() == 0 || c.ncols() == 0 {
        return DMatrix::zeros(c.nrows(), 0);
    }
    let svd = JacobiSvd::new(c);
    let tol = svd.tolerance();
    let cols: Vec<DVector<f64>> = (0..svd.singular_values.len())
        .filter(|&j| svd.singular_values[j] > tol)
        .map(|j| svd.w.column(j) / svd.singular_values[j])
        .collect();
    if cols.is_empty() {
        DMatrix::zeros(c.nrows(), 0)
    } else {
        DMatrix::from_columns(&cols)
    }
}

/// y minimising |(CᵀQ) y − t| (CᵀQ has full column rank: Q spans the range of C).
fn mode_coordinates(c: &DMatrix<f64>, basis: &DMatrix<f64>, t: &DVector<f64>) -> DVector<f64> {
    if basis.ncols() == 0 {
        return DVector::zeros(0);
    }
    pinv_solve(&(c.transpose() * basis), t).0
}

/// The restitution / exact Dirac map with a rate factor f_s per impacting slot (see
/// [`restitution_law`]): conserve the momenta of the motions that leave the slot rates unchanged
/// (from the bodies' real velocities), and give the impact mode the slot-rate direction
/// f_s ψ̇_s⁻ with the energy of those rates on the `before` chain (capped at f_max² E⁻).
fn rate_law(
    law: &'static str,
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot_minus: &DVector<f64>,
    before: &ActivePivots,
    after: &ActivePivots,
    slots: &[(usize, f64)],
    held: &[usize],
) -> Result<ImpactResult, ImpactError> {
    let mut ws = LawWorkspace::default();
    pre_impact_momentum(model, kin, q, qdot_minus, before, after, held, &mut ws);
    let (minus, plus, momentum) = (&ws.minus, &ws.plus, &ws.momentum);
    // The slot directions do not depend on the pivots (only on the Γ's).
    let a = directions(model, kin, slots.iter().map(|x| x.0));
    let rates = a.tr_mul(qdot_minus);
    let targets = DVector::from_iterator(
        slots.len(),
        slots.iter().zip(rates.iter()).map(|(s, v)| s.1 * v),
    );
    let f_max = slots.iter().map(|s| s.1).fold(0.0, f64::max);

    // Before: the impact mode's energy E⁻ and the energy of the target rates.
    let metric_minus = Metric::new(law, minus)?;
    let c_minus = metric_minus.slot_map(&a);
    let q_minus = range_basis(&c_minus);
    let mode_energy = 0.5
        * q_minus
            .tr_mul(&metric_minus.w_of_qdot(qdot_minus))
            .norm_squared();
    let target_energy = (0.5 * mode_coordinates(&c_minus, &q_minus, &targets).norm_squared())
        .min(f_max * f_max * mode_energy);

    // After: keep the momentum along ker Cᵀ, set the impact mode.
    let metric_plus = Metric::new(law, plus)?;
    let c_plus = metric_plus.slot_map(&a);
    let q_plus = range_basis(&c_plus);
    if q_plus.ncols() < q_minus.ncols() {
        return Err(ImpactError::Singular {
            law,
            rank: q_plus.ncols(),
            needed: q_minus.ncols(),
            hint: "an impacting slot's rate is locked by the closures of the new chain",
        });
    }
    let w_momentum = metric_plus.w_of_momentum(momentum);
    let y = mode_coordinates(&c_plus, &q_plus, &targets);
    let y_energy = 0.5 * y.norm_squared();
    let scale = if y_energy > 0.0 {
        (target_energy / y_energy).sqrt()
    } else {
        0.0
    };
    let w = &w_momentum - &q_plus * q_plus.tr_mul(&w_momentum) + &q_plus * (y * scale);
    let qdot = metric_plus.qdot_of_w(&w);
    if !qdot.iter().all(|x| x.is_finite()) {
        return Err(ImpactError::Invalid(format!(
            "{law}: non-finite rates after the impact"
        )));
    }
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

/// A slot under the regularised Dirac law (eq 5): which slot, its r and C, and the width ε of
/// its δ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegularisedSlot {
    /// The angle slot s.
    pub slot: usize,
    /// Coefficient r of the law.
    pub r: f64,
    /// Coefficient C of the law.
    pub c: f64,
    /// Width ε of the regularised δ (rad).
    pub width: f64,
}

/// Generalized force of the regularised eq 5 for the listed slots at the current state,
/// written into `out` (overwritten):
/// F = Σ_s a_s C ln(r) ψ̇_s|ψ̇_s| δ_ε(ψ_s) / D_s, ψ̇_s = a_sᵀq̇ ([`slot_rate_direction`]).
///
/// The normalisation D_s makes a crossing multiply the rate by r^C, as [`dirac_law`] does:
/// with P the inverse of M on the mechanism's velocities (P = N(NᵀMN)⁻¹Nᵀ, N a basis of ker Φ_q;
/// M⁻¹ on an open chain) the force gives ψ̈_s = aᵀPF, so a slot alone needs D_s = κ_s = a_sᵀPa_s.
/// Slots whose rates the loops tie together (Nᵀa_t ∥ Nᵀa_s: a trilithon's four hinges, an arch's
/// four joints) cross as one impact mode and each of their forces acts on the whole mode: D_s is
/// the sum of κ_t over the slots tied to s, so that the mode's rate is multiplied by r^C in all
/// (for tied slots with the same r and C). On an open chain no two slots are tied and D_s = κ_s
/// = (M⁻¹)_ss.
///
/// `angles[s]` are the slot angles (q, then the closure angles). `kin` must hold the forward
/// kinematics, M and (for loops) Φ_q of the current chain. Slots outside their δ support cost
/// nothing.
///
/// # Panics
/// If a slot index is out of range of `angles` or of the model's slots.
pub fn dirac_regularised_force(
    model: &Model,
    kin: &Data,
    qdot: &DVector<f64>,
    angles: &[f64],
    slots: &[RegularisedSlot],
    out: &mut DVector<f64>,
) {
    out.fill(0.0);
    let active: Vec<(usize, f64)> = slots
        .iter()
        .enumerate()
        .filter_map(|(i, z)| {
            let d = regularised_delta(angles[z.slot], z.width);
            (d != 0.0).then_some((i, d))
        })
        .collect();
    if active.is_empty() {
        return;
    }
    let Some(inverse) = mechanism_inverse(model, kin) else {
        return;
    };
    let directions: Vec<DVector<f64>> = slots
        .iter()
        .map(|z| slot_rate_direction(model, kin, z.slot))
        .collect();
    let p_dirs: Vec<DVector<f64>> = directions.iter().map(|a| &inverse * a).collect();
    let kappa: Vec<f64> = directions
        .iter()
        .zip(&p_dirs)
        .map(|(a, pa)| a.dot(pa))
        .collect();
    for (i, delta) in active {
        let RegularisedSlot { r, c, .. } = slots[i];
        if !(kappa[i] > 0.0 && kappa[i].is_finite()) {
            continue;
        }
        // Tied: |cos| = 1 in the metric P (Cauchy–Schwarz is strict otherwise).
        let denom: f64 = (0..slots.len())
            .filter(|&t| {
                let k_st = directions[i].dot(&p_dirs[t]);
                k_st * k_st >= (1.0 - TIE_TOLERANCE) * kappa[i] * kappa[t]
            })
            .map(|t| kappa[t])
            .sum();
        let rate = directions[i].dot(qdot);
        *out += &directions[i] * (c * r.ln() * rate * rate.abs() * delta / denom);
    }
}

/// Two slots count as tied by the loops when the cosine of their rate directions in the
/// mechanism's metric is 1 within this (squared) tolerance.
const TIE_TOLERANCE: f64 = 1e-9;

/// P = N(NᵀMN)⁻¹Nᵀ, the inverse of M on the mechanism's velocities (M⁻¹ on an open chain), or
/// None when M is not positive definite there.
fn mechanism_inverse(model: &Model, kin: &Data) -> Option<DMatrix<f64>> {
    let n = model.dof();
    let null = if model.constraint_rows == 0 {
        DMatrix::identity(n, n)
    } else {
        null_space(&kin.phi_q, &constraint_row_scale(model))
    };
    let mut l = null.transpose() * &kin.mass_matrix * &null;
    cholesky_in_place(&mut l).ok()?;
    let mut inv_nt = null.transpose();
    for mut col in inv_nt.column_iter_mut() {
        let mut v = col.clone_owned();
        cholesky_solve(&l, v.as_mut_slice());
        col.copy_from(&v);
    }
    Some(&null * inv_nt)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crr_kinematics::Side;
    use crr_kinematics::fixtures::{
        colonnade_row, four_hinge_arch, random_chain, serial_chain, single_block, trilithon,
        voussoir_arch,
    };

    /// The momentum law posed on the constraints' range (Gauss' principle of impulsive motion on
    /// the sparse factors, [`momentum_law_projected`]) and on their null space (the Jacobi SVD's
    /// orthonormal basis, [`momentum_law`]) are two derivations of one minimisation: they agree
    /// to 1e-10 of |q̇⁺| (the fixtures' M and Φ_q have condition numbers below 1e4, so the two
    /// factorisations' round-off stays near 1e-12) on open chains, on loops with redundant
    /// closure rows (planar arches: three of a hinge closure's five rows are zero or dependent)
    /// and on random 3D chains with loops, at a configuration off the reference. Each answer
    /// also keeps the loops closed (Φ_q⁺ q̇⁺ = 0), T⁻ is the same from the bodies' velocities as
    /// ½q̇⁻ᵀM⁻q̇⁻, and no energy is created.
    #[test]
    fn the_momentum_law_on_the_constraints_range_is_the_null_space_law() {
        let specs = [
            single_block(0.2, 1.0, 2500.0),
            serial_chain(4),
            trilithon(0.3, 2.0, 2.0, 0.5, 0.4),
            four_hinge_arch(1.0, 1.3, 0.5, true),
            voussoir_arch(9, 2.0, 2.4, 0.6),
            colonnade_row(3, 3),
            random_chain(5, 6, 2),
            random_chain(17, 7, 3),
        ];
        let ground = GroundMotion::none();
        for spec in &specs {
            let model = Model::from_spec(spec).expect("valid fixture");
            let n = model.dof();
            let before = ActivePivots::uniform(&model, Side::Positive);
            let mut after = before.clone();
            after.sides[0] = Side::Negative;
            let mut kin = Data::new(&model);
            let mut q = DVector::from_fn(n, |i, _| 0.01 * ((i as f64 * 1.7).sin()));
            q[0] = 0.0;
            if model.constraint_rows > 0 {
                crr_dynamics::closed_chain::project_positions(
                    &model, &mut kin, &after, &mut q, None,
                )
                .expect("the loops close near the reference");
            }
            let qd = DVector::from_fn(n, |i, _| 0.3 - 0.17 * i as f64);
            let reference = momentum_law(&model, &mut kin, &q, &qd, &before, &after)
                .unwrap_or_else(|e| panic!("{n} coordinates: {e}"));
            let mut work = Dynamics::new(&model, after.clone());
            let mut ws = LawWorkspace::default();
            let projected = momentum_law_projected(
                &model, &mut kin, &mut ws, &mut work, &ground, 0.0, &q, &qd, &before, &after,
            )
            .unwrap_or_else(|e| panic!("{n} coordinates, projected: {e}"));
            let scale = reference.qdot.norm();
            let gap = (&projected.qdot - &reference.qdot).norm();
            assert!(
                gap <= 1e-10 * scale,
                "{n} coordinates: |Δq̇⁺| = {gap:e} of {scale:e}"
            );
            let t_rel = (projected.kinetic_before - reference.kinetic_before).abs();
            assert!(
                t_rel <= 1e-12 * reference.kinetic_before,
                "{n}: T⁻ {t_rel:e}"
            );
            assert!(projected.kinetic_after <= projected.kinetic_before * (1.0 + 1e-12));
            if model.constraint_rows > 0 {
                forward_kinematics(&model, &mut kin, &q, &after);
                constraint_jacobian(&model, &mut kin, &after);
                let scale_rows = constraint_row_scale(&model);
                let drift = (0..model.constraint_rows)
                    .map(|i| {
                        (scale_rows[i] * kin.phi_q.row(i).dot(&projected.qdot.transpose())).abs()
                    })
                    .fold(0.0, f64::max);
                assert!(drift <= 1e-11 * scale, "{n}: Φ_q⁺ q̇⁺ = {drift:e}");
            }
        }
    }

    /// One workspace reused across chains of different sizes, open and closed, gives the
    /// momentum law's results to the last bit of a fresh workspace's: the buffers are resized
    /// when the chain changes and nothing of one impact leaks into the next. (That the results
    /// are the allocating code's before the workspace existed is checked on whole runs: the
    /// bundled models' outputs are byte-identical, docs/performance.md item 19; the physics of
    /// the law is checked in `tests/laws.rs`.)
    #[test]
    fn a_reused_workspace_gives_the_fresh_results_to_the_last_bit() {
        // Consecutive chains of one size reuse the storage (open and open, closed and closed,
        // closed and open, open and closed: a trilithon and a serial chain have 3 coordinates),
        // the others resize it.
        let specs = [
            single_block(0.2, 1.0, 2500.0),
            single_block(0.3, 1.2, 2400.0),
            random_chain(3, 4, 0),
            serial_chain(3),
            trilithon(0.3, 2.0, 2.0, 0.5, 0.4),
            trilithon(0.25, 1.5, 1.8, 0.4, 0.2),
            serial_chain(3),
            random_chain(11, 6, 0),
        ];
        let bits = |r: &ImpactResult| {
            let mut b: Vec<u64> = r.qdot.iter().map(|x| x.to_bits()).collect();
            b.extend([r.kinetic_before.to_bits(), r.kinetic_after.to_bits()]);
            b
        };
        let mut ws = LawWorkspace::default();
        for spec in &specs {
            let model = Model::from_spec(spec).expect("valid fixture");
            let n = model.dof();
            let before = ActivePivots::uniform(&model, Side::Positive);
            let after = ActivePivots {
                sides: before.sides.iter().map(|s| s.flipped()).collect(),
            };
            let q = DVector::zeros(n);
            let qd = DVector::from_fn(n, |i, _| 0.3 - 0.17 * i as f64);
            let (mut k1, mut k2) = (Data::new(&model), Data::new(&model));
            let fresh = momentum_law(&model, &mut k1, &q, &qd, &before, &after)
                .unwrap_or_else(|e| panic!("{n} coordinates: {e}"));
            let reused = momentum_law_with(&model, &mut k2, &mut ws, &q, &qd, &before, &after)
                .unwrap_or_else(|e| panic!("{n} coordinates, reused: {e}"));
            assert_eq!(bits(&fresh), bits(&reused), "{n} coordinates");
        }
    }
}
