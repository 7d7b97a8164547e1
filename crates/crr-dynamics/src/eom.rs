//! Equations of motion of the multi-DOF chain:
//! M(q) q̈ + h(q, q̇) = Q(q, t) + Φ_qᵀ λ,  Φ_q q̈ + Φ̇_q q̇ = 0,
//! with the ground motion as the effective gravity g_eff(t) = (−a_x, −a_y, −g − a_z) on every body
//! (the equations are written in the frame of the ground): Q = Σₙ Mⁿ J_cₙᵀ g_eff.
//!
//! Closed chains are solved with explicit multipliers by Gauss' principle: with M = L Lᵀ and
//! z = Lᵀq̈, z is the point of B z = −Φ̇_q q̇ (B = Φ_q L⁻ᵀ) nearest to z_free = L⁻¹(Q − h), and
//! Φ_qᵀλ = L(z − z_free). Redundant closures (a colonnade under a rigid slab) make B rank-deficient:
//! its pseudo-inverse (one-sided Jacobi SVD, singular values below √[`RANK_TOLERANCE`]·σ_max
//! dropped) gives the minimum-norm λ, and q̈ is unique. The rank structure of B changes with the
//! chain (pivots, seated set), not within a segment: the SVD picks r independent rows S once
//! (pivoted Gram–Schmidt), and later evaluations solve on them through the Cholesky factor of
//! B_S B_Sᵀ (r × r), after checking that the SVD would make the same rank decision (σ_min(B_S)
//! above its threshold, the other rows in the span of B_S to 1e-9); the minimum-norm λ over all
//! rows follows from the null space of Bᵀ, [−Cᵀ; I] with B_D = C B_S ([`ClosedChainSolve`]).
//!
//! Open chains whose seated slots are all tree coordinates (no closure rows) are solved (from
//! [`ARTICULATED_BODY_MIN_DOF`] coordinates on) by the articulated-body algorithm
//! ([`crate::articulated_body`]) in O(DOF(1)) without forming M; M is then computed only on
//! request ([`Dynamics::ensure_mass_matrix`]).

use nalgebra::{DMatrix, DVector, Vector3, Vector6};

use crr_kinematics::{
    ActivePivots, Data, Model, constraint_bias, constraint_jacobian, forward_kinematics,
    generalized_gravity, mass_matrix, velocities, velocity_product,
};

use crate::articulated_body::ArticulatedBody;
use crate::ground_motion::GroundMotion;
use crate::linalg::{
    JacobiSvd, RANK_TOLERANCE, back_substitute_transposed, cholesky_in_place, cholesky_solve,
    forward_substitute, pivot_columns,
};
use crate::single_coordinate;

/// A failure of the equations of motion at some state.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DynamicsError {
    /// M(q) is not positive definite (a body of zero inertia about its axis, or a NaN state).
    #[error(
        "the mass matrix is singular at coordinate \"{coordinate}\" (is the body's inertia about that axis zero, or the state NaN?)"
    )]
    SingularMassMatrix {
        /// Name of the coordinate whose pivot failed.
        coordinate: String,
    },
    /// The loop closures cannot be satisfied from this state.
    #[error("the loop closures cannot be satisfied: {0}")]
    Closure(String),
    /// Inconsistent or impossible initial conditions.
    #[error("initial conditions: {0}")]
    Initial(String),
    /// A NaN or infinite value appeared.
    #[error("non-finite {what} at t = {t}")]
    NonFinite {
        /// Which quantity.
        what: &'static str,
        /// Time (s).
        t: f64,
    },
}

/// g_eff(t) = (−a_x, −a_y, −g − a_z) (m/s²), the load of gravity and ground motion in the frame of
/// the ground.
pub fn effective_gravity(model: &Model, ground: &GroundMotion, t: f64) -> Vector3<f64> {
    let a = ground.acceleration(t);
    gravity_with_ground(model, &a)
}

/// g_eff = (−a_x, −a_y, −g − a_z) for a ground acceleration a_g already looked up.
fn gravity_with_ground(model: &Model, a: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(-a.x, -a.y, -model.gravity - a.z)
}

/// Weights that make the rows of Φ comparable: 1/size for point rows (m), 1 for axis rows.
pub fn constraint_row_scale(model: &Model) -> DVector<f64> {
    let mut s = DVector::from_element(model.constraint_rows, 1.0);
    for cl in &model.closures {
        for r in 0..3 {
            s[cl.first_row + r] = 1.0 / model.size;
        }
    }
    s
}

/// Workspace and results of one evaluation of the equations of motion (allocated once).
#[derive(Clone, Debug)]
pub struct Dynamics {
    /// The kinematics workspace (Γ, M, h, Φ_q …). After [`Self::accelerations`] on the
    /// articulated-body path it holds the frames, V and A (and Q's subtree sums) but neither M nor
    /// h: call [`Self::ensure_mass_matrix`] before reading `kin.mass_matrix` (or
    /// [`Self::evaluate`] for everything).
    pub kin: Data,
    /// The dynamic chain: the active pivots, held fixed between impacts.
    pub pivots: ActivePivots,
    /// Q(q, t) = Σ Mⁿ J_cᵀ g_eff (N m).
    pub load: DVector<f64>,
    /// Generalized force of the ground-motion part alone, Σ Mⁿ J_cᵀ(−a_g) (N m): its power
    /// Q_gᵀq̇ is the rate of work done by the ground motion.
    pub ground_force: DVector<f64>,
    /// q̈ (rad/s²).
    pub qddot: DVector<f64>,
    /// λ, closure multipliers (N for point rows, N m for axis rows); Φ_qᵀλ is the generalized
    /// constraint force.
    pub lambda: DVector<f64>,
    /// Angle slots held at φ = 0 (seated interfaces): extra constraint rows after Φ's.
    pub seated: Vec<usize>,
    /// Generalized reaction moments holding the seated slots (N m), in the order of `seated`.
    pub seat_reactions: DVector<f64>,
    /// Extra generalized force added to Q at the last evaluation (e.g. a regularised impact law).
    pub extra_force: DVector<f64>,
    /// On closed chains, solve the seated coordinates as constraint rows with the loops, so that
    /// λ and the seat reactions are the minimum-norm set over all rows (what the contact forces
    /// report; the default). When false they are eliminated like on open chains: the same q̈,
    /// at a fraction of the cost, but an indeterminate split of the reactions between the loops
    /// and the seats (the integration and the uplift test need q̈ only).
    pub min_norm_multipliers: bool,
    /// The algorithm [`Self::accelerations_with`] uses ([`ForwardSolver::Auto`] by default).
    pub solver: ForwardSolver,
    /// How Gauss' principle is solved on the constraint rows ([`ClosedChainSolve::SelectedRows`]
    /// by default).
    pub closed_chain_solve: ClosedChainSolve,
    /// Independent rows of B chosen by the SVD, with the (rows, free coordinates, seated slots)
    /// they were chosen for: reused, after a check, while they pass it. Several sets, since the
    /// uplift test solves a few seated sets at every step ([`SELECTION_CACHE`] at most).
    selections: Vec<RowSelection>,
    /// The entry of `selections` replaced next when it is full.
    next_evicted: usize,
    /// Workspace of the solve on the selected rows.
    rows_work: SelectedRowsWork,
    /// The last closed-chain solve used the selected rows (not the SVD).
    used_selected: bool,
    /// Cholesky factor L of M_ff, the block of M over the free (not seated) coordinates.
    factor: DMatrix<f64>,
    row_scale: DVector<f64>,
    /// Seated tree coordinates (q̈ₖ = 0), by coordinate.
    locked: Vec<bool>,
    /// The coordinates not seated, in order: the columns of `factor`.
    free: Vec<usize>,
    /// r = Q + F_extra − h at the last evaluation (N m).
    residual: DVector<f64>,
    /// Working vector over the free coordinates: z_free, then q̈_f.
    z: DVector<f64>,
    articulated: ArticulatedBody,
    /// g_eff of the last evaluation (m/s²).
    g_eff: Vector3<f64>,
    /// `kin.mass_matrix` holds M of the current kinematics.
    mass_current: bool,
    /// The last [`Self::accelerations_with`] used the articulated-body algorithm.
    used_articulated: bool,
    /// The last [`Self::accelerations_with`] used the one-coordinate closed form
    /// ([`crate::single_coordinate`]).
    used_single_coordinate: bool,
    /// The one-coordinate kernel of the last active pivot ([`Self::integration_accelerations`]).
    kernel: Option<single_coordinate::Kernel>,
    /// The kernel of the pivot before: a rocking block alternates between two.
    previous_kernel: Option<single_coordinate::Kernel>,
}

