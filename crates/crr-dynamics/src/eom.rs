//! Equations of motion of the multi-DOF chain:
//! M(q) q̈ + h(q, q̇) = Q(q, t) + Φ_qᵀ λ,  Φ_q q̈ + Φ̇_q q̇ = 0,
//! with the ground motion as the effective gravity g_eff(t) = (−a_x, −a_y, −g − a_z) on every body
//! (the equations are written in the frame of the ground): Q = Σₙ Mⁿ J_cₙᵀ g_eff.
//!
//! Closed chains are solved with explicit multipliers by Gauss' principle: with M = L Lᵀ and
//! z = Lᵀq̈, z is the point of B z = −Φ̇_q q̇ (B = Φ_q L⁻ᵀ) nearest to z_free = L⁻¹(Q − h), and
//! Φ_qᵀλ = L(z − z_free). Redundant closures (a colonnade under a rigid slab) make B rank-deficient:
//! its pseudo-inverse (one-sided Jacobi SVD, singular values below √[`RANK_TOLERANCE`]·σ_max
//! dropped) gives the minimum-norm λ, and q̈ is unique.
//!
//! Open chains whose seated slots are all tree coordinates (no closure rows) are solved (from
//! [`ARTICULATED_BODY_MIN_DOF`] coordinates on) by the articulated-body algorithm
//! ([`crate::articulated_body`]) in O(DOF(1)) without forming M; M and its factor are then
//! computed only on request ([`Dynamics::ensure_mass_matrix`], [`Dynamics::ensure_factor`]).

use nalgebra::{DMatrix, DVector, Vector3};

use crr_kinematics::{
    ActivePivots, Data, Model, constraint_bias, constraint_jacobian, forward_kinematics,
    generalized_gravity, mass_matrix, velocities, velocity_product,
};

use crate::articulated_body::ArticulatedBody;
use crate::ground_motion::GroundMotion;
use crate::linalg::{
    JacobiSvd, RANK_TOLERANCE, back_substitute_transposed, cholesky_in_place, cholesky_solve,
    forward_substitute,
};

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
    /// The algorithm [`Self::accelerations_with`] uses ([`ForwardSolver::Auto`] by default).
    pub solver: ForwardSolver,
    factor: DMatrix<f64>,
    row_scale: DVector<f64>,
    articulated: ArticulatedBody,
    /// `kin.mass_matrix` holds M of the current kinematics.
    mass_current: bool,
    /// `factor` holds the Cholesky factor of the current M.
    factor_current: bool,
    /// The last [`Self::accelerations_with`] used the articulated-body algorithm.
    used_articulated: bool,
}

/// Open chains with at least this many coordinates (DOF(1)) are solved by the articulated-body
/// algorithm under [`ForwardSolver::Auto`], below it by M (composite rigid bodies) and Cholesky.
/// On the serial chains of `benches/dynamics.rs` (`forward_dynamics_aba` against
/// `forward_dynamics_cholesky`, N = 1 … 128) the articulated-body path is never the slower one,
/// 0.21 µs against 0.25 µs already at N = 1 (it skips h and the second pass of Q), so the
/// crossover is 1: every eligible chain uses it. See ARCHITECTURE.md, "Equations of motion".
pub const ARTICULATED_BODY_MIN_DOF: usize = 1;

