//! Energy bookkeeping: kinetic T, potential U relative to rest, and the work W done by the ground
//! motion. Without impacts, T + U − W is constant along a solution (to the integration
//! tolerance): the balance checked by the tests and reported by simulations.

use nalgebra::DVector;

use crr_kinematics::{
    ActivePivots, Data, Model, forward_kinematics, mass_matrix, potential_energy,
};

/// Energies of one state (J).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Energies {
    /// T = ½ q̇ᵀ M q̇ (J).
    pub kinetic: f64,
    /// U(q) − U(rest) (J).
    pub potential: f64,
    /// W: work done by the ground motion since the start (J).
    pub work_in: f64,
}

impl Energies {
    /// Mechanical energy T + U (J).
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.potential
    }
}

/// U at rest (q = 0; independent of the pivots), Σ m g z of the centres at rest (J).
pub fn rest_potential(model: &Model) -> f64 {
    model.gravity * model.bodies.iter().map(|b| b.mass * b.com.z).sum::<f64>()
}

/// T and U − U_rest at (q, q̇) with the given pivots (fills `kin`), and the given work.
pub fn energies(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    qdot: &DVector<f64>,
    pivots: &ActivePivots,
    work_in: f64,
) -> Energies {
    forward_kinematics(model, kin, q, pivots);
    mass_matrix(model, kin);
    Energies {
        kinetic: 0.5 * qdot.dot(&(&kin.mass_matrix * qdot)),
        potential: potential_energy(model, kin) - rest_potential(model),
        work_in,
    }
}