/// Open chains with at least this many coordinates (DOF(1)) are solved by the articulated-body
/// algorithm under [`ForwardSolver::Auto`], below it by M (composite rigid bodies) and Cholesky.
/// On the serial chains of `benches/dynamics.rs` (`forward_dynamics_aba` against
/// `forward_dynamics_cholesky`, N = 1 … 128) the articulated-body path is never the slower one,
/// 0.21 µs against 0.25 µs already at N = 1 (it skips h and the second pass of Q), so the
/// crossover is 1: every eligible chain uses it. See docs/engine.md, "Equations of motion".
pub const ARTICULATED_BODY_MIN_DOF: usize = 1;

/// The forward-dynamics algorithm of [`Dynamics::accelerations_with`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ForwardSolver {
    /// The articulated-body algorithm when it applies (no closure rows, every seated slot a tree
    /// coordinate) and DOF(1) ≥ [`ARTICULATED_BODY_MIN_DOF`]; otherwise [`Self::Cholesky`].
    #[default]
    Auto,
    /// Always M by composite rigid bodies, Cholesky of its free block, and Gauss' principle for
    /// the constraint rows.
    Cholesky,
    /// The articulated-body algorithm whenever it applies (open chains with seated tree
    /// coordinates only), whatever DOF(1); otherwise [`Self::Cholesky`].
    ArticulatedBody,
}

/// How [`Dynamics::solve_evaluated`] solves Gauss' principle on the constraint rows of a closed
/// chain (or on seated closure angles).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ClosedChainSolve {
    /// A set of independent rows of B chosen by the SVD is reused while it stays independent
    /// and spans the other rows (checked at every evaluation against the SVD's rank rule):
    /// B_S B_Sᵀ = L_G L_Gᵀ (rank × rank) instead of a Jacobi SVD of B; the SVD runs (and
    /// re-selects) when the check fails or the chain changes. Same q̈ and λ as [`Self::Svd`] to
    /// round-off when the other rows are dependent to round-off.
    #[default]
    SelectedRows,
    /// The one-sided Jacobi SVD of B at every evaluation (the reference).
    Svd,
}

/// Independent rows of B, and the problem they were chosen for.
#[derive(Clone, Debug)]
struct RowSelection {
    rows: usize,
    free: usize,
    seated: Vec<usize>,
    selected: Vec<usize>,
}

/// Number of seated sets whose row selections [`Dynamics`] keeps: the integration's set, and
/// the uplift test's single releases (two per seated slot, one per side) and active sets.
const SELECTION_CACHE: usize = 256;

/// Largest ‖R_D‖_F/‖B‖_F accepted by the solve on selected rows, R_D the part of the rows not
/// selected outside the span of the selected ones. Redundant closures that are exactly closed
/// leave round-off there (1e-16 … 1e-14); the projection after each step closes the loops to
/// 1e-10 relative or better, so the rows are dependent to about that. Far below the SVD's rank
/// threshold √RANK_TOLERANCE/√rows ≥ 3e-6: the rank decision is the SVD's.
pub const DEPENDENT_ROW_TOLERANCE: f64 = 1e-9;

/// Safety factor between the lower bound on σ_min(B_S) and the SVD's rank threshold, and
/// between ‖R_D‖ and that threshold (a margin for the round-off of both computations).
const RANK_MARGIN: f64 = 10.0;

/// Workspace of [`solve_selected_rows`], kept in [`Dynamics`] so that the solve allocates
/// nothing once sized.
#[derive(Clone, Debug, Default)]
struct SelectedRowsWork {
    /// Whether each row of B is selected.
    is_selected: Vec<bool>,
    /// The rows not selected, in order.
    others: Vec<usize>,
    /// L_G, the Cholesky factor of G = B_S B_Sᵀ (r × r).
    g: DMatrix<f64>,
    /// C, row-major (rows D × r): B_D ≈ C B_S.
    c: Vec<f64>,
    /// I + C Cᵀ, then its Cholesky factor.
    nn: DMatrix<f64>,
    /// Scratch of length max(r, rows D).
    e: Vec<f64>,
    /// y = −G⁻¹ e_S.
    y: Vec<f64>,
}