/// The forward-dynamics algorithm of [`Dynamics::accelerations_with`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ForwardSolver {
    /// The articulated-body algorithm when it applies (no closure rows, every seated slot a tree
    /// coordinate) and DOF(1) ≥ [`ARTICULATED_BODY_MIN_DOF`]; otherwise [`Self::Cholesky`].
    #[default]
    Auto,
    /// Always M by composite rigid bodies, Cholesky, and Gauss' principle for the constraint rows.
    Cholesky,
    /// The articulated-body algorithm whenever it applies (open chains with seated tree
    /// coordinates only), whatever DOF(1); otherwise [`Self::Cholesky`].
    ArticulatedBody,
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
    let rot = |k: Option<usize>| k.map_or_else(nalgebra::Matrix3::identity, |k| kin.rot_ops[k]);
    let ang = |k: Option<usize>, part: usize| -> Vector3<f64> {
        k.map_or_else(Vector3::zeros, |k| {
            let v = if part == 0 {
                &kin.spatial_velocity[k]
            } else {
                &kin.bias_acceleration[k]
            };
            Vector3::new(v[0], v[1], v[2])
        })
    };
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
            solver: ForwardSolver::Auto,
            articulated: ArticulatedBody::new(model),
            mass_current: false,
            factor_current: false,
            used_articulated: false,
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
        self.factor_current = false;
        velocities(model, &mut self.kin, qdot);
        velocity_product(model, &mut self.kin);
        let a = ground.acceleration(t);
        generalized_gravity(
            model,
            &mut self.kin,
            &effective_gravity(model, ground, t),
            &mut self.load,
        );
        generalized_gravity(model, &mut self.kin, &(-a), &mut self.ground_force);
        if model.constraint_rows > 0 {
            constraint_jacobian(model, &mut self.kin, &self.pivots);
            constraint_bias(model, &mut self.kin, &self.pivots);
        }
    }

    /// Factorises M (after [`Self::evaluate`]).
    fn factorise(&mut self, model: &Model) -> Result<(), DynamicsError> {
        self.factor.copy_from(&self.kin.mass_matrix);
        let result =
            cholesky_in_place(&mut self.factor).map_err(|k| DynamicsError::SingularMassMatrix {
                coordinate: model.coords[k].name.clone(),
            });
        self.factor_current = result.is_ok();
        result
    }

    /// Makes `kin.mass_matrix` hold M(q) of the last evaluation: the articulated-body path does
    /// not form M, so readers of M after [`Self::accelerations`] call this first (O(DOF(1) ×
    /// depth), nothing done when M is already current).
    pub fn ensure_mass_matrix(&mut self, model: &Model) {
        if !self.mass_current {
            mass_matrix(model, &mut self.kin);
            self.mass_current = true;
        }
    }

    /// Makes the Cholesky factor used by [`Self::solve_mass`] that of the current M.
    pub fn ensure_factor(&mut self, model: &Model) -> Result<(), DynamicsError> {
        self.ensure_mass_matrix(model);
        if self.factor_current {
            Ok(())
        } else {
            self.factorise(model)
        }
    }

    /// True when the last [`Self::accelerations_with`] used the articulated-body algorithm.
    pub fn used_articulated_body(&self) -> bool {
        self.used_articulated
    }

    /// Solves M x = b with the current factor (after [`Self::accelerations`] on the Cholesky path,
    /// or [`Self::ensure_factor`]).
    ///
    /// # Panics
    /// If the factor is not that of the current M.
    pub fn solve_mass(&self, b: &mut DVector<f64>) {
        assert!(
            self.factor_current,
            "Dynamics::solve_mass: call ensure_factor first (the articulated-body path forms no M)"
        );
        cholesky_solve(&self.factor, b.as_mut_slice());
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
        let g_eff = effective_gravity(model, ground, t);
        self.extra_force.fill(0.0);
        if let Some(f) = extra {
            // The extra force is promised the full evaluation (M, V, A, h …) of this state.
            self.evaluate(model, ground, t, q, qdot);
            f.add(model, &self.kin, t, q, qdot, &mut self.extra_force);
        } else {
            forward_kinematics(model, &mut self.kin, q, &self.pivots);
            self.mass_current = false;
            self.factor_current = false;
            generalized_gravity(model, &mut self.kin, &g_eff, &mut self.load);
            // Q_g from the same subtree sums: Q_gₖ = (−a_g) · (wₖ × (Sₖ − mₖpₖ)).
            let a = ground.acceleration(t);
            for k in 0..model.dof() {
                let kin = &self.kin;
                let lever = kin.subtree_moment[k] - kin.pivot[k] * kin.subtree_mass[k];
                self.ground_force[k] = -a.dot(&kin.axis[k].cross(&lever));
            }
        }
        if self.seat_reactions.len() != self.seated.len() {
            self.seat_reactions = DVector::zeros(self.seated.len());
        }
        self.articulated
            .solve(
                model,
                &mut self.kin,
                qdot,
                &g_eff,
                &self.extra_force,
                &self.seated,
                &mut self.qddot,
                self.seat_reactions.as_mut_slice(),
            )
            .map_err(|k| DynamicsError::SingularMassMatrix {
                coordinate: model.coords[k].name.clone(),
            })
    }

    /// Computes q̈ (and λ for closed chains) at (t, q, q̇). Open chains with nothing seated do not
    /// allocate.
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
    pub fn accelerations_with(
        &mut self,
        model: &Model,
        ground: &GroundMotion,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        extra: Option<&mut dyn GeneralizedForce>,
    ) -> Result<(), DynamicsError> {
        self.used_articulated = self.articulated_applies(model);
        if self.used_articulated {
            return self.accelerations_articulated(model, ground, t, q, qdot, extra);
        }
        self.evaluate(model, ground, t, q, qdot);
        self.factorise(model)?;
        self.extra_force.fill(0.0);
        if let Some(f) = extra {
            f.add(model, &self.kin, t, q, qdot, &mut self.extra_force);
        }
        // Gauss' principle in the coordinates z = Lᵀq̈ (M = L Lᵀ): z is the point of the affine set
        // B z = −c nearest to z_free = L⁻¹(Q − h), with B = Φ' L⁻ᵀ the row-scaled closures and
        // seated slot rows. Decomposing B (rows × DOF(1)) rather than B Bᵀ keeps the conditioning
        // unsquared and the matrix small when many rows are redundant.
        self.qddot.copy_from(&self.load);
        self.qddot += &self.extra_force;
        self.qddot -= &self.kin.velocity_product;
        forward_substitute(&self.factor, self.qddot.as_mut_slice());
        let rows = model.constraint_rows + self.seated.len();
        if rows == 0 {
            back_substitute_transposed(&self.factor, self.qddot.as_mut_slice());
            return Ok(());
        }
        let n = model.dof();
        // Bᵀ = L⁻¹ (row-scaled Φ_q, seated rows)ᵀ, filled column by column.
        let mut bt = DMatrix::zeros(n, rows);
        for i in 0..model.constraint_rows {
            for j in 0..n {
                bt[(j, i)] = self.row_scale[i] * self.kin.phi_q[(i, j)];
            }
        }
        let mut bias = DVector::zeros(rows);
        bias.rows_mut(0, model.constraint_rows)
            .copy_from(&self.kin.phi_bias.component_mul(&self.row_scale));
        let mut row = DVector::zeros(n);
        for (k, &slot) in self.seated.iter().enumerate() {
            bias[model.constraint_rows + k] = slot_row(model, &self.kin, slot, &mut row);
            bt.column_mut(model.constraint_rows + k).copy_from(&row);
        }
        for mut col in bt.column_iter_mut() {
            forward_substitute(&self.factor, col.as_mut_slice());
        }
        let b = bt.transpose();
        let svd = JacobiSvd::thin(&b);
        // The threshold of the former solve on B Bᵀ (σ(BBᵀ) = σ(B)²): same rank decisions.
        let tol = svd.tolerance_relative(RANK_TOLERANCE.sqrt());
        let residual = &b * &self.qddot + &bias;
        let dz = -svd.solve_with(&residual, tol);
        // z − z_free = Bᵀ λ': the minimum-norm multipliers.
        let lambda_scaled = svd.solve_transposed_with(&dz, tol);
        self.qddot += &dz;
        back_substitute_transposed(&self.factor, self.qddot.as_mut_slice());
        self.lambda = lambda_scaled
            .rows(0, model.constraint_rows)
            .component_mul(&self.row_scale);
        self.seat_reactions = lambda_scaled
            .rows(model.constraint_rows, self.seated.len())
            .into_owned();
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
