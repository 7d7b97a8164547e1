//! Potential energy U(q) (eq 3) and generalized gravity forces.

use nalgebra::{DVector, Vector3};

use crate::data::Data;
use crate::model::Model;

/// U = g Σₙ Mⁿ zₙ (eq 3): absolute, the heights of the centres above z = 0 (J).
/// Requires [`crate::forward_kinematics`].
pub fn potential_energy(model: &Model, data: &Data) -> f64 {
    model.gravity
        * model
            .bodies
            .iter()
            .zip(&data.com)
            .map(|(b, c)| b.mass * c.z)
            .sum::<f64>()
}

/// Generalized force of a uniform acceleration field `field` (m/s²) on every body:
/// Q = Σₙ Mⁿ J_cₙᵀ field. With field = (0, 0, −g) it is the generalized gravity −∂U/∂q; with the
/// effective gravity (−a_x, −a_y, −g − a_z) it is the full load of a ground motion.
/// Computed in O(DOF(1)) from subtree masses and first moments:
/// Qₖ = field · (wₖ × (Sₖ − mₖ pₖ)). Requires [`crate::forward_kinematics`].
pub fn generalized_gravity(
    model: &Model,
    data: &mut Data,
    field: &Vector3<f64>,
    out: &mut DVector<f64>,
) {
    let n = model.dof();
    data.subtree_mass.fill(0.0);
    data.subtree_moment.fill(Vector3::zeros());
    for (b, body) in model.bodies.iter().enumerate() {
        let k = model.body_coord[b];
        data.subtree_mass[k] += body.mass;
        data.subtree_moment[k] += data.com[b] * body.mass;
    }
    for k in (0..n).rev() {
        if let Some(p) = model.coords[k].parent {
            let (m, s) = (data.subtree_mass[k], data.subtree_moment[k]);
            data.subtree_mass[p] += m;
            data.subtree_moment[p] += s;
        }
    }
    for k in 0..n {
        let lever = data.subtree_moment[k] - data.pivot[k] * data.subtree_mass[k];
        out[k] = field.dot(&data.axis[k].cross(&lever));
    }
}