/// Gauss' principle on the rows `selected` of B, given as the columns of `bt` = Bᵀ
/// (n_f × m): with G = B_S B_Sᵀ = L_G L_Gᵀ, y = −G⁻¹ e_S and dz = B_Sᵀ y (e = B z + bias, the
/// constraint residual at z_free), and, when `min_norm`, the minimum-norm multipliers over all
/// rows, Bᵀλ = dz (otherwise λ_S = y, λ_D = 0: another solution of the same equations). Returns
/// false (use the SVD) unless the rank decision is provably the SVD's, within [`RANK_MARGIN`]:
/// σ_min(B_S)² ≥ 1/‖L_G⁻¹‖_F² must exceed the SVD's threshold
/// max(√RANK_TOLERANCE·σ_max(B), `floor`) (bounded above by √RANK_TOLERANCE·‖B‖_F), so the SVD
/// keeps r = |S| singular values; and the rows D not selected must lie in the span of B_S:
/// B_D = C B_S + R_D with ‖R_D‖_F ≤ [`DEPENDENT_ROW_TOLERANCE`]·‖B‖_F, which bounds
/// σ_{r+1}(B) ≤ ‖R_D‖₂ far below the threshold, so the SVD drops the rest.
///
/// The multipliers: λ_p = (y, 0) solves Bᵀλ = dz; the null space of Bᵀ is spanned by the
/// columns of N = [−Cᵀ; I] (rows S then D), so the minimum-norm solution is
/// λ = λ_p − N (NᵀN)⁻¹ Nᵀλ_p, with NᵀN = I + C Cᵀ and Nᵀλ_p = −C y: λ_S = y + Cᵀw,
/// λ_D = −w, w = −(I + C Cᵀ)⁻¹ C y. Work: O(m r n_f + r³) (+ O(d² r + d³) for the multipliers,
/// d = m − r), against a Jacobi SVD's sweeps of O(m² n_f) each.
#[allow(clippy::too_many_arguments)]
fn solve_selected_rows(
    work: &mut SelectedRowsWork,
    bt: &DMatrix<f64>,
    residual: &DVector<f64>,
    selected: &[usize],
    floor: f64,
    min_norm: bool,
    dz: &mut DVector<f64>,
    lambda: &mut DVector<f64>,
) -> bool {
    let (nf, m) = (bt.nrows(), bt.ncols());
    let r = selected.len();
    let row = |i: usize| &bt.as_slice()[i * nf..(i + 1) * nf];
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let b_norm = bt.norm();
    let threshold = (RANK_TOLERANCE.sqrt() * b_norm).max(floor);
    work.is_selected.clear();
    work.is_selected.resize(m, false);
    for &i in selected {
        if i >= m || work.is_selected[i] {
            return false;
        }
        work.is_selected[i] = true;
    }
    work.others.clear();
    work.others.extend((0..m).filter(|&i| !work.is_selected[i]));
    let d = work.others.len();
    if work.g.nrows() != r {
        work.g = DMatrix::zeros(r, r);
    }
    for k in 0..r {
        for l in 0..=k {
            work.g[(k, l)] = dot(row(selected[k]), row(selected[l]));
        }
    }
    if cholesky_in_place(&mut work.g).is_err() {
        return false;
    }
    // ‖L_G⁻¹‖_F² ≥ ‖G⁻¹‖₂ = 1/σ_min(B_S)².
    let mut inv_norm2 = 0.0;
    work.e.clear();
    work.e.resize(r.max(d), 0.0);
    for k in 0..r {
        let e = &mut work.e[..r];
        e.fill(0.0);
        e[k] = 1.0;
        forward_substitute(&work.g, e);
        inv_norm2 += e.iter().map(|x| x * x).sum::<f64>();
    }
    // A NaN fails the check too.
    let sigma_min = 1.0 / inv_norm2.sqrt();
    if r > 0 && (sigma_min.is_nan() || sigma_min <= RANK_MARGIN * threshold) {
        return false;
    }
    // C (rows D in the basis of B_S) and ‖R_D‖_F.
    work.c.clear();
    work.c.resize(d * r, 0.0);
    let mut outside = 0.0;
    for (a, &i) in work.others.iter().enumerate() {
        let coef = &mut work.c[a * r..(a + 1) * r];
        for (k, x) in coef.iter_mut().enumerate() {
            *x = dot(row(i), row(selected[k]));
        }
        cholesky_solve(&work.g, coef);
        for (j, &bij) in row(i).iter().enumerate() {
            let mut rest = bij;
            for (k, &ck) in coef.iter().enumerate() {
                rest -= ck * bt[(j, selected[k])];
            }
            outside += rest * rest;
        }
    }
    let outside = outside.sqrt();
    if outside.is_nan()
        || outside > DEPENDENT_ROW_TOLERANCE * b_norm
        || RANK_MARGIN * outside > threshold
    {
        return false;
    }
    work.y.clear();
    work.y.extend(selected.iter().map(|&i| -residual[i]));
    cholesky_solve(&work.g, &mut work.y);
    dz.resize_vertically_mut(nf, 0.0);
    dz.fill(0.0);
    for (k, &i) in selected.iter().enumerate() {
        for (x, b) in dz.iter_mut().zip(row(i)) {
            *x += work.y[k] * b;
        }
    }
    lambda.resize_vertically_mut(m, 0.0);
    lambda.fill(0.0);
    for (k, &i) in selected.iter().enumerate() {
        lambda[i] = work.y[k];
    }
    if min_norm && d > 0 {
        if work.nn.nrows() != d {
            work.nn = DMatrix::zeros(d, d);
        }
        let c = &work.c;
        for a in 0..d {
            for b in 0..=a {
                work.nn[(a, b)] =
                    dot(&c[a * r..(a + 1) * r], &c[b * r..(b + 1) * r]) + f64::from(a == b);
            }
        }
        if cholesky_in_place(&mut work.nn).is_err() {
            return false;
        }
        let w = &mut work.e[..d];
        for (a, x) in w.iter_mut().enumerate() {
            *x = -dot(&c[a * r..(a + 1) * r], &work.y);
        }
        cholesky_solve(&work.nn, w);
        for (a, &i) in work.others.iter().enumerate() {
            for (k, &s) in selected.iter().enumerate() {
                lambda[s] += c[a * r + k] * w[a];
            }
            lambda[i] = -w[a];
        }
    }
    true
}

/// A generalized force added to the equations of motion (e.g. the regularised Dirac-delta law).
pub trait GeneralizedForce {
    /// Adds the force at (t, q, q̇) to `out`; `kin` holds the kinematics and M of that state.
    fn add(
        &mut self,
        model: &Model,
        kin: &Data,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        out: &mut DVector<f64>,
    );
}

