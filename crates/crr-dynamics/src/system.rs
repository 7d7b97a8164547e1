//! The equations of motion as first-order ODE systems for the integrators, in the two forms that
//! must agree on every closed chain:
//! - [`ConstrainedSystem`]: the multi-DOF form, y = [q, q̇, W] over all DOF(1) coordinates, with
//!   multipliers (index-reduced to the acceleration level) and projection back onto Φ = 0 and
//!   Φ_q q̇ = 0 after every step;
//! - [`ReducedSystem`]: coordinate partitioning, y = [z, ż, W] over the DOF(2) independent
//!   coordinates, the dependent ones solved by Newton at every evaluation.
//!
//! W is the work done by the ground motion, Ẇ = Q_gᵀq̇ with Q_g = Σ Mⁿ J_cᵀ(−a_g).

use nalgebra::{DMatrix, DVector};

use crr_kinematics::Model;

use crate::closed_chain::{Partition, project_positions, project_velocities_with};
use crate::eom::{Dynamics, GeneralizedForce};
use crate::ground_motion::GroundMotion;
use crate::integrator::{OdeSystem, RhsError};
use crate::linalg::{cholesky_in_place, cholesky_solve, pseudo_inverse};
use crr_kinematics::short_copy::copy_short;

/// The multi-DOF constrained form: y = [q, q̇, W, D] with W the work of the ground motion and D
/// the energy dissipated by the extra force (if any), Ḋ = −F_extraᵀq̇.
pub struct ConstrainedSystem<'a> {
    /// The structure.
    pub model: &'a Model,
    /// The ground motion.
    pub ground: &'a GroundMotion,
    /// Equations-of-motion workspace, with the dynamic chain (pivots) and seated slots.
    pub dynamics: &'a mut Dynamics,
    /// An extra generalized force (e.g. a regularised impact law).
    pub extra: Option<&'a mut dyn GeneralizedForce>,
    q: DVector<f64>,
    qdot: DVector<f64>,
}

impl<'a> ConstrainedSystem<'a> {
    /// Wraps the model, ground motion and workspace.
    pub fn new(model: &'a Model, ground: &'a GroundMotion, dynamics: &'a mut Dynamics) -> Self {
        let n = model.dof();
        Self::with_buffers(
            model,
            ground,
            dynamics,
            (DVector::zeros(n), DVector::zeros(n)),
        )
    }

    /// [`Self::new`] on the q and q̇ buffers of an earlier system ([`Self::into_buffers`]),
    /// resized to the model when needed: a simulation builds a system for every segment between
    /// events, and this one does not allocate.
    pub fn with_buffers(
        model: &'a Model,
        ground: &'a GroundMotion,
        dynamics: &'a mut Dynamics,
        (mut q, mut qdot): (DVector<f64>, DVector<f64>),
    ) -> Self {
        let n = model.dof();
        if q.len() != n || qdot.len() != n {
            (q, qdot) = (DVector::zeros(n), DVector::zeros(n));
        }
        Self {
            model,
            ground,
            dynamics,
            extra: None,
            q,
            qdot,
        }
    }

    /// The q and q̇ buffers, for [`Self::with_buffers`].
    pub fn into_buffers(self) -> (DVector<f64>, DVector<f64>) {
        (self.q, self.qdot)
    }

    /// State vector [q, q̇, W, D].
    pub fn pack(q: &DVector<f64>, qdot: &DVector<f64>, work: f64, dissipated: f64) -> Vec<f64> {
        q.iter()
            .chain(qdot.iter())
            .copied()
            .chain([work, dissipated])
            .collect()
    }
}

