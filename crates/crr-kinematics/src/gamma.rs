//! The paper's own route to M(q): rotation operators Γ and their inner products γ (eqs 1–2).
//!
//! Along the tree path of body n (coordinates j₀ … j_{m−1} from the ground), with Rᵢ the rotation
//! by q_{jᵢ} about the rest axis u_{jᵢ}, Γⁱ = R₀R₁…Rᵢ, the hinge vectors aⁱ = P_{jᵢ₊₁} − P_{jᵢ} and
//! x = X − P_{j_{m−1}}, a body point is r = P_{j₀} + Σᵢ Γⁱaⁱ + Γ^{m−1}x (eq 1). Then
//! ṙ = Σᵢ Γ̇ⁱaⁱ + Γ̇^{m−1}x and, with γⁱᵏ = (Γ̇ⁱ)ᵀΓ̇ᵏ = Σ_{a,b} q̇ₐq̇_b (∂ₐΓⁱ)ᵀ∂_bΓᵏ (the paper writes
//! Γ̇ʲ(Γ̇ᵏ)ᵀ in its row-vector convention), eq 2 reads
//! T = ½ Σₙ [Mⁿ Σ aⁱᵀγⁱᵏaᵏ + ∫ρ xᵀγ^{mm}x dV + 2Mⁿ Σ aⁱᵀγ^{im}x̄], x̄ the centre from the last pivot.
//! This module assembles M from exactly that, computing each ∂Γ by explicit products of
//! rotation matrices. It allocates and is O(m⁴) per body: a reference, not a hot path.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crate::model::Model;
use crate::pivots::ActivePivots;
use crate::rotation::{axis_angle, axis_angle_derivative};

/// The coordinates on the tree path of body `b`, from the ground to the body.
pub fn body_path(model: &Model, b: usize) -> Vec<usize> {
    let mut path = Vec::new();
    let mut j = Some(model.body_coord[b]);
    while let Some(jj) = j {
        path.push(jj);
        j = model.coords[jj].parent;
    }
    path.reverse();
    path
}

/// ∂Γⁱ/∂q_{`path[a]`} for all a, i on the path of body `b` (zero for a > i), indexed `[a][i]`.
#[doc(alias = "Γ")]
pub fn rot_op_partials(model: &Model, q: &DVector<f64>, path: &[usize]) -> Vec<Vec<Matrix3<f64>>> {
    let m = path.len();
    let rots: Vec<_> = path
        .iter()
        .map(|&j| axis_angle(&model.coords[j].axis, q[j]))
        .collect();
    let drots: Vec<_> = path
        .iter()
        .map(|&j| axis_angle_derivative(&model.coords[j].axis, q[j]))
        .collect();
    (0..m)
        .map(|a| {
            let mut prod = Matrix3::identity();
            (0..m)
                .map(|i| {
                    if i < a {
                        prod *= rots[i];
                        Matrix3::zeros()
                    } else {
                        prod *= if i == a { drots[i] } else { rots[i] };
                        prod
                    }
                })
                .collect()
        })
        .collect()
}

/// M(q) assembled from the γ inner products exactly as in eq 2 (an independent check of
/// [`crate::mass_matrix()`]; allocates).
#[doc(alias = "γ")]
pub fn mass_matrix_gamma(model: &Model, q: &DVector<f64>, pivots: &ActivePivots) -> DMatrix<f64> {
    let n = model.dof();
    let mut mm = DMatrix::zeros(n, n);
    let pivot_rest = |j: usize| {
        let iface = &model.interfaces[model.coords[j].interface];
        iface.kind.pivot(&pivots.sides[iface.slots.clone()])
    };
    for (b, body) in model.bodies.iter().enumerate() {
        let path = body_path(model, b);
        let m = path.len();
        let d = rot_op_partials(model, q, &path);
        // Hinge vectors aⁱ (i < m − 1), centre x̄ and second moment S about the last pivot.
        let hinge: Vec<Vector3<f64>> = (0..m - 1)
            .map(|i| pivot_rest(path[i + 1]) - pivot_rest(path[i]))
            .collect();
        let last = pivot_rest(path[m - 1]);
        let xbar = body.com - last;
        let s = body.second_moment + xbar * xbar.transpose() * body.mass;
        // γ^{ik}_{ab} = (∂ₐΓⁱ)ᵀ ∂_bΓᵏ.
        let gamma = |a: usize, i: usize, bb: usize, k: usize| d[a][i].transpose() * d[bb][k];
        for a in 0..m {
            for bb in 0..m {
                let mut v = 0.0;
                for i in a..m - 1 {
                    for k in bb..m - 1 {
                        v += body.mass * hinge[i].dot(&(gamma(a, i, bb, k) * hinge[k]));
                    }
                    v += body.mass * hinge[i].dot(&(gamma(a, i, bb, m - 1) * xbar));
                }
                for k in bb..m - 1 {
                    v += body.mass * xbar.dot(&(gamma(a, m - 1, bb, k) * hinge[k]));
                }
                v += (gamma(a, m - 1, bb, m - 1) * s).trace();
                mm[(path[a], path[bb])] += v;
            }
        }
    }
    mm
}