/// The constraint row of an angle slot: the generalized direction a with φ̇ = aᵀq̇ (eₖ for a tree
/// coordinate; for a closure angle the relative angular velocity of child and parent frames along
/// the angle's world axis), and its bias ȧᵀq̇. Requires kinematics and velocities in `kin`.
pub fn slot_row(model: &Model, kin: &Data, slot: usize, row: &mut DVector<f64>) -> f64 {
    row.fill(0.0);
    if slot < model.dof() {
        row[slot] = 1.0;
        return 0.0;
    }
    let (iface, component) = model
        .interfaces
        .iter()
        .find_map(|i| i.slots.clone().position(|s| s == slot).map(|c| (i, c)))
        .expect("slot of a closure interface");
    let (a, b) = (
        model.frame_of(iface.parent),
        Some(model.body_coord[iface.child]),
    );
    let rot = |k: Option<usize>| frame_rotation(kin, k);
    let ang = |k: Option<usize>, part: usize| frame_angular(kin, k, part);
    if let crr_kinematics::InterfaceKind::RockingBase {
        normal,
        e1,
        e2,
        twist: true,
        ..
    } = &iface.kind
    {
        return twisting_tilt_row(model, kin, (a, b), (normal, e1, e2), component, row);
    }
    // The axis is attached to the parent, except a rocking base's second tilt (child).
    let (w, on_child) = match &iface.kind {
        crr_kinematics::InterfaceKind::Hinge { axis, .. } => (rot(a) * axis, false),
        crr_kinematics::InterfaceKind::RockingBase { e1, e2, .. } => {
            if component == 0 {
                (rot(a) * e1, false)
            } else {
                (rot(b) * e2, true)
            }
        }
    };
    for (frame, sign) in [(b, 1.0), (a, -1.0)] {
        let mut j = frame;
        while let Some(jj) = j {
            row[jj] += sign * w.dot(&kin.axis[jj]);
            j = model.coords[jj].parent;
        }
    }
    let (wa, wb) = (ang(a, 0), ang(b, 0));
    let w_dot = if on_child { wb.cross(&w) } else { wa.cross(&w) };
    w.dot(&(ang(b, 1) - ang(a, 1))) + (wb - wa).dot(&w_dot)
}

/// The rotation Γ of frame `k` (the identity for the ground, `None`).
fn frame_rotation(kin: &Data, k: Option<usize>) -> nalgebra::Matrix3<f64> {
    k.map_or_else(nalgebra::Matrix3::identity, |k| kin.rot_ops[k])
}

/// The angular part of frame `k`'s spatial velocity (`part` 0) or bias acceleration (`part` 1),
/// world axes; zero for the ground (`None`).
fn frame_angular(kin: &Data, k: Option<usize>, part: usize) -> Vector3<f64> {
    k.map_or_else(Vector3::zeros, |k| {
        let v = if part == 0 {
            &kin.spatial_velocity[k]
        } else {
            &kin.bias_acceleration[k]
        };
        Vector3::new(v[0], v[1], v[2])
    })
}

/// [`slot_row`] of a closure tilt of a rocking base that may twist: the tilts are those of the
/// child's face normal m = Γ_B n seen from the parent, θ₁ = atan2(u, v) with u = −(Γ_A e₂)·m,
/// v = (Γ_A n)·m, and θ₂ = asin((Γ_A e₁)·m). With Ω = ω_B − ω_A (world), ṁ = ω_B × m and the
/// parent's axes turning with ω_A: θ̇₂ = Ω·(m × Γ_A e₁)/cos θ₂ and
/// θ̇₁ = Ω·(−v (m × Γ_A e₂) − u (m × Γ_A n))/(u² + v²). So θ̇ = wᵀΩ, whose row over q̇ is built
/// like a plain axis's, and the bias of θ̈ is wᵀ(Ω̇'s bias) + ẇᵀΩ.
fn twisting_tilt_row(
    model: &Model,
    kin: &Data,
    (a, b): (Option<usize>, Option<usize>),
    (normal, e1, e2): (&Vector3<f64>, &Vector3<f64>, &Vector3<f64>),
    component: usize,
    row: &mut DVector<f64>,
) -> f64 {
    let rot = |k: Option<usize>| frame_rotation(kin, k);
    let ang = |k: Option<usize>, part: usize| frame_angular(kin, k, part);
    let (ra, rb) = (rot(a), rot(b));
    let (wa, wb) = (ang(a, 0), ang(b, 0));
    let m = rb * normal;
    let m_dot = wb.cross(&m);
    let (w, w_dot) = if component == 0 {
        let (e2a, na) = (ra * e2, ra * normal);
        let (e2a_dot, na_dot) = (wa.cross(&e2a), wa.cross(&na));
        let (u, v) = (-e2a.dot(&m), na.dot(&m));
        let (u_dot, v_dot) = (
            -(e2a_dot.dot(&m) + e2a.dot(&m_dot)),
            na_dot.dot(&m) + na.dot(&m_dot),
        );
        let d = u * u + v * v;
        let d_dot = 2.0 * (u * u_dot + v * v_dot);
        let p = -m.cross(&e2a) * v - m.cross(&na) * u;
        let p_dot = -m.cross(&e2a) * v_dot
            - (m_dot.cross(&e2a) + m.cross(&e2a_dot)) * v
            - m.cross(&na) * u_dot
            - (m_dot.cross(&na) + m.cross(&na_dot)) * u;
        (p / d, p_dot / d - p * (d_dot / (d * d)))
    } else {
        let e1a = ra * e1;
        let e1a_dot = wa.cross(&e1a);
        let s = e1a.dot(&m);
        let s_dot = e1a_dot.dot(&m) + e1a.dot(&m_dot);
        let c = (1.0 - s * s).max(0.0).sqrt();
        let c_dot = -s * s_dot / c;
        let p = m.cross(&e1a);
        let p_dot = m_dot.cross(&e1a) + m.cross(&e1a_dot);
        (p / c, p_dot / c - p * (c_dot / (c * c)))
    };
    row.fill(0.0);
    for (frame, sign) in [(b, 1.0), (a, -1.0)] {
        let mut j = frame;
        while let Some(jj) = j {
            row[jj] += sign * w.dot(&kin.axis[jj]);
            j = model.coords[jj].parent;
        }
    }
    w.dot(&(ang(b, 1) - ang(a, 1))) + (wb - wa).dot(&w_dot)
}

impl Dynamics {
    /// Allocates the workspace for `model` with the given dynamic chain.
    pub fn new(model: &Model, pivots: ActivePivots) -> Self {
        let n = model.dof();
        Self {
            kin: Data::new(model),
            pivots,
            load: DVector::zeros(n),
            ground_force: DVector::zeros(n),
            qddot: DVector::zeros(n),
            lambda: DVector::zeros(model.constraint_rows),
            factor: DMatrix::zeros(n, n),
            row_scale: constraint_row_scale(model),
            seated: Vec::new(),
            seat_reactions: DVector::zeros(0),
            extra_force: DVector::zeros(n),
            min_norm_multipliers: true,
            solver: ForwardSolver::Auto,
            closed_chain_solve: ClosedChainSolve::SelectedRows,
            selections: Vec::new(),
            next_evicted: 0,
            rows_work: SelectedRowsWork::default(),
            used_selected: false,
            articulated: ArticulatedBody::new(model),
            g_eff: Vector3::zeros(),
            mass_current: false,
            used_articulated: false,
            used_single_coordinate: false,
            kernel: None,
            previous_kernel: None,
            locked: vec![false; n],
            free: (0..n).collect(),
            residual: DVector::zeros(n),
            z: DVector::zeros(n),
        }
    }