impl OdeSystem for ConstrainedSystem<'_> {
    fn dim(&self) -> usize {
        2 * self.model.dof() + 2
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        let n = self.model.dof();
        // One coordinate: the kernel straight from y (no copies into q and q̇).
        if n == 1
            && self.extra.is_none()
            && let Some(rates) =
                self.dynamics
                    .single_coordinate_rates(self.model, self.ground, t, y[0])
        {
            let (qddot, ground_force) = rates.map_err(|e| RhsError(e.to_string()))?;
            let rate = y[1];
            dydt[0] = rate;
            dydt[1] = qddot;
            // Q_g·q̇ and −τ·q̇ (τ = 0) summed as the one-term dot products below sum them.
            dydt[2] = 0.0 + ground_force * rate;
            dydt[3] = -(0.0 + 0.0 * rate);
            return Ok(());
        }
        copy_short(self.q.as_mut_slice(), &y[..n]);
        copy_short(self.qdot.as_mut_slice(), &y[n..2 * n]);
        let extra: Option<&mut dyn GeneralizedForce> = match &mut self.extra {
            Some(f) => Some(&mut **f),
            None => None,
        };
        self.dynamics
            .integration_accelerations(self.model, self.ground, t, &self.q, &self.qdot, extra)
            .map_err(|e| RhsError(e.to_string()))?;
        copy_short(&mut dydt[..n], &y[n..2 * n]);
        copy_short(&mut dydt[n..2 * n], self.dynamics.qddot.as_slice());
        dydt[2 * n] = self.dynamics.ground_force.dot(&self.qdot);
        dydt[2 * n + 1] = -self.dynamics.extra_force.dot(&self.qdot);
        Ok(())
    }

    fn project(&mut self, _t: f64, y: &mut [f64]) -> Result<bool, RhsError> {
        let seated_tree: Vec<usize> = self
            .dynamics
            .seated
            .iter()
            .copied()
            .filter(|&s| s < self.model.dof())
            .collect();
        if self.model.constraint_rows == 0 && seated_tree.is_empty() {
            return Ok(false);
        }
        let n = self.model.dof();
        // Without loops only the seated coordinates are set, to exactly 0: where each q and q̇
        // already is +0.0 bit for bit (either forward solve gives a seated coordinate q̈ = 0.0,
        // so the integrator keeps it there) nothing moves, and f(t, y) and the events
        // at the step end stay valid (reporting a move re-evaluated both at every such step).
        if self.model.constraint_rows == 0
            && seated_tree
                .iter()
                .all(|&k| y[k].to_bits() == 0 && y[n + k].to_bits() == 0)
        {
            return Ok(false);
        }
        self.q.as_mut_slice().copy_from_slice(&y[..n]);
        self.qdot.as_mut_slice().copy_from_slice(&y[n..2 * n]);
        // Seated tree coordinates are exactly 0; the others close the loops.
        for &k in &seated_tree {
            self.q[k] = 0.0;
            self.qdot[k] = 0.0;
        }
        if self.model.constraint_rows > 0 {
            let free: Vec<usize> = (0..n).filter(|k| !seated_tree.contains(k)).collect();
            let d = &mut *self.dynamics;
            project_positions(self.model, &mut d.kin, &d.pivots, &mut self.q, Some(&free))
                .map_err(|e| RhsError(e.to_string()))?;
            project_velocities_with(
                self.model,
                &mut d.kin,
                &d.pivots,
                &self.q,
                &mut self.qdot,
                Some(&free),
                Some(&mut d.velocity_projection),
            );
        }
        y[..n].copy_from_slice(self.q.as_slice());
        y[n..2 * n].copy_from_slice(self.qdot.as_slice());
        Ok(true)
    }
}

/// The reduced form by coordinate partitioning.
pub struct ReducedSystem<'a> {
    /// The structure.
    pub model: &'a Model,
    /// The ground motion.
    pub ground: &'a GroundMotion,
    /// Equations-of-motion workspace, with the dynamic chain (pivots).
    pub dynamics: &'a mut Dynamics,
    /// Independent / dependent coordinates.
    pub partition: Partition,
    /// The full q of the last evaluation (warm start of the Newton solve for the dependent ones).
    pub q: DVector<f64>,
    /// The full q̇ of the last evaluation.
    pub qdot: DVector<f64>,
    /// The full q̈ of the last evaluation.
    pub qddot: DVector<f64>,
}

impl<'a> ReducedSystem<'a> {
    /// Wraps the model, ground motion and workspace; `q_start` is a closed configuration used as the
    /// first Newton guess.
    pub fn new(
        model: &'a Model,
        ground: &'a GroundMotion,
        dynamics: &'a mut Dynamics,
        partition: Partition,
        q_start: &DVector<f64>,
    ) -> Self {
        let n = model.dof();
        Self {
            model,
            ground,
            dynamics,
            partition,
            q: q_start.clone(),
            qdot: DVector::zeros(n),
            qddot: DVector::zeros(n),
        }
    }

