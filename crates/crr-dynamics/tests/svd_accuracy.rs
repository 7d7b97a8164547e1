//! The SVDs on the rank-deficient matrices of the engine. The crate carries its own Jacobi SVD
//! because nalgebra's recomposes such matrices with errors up to 1e-7 relative
//! (dimforge/nalgebra#1072, #1172); faer's was measured as the replacement (docs/performance.md,
//! "Dense factorisations") and is as accurate, but slower on these sizes. These tests hold both
//! to round-off on the 2 × 2 of #1072 and on the closed chains' B = Φ' L⁻ᵀ and Φ' (the colonnade's
//! 12 rows of rank 8 over 10 coordinates). nalgebra's SVD fails the 100 ε bound below on the
//! colonnade's B (1.6e-13 measured by `cargo bench --bench linalg`).
//!
//! Tolerances: a backward-stable SVD satisfies ‖U Σ Vᵀ − A‖ ≤ p(m, n) ε ‖A‖ and
//! ‖VᵀV − I‖ ≤ p(m, n) ε, with p a low-degree polynomial, in practice of the order of max(m, n)
//! (Householder bidiagonalisation; for one-sided Jacobi, the √m ε stopping test on each column
//! pair). The matrices here have at most 12 rows and columns, so 100 ε (Frobenius norms) leaves a
//! factor of several over that and is still nine orders of magnitude under the 1e-7 failure it
//! guards against. A solve from factors with backward error δ‖A‖ has a residual within
//! δ κ ‖A‖ ‖x‖, κ = σ_max/σ_r of the kept part.

use std::collections::BTreeMap;

use crr_dynamics::eom::constraint_row_scale;
use crr_dynamics::linalg::{JacobiSvd, RANK_TOLERANCE};
use crr_dynamics::{InitialSpec, solve_initial};
use crr_kinematics::fixtures::{colonnade, four_hinge_arch, trilithon};
use crr_kinematics::{
    ActivePivots, Data, Model, Side, constraint_jacobian, forward_kinematics, jacobians,
    mass_matrix,
};
use faer::MatRef;
use nalgebra::{DMatrix, DVector};

const EPS: f64 = f64::EPSILON;

/// Relative bound on the factorisation and orthogonality errors (see the module doc).
const BACKWARD: f64 = 100.0 * EPS;

/// A = U diag(σ) Vᵀ as three nalgebra matrices (σ in any order; U's columns of zero σ unused).
struct Factors {
    u: DMatrix<f64>,
    s: Vec<f64>,
    v: DMatrix<f64>,
}

fn faer_thin(a: &DMatrix<f64>) -> Factors {
    let view = MatRef::from_column_major_slice(a.as_slice(), a.nrows(), a.ncols());
    let svd = view.thin_svd().expect("faer's SVD converges");
    let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
    Factors {
        u: DMatrix::from_fn(u.nrows(), u.ncols(), |i, j| u[(i, j)]),
        s: (0..s.nrows()).map(|j| s[j]).collect(),
        v: DMatrix::from_fn(v.nrows(), v.ncols(), |i, j| v[(i, j)]),
    }
}

fn jacobi(a: &DMatrix<f64>) -> Factors {
    let svd = JacobiSvd::new(a);
    let s: Vec<f64> = svd.singular_values.iter().copied().collect();
    Factors {
        u: DMatrix::from_fn(a.nrows(), s.len(), |i, j| {
            if s[j] > 0.0 {
                svd.w[(i, j)] / s[j]
            } else {
                0.0
            }
        }),
        v: svd.v.clone(),
        s,
    }
}

/// Checks the factors of `a` to round-off; returns the rank at `relative` σ_max.
fn check(name: &str, a: &DMatrix<f64>, f: &Factors, relative: f64) -> usize {
    let norm = a.norm();
    let sigma = DMatrix::from_diagonal(&DVector::from_vec(f.s.clone()));
    let recon = (&f.u * sigma * f.v.transpose() - a).norm() / norm;
    assert!(recon <= BACKWARD, "{name}: ‖UΣVᵀ − A‖/‖A‖ = {recon:e}");
    let k = f.v.ncols();
    let vv = (f.v.transpose() * &f.v - DMatrix::identity(k, k)).norm();
    assert!(vv <= BACKWARD, "{name}: ‖VᵀV − I‖ = {vv:e}");
    let s_max = f.s.iter().copied().fold(0.0, f64::max);
    let tol = relative * s_max;
    let kept: Vec<usize> = (0..f.s.len()).filter(|&j| f.s[j] > tol).collect();
    for &i in &kept {
        for &j in &kept {
            let d = f.u.column(i).dot(&f.u.column(j)) - if i == j { 1.0 } else { 0.0 };
            assert!(d.abs() <= BACKWARD, "{name}: uᵢᵀuⱼ − δᵢⱼ = {d:e}");
        }
    }
    // A rank decision is robust only with a gap: the dropped singular values are round-off
    // (below 1000 ε ‖A‖, far under the threshold), the kept ones far above it.
    for &x in &f.s {
        assert!(x >= 0.0);
        assert!(
            x > 1e3 * tol || x < 1e3 * EPS * norm,
            "{name}: σ = {x:e} near the rank threshold {tol:e}"
        );
    }
    // The minimum-norm solve of a consistent system from the factors: A x = b to round-off.
    let kappa = s_max / kept.iter().map(|&j| f.s[j]).fold(f64::INFINITY, f64::min);
    let x0 = DVector::from_fn(a.ncols(), |i, _| ((i * 7 + 3) % 5) as f64 - 2.0);
    let b = a * &x0;
    let mut x = DVector::zeros(a.ncols());
    for &j in &kept {
        x.axpy(f.u.column(j).dot(&b) / f.s[j], &f.v.column(j), 1.0);
    }
    let residual = (a * &x - &b).norm();
    assert!(
        residual <= BACKWARD * kappa * norm * x0.norm(),
        "{name}: residual {residual:e}, κ {kappa:e}"
    );
    kept.len()
}