    /// Evaluates kinematics, M(q), h(q, q̇), Q(q, t) and the ground force at (t, q, q̇), without
    /// solving for q̈.
    pub fn evaluate(
        &mut self,
        model: &Model,
        ground: &GroundMotion,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
    ) {
        forward_kinematics(model, &mut self.kin, q, &self.pivots);
        mass_matrix(model, &mut self.kin);
        self.mass_current = true;
        velocities(model, &mut self.kin, qdot);
        velocity_product(model, &mut self.kin);
        // One look-up of a_g(t) (a record's is a binary search) for both loads.
        let a = ground.acceleration(t);
        let g_eff = gravity_with_ground(model, &a);
        self.g_eff = g_eff;
        generalized_gravity(model, &mut self.kin, &g_eff, &mut self.load);
        generalized_gravity(model, &mut self.kin, &(-a), &mut self.ground_force);
        if model.constraint_rows > 0 {
            constraint_jacobian(model, &mut self.kin, &self.pivots);
            constraint_bias(model, &mut self.kin, &self.pivots);
        }
    }

    /// Collects the free coordinates (those not seated) and factorises their block of M,
    /// M_ff = L Lᵀ (after [`Self::evaluate`]).
    fn factorise(&mut self, model: &Model) -> Result<(), DynamicsError> {
        let n = model.dof();
        self.locked.clear();
        self.locked.resize(n, false);
        // On closed chains seated coordinates stay constraint rows when the multipliers are
        // wanted: with the loops their reactions are statically indeterminate, and the
        // minimum-norm set over all rows together is the one the contact forces report. q̈ is the
        // same either way.
        if model.constraint_rows == 0 || !self.min_norm_multipliers {
            for &s in &self.seated {
                if s < n {
                    self.locked[s] = true;
                }
            }
        }
        self.free.clear();
        self.free.extend((0..n).filter(|&k| !self.locked[k]));
        let nf = self.free.len();
        if self.factor.nrows() != nf {
            self.factor = DMatrix::zeros(nf, nf);
        }
        for (i, &fi) in self.free.iter().enumerate() {
            for (j, &fj) in self.free.iter().enumerate().take(i + 1) {
                self.factor[(i, j)] = self.kin.mass_matrix[(fi, fj)];
            }
        }
        cholesky_in_place(&mut self.factor).map_err(|k| DynamicsError::SingularMassMatrix {
            coordinate: model.coords[self.free[k]].name.clone(),
        })
    }

    /// Computes q̈ (and λ for closed chains) at (t, q, q̇). Open chains with no seated closure
    /// angle do not allocate.
    pub fn accelerations(
        &mut self,
        model: &Model,
        ground: &GroundMotion,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
    ) -> Result<(), DynamicsError> {
        self.accelerations_with(model, ground, t, q, qdot, None)
    }

    /// [`Self::accelerations`] with an extra generalized force.
    ///
    /// On open chains seated coordinates are held by eliminating them: q̈ₖ = 0 and the free
    /// coordinates solve M_ff q̈_f = (Q − h)_f, the reaction of a seated coordinate being the
    /// residual of its own row, M_k· q̈ + h_k − Q_k. This is Gauss' principle with the rows
    /// eₖᵀq̈ = 0 solved exactly instead of by a rank-revealing decomposition. On closed chains
    /// they stay rows of B (their reactions and the loops' are indeterminate together; the
    /// minimum-norm set over all rows is the reported one).
    pub fn accelerations_with(
        &mut self,
        model: &Model,
        ground: &GroundMotion,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        extra: Option<&mut dyn GeneralizedForce>,
    ) -> Result<(), DynamicsError> {
        if self.articulated_applies(model) {
            return self.accelerations_articulated(model, ground, t, q, qdot, extra);
        }
        self.evaluate(model, ground, t, q, qdot);
        self.solve_evaluated(model, t, q, qdot, extra)
    }

    /// What the integrator's right-hand side reads, q̈, Q, Q_g and the extra force, at
    /// (t, q, q̇): [`Self::accelerations_with`], except on a structure of one coordinate with
    /// nothing seated, no extra force and [`ForwardSolver::Auto`], where the
    /// [`single_coordinate::Kernel`] of the active pivot gives them from sin θ and cos θ alone.
    /// `kin` (frames, V, M) is then left as it was: code that reads the kinematics of the state
    /// calls [`Self::accelerations_with`].
    pub fn integration_accelerations(
        &mut self,
        model: &Model,
        ground: &GroundMotion,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        extra: Option<&mut dyn GeneralizedForce>,
    ) -> Result<(), DynamicsError> {
        if extra.is_none()
            && q.len() == 1
            && let Some(rates) = self.single_coordinate_rates(model, ground, t, q[0])
        {
            return rates.map(|_| ());
        }
        self.accelerations_with(model, ground, t, q, qdot, extra)
    }

    /// [`Self::integration_accelerations`]' one-coordinate kernel alone, at (t, θ) with no extra
    /// force: returns (θ̈, Q_g) and sets q̈, Q, Q_g and the extra force (0) as it does; None when
    /// the kernel does not apply (more coordinates, something seated, another solver, a massless
    /// coordinate). The integrator's right-hand side of a single block calls it directly.
    pub fn single_coordinate_rates(
        &mut self,
        model: &Model,
        ground: &GroundMotion,
        t: f64,
        theta: f64,
    ) -> Option<Result<(f64, f64), DynamicsError>> {
        self.single_coordinate_kernel(model)?;
        let a = ground.acceleration(t);
        let g_eff = gravity_with_ground(model, &a);
        self.g_eff = g_eff;
        let kernel = self.kernel.as_ref()?;
        let (sin, cos) = theta.sin_cos();
        let load = kernel.load(&g_eff, sin, cos);
        let ground_force = kernel.load(&(-a), sin, cos);
        let qddot = load / kernel.inertia();
        self.load[0] = load;
        self.ground_force[0] = ground_force;
        self.extra_force[0] = 0.0;
        self.qddot[0] = qddot;
        self.mass_current = false;
        self.mark_single_coordinate();
        Some(if qddot.is_finite() {
            Ok((qddot, ground_force))
        } else {
            Err(DynamicsError::NonFinite {
                what: "acceleration",
                t,
            })
        })
    }

