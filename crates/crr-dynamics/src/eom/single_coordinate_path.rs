//! The one-coordinate path of [`Dynamics`]: a single free tree coordinate (everything else
//! seated, no loops) in closed form, I_p θ̈ = Q + τ ([`crate::single_coordinate`]).

use super::*;

impl Dynamics {
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
    pub(super) fn single_coordinate_applies(&self, model: &Model) -> bool {
        self.solver == ForwardSolver::Auto
            && self.seated.is_empty()
            && single_coordinate::applies(model)
    }

    /// Records a solve by the one-coordinate closed form: nothing is seated, so no seat
    /// reactions (not those of an earlier seated solve) and no joint force.
    pub(super) fn mark_single_coordinate(&mut self) {
        self.used_articulated = false;
        self.used_single_coordinate = true;
        if !self.seat_reactions.is_empty() {
            self.seat_reactions = DVector::zeros(0);
        }
    }
}