    /// Number of independent coordinates, DOF(2).
    pub fn reduced_dof(&self) -> usize {
        self.partition.independent.len()
    }

    /// State vector [z, ż, W] from full q, q̇.
    pub fn pack(&self, q: &DVector<f64>, qdot: &DVector<f64>, work: f64) -> Vec<f64> {
        let ind = &self.partition.independent;
        ind.iter()
            .map(|&k| q[k])
            .chain(ind.iter().map(|&k| qdot[k]))
            .chain(std::iter::once(work))
            .collect()
    }

    /// Expands a reduced state into full q and q̇ (stored in `self.q`, `self.qdot`), returning B, the
    /// map q̇ = B ż.
    pub fn expand(&mut self, y: &[f64]) -> Result<DMatrix<f64>, RhsError> {
        let ind = self.partition.independent.clone();
        let dep = self.partition.dependent.clone();
        let k = ind.len();
        for (j, &c) in ind.iter().enumerate() {
            self.q[c] = y[j];
        }
        let d = &mut *self.dynamics;
        project_positions(self.model, &mut d.kin, &d.pivots, &mut self.q, Some(&dep))
            .map_err(|e| RhsError(e.to_string()))?;
        // Φ_d q̇_d = −Φ_i ż  ⇒  B = [I; −Φ_d⁺ Φ_i].
        crr_kinematics::forward_kinematics(self.model, &mut d.kin, &self.q, &d.pivots);
        crr_kinematics::constraint_jacobian(self.model, &mut d.kin, &d.pivots);
        let jac = d.scaled_jacobian();
        let phi_d = DMatrix::from_fn(jac.nrows(), dep.len(), |i, j| jac[(i, dep[j])]);
        let phi_i = DMatrix::from_fn(jac.nrows(), k, |i, j| jac[(i, ind[j])]);
        let pinv = pseudo_inverse(&phi_d);
        let dep_map = -(&pinv * &phi_i);
        let mut b = DMatrix::zeros(self.model.dof(), k);
        for (j, &c) in ind.iter().enumerate() {
            b[(c, j)] = 1.0;
        }
        for (i, &c) in dep.iter().enumerate() {
            for j in 0..k {
                b[(c, j)] = dep_map[(i, j)];
            }
        }
        let zdot = DVector::from_column_slice(&y[k..2 * k]);
        self.qdot = &b * zdot;
        Ok(b)
    }
}

impl OdeSystem for ReducedSystem<'_> {
    fn dim(&self) -> usize {
        2 * self.reduced_dof() + 1
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsError> {
        let k = self.reduced_dof();
        let b = self.expand(y)?;
        let d = &mut *self.dynamics;
        d.evaluate(self.model, self.ground, t, &self.q, &self.qdot);
        // q̈ = B z̈ + β with β_d = −Φ_d⁺ Φ̇_q q̇ (β_i = 0).
        let dep = &self.partition.dependent;
        let jac = d.scaled_jacobian();
        let phi_d = DMatrix::from_fn(jac.nrows(), dep.len(), |i, j| jac[(i, dep[j])]);
        let bias = d.kin.phi_bias.component_mul(d.row_scale());
        let pinv = pseudo_inverse(&phi_d);
        let beta_d = -(&pinv * bias);
        let mut beta = DVector::zeros(self.model.dof());
        for (i, &c) in dep.iter().enumerate() {
            beta[c] = beta_d[i];
        }
        // (Bᵀ M B) z̈ = Bᵀ (Q − h − M β).
        let m = &d.kin.mass_matrix;
        let mut m_red = b.transpose() * m * &b;
        let f = &d.load - &d.kin.velocity_product - m * &beta;
        let mut zdd: Vec<f64> = (b.transpose() * f).iter().copied().collect();
        cholesky_in_place(&mut m_red)
            .map_err(|_| RhsError("the reduced mass matrix is singular".into()))?;
        cholesky_solve(&m_red, &mut zdd);
        self.qddot = &b * DVector::from_column_slice(&zdd) + beta;
        dydt[..k].copy_from_slice(&y[k..2 * k]);
        dydt[k..2 * k].copy_from_slice(&zdd);
        dydt[2 * k] = d.ground_force.dot(&self.qdot);
        Ok(())
    }
}