    /// [`Self::accelerations`] of a structure of one coordinate ([`ForwardSolver::Auto`], no
    /// closures), from the forward kinematics of the state (left in `kin`, as the general solve
    /// leaves it): Q_f = f · (w × Σₙ mₙ(cₙ − p)) for f = g_eff and −a_g, and
    ///
    /// * free: θ̈ = Q/I_p with the kernel's I_p (no sin/cos beyond the kinematics', which code
    ///   that needs the kinematics of the state anyway, the monitor of the output samples, saves);
    /// * seated: θ̈ = 0 (held), and the seat's reaction is the residual of the one row,
    ///   M θ̈ + h − Q = −Q (h = 0: I_p does not depend on θ), as the general solve reports it.
    ///
    /// None when neither applies. The velocities in `kin` are not set; M is not formed.
    pub fn single_coordinate_accelerations(
        &mut self,
        model: &Model,
        ground: &GroundMotion,
        t: f64,
        q: &DVector<f64>,
    ) -> Option<Result<(), DynamicsError>> {
        let held = self.solver == ForwardSolver::Auto
            && single_coordinate::applies(model)
            && self.seated == [0];
        let inertia = if held {
            None
        } else {
            Some(self.single_coordinate_kernel(model)?.inertia())
        };
        forward_kinematics(model, &mut self.kin, q, &self.pivots);
        let a = ground.acceleration(t);
        let g_eff = gravity_with_ground(model, &a);
        self.g_eff = g_eff;
        let (w, p) = (self.kin.axis[0], self.kin.pivot[0]);
        let mut moment = Vector3::zeros();
        for (c, body) in self.kin.com.iter().zip(&model.bodies) {
            moment += (c - p) * body.mass;
        }
        let arm = w.cross(&moment);
        self.load[0] = g_eff.dot(&arm);
        self.ground_force[0] = -a.dot(&arm);
        self.extra_force[0] = 0.0;
        self.mass_current = false;
        match inertia {
            Some(inertia) => {
                self.qddot[0] = self.load[0] / inertia;
                self.mark_single_coordinate();
            }
            None => {
                self.qddot[0] = 0.0;
                (self.used_articulated, self.used_single_coordinate) = (false, false);
                if self.seat_reactions.len() != 1 {
                    self.seat_reactions = DVector::zeros(1);
                }
                self.seat_reactions[0] = -self.load[0];
            }
        }
        Some(self.check_finite(t))
    }

    /// g_eff = g + (−a_g) of the last solve (m/s², world axes): the field whose generalized
    /// force is the load Q.
    pub fn effective_gravity(&self) -> Vector3<f64> {
        self.g_eff
    }

    /// The [`single_coordinate::Kernel`] of the active pivot, when [`Self::single_coordinate_rates`]
    /// applies; its I_p is what a reader of the kinematics of a one-coordinate state needs to
    /// solve for θ̈ without the sin/cos. Built on the first call after a switch to a new pivot;
    /// the kernel of the pivot before is kept, so that a block rocking between its two edges
    /// builds two in all.
    #[inline(always)]
    pub fn single_coordinate_kernel(
        &mut self,
        model: &Model,
    ) -> Option<&single_coordinate::Kernel> {
        if !self.single_coordinate_applies(model) {
            return None;
        }
        let is_current = |k: &Option<single_coordinate::Kernel>, pivots: &ActivePivots| {
            k.as_ref().is_some_and(|k| k.is_for(model, pivots))
        };
        if !is_current(&self.kernel, &self.pivots) {
            std::mem::swap(&mut self.kernel, &mut self.previous_kernel);
            if !is_current(&self.kernel, &self.pivots) {
                self.kernel = single_coordinate::Kernel::new(model, &self.pivots);
            }
        }
        self.kernel.as_ref()
    }

    /// Whether a solve takes the one-coordinate closed form ([`crate::single_coordinate`]):
    /// DOF(1) = 1, no closures, nothing seated, [`ForwardSolver::Auto`].
    fn single_coordinate_applies(&self, model: &Model) -> bool {
        self.solver == ForwardSolver::Auto
            && self.seated.is_empty()
            && single_coordinate::applies(model)
    }

    /// Records a solve by the one-coordinate closed form: nothing is seated, so no seat
    /// reactions (not those of an earlier seated solve) and no joint force.
    fn mark_single_coordinate(&mut self) {
        self.used_articulated = false;
        self.used_single_coordinate = true;
        if !self.seat_reactions.is_empty() {
            self.seat_reactions = DVector::zeros(0);
        }
    }

    /// Makes `kin.mass_matrix` hold M(q) of the last evaluation: the articulated-body path does
    /// not form M, so readers of M after [`Self::accelerations`] call this first (O(DOF(1) ×
    /// depth), nothing done when M is already current). Not after
    /// [`Self::integration_accelerations`] on its one-coordinate kernel, which leaves the
    /// kinematics of an earlier state in `kin`.
    pub fn ensure_mass_matrix(&mut self, model: &Model) {
        if !self.mass_current {
            mass_matrix(model, &mut self.kin);
            self.mass_current = true;
        }
    }

    /// True when the last [`Self::accelerations_with`] used the articulated-body algorithm.
    pub fn used_articulated_body(&self) -> bool {
        self.used_articulated
    }

    /// True when the last [`Self::accelerations_with`] used the one-coordinate closed form
    /// I_p θ̈ = Q + τ ([`crate::single_coordinate`]).
    pub fn used_single_coordinate(&self) -> bool {
        self.used_single_coordinate
    }

    /// The spatial force fₖ = Iᴬₖaₖ + pᴬₖ = [n₀; f] (N m about the world origin; N) that the
    /// parent side transmits across coordinate k's joint to the bodies beyond it, gravity and
    /// inertia included, from the last solve when it was the articulated-body algorithm (None
    /// after a solve on M). Its component along the joint's spatial axis is sₖᵀfₖ = τₖ + rₖ (rₖ = 0
    /// for a free coordinate); along any other axis through any other point it is the moment the
    /// joint would have to carry about that axis with the same motion, e.g. the reaction of a
    /// seated joint about the pivot on its other side. None also after the one-coordinate closed
    /// form ([`Self::used_single_coordinate`]), taken only when nothing is seated.
    pub fn joint_force(&self, k: usize) -> Option<Vector6<f64>> {
        self.used_articulated.then(|| {
            self.articulated.inertia[k] * self.articulated.acceleration[k]
                + self.articulated.bias_force[k]
        })
    }

    /// Whether [`Self::accelerations_with`] (and [`Self::solve_evaluated`]) take the
    /// articulated-body path with the current solver choice and seated slots, which needs no
    /// [`Self::evaluate`] (M is not used).
    pub fn articulated_body_applies(&self, model: &Model) -> bool {
        self.articulated_applies(model)
    }

