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
    JacobiSvd, RANK_TOLERANCE, cholesky_in_place, cholesky_solve, pivot_columns,
    pivot_columns_above,
};
use crate::single_coordinate;
use crate::sparse_cholesky::SparseCholesky;

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
    /// Cholesky factor L of M_ff, the block of M over the free (not seated) coordinates, on
    /// its tree pattern (no fill in the order of `free`).
    factor: SparseCholesky,
    /// The free coordinates `factor`'s pattern was analysed for.
    factor_free: Vec<usize>,
    row_scale: DVector<f64>,
    /// Seated tree coordinates (q̈ₖ = 0), by coordinate.
    locked: Vec<bool>,
    /// The coordinates not seated, descendants before ancestors (decreasing index: a parent's
    /// index is below its children's): the columns of `factor`, in the order that gives a
    /// tree's mass matrix no fill (Featherstone's L^T L order).
    free: Vec<usize>,
    /// Position of each coordinate in `free` (`usize::MAX` when seated).
    free_position: Vec<usize>,
    /// The constraint rows over every coordinate on their patterns (row-scaled Φ_q, seated
    /// rows) at the last closed-chain solve.
    rows_full: SparseRows,
    /// B = those rows over the free columns times L⁻ᵀ, on the same patterns.
    rows_b: SparseRows,
    /// Scratch of the closed-chain solve: a row spread over the free coordinates (zero between
    /// uses), a row's free pattern, an interface's frame paths, a dense rate row.
    spread: Vec<f64>,
    pattern: Vec<usize>,
    /// Each closure's interface and its rows' pattern, its frames' paths to the ground (found
    /// once per model).
    closure_paths: Vec<(usize, Vec<usize>)>,
    path: Vec<usize>,
    dense_row: DVector<f64>,
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
    /// Independent constraint rows kept for the integration's velocity projections.
    pub velocity_projection: crate::closed_chain::VelocityProjection,
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

mod articulated_path;
mod closed_chain_path;
mod selected_rows;
mod single_coordinate_path;
mod slot_rows;

pub use selected_rows::DEPENDENT_ROW_TOLERANCE;
use selected_rows::{RowSelection, SELECTION_CACHE};
pub(crate) use selected_rows::{SelectedRowsWork, SparseRows, solve_selected_rows};
pub use slot_rows::slot_row;

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
            factor: SparseCholesky::default(),
            factor_free: Vec::new(),
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
            velocity_projection: Default::default(),
            kernel: None,
            previous_kernel: None,
            locked: vec![false; n],
            free: (0..n).rev().collect(),
            free_position: Vec::new(),
            rows_full: SparseRows::default(),
            rows_b: SparseRows::default(),
            spread: Vec::new(),
            pattern: Vec::new(),
            closure_paths: Vec::new(),
            path: Vec::new(),
            dense_row: DVector::zeros(n),
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
        self.free.extend((0..n).rev().filter(|&k| !self.locked[k]));
        if self.factor_free != self.free || self.free_position.len() != n {
            self.analyse_mass_pattern(model);
        }
        let (free, mass) = (&self.free, &self.kin.mass_matrix);
        self.factor
            .factor(|i, j| mass[(free[i], free[j])])
            .map_err(|k| DynamicsError::SingularMassMatrix {
                coordinate: model.coords[self.free[k]].name.clone(),
            })
    }

    /// The pattern of M_ff for `factor`: M_ij ≠ 0 only when one of coordinates i, j carries the
    /// other (composite rigid bodies write nothing else), so row i's entries left of the
    /// diagonal, in the order of `free`, are the free descendants of coordinate i.
    fn analyse_mass_pattern(&mut self, model: &Model) {
        let n = model.dof();
        let mut position = vec![usize::MAX; n];
        for (i, &k) in self.free.iter().enumerate() {
            position[k] = i;
        }
        let mut descendants: Vec<Vec<usize>> = vec![Vec::new(); self.free.len()];
        for (i, &k) in self.free.iter().enumerate() {
            let mut up = model.coords[k].parent;
            while let Some(a) = up {
                if position[a] != usize::MAX {
                    descendants[position[a]].push(i);
                }
                up = model.coords[a].parent;
            }
        }
        self.factor.analyse(self.free.len(), |i, out| {
            out.extend_from_slice(&descendants[i])
        });
        self.factor_free.clone_from(&self.free);
        self.free_position = position;
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

    /// g_eff = g + (−a_g) of the last solve (m/s², world axes): the field whose generalized
    /// force is the load Q.
    pub fn effective_gravity(&self) -> Vector3<f64> {
        self.g_eff
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

    /// True when the last closed-chain solve of [`Self::solve_evaluated`] used the cached
    /// selection of independent rows ([`ClosedChainSolve::SelectedRows`]) rather than the SVD.
    pub fn used_selected_rows(&self) -> bool {
        self.used_selected
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

    /// How far the last solve leaves the loops open at acceleration level: the largest closure
    /// row of Φ_q q̈ + Φ̇_q q̇ (a corner row's m/s², an orientation row's 1/s² times the model
    /// size, so m/s² too), from the kinematics' rows of the state solved. Round-off where the
    /// closure rows are independent or exactly dependent; near a hyperstatic seat, rows
    /// dependent to less than the rank rule are taken as dependent and left open by this much.
    /// 0 without loops.
    pub fn loop_residual(&self, model: &Model) -> f64 {
        let mut worst: f64 = 0.0;
        for closure in &model.closures {
            for r in 0..closure.rows {
                let i = closure.first_row + r;
                let rate = self
                    .kin
                    .phi_q
                    .row(i)
                    .iter()
                    .zip(self.qddot.iter())
                    .map(|(a, b)| a * b)
                    .sum::<f64>()
                    + self.kin.phi_bias[i];
                let rate = if r < 3 { rate } else { rate * model.size };
                worst = worst.max(rate.abs());
            }
        }
        worst
    }
}