/// (Φ' = row-scaled Φ_q, B = Φ' L⁻ᵀ with M = L Lᵀ) at the consistent state with `coord` at
/// `angle`: the matrix of the impact laws' null spaces and that of the equations of motion.
fn matrices(model: &Model, coord: &str, angle: f64) -> (DMatrix<f64>, DMatrix<f64>) {
    let spec = InitialSpec {
        angles: BTreeMap::from([(coord.to_string(), angle)]),
        rates: BTreeMap::new(),
    };
    let q = solve_initial(model, &spec).expect("consistent state").q;
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    pivots.follow_coordinates(&q);
    let mut kin = Data::new(model);
    forward_kinematics(model, &mut kin, &q, &pivots);
    jacobians(model, &mut kin);
    mass_matrix(model, &mut kin);
    constraint_jacobian(model, &mut kin, &pivots);
    let scale = constraint_row_scale(model);
    let phi = DMatrix::from_fn(kin.phi_q.nrows(), kin.phi_q.ncols(), |i, j| {
        scale[i] * kin.phi_q[(i, j)]
    });
    // L by nalgebra's Cholesky (not the code under test).
    let l = kin.mass_matrix.clone().cholesky().expect("M > 0").unpack();
    let bt = l
        .solve_lower_triangular(&phi.transpose())
        .expect("L regular");
    (phi, bt.transpose())
}

#[test]
fn both_svds_recompose_the_two_by_two_of_nalgebra_1072() {
    // A = U diag(1, 0) Vᵀ with exact rotations (the example of dimforge/nalgebra#1072): rank 1.
    let u = DMatrix::from_row_slice(2, 2, &[0.6, -0.8, 0.8, 0.6]);
    let v = DMatrix::from_row_slice(2, 2, &[0.28, 0.96, -0.96, 0.28]);
    let a = &u * DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 0.0])) * v.transpose();
    assert_eq!(check("faer 2×2", &a, &faer_thin(&a), RANK_TOLERANCE), 1);
    assert_eq!(check("jacobi 2×2", &a, &jacobi(&a), RANK_TOLERANCE), 1);
}

#[test]
fn both_svds_factorise_the_closed_chains_b_and_phi_to_round_off() {
    // Ranks by construction: the trilithon and the four-hinge arch are one-DOF mechanisms of three
    // coordinates (rank 2); the 2×2 colonnade has 10 coordinates and DOF(2) = 2 (the slab
    // translates in x and y; see its fixture), so its 12 closure rows have rank 8. L is regular,
    // so B has the rank of Φ'.
    for (name, spec, coord, angle, rank) in [
        (
            "trilithon",
            trilithon(0.25, 1.5, 2.0, 0.5, 1.0),
            "base_left",
            0.05,
            2,
        ),
        (
            "arch",
            four_hinge_arch(4.0, 4.6, 1.0, false),
            "springing_right",
            0.02,
            2,
        ),
        (
            "colonnade",
            colonnade(0.2, 1.5, 1.2, 0.4),
            "base_1.1",
            0.03,
            8,
        ),
    ] {
        let model = Model::from_spec(&spec).unwrap();
        let (phi, b) = matrices(&model, coord, angle);
        // The equations of motion drop σ ≤ √RANK_TOLERANCE σ_max of B; the laws and the
        // mobility σ ≤ RANK_TOLERANCE σ_max of Φ'.
        for (what, a, relative) in [
            ("B", &b, RANK_TOLERANCE.sqrt()),
            ("Φ'", &phi, RANK_TOLERANCE),
        ] {
            for (method, f) in [("faer", faer_thin(a)), ("jacobi", jacobi(a))] {
                let got = check(&format!("{method} {name} {what}"), a, &f, relative);
                assert_eq!(got, rank, "{method} {name} {what}: rank");
            }
            // The thin decomposition the engine solves with finds the same rank.
            let thin = JacobiSvd::thin(a);
            let tol = thin.tolerance_relative(relative);
            let thin_rank = thin.singular_values.iter().filter(|s| **s > tol).count();
            assert_eq!(thin_rank, rank, "thin {name} {what}");
        }
    }
}