    /// True when the last closed-chain solve of [`Self::solve_evaluated`] used the cached
    /// selection of independent rows ([`ClosedChainSolve::SelectedRows`]) rather than the SVD.
    pub fn used_selected_rows(&self) -> bool {
        self.used_selected
    }

    /// Whether [`Self::accelerations_with`] takes the articulated-body path at this state.
    fn articulated_applies(&self, model: &Model) -> bool {
        let n = model.dof();
        let threshold = match self.solver {
            ForwardSolver::Auto => ARTICULATED_BODY_MIN_DOF,
            ForwardSolver::Cholesky => return false,
            ForwardSolver::ArticulatedBody => 0,
        };
        n >= threshold && model.constraint_rows == 0 && self.seated.iter().all(|&s| s < n)
    }

    /// The articulated-body path of [`Self::accelerations_with`]: kinematics, Q, Q_g and (only
    /// when an extra force needs them, see [`GeneralizedForce::add`]) M and h; then q̈ and the
    /// seat reactions in O(DOF(1)).
    fn accelerations_articulated(
        &mut self,
        model: &Model,
        ground: &GroundMotion,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        extra: Option<&mut dyn GeneralizedForce>,
    ) -> Result<(), DynamicsError> {
        if extra.is_some() {
            // The extra force is promised the full evaluation (M, V, A, h …) of this state.
            self.evaluate(model, ground, t, q, qdot);
        } else {
            forward_kinematics(model, &mut self.kin, q, &self.pivots);
            self.mass_current = false;
            let a = ground.acceleration(t);
            self.g_eff = gravity_with_ground(model, &a);
            generalized_gravity(model, &mut self.kin, &self.g_eff, &mut self.load);
            // Q_g from the same subtree sums: Q_gₖ = (−a_g) · (wₖ × (Sₖ − mₖpₖ)).
            for k in 0..model.dof() {
                let kin = &self.kin;
                let lever = kin.subtree_moment[k] - kin.pivot[k] * kin.subtree_mass[k];
                self.ground_force[k] = -a.dot(&kin.axis[k].cross(&lever));
            }
        }
        self.solve_articulated(model, t, q, qdot, extra)
    }

    /// q̈ and the seat reactions by the articulated-body algorithm on the kinematics, Q and
    /// g_eff of this state (V and A are filled by its first pass).
    fn solve_articulated(
        &mut self,
        model: &Model,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        extra: Option<&mut dyn GeneralizedForce>,
    ) -> Result<(), DynamicsError> {
        self.add_extra_force(model, t, q, qdot, extra);
        if self.single_coordinate_applies(model) {
            // One coordinate about a fixed line: I_p θ̈ = Q + τ, no 6 × 6 algebra.
            self.mark_single_coordinate();
            let force = self.load[0] + self.extra_force[0];
            self.qddot[0] = single_coordinate::solve(model, &mut self.kin, qdot[0], force)
                .ok_or_else(|| DynamicsError::SingularMassMatrix {
                    coordinate: model.coords[0].name.clone(),
                })?;
            return self.check_finite(t);
        }
        self.used_articulated = true;
        self.used_single_coordinate = false;
        if self.seat_reactions.len() != self.seated.len() {
            self.seat_reactions = DVector::zeros(self.seated.len());
        }
        self.articulated
            .solve(
                model,
                &mut self.kin,
                qdot,
                &self.g_eff,
                &self.extra_force,
                &self.seated,
                &mut self.qddot,
                self.seat_reactions.as_mut_slice(),
            )
            .map_err(|k| DynamicsError::SingularMassMatrix {
                coordinate: model.coords[k].name.clone(),
            })?;
        self.check_finite(t)
    }

