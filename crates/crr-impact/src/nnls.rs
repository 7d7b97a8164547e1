//! Non-negative least squares (Lawson–Hanson): the uplift of loops at rest (Gauss' principle over
//! the seated slots, uplift_from_rest.rs).

use nalgebra::{DMatrix, DVector};

use crr_dynamics::linalg::pinv_solve;

/// Non-negative least squares, min ‖A x − b‖ over x ≥ 0 (Lawson & Hanson 1974, ch. 23): the
/// passive set grows by the most negative gradient component and the iterate is pulled back
/// into x ≥ 0 along the segment to each unconstrained least-squares solution; rank-deficient
/// passive sets are solved by the minimum-norm pseudo-inverse.
pub fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let s = a.ncols();
    let mut x = DVector::zeros(s);
    let mut passive = vec![false; s];
    let scale = a.norm() * b.norm();
    let w_tol = 1e-13 * scale.max(f64::MIN_POSITIVE);
    let gram = a.tr_mul(a);
    let atb = a.tr_mul(b);
    for _ in 0..3 * s + 3 {
        let w = a.tr_mul(&(b - a * &x));
        let Some(j) = (0..s)
            .filter(|&j| !passive[j] && w[j] > w_tol)
            .max_by(|&i, &j| w[i].total_cmp(&w[j]))
        else {
            break;
        };
        passive[j] = true;
        for _ in 0..3 * s + 3 {
            let cols: Vec<usize> = (0..s).filter(|&i| passive[i]).collect();
            let sp = passive_least_squares(a, &gram, &atb, b, &cols);
            if sp.iter().all(|&v| v > 0.0) {
                x.fill(0.0);
                for (c, &i) in cols.iter().enumerate() {
                    x[i] = sp[c];
                }
                break;
            }
            // Step from x towards the solution until the first passive component reaches 0.
            let mut alpha: f64 = 1.0;
            for (c, &i) in cols.iter().enumerate() {
                if sp[c] <= 0.0 {
                    alpha = alpha.min(x[i] / (x[i] - sp[c]));
                }
            }
            for (c, &i) in cols.iter().enumerate() {
                x[i] += alpha * (sp[c] - x[i]);
                if x[i] <= 1e-15 * (1.0 + x.amax()) {
                    x[i] = 0.0;
                    passive[i] = false;
                }
            }
            if !passive.iter().any(|&p| p) {
                break;
            }
        }
    }
    x
}

/// min ‖A_P x − b‖ over the columns `cols` of A: by the Cholesky factor of their Gram matrix
/// A_PᵀA_P (the passive columns of Lawson–Hanson are independent, and this is the cheap way),
/// or by the minimum-norm pseudo-inverse when that matrix is singular to round-off.
fn passive_least_squares(
    a: &DMatrix<f64>,
    gram: &DMatrix<f64>,
    atb: &DVector<f64>,
    b: &DVector<f64>,
    cols: &[usize],
) -> DVector<f64> {
    let k = cols.len();
    let sub = DMatrix::from_fn(k, k, |i, j| gram[(cols[i], cols[j])]);
    let rhs = DVector::from_fn(k, |i, _| atb[cols[i]]);
    let largest = (0..k).map(|i| sub[(i, i)]).fold(0.0_f64, f64::max);
    if let Some(chol) = sub.cholesky() {
        let l = chol.l_dirty();
        let smallest = (0..k)
            .map(|i| l[(i, i)] * l[(i, i)])
            .fold(f64::INFINITY, f64::min);
        if smallest > 1e-10 * largest {
            return chol.solve(&rhs);
        }
    }
    let ap = DMatrix::from_fn(a.nrows(), k, |r, c| a[(r, cols[c])]);
    pinv_solve(&ap, b).0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// NNLS against the closed form of a 2 × 2 problem with one active bound, and the
    /// Karush–Kuhn–Tucker conditions of a random one.
    #[test]
    fn nnls_satisfies_the_kkt_conditions() {
        // min (x₁ − 1)² + (x₂ + 1)²: x = (1, 0).
        let a = DMatrix::identity(2, 2);
        let b = DVector::from_vec(vec![1.0, -1.0]);
        let x = nnls(&a, &b);
        assert!((x[0] - 1.0).abs() < 1e-15 && x[1] == 0.0);
        // A wide, rank-deficient A (3 × 6): x ≥ 0, w = Aᵀ(b − Ax) ≤ 0, and w = 0 where x > 0.
        let a = DMatrix::from_fn(3, 6, |i, j| {
            ((i * 7 + j * 3) % 5) as f64 - 2.0 + 0.1 * j as f64
        });
        let b = DVector::from_vec(vec![1.0, -2.0, 0.5]);
        let x = nnls(&a, &b);
        let w = a.tr_mul(&(&b - &a * &x));
        for j in 0..6 {
            assert!(x[j] >= 0.0);
            assert!(w[j] <= 1e-12, "gradient {j}: {}", w[j]);
            if x[j] > 0.0 {
                assert!(w[j].abs() <= 1e-12, "passive gradient {j}: {}", w[j]);
            }
        }
    }
}
