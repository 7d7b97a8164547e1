//! The generalized mass matrix M(q) of T = ½ q̇ᵀ M(q) q̇ (eq 2), by two independent routes:
//! the composite-rigid-body recursion (fast, used by the dynamics) and Σ Jᵀ𝕄J from the body
//! Jacobians. The γ route of eq 2 itself is in [`crate::gamma`].

use nalgebra::{DMatrix, Matrix3, Matrix6, Vector6};

use crate::data::Data;
use crate::model::{Body, Model};
use crate::rotation::skew;

/// Spatial inertia about the world origin of a body with world centre `c` and world inertia
/// `i_c` about its centre, acting on [ω; v₀] (v₀ the velocity of the body point at the origin):
/// `[[I_c − m[c]×², m[c]×], [−m[c]×, m 1]]`.
pub fn spatial_inertia(mass: f64, c: &nalgebra::Vector3<f64>, i_c: &Matrix3<f64>) -> Matrix6<f64> {
    let cx = skew(c);
    let mut s = Matrix6::zeros();
    s.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(i_c - cx * cx * mass));
    s.fixed_view_mut::<3, 3>(0, 3).copy_from(&(cx * mass));
    s.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-cx * mass));
    s.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(Matrix3::identity() * mass));
    s
}

/// World inertia tensor about the centre of a body rotated by `rot`: R I Rᵀ.
pub fn world_inertia(body: &Body, rot: &Matrix3<f64>) -> Matrix3<f64> {
    rot * body.inertia * rot.transpose()
}

/// Spatial axis of coordinate k: [wₖ; pₖ × wₖ] (rotation about the line through pₖ along wₖ).
pub fn spatial_axis(data: &Data, k: usize) -> Vector6<f64> {
    let w = data.axis[k];
    let v = data.pivot[k].cross(&w);
    Vector6::new(w.x, w.y, w.z, v.x, v.y, v.z)
}

/// Fills `data.mass_matrix` with M(q) by the composite-rigid-body recursion:
/// Mᵢⱼ = sᵢᵀ I꜀ₘₐₓ₍ᵢ,ⱼ₎ sⱼ for j on the path of i, with I꜀ the composite spatial inertia of the subtree.
/// O(DOF(1) × depth); no allocation. Requires [`crate::forward_kinematics`].
pub fn mass_matrix(model: &Model, data: &mut Data) {
    let n = model.dof();
    for ic in data.composite_inertia.iter_mut() {
        *ic = Matrix6::zeros();
    }
    for (b, body) in model.bodies.iter().enumerate() {
        let k = model.body_coord[b];
        let i_w = world_inertia(body, &data.rot_ops[k]);
        data.composite_inertia[k] += spatial_inertia(body.mass, &data.com[b], &i_w);
    }
    for k in (0..n).rev() {
        if let Some(p) = model.coords[k].parent {
            let ck = data.composite_inertia[k];
            data.composite_inertia[p] += ck;
        }
    }
    // M_ij of coordinates that do not carry one another is 0 and never written here (zero since
    // `Data::new`; nothing else writes M): only the pairs along each path to the ground are set,
    // so the cost is the tree's depth times DOF(1), not DOF(1)².
    for i in 0..n {
        let f = data.composite_inertia[i] * spatial_axis(data, i);
        let mut j = Some(i);
        while let Some(jj) = j {
            let m = spatial_axis(data, jj).dot(&f);
            data.mass_matrix[(i, jj)] = m;
            data.mass_matrix[(jj, i)] = m;
            j = model.coords[jj].parent;
        }
    }
}

/// M(q) = Σₙ (Mⁿ J_cₙᵀ J_cₙ + J_ωₙᵀ Iₙ J_ωₙ) from the body Jacobians (a second, independent route;
/// allocates). Requires [`crate::forward_kinematics`] and [`crate::jacobians`].
pub fn mass_matrix_from_jacobians(model: &Model, data: &Data) -> DMatrix<f64> {
    let n = model.dof();
    let mut m = DMatrix::zeros(n, n);
    for (b, body) in model.bodies.iter().enumerate() {
        let jc = data.com_jacobian.rows(3 * b, 3);
        let jw = data.angular_jacobian.rows(3 * b, 3);
        let i_w = world_inertia(body, &data.rot_ops[model.body_coord[b]]);
        m += jc.transpose() * jc * body.mass + jw.transpose() * i_w * jw;
    }
    m
}

/// Kinetic energy T = ½ q̇ᵀ M q̇ (J), from `data.mass_matrix`.
pub fn kinetic_energy(data: &Data, qdot: &nalgebra::DVector<f64>) -> f64 {
    0.5 * qdot.dot(&(&data.mass_matrix * qdot))
}