    /// The solve of [`Self::accelerations_with`] on the state last given to [`Self::evaluate`]:
    /// q̈, λ and the seat reactions for the current seated slots. The kinematics, M, h and Q do
    /// not depend on which slots are seated, so that trying several seated sets at one state
    /// (the uplift test) evaluates them once.
    pub fn solve_evaluated(
        &mut self,
        model: &Model,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        extra: Option<&mut dyn GeneralizedForce>,
    ) -> Result<(), DynamicsError> {
        if self.articulated_applies(model) {
            return self.solve_articulated(model, t, q, qdot, extra);
        }
        self.used_articulated = false;
        self.used_single_coordinate = false;
        self.used_selected = false;
        self.factorise(model)?;
        self.add_extra_force(model, t, q, qdot, extra);
        let n = model.dof();
        let nf = self.free.len();
        // r = Q + F_extra − h: the generalized force left for inertia and constraints.
        self.residual.copy_from(&self.load);
        self.residual += &self.extra_force;
        self.residual -= &self.kin.velocity_product;
        // Gauss' principle in the coordinates z = Lᵀq̈_f (M_ff = L Lᵀ): z is the point of the
        // affine set B z = −c nearest to z_free = L⁻¹ r_f, with B = Φ'_f L⁻ᵀ the row-scaled closures
        // and the seated rows not eliminated, over the free columns. Decomposing B (rows × free) rather
        // than B Bᵀ keeps the conditioning unsquared and the matrix small when many rows are
        // redundant.
        self.z.resize_vertically_mut(nf, 0.0);
        for (i, &k) in self.free.iter().enumerate() {
            self.z[i] = self.residual[k];
        }
        forward_substitute(&self.factor, self.z.as_mut_slice());
        let seated_rows = self.seated.iter().filter(|&&s| self.is_row(s)).count();
        let rows = model.constraint_rows + seated_rows;
        if rows == 0 {
            back_substitute_transposed(&self.factor, self.z.as_mut_slice());
            self.scatter_accelerations();
            self.lambda.fill(0.0);
            self.seat_reactions
                .resize_vertically_mut(self.seated.len(), 0.0);
            self.tree_reactions(None);
            return self.check_finite(t);
        }
        // Bᵀ = L⁻¹ (row-scaled Φ_q, seated rows)ᵀ over the free columns, column by column.
        let mut bt = DMatrix::zeros(nf, rows);
        for i in 0..model.constraint_rows {
            for (j, &k) in self.free.iter().enumerate() {
                bt[(j, i)] = self.row_scale[i] * self.kin.phi_q[(i, k)];
            }
        }
        let mut bias = DVector::zeros(rows);
        bias.rows_mut(0, model.constraint_rows)
            .copy_from(&self.kin.phi_bias.component_mul(&self.row_scale));
        let mut seated_row_matrix = DMatrix::zeros(n, seated_rows);
        let mut row = DVector::zeros(n);
        let row_slots = self.seated.iter().copied().filter(|&s| self.is_row(s));
        for (k, slot) in row_slots.enumerate() {
            bias[model.constraint_rows + k] = slot_row(model, &self.kin, slot, &mut row);
            seated_row_matrix.column_mut(k).copy_from(&row);
            for (j, &c) in self.free.iter().enumerate() {
                bt[(j, model.constraint_rows + k)] = row[c];
            }
        }
        for mut col in bt.column_iter_mut() {
            forward_substitute(&self.factor, col.as_mut_slice());
        }
        // With seated coordinates eliminated, B's own σ_max can be round-off (a loop whose free
        // coordinates do not enter its closure here): the rank threshold is then taken against the
        // whole row-scaled Jacobian with every column, Jacobi-scaled by M's diagonal
        // (‖Φ'_j‖/√M_jj, the size of B's column j), so that noise is never inverted.
        let mut floor = 0.0;
        if nf < n {
            let mut whole = 0.0;
            for j in 0..n {
                let mut col = 0.0;
                for i in 0..model.constraint_rows {
                    col += (self.row_scale[i] * self.kin.phi_q[(i, j)]).powi(2);
                }
                for k in 0..seated_rows {
                    col += seated_row_matrix[(j, k)].powi(2);
                }
                whole += col / self.kin.mass_matrix[(j, j)];
            }
            floor = RANK_TOLERANCE.sqrt() * whole.sqrt();
        }
        let residual = bt.tr_mul(&self.z) + &bias;
        let cached = self
            .selections
            .iter()
            .position(|sel| sel.rows == rows && sel.free == nf && sel.seated == self.seated);
        let mut dz = DVector::zeros(nf);
        let mut lambda_scaled = DVector::zeros(rows);
        let fast = match (cached, self.closed_chain_solve) {
            (Some(c), ClosedChainSolve::SelectedRows) => solve_selected_rows(
                &mut self.rows_work,
                &bt,
                &residual,
                &self.selections[c].selected,
                floor,
                self.min_norm_multipliers,
                &mut dz,
                &mut lambda_scaled,
            ),
            _ => false,
        };
        self.used_selected = fast;
        if !fast {
            let svd = JacobiSvd::thin(&bt.transpose());
            // The threshold of the former solve on B Bᵀ (σ(BBᵀ) = σ(B)²): same rank decisions.
            let tol = svd.tolerance_relative(RANK_TOLERANCE.sqrt()).max(floor);
            dz = -svd.solve_with(&residual, tol);
            // z − z_free = Bᵀ λ': the minimum-norm multipliers.
            lambda_scaled = svd.solve_transposed_with(&dz, tol);
            if self.closed_chain_solve == ClosedChainSolve::SelectedRows {
                let rank = svd.singular_values.iter().filter(|s| **s > tol).count();
                let selection = RowSelection {
                    rows,
                    free: nf,
                    seated: self.seated.clone(),
                    selected: pivot_columns(&bt, rank),
                };
                match cached {
                    Some(c) => self.selections[c] = selection,
                    None if self.selections.len() < SELECTION_CACHE => {
                        self.selections.push(selection);
                    }
                    None => {
                        self.selections[self.next_evicted] = selection;
                        self.next_evicted = (self.next_evicted + 1) % SELECTION_CACHE;
                    }
                }
            }
        }
        self.z += &dz;
        back_substitute_transposed(&self.factor, self.z.as_mut_slice());
        self.scatter_accelerations();
        self.lambda = lambda_scaled
            .rows(0, model.constraint_rows)
            .component_mul(&self.row_scale);
        let row_reactions = lambda_scaled.rows(model.constraint_rows, seated_rows);
        // Seat reactions in the order of `seated`: tree coordinates from their rows' residuals
        // (below), closure angles from the decomposition.
        self.seat_reactions
            .resize_vertically_mut(self.seated.len(), 0.0);
        let mut a = 0;
        for (i, &s) in self.seated.iter().enumerate() {
            if self.is_row(s) {
                self.seat_reactions[i] = row_reactions[a];
                a += 1;
            }
        }
        let row_force = &seated_row_matrix * row_reactions;
        self.tree_reactions(Some(&row_force));
        self.check_finite(t)
    }

    /// Sets `extra_force` to the extra generalized force at this state (0 without one).
    fn add_extra_force(
        &mut self,
        model: &Model,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        extra: Option<&mut dyn GeneralizedForce>,
    ) {
        self.extra_force.fill(0.0);
        if let Some(f) = extra {
            f.add(model, &self.kin, t, q, qdot, &mut self.extra_force);
        }
    }

    /// True if seated slot `s` is held by a constraint row (a closure angle, or any slot of a
    /// closed chain), false if eliminated (a tree coordinate of an open chain).
    fn is_row(&self, s: usize) -> bool {
        s >= self.locked.len() || !self.locked[s]
    }

    /// Writes q̈ from the free accelerations in `z` (seated tree coordinates: 0).
    fn scatter_accelerations(&mut self) {
        self.qddot.fill(0.0);
        for (i, &k) in self.free.iter().enumerate() {
            self.qddot[k] = self.z[i];
        }
    }

    /// Reactions of the eliminated seated coordinates: the residual of their rows of the
    /// equations of motion, M_k· q̈ − r_k − (Φ_qᵀλ)_k − (seated rows' force)_k, written at their
    /// places in `seat_reactions` (sized to `seated`). q̈ vanishes on the seated coordinates, so
    /// M_k· q̈ sums over the free ones only.
    fn tree_reactions(&mut self, row_force: Option<&DVector<f64>>) {
        for (i, &s) in self.seated.iter().enumerate() {
            if self.is_row(s) {
                continue;
            }
            let inertial: f64 = self
                .free
                .iter()
                .map(|&j| self.kin.mass_matrix[(s, j)] * self.qddot[j])
                .sum();
            let mut reaction = inertial - self.residual[s];
            for r in 0..self.lambda.len() {
                reaction -= self.kin.phi_q[(r, s)] * self.lambda[r];
            }
            if let Some(f) = row_force {
                reaction -= f[s];
            }
            self.seat_reactions[i] = reaction;
        }
    }

    fn check_finite(&self, t: f64) -> Result<(), DynamicsError> {
        if self.qddot.iter().any(|x| !x.is_finite()) {
            return Err(DynamicsError::NonFinite {
                what: "acceleration",
                t,
            });
        }
        Ok(())
    }

    /// Row-scaled Φ_q (after [`Self::evaluate`] or a kinematics call filling `kin.phi_q`).
    pub fn scaled_jacobian(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.kin.phi_q.nrows(), self.kin.phi_q.ncols(), |i, j| {
            self.row_scale[i] * self.kin.phi_q[(i, j)]
        })
    }

    /// The row weights used for Φ.
    pub fn row_scale(&self) -> &DVector<f64> {
        &self.row_scale
    }
}
