//! Least-distance programming: the nearest point of a polyhedron to the origin, by `clarabel`.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::{DMatrix, DVector};

/// Least-distance programming, min ‖ν‖ subject to G ν ≥ h (Lawson & Hanson 1974, ch. 23): in the
/// hypotheses monitor, the nearest self-stress change that makes every monitored force
/// compressive. A convex quadratic program, solved by `clarabel`'s interior point on the problem
/// scaled to order one; None when it has no solution (no compressive distribution exists) or the
/// solver fails.
pub fn least_distance(g: &DMatrix<f64>, h: &DVector<f64>) -> Option<DVector<f64>> {
    let (rows, n) = g.shape();
    // Scaled to order one: G = g G′, h = η h′ and ν = (η/g) μ with G′μ ≥ h′ (min ‖μ‖ is min ‖ν‖).
    let (g_max, h_max) = (g.amax(), h.amax());
    if g_max == 0.0 || h_max == 0.0 {
        return (h_max == 0.0 || h.iter().all(|&x| x <= 0.0)).then(|| DVector::zeros(n));
    }
    let p = CscMatrix::new_from_triplets(n, n, (0..n).collect(), (0..n).collect(), vec![1.0; n]);
    // −G ν + slack = −h, slack ≥ 0.
    let (mut ri, mut ci, mut vi) = (Vec::new(), Vec::new(), Vec::new());
    for c in 0..n {
        for r in 0..rows {
            let v = g[(r, c)];
            if v != 0.0 {
                ri.push(r);
                ci.push(c);
                vi.push(-v / g_max);
            }
        }
    }
    let a = CscMatrix::new_from_triplets(rows, n, ri, ci, vi);
    let b: Vec<f64> = h.iter().map(|x| -x / h_max).collect();
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(200)
        .build()
        .ok()?;
    let cones = [SupportedConeT::NonnegativeConeT(rows)];
    let mut solver = DefaultSolver::new(&p, &vec![0.0; n], &a, &b, &cones, settings).ok()?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            Some(DVector::from_column_slice(&solver.solution.x) * (h_max / g_max))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// LDP on a closed form (the nearest point of a half-plane), on an inconsistent pair, and the
    /// KKT conditions of a random consistent one, to the interior point's accuracy (1e-8).
    #[test]
    fn least_distance_finds_the_nearest_feasible_point() {
        // x₁ + x₂ ≥ 2: the nearest point to the origin is (1, 1).
        let g = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
        let h = DVector::from_vec(vec![2.0]);
        let x = least_distance(&g, &h).expect("consistent");
        assert!(
            (x[0] - 1.0).abs() < 1e-8 && (x[1] - 1.0).abs() < 1e-8,
            "{x}"
        );
        // x₁ ≥ 1 and −x₁ ≥ 0 cannot hold together.
        let g = DMatrix::from_row_slice(2, 1, &[1.0, -1.0]);
        let h = DVector::from_vec(vec![1.0, 0.0]);
        assert!(least_distance(&g, &h).is_none());
        // Three random-looking constraints in 4 unknowns that hold at some x: the answer
        // satisfies them, and it is the nearest (KKT: x = Gᵀμ with μ ≥ 0 on the active ones).
        let g = DMatrix::from_fn(3, 4, |i, j| ((i * 5 + j * 3) % 7) as f64 - 3.0);
        let h = DVector::from_vec(vec![1.0, 0.5, -2.0]);
        let x = least_distance(&g, &h).expect("consistent");
        let slack = &g * &x - &h;
        assert!(slack.min() >= -1e-8, "{slack}");
        let active: Vec<usize> = (0..3).filter(|&i| slack[i] < 1e-6).collect();
        let ga = DMatrix::from_fn(active.len(), 4, |r, c| g[(active[r], c)]);
        let (mu, _) = crr_dynamics::linalg::pinv_solve(&ga.transpose(), &x);
        assert!((ga.transpose() * &mu - &x).amax() < 1e-8);
        assert!(mu.min() >= -1e-8, "{mu}");
    }
}
