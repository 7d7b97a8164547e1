//! The articulated-body path of [`Dynamics`]: open chains whose seated slots are all tree
//! coordinates, in O(DOF(1)) without forming M ([`crate::articulated_body`]).

use super::*;

impl Dynamics {
    /// Whether [`Self::accelerations_with`] (and [`Self::solve_evaluated`]) take the
    /// articulated-body path with the current solver choice and seated slots, which needs no
    /// [`Self::evaluate`] (M is not used).
    pub fn articulated_body_applies(&self, model: &Model) -> bool {
        self.articulated_applies(model)
    }

    /// Whether [`Self::accelerations_with`] takes the articulated-body path at this state.
    pub(super) fn articulated_applies(&self, model: &Model) -> bool {
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
    pub(super) fn accelerations_articulated(
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
    pub(super) fn solve_articulated(
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
}
