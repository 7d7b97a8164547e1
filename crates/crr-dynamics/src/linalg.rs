//! Small dense linear algebra used by the equations of motion: in-place Cholesky (no allocation)
//! and rank-revealing least squares by the singular value decomposition.

use nalgebra::{DMatrix, DVector};

/// Relative threshold on singular values below which a direction counts as dependent.
pub const RANK_TOLERANCE: f64 = 1e-9;

/// Factorises the symmetric positive definite `a` in place into its lower Cholesky factor L
/// (a = L Lᵀ; the strict upper triangle is left untouched). Returns the failing pivot on a
/// non-positive one.
pub fn cholesky_in_place(a: &mut DMatrix<f64>) -> Result<(), usize> {
    let n = a.nrows();
    for j in 0..n {
        let mut d = a[(j, j)];
        for k in 0..j {
            d -= a[(j, k)] * a[(j, k)];
        }
        if !(d > 0.0 && d.is_finite()) {
            return Err(j);
        }
        let d = d.sqrt();
        a[(j, j)] = d;
        for i in j + 1..n {
            let mut s = a[(i, j)];
            for k in 0..j {
                s -= a[(i, k)] * a[(j, k)];
            }
            a[(i, j)] = s / d;
        }
    }
    Ok(())
}

/// Solves L Lᵀ x = b in place with the factor from [`cholesky_in_place`].
pub fn cholesky_solve(l: &DMatrix<f64>, b: &mut [f64]) {
    let n = l.nrows();
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[(i, k)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[(k, i)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
}

/// The minimum-norm least-squares solution x = A⁺ b with singular values below
/// `RANK_TOLERANCE · σ_max` treated as zero, and the numerical rank of A.
pub fn pinv_solve(a: &DMatrix<f64>, b: &DVector<f64>) -> (DVector<f64>, usize) {
    if a.nrows() == 0 || a.ncols() == 0 {
        return (DVector::zeros(a.ncols()), 0);
    }
    let svd = a.clone().svd(true, true);
    let smax = svd.singular_values.max();
    let tol = RANK_TOLERANCE * smax.max(f64::MIN_POSITIVE);
    let rank = svd.singular_values.iter().filter(|s| **s > tol).count();
    let x = svd.solve(b, tol).expect("U and V were computed");
    (x, rank)
}

/// A⁺, the pseudo-inverse with singular values below `RANK_TOLERANCE · σ_max` dropped.
pub fn pseudo_inverse(a: &DMatrix<f64>) -> DMatrix<f64> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return DMatrix::zeros(a.ncols(), a.nrows());
    }
    let svd = a.clone().svd(true, true);
    let tol = RANK_TOLERANCE * svd.singular_values.max().max(f64::MIN_POSITIVE);
    svd.pseudo_inverse(tol).expect("U and V were computed")
}

/// Numerical rank of A (singular values above `RANK_TOLERANCE · σ_max`).
pub fn rank(a: &DMatrix<f64>) -> usize {
    if a.nrows() == 0 || a.ncols() == 0 {
        return 0;
    }
    let s = a.clone().singular_values();
    let tol = RANK_TOLERANCE * s.max().max(f64::MIN_POSITIVE);
    s.iter().filter(|x| **x > tol).count()
}

/// Chooses `r` columns of A that are as independent as possible (Gram–Schmidt with column
/// pivoting: each time the column with the largest remaining norm). Returns them in the order
/// chosen.
pub fn pivot_columns(a: &DMatrix<f64>, r: usize) -> Vec<usize> {
    let mut work = a.clone();
    let mut chosen = Vec::with_capacity(r);
    for _ in 0..r {
        let (best, norm) = (0..work.ncols())
            .filter(|j| !chosen.contains(j))
            .map(|j| (j, work.column(j).norm()))
            .fold(
                (usize::MAX, -1.0),
                |acc, x| if x.1 > acc.1 { x } else { acc },
            );
        if best == usize::MAX || norm <= 0.0 {
            break;
        }
        chosen.push(best);
        let q = work.column(best) / norm;
        for j in 0..work.ncols() {
            let d = q.dot(&work.column(j));
            let qd = &q * d;
            let mut col = work.column_mut(j);
            col -= qd;
        }
    }
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cholesky_solves_a_random_spd_system_to_round_off() {
        let b = DMatrix::from_fn(5, 5, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
        let a = &b * b.transpose() + DMatrix::identity(5, 5);
        let x_true = DVector::from_fn(5, |i, _| i as f64 - 2.0);
        let mut rhs: Vec<f64> = (&a * &x_true).iter().copied().collect();
        let mut l = a.clone();
        cholesky_in_place(&mut l).unwrap();
        cholesky_solve(&l, &mut rhs);
        // Condition number here is below 1e3: the error is within 1e3 ε |x|.
        for i in 0..5 {
            assert!((rhs[i] - x_true[i]).abs() < 1e-12);
        }
        // A singular matrix is reported at its failing pivot, never a NaN.
        let mut s = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        assert_eq!(cholesky_in_place(&mut s), Err(1));
    }

    #[test]
    fn rank_and_pivot_columns_see_redundant_rows() {
        // Rows 0 and 2 equal: rank 2; columns 0 and 1 are parallel, so a pivoted choice of two
        // independent columns never takes both.
        let a = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 0.0]);
        assert_eq!(rank(&a), 2);
        let cols = pivot_columns(&a, 2);
        assert_eq!(cols.len(), 2);
        assert!(cols.contains(&2));
        let (x, r) = pinv_solve(&a, &DVector::from_vec(vec![5.0, 1.0, 5.0]));
        assert_eq!(r, 2);
        assert!((&a * &x - DVector::from_vec(vec![5.0, 1.0, 5.0])).norm() < 1e-12);
    }
}
