//! Small dense linear algebra used by the equations of motion: in-place Cholesky (no allocation
//! below [`FAER_CHOLESKY_MIN`] = 32 coordinates; faer's blocked factorisation from there on) and
//! rank-revealing least squares by a one-sided Jacobi singular value decomposition.
//!
//! Which code serves which size was decided by `cargo bench --bench linalg` (docs/performance.md,
//! "Dense factorisations: faer, nalgebra and the crate's own"): faer's Cholesky is slower than the
//! loops below up to 16 coordinates and faster from 32 (7–10 times at 128); its SVD is 3–5 times
//! slower than the Jacobi SVD on the 5 × 3 matrices of the engine and on par at 12 × 10, so the
//! Jacobi SVD stays.

use std::mem::MaybeUninit;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{
    LltError, cholesky_in_place as faer_cholesky_in_place, cholesky_in_place_scratch,
};
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{MatMut, MatRef, Par};
use nalgebra::{DMatrix, DVector};

/// Relative threshold on singular values below which a direction counts as dependent.
pub const RANK_TOLERANCE: f64 = 1e-9;

/// Order from which [`cholesky_in_place`] and the triangular solves use faer (blocked, SIMD)
/// rather than the plain loops of [`cholesky_in_place_unblocked`]: the crossover measured by
/// `cargo bench --bench linalg` (faer's call overhead dominates below 16, its blocking wins from 32).
pub const FAER_CHOLESKY_MIN: usize = 32;

/// Bytes of faer's Cholesky workspace kept on the stack (one column of n values, aligned): enough
/// up to n ≈ 480; larger orders allocate it.
const CHOLESKY_STACK_BYTES: usize = 4096;

/// Factorises the symmetric positive definite `a` in place into its lower Cholesky factor L
/// (a = L Lᵀ; only the lower triangle is read, and the strict upper one holds scratch afterwards:
/// faer's blocked factorisation writes there). Returns the failing pivot on a non-positive (or
/// non-finite) one. Plain loops below [`FAER_CHOLESKY_MIN`], faer's blocked
/// factorisation from there on, with its workspace on the stack below about 480 coordinates.
pub fn cholesky_in_place(a: &mut DMatrix<f64>) -> Result<(), usize> {
    let n = a.nrows();
    if n < FAER_CHOLESKY_MIN {
        return cholesky_in_place_unblocked(a);
    }
    let req = cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default());
    let mut on_stack = [MaybeUninit::<u8>::uninit(); CHOLESKY_STACK_BYTES];
    let mut on_heap;
    let stack = if req.unaligned_bytes_required() <= CHOLESKY_STACK_BYTES {
        MemStack::new(&mut on_stack)
    } else {
        on_heap = MemBuffer::new(req);
        MemStack::new(&mut on_heap)
    };
    let view = MatMut::from_column_major_slice_mut(a.as_mut_slice(), n, n);
    let result = faer_cholesky_in_place(
        view,
        Default::default(),
        Par::Seq,
        stack,
        Default::default(),
    );
    match result {
        Ok(_) => {
            // faer's kernel already rejects NaN and infinite pivots (`!(d > 0)`, then a finiteness
            // test); this O(n) check keeps the loops' contract whichever of its paths ran.
            match (0..n).find(|&j| !(a[(j, j)] > 0.0 && a[(j, j)].is_finite())) {
                Some(j) => Err(j),
                None => Ok(()),
            }
        }
        Err(LltError::NonPositivePivot { index }) => Err(index),
    }
}

/// [`cholesky_in_place`] by plain loops (used below [`FAER_CHOLESKY_MIN`]; public so that the
/// benchmark can time it on every order).
pub fn cholesky_in_place_unblocked(a: &mut DMatrix<f64>) -> Result<(), usize> {
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
    forward_substitute(l, b);
    back_substitute_transposed(l, b);
}

/// L (lower triangle of `l`, n × n) as a faer view, and `b` as an n × 1 one.
fn faer_views<'a>(l: &'a DMatrix<f64>, b: &'a mut [f64]) -> (MatRef<'a, f64>, MatMut<'a, f64>) {
    let n = l.nrows();
    (
        MatRef::from_column_major_slice(l.as_slice(), n, n),
        MatMut::from_column_major_slice_mut(b, n, 1),
    )
}

/// Solves L y = b in place (L lower triangular, from [`cholesky_in_place`]).
pub fn forward_substitute(l: &DMatrix<f64>, b: &mut [f64]) {
    if l.nrows() >= FAER_CHOLESKY_MIN {
        let (l, b) = faer_views(l, b);
        solve_lower_triangular_in_place(l, b, Par::Seq);
        return;
    }
    for i in 0..l.nrows() {
        let mut s = b[i];
        for k in 0..i {
            s -= l[(i, k)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
}

/// Solves Lᵀ x = y in place (L lower triangular, from [`cholesky_in_place`]).
pub fn back_substitute_transposed(l: &DMatrix<f64>, b: &mut [f64]) {
    let n = l.nrows();
    if n >= FAER_CHOLESKY_MIN {
        let (l, b) = faer_views(l, b);
        solve_upper_triangular_in_place(l.transpose(), b, Par::Seq);
        return;
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[(k, i)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
}

/// Singular value decomposition A = W Vᵀ with W = U Σ (orthogonal columns of norms σⱼ) and V
/// orthogonal (n × n), by one-sided Jacobi rotations (Hestenes).
///
/// Written here rather than taken from nalgebra because nalgebra's bidiagonal SVD can return a
/// factorisation whose product is off by 1e-7 relative for rank-deficient matrices
/// (dimforge/nalgebra#1072, #1172): the redundant closures of a colonnade hit exactly that case
/// and the constrained accelerations became noisy. One-sided Jacobi has no such failure mode:
/// it only applies plane rotations until every pair of columns is orthogonal to round-off, and it
/// computes small singular values with high relative accuracy. Matrices here are at most a few
/// tens of rows and columns, where a Jacobi sweep is cheap.
#[derive(Clone, Debug)]
pub struct JacobiSvd {
    /// A V: its column j is σⱼ uⱼ (m × n).
    pub w: DMatrix<f64>,
    /// The right singular vectors as columns (n × n, orthogonal).
    pub v: DMatrix<f64>,
    /// σⱼ = |column j of W| (unsorted).
    pub singular_values: DVector<f64>,
    /// The decomposition is of Aᵀ ([`Self::thin`] of a wide A): `w` and `v` describe Aᵀ.
    transposed: bool,
    /// [`Self::thin`] only: the rows and columns of A that hold a nonzero entry, when some do
    /// not (A's shape is `shape`). `w`, `v` and `singular_values` then describe the submatrix
    /// of those rows and columns; solves scatter back (a zero column's unknown is 0, a zero
    /// row's multiplier is 0: both the minimum-norm choice).
    support: Option<Support>,
}

/// The nonzero rows and columns of a matrix of shape `shape`, in order.
#[derive(Clone, Debug)]
struct Support {
    rows: Vec<usize>,
    cols: Vec<usize>,
    shape: (usize, usize),
}

impl Support {
    /// The nonzero rows and columns of `a`, or None when every row and column has an entry.
    fn of(a: &DMatrix<f64>) -> Option<Support> {
        let (m, n) = a.shape();
        let mut row_used = vec![false; m];
        let mut cols = Vec::with_capacity(n);
        for j in 0..n {
            let mut used = false;
            for (i, &x) in a.column(j).iter().enumerate() {
                if x != 0.0 {
                    row_used[i] = true;
                    used = true;
                }
            }
            if used {
                cols.push(j);
            }
        }
        let rows: Vec<usize> = (0..m).filter(|&i| row_used[i]).collect();
        (rows.len() < m || cols.len() < n).then_some(Support {
            rows,
            cols,
            shape: (m, n),
        })
    }

    /// `x` (indexed like A's kept columns or rows, `kept`) spread to length `len` with zeros.
    fn scatter(x: &DVector<f64>, kept: &[usize], len: usize) -> DVector<f64> {
        let mut out = DVector::zeros(len);
        for (k, &i) in kept.iter().enumerate() {
            out[i] = x[k];
        }
        out
    }
}

/// Largest number of Jacobi sweeps (each visits every column pair once); convergence is
/// quadratic and takes at most about 16 sweeps for the matrices of this crate.
const JACOBI_SWEEPS: usize = 60;

impl JacobiSvd {
    /// Decomposes `a` (any shape; a wide matrix is handled as is: its W has zero columns).
    pub fn new(a: &DMatrix<f64>) -> Self {
        let n = a.ncols();
        let mut w = a.clone();
        let mut v = DMatrix::identity(n, n);
        // A column whose norm is below 1000 ε‖A‖ is round-off: a zero singular value far under
        // the rank threshold (RANK_TOLERANCE σ_max ≥ 1e-9 ‖A‖/√n). Rotating it against a large
        // column only exchanges noise and never passes the relative orthogonality test, so it is
        // left alone; it counts as a zero singular value.
        let negligible = (1e3 * f64::EPSILON * a.norm()).powi(2);
        // A rounded dot product of m terms is only good to about √m ε relative (the stopping
        // test of LAPACK's dgesvj); a stricter test can cycle through every sweep on round-off.
        let dot_error = (a.nrows().max(1) as f64).sqrt() * f64::EPSILON;
        for _ in 0..JACOBI_SWEEPS {
            let mut rotated = false;
            for p in 0..n {
                for q in (p + 1)..n {
                    let (mut alpha, mut beta, mut gamma) = (0.0, 0.0, 0.0);
                    let rows = w.nrows();
                    let data = w.as_slice();
                    let (cp, cq) = (
                        &data[p * rows..(p + 1) * rows],
                        &data[q * rows..(q + 1) * rows],
                    );
                    for (x, y) in cp.iter().zip(cq) {
                        alpha += x * x;
                        beta += y * y;
                        gamma += x * y;
                    }
                    // Columns already orthogonal to round-off (or one of them negligible): skip.
                    if alpha <= negligible
                        || beta <= negligible
                        || gamma.abs() <= dot_error * (alpha * beta).sqrt()
                    {
                        continue;
                    }
                    rotated = true;
                    let zeta = (beta - alpha) / (2.0 * gamma);
                    let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                    let t = if zeta == 0.0 { 1.0 } else { t };
                    let c = 1.0 / (1.0 + t * t).sqrt();
                    let s = c * t;
                    rotate_columns(&mut w, p, q, c, s);
                    rotate_columns(&mut v, p, q, c, s);
                }
            }
            if !rotated {
                break;
            }
        }
        let singular_values = DVector::from_fn(n, |j, _| w.column(j).norm());
        Self {
            w,
            v,
            singular_values,
            transposed: false,
            support: None,
        }
    }

    /// The decomposition of A or of Aᵀ, whichever has fewer columns (Jacobi's work grows with the
    /// square of the column count): for solves, pseudo-inverses and ranks. A wide matrix (the
    /// seated-slot rows of a chain) costs a fraction of [`Self::new`]. No null space.
    ///
    /// Rows and columns of exact zeros are left out first: they change no solve and no nonzero
    /// singular value, and planar structures have many (a planar loop's out-of-plane closure
    /// rows are identically zero), which would otherwise set the work.
    pub fn thin(a: &DMatrix<f64>) -> Self {
        if let Some(support) = Support::of(a) {
            let sub = a
                .select_rows(support.rows.iter())
                .select_columns(support.cols.iter());
            return Self {
                support: Some(support),
                ..Self::thin_dense(&sub)
            };
        }
        Self::thin_dense(a)
    }

    /// [`Self::thin`] without leaving zero rows and columns out.
    fn thin_dense(a: &DMatrix<f64>) -> Self {
        if a.nrows() < a.ncols() {
            Self {
                transposed: true,
                ..Self::new(&a.transpose())
            }
        } else {
            Self::new(a)
        }
    }

    /// The threshold `RANK_TOLERANCE · σ_max` below which a singular value counts as zero.
    pub fn tolerance(&self) -> f64 {
        self.tolerance_relative(RANK_TOLERANCE)
    }

    /// `relative · σ_max`.
    pub fn tolerance_relative(&self, relative: f64) -> f64 {
        relative * self.singular_values.max().max(f64::MIN_POSITIVE)
    }

    /// Numerical rank: singular values above [`Self::tolerance`].
    pub fn rank(&self) -> usize {
        let tol = self.tolerance();
        self.singular_values.iter().filter(|s| **s > tol).count()
    }

    /// x = A⁺ b = Σ_{σⱼ > tol} vⱼ (wⱼᵀ b)/σⱼ², the minimum-norm least-squares solution.
    pub fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        self.solve_with(b, self.tolerance())
    }

    /// [`Self::solve`] with singular values at or below `tol` (absolute) dropped.
    pub fn solve_with(&self, b: &DVector<f64>, tol: f64) -> DVector<f64> {
        if let Some(sup) = &self.support {
            let x = self.solve_kept(&b.select_rows(sup.rows.iter()), tol);
            return Support::scatter(&x, &sup.cols, sup.shape.1);
        }
        self.solve_kept(b, tol)
    }

    /// [`Self::solve_with`] on the decomposed (kept) rows and columns.
    fn solve_kept(&self, b: &DVector<f64>, tol: f64) -> DVector<f64> {
        if self.transposed {
            // A = (Aᵀ)ᵀ: A⁺ b = ((Aᵀ)ᵀ)⁺ b.
            return self.solve_transposed_raw(b, tol);
        }
        self.solve_raw(b, tol)
    }

    /// Σ vⱼ (wⱼᵀ b)/σⱼ² of the stored factors.
    fn solve_raw(&self, b: &DVector<f64>, tol: f64) -> DVector<f64> {
        let mut x = DVector::zeros(self.v.nrows());
        for (j, &sigma) in self.singular_values.iter().enumerate() {
            if sigma > tol {
                let coef = self.w.column(j).dot(b) / (sigma * sigma);
                x.axpy(coef, &self.v.column(j), 1.0);
            }
        }
        x
    }

    /// y = (Aᵀ)⁺ c = Σ_{σⱼ > tol} wⱼ (vⱼᵀ c)/σⱼ², the minimum-norm least-squares solution of
    /// Aᵀ y = c (singular values at or below `tol`, absolute, dropped).
    pub fn solve_transposed_with(&self, c: &DVector<f64>, tol: f64) -> DVector<f64> {
        if let Some(sup) = &self.support {
            let y = self.solve_transposed_kept(&c.select_rows(sup.cols.iter()), tol);
            return Support::scatter(&y, &sup.rows, sup.shape.0);
        }
        self.solve_transposed_kept(c, tol)
    }

    /// [`Self::solve_transposed_with`] on the decomposed (kept) rows and columns.
    fn solve_transposed_kept(&self, c: &DVector<f64>, tol: f64) -> DVector<f64> {
        if self.transposed {
            return self.solve_raw(c, tol);
        }
        self.solve_transposed_raw(c, tol)
    }

    /// Σ wⱼ (vⱼᵀ c)/σⱼ² of the stored factors.
    fn solve_transposed_raw(&self, c: &DVector<f64>, tol: f64) -> DVector<f64> {
        let mut y = DVector::zeros(self.w.nrows());
        for (j, &sigma) in self.singular_values.iter().enumerate() {
            if sigma > tol {
                let coef = self.v.column(j).dot(c) / (sigma * sigma);
                y.axpy(coef, &self.w.column(j), 1.0);
            }
        }
        y
    }

    /// A⁺ (n × m).
    pub fn pseudo_inverse(&self) -> DMatrix<f64> {
        let tol = self.tolerance();
        // For the decomposition of Aᵀ this is (Aᵀ)⁺, transposed at the end.
        let mut out = DMatrix::zeros(self.v.nrows(), self.w.nrows());
        for (j, &sigma) in self.singular_values.iter().enumerate() {
            if sigma > tol {
                out += self.v.column(j) * self.w.column(j).transpose() / (sigma * sigma);
            }
        }
        let out = if self.transposed {
            out.transpose()
        } else {
            out
        };
        match &self.support {
            Some(sup) => {
                let mut full = DMatrix::zeros(sup.shape.1, sup.shape.0);
                for (a, &i) in sup.cols.iter().enumerate() {
                    for (b, &j) in sup.rows.iter().enumerate() {
                        full[(i, j)] = out[(a, b)];
                    }
                }
                full
            }
            None => out,
        }
    }

    /// Orthonormal basis of the null space of A (the vⱼ with σⱼ ≤ tol), as columns. Needs the
    /// full decomposition of [`Self::new`].
    ///
    /// # Panics
    /// On a decomposition from [`Self::thin`] of a wide matrix (it has no full V).
    pub fn null_space(&self) -> DMatrix<f64> {
        assert!(
            !self.transposed && self.support.is_none(),
            "JacobiSvd::null_space needs JacobiSvd::new, not thin"
        );
        let tol = self.tolerance();
        let cols: Vec<usize> = (0..self.singular_values.len())
            .filter(|&j| self.singular_values[j] <= tol)
            .collect();
        DMatrix::from_fn(self.v.nrows(), cols.len(), |i, c| self.v[(i, cols[c])])
    }
}

/// Columns (p, q) ← (c p − s q, s p + c q), p < q (on the column-major storage).
fn rotate_columns(m: &mut DMatrix<f64>, p: usize, q: usize, c: f64, s: f64) {
    let rows = m.nrows();
    let (left, right) = m.as_mut_slice().split_at_mut(q * rows);
    let cp = &mut left[p * rows..(p + 1) * rows];
    for (x, y) in cp.iter_mut().zip(&mut right[..rows]) {
        let (a, b) = (*x, *y);
        *x = c * a - s * b;
        *y = s * a + c * b;
    }
}

/// The minimum-norm least-squares solution x = A⁺ b with singular values below
/// `RANK_TOLERANCE · σ_max` treated as zero, and the numerical rank of A.
pub fn pinv_solve(a: &DMatrix<f64>, b: &DVector<f64>) -> (DVector<f64>, usize) {
    if a.nrows() == 0 || a.ncols() == 0 {
        return (DVector::zeros(a.ncols()), 0);
    }
    let svd = JacobiSvd::thin(a);
    (svd.solve(b), svd.rank())
}

/// [`pinv_solve`] for a block of columns of a larger matrix whose norm is `reference`: singular
/// values at or below `RANK_TOLERANCE · max(σ_max(A), reference)` are dropped. A block's own σ_max
/// is the wrong scale: a coordinate that does not enter the constraints at this configuration has
/// a column of round-off (1e-17), which a block of that column alone would invert, wiping the
/// coordinate's velocity in a projection.
pub fn pinv_solve_in(a: &DMatrix<f64>, b: &DVector<f64>, reference: f64) -> (DVector<f64>, usize) {
    if a.nrows() == 0 || a.ncols() == 0 {
        return (DVector::zeros(a.ncols()), 0);
    }
    let svd = JacobiSvd::thin(a);
    let tol = svd.tolerance().max(RANK_TOLERANCE * reference);
    let rank = svd.singular_values.iter().filter(|s| **s > tol).count();
    (svd.solve_with(b, tol), rank)
}

/// Orthonormal basis of the null space of A, as columns: the right singular vectors of its
/// Jacobi SVD with σ ≤ `RANK_TOLERANCE · σ_max` ([`JacobiSvd::null_space`]). A's rows of exact
/// zeros are left out first: they constrain nothing and change no singular value, and a planar
/// structure's loops have many (their out-of-plane rows), which would otherwise set the work.
pub fn null_space(a: &DMatrix<f64>) -> DMatrix<f64> {
    let rows: Vec<usize> = (0..a.nrows())
        .filter(|&i| a.row(i).iter().any(|&x| x != 0.0))
        .collect();
    if rows.len() == a.nrows() {
        return JacobiSvd::new(a).null_space();
    }
    JacobiSvd::new(&a.select_rows(rows.iter())).null_space()
}

/// A⁺, the pseudo-inverse with singular values below `RANK_TOLERANCE · σ_max` dropped.
pub fn pseudo_inverse(a: &DMatrix<f64>) -> DMatrix<f64> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return DMatrix::zeros(a.ncols(), a.nrows());
    }
    JacobiSvd::thin(a).pseudo_inverse()
}

/// Numerical rank of A (singular values above `RANK_TOLERANCE · σ_max`).
pub fn rank(a: &DMatrix<f64>) -> usize {
    if a.nrows() == 0 || a.ncols() == 0 {
        return 0;
    }
    JacobiSvd::thin(a).rank()
}

/// Chooses `r` columns of A that are as independent as possible (Gram–Schmidt with column
/// pivoting: each time the column with the largest remaining norm, the first among equals).
/// Returns them in the order chosen.
pub fn pivot_columns(a: &DMatrix<f64>, r: usize) -> Vec<usize> {
    gram_schmidt_pivoting(a, r, 0.0)
}

/// Chooses columns of A while one is left whose part outside the span of those chosen is longer
/// than `threshold`, the longest first (the first among equals). Returns them in the order
/// chosen.
///
/// The Gram–Schmidt of [`pivot_columns`], stopping on the residual norm rather than at a given
/// rank: where [`pivot_columns`] is given the rank this one finds, both choose the same
/// columns. O(m n r) for A of n × m and r columns chosen, against an SVD's several sweeps of
/// O(m n²). A choice for a caller to certify, not itself a rank decision.
pub fn pivot_columns_above(a: &DMatrix<f64>, threshold: f64) -> Vec<usize> {
    gram_schmidt_pivoting(a, a.nrows(), threshold)
}

/// Gram–Schmidt with column pivoting on A: at most `most` columns, each the longest remaining
/// (the first among equals) while it is longer than `threshold` (≥ 0). A column whose residual
/// has fallen to the threshold is dropped for good (projections only shorten it), so that the
/// columns that are dependent (most rows of a hyperstatic structure's B) cost nothing once
/// found; a dropped or chosen column is left out of the projections, which changes nothing in
/// the others'.
fn gram_schmidt_pivoting(a: &DMatrix<f64>, most: usize, threshold: f64) -> Vec<usize> {
    let m = a.ncols();
    let mut work = a.clone();
    let mut chosen = Vec::new();
    // Chosen or dropped: out of the search and of the projections.
    let mut out = vec![false; m];
    while chosen.len() < most.min(a.nrows()) {
        let mut best = (usize::MAX, -1.0);
        for j in 0..m {
            if out[j] {
                continue;
            }
            let norm = work.column(j).norm();
            if norm.is_nan() || norm <= threshold {
                out[j] = true;
            } else if norm > best.1 {
                best = (j, norm);
            }
        }
        let (best, norm) = best;
        if best == usize::MAX {
            break;
        }
        out[best] = true;
        chosen.push(best);
        let q = work.column(best) / norm;
        for j in 0..m {
            if out[j] {
                continue;
            }
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
    fn the_null_space_without_zero_rows_is_the_null_space() {
        // Rows (1, 1, 0, 0), (0, 0, 1, −1) and three zero rows: the null space is spanned by
        // (1, −1, 0, 0)/√2 and (0, 0, 1, 1)/√2 (by hand). Bases differ by a rotation, so their
        // projectors N Nᵀ are compared.
        let mut a = DMatrix::zeros(5, 4);
        a[(1, 0)] = 1.0;
        a[(1, 1)] = 1.0;
        a[(3, 2)] = 1.0;
        a[(3, 3)] = -1.0;
        let n = null_space(&a);
        assert_eq!(n.ncols(), 2);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mut by_hand = DMatrix::zeros(4, 2);
        by_hand[(0, 0)] = h;
        by_hand[(1, 0)] = -h;
        by_hand[(2, 1)] = h;
        by_hand[(3, 1)] = h;
        let diff = &n * n.transpose() - &by_hand * by_hand.transpose();
        assert!(diff.amax() <= 1e-15, "{diff}");
        // No rows at all constrain nothing.
        assert_eq!(null_space(&DMatrix::zeros(3, 4)).ncols(), 4);
    }

    #[test]
    fn the_thin_decomposition_leaves_zero_rows_and_columns_out_without_changing_a_solve() {
        // A rank-2 core (3 × 3) embedded in 6 × 5 with zero rows 1, 4, 5 and zero columns 0, 3.
        // Its minimum-norm solutions are the core's, scattered: a zero column's unknown and a
        // zero row's multiplier are 0. Checked against the normal equations of the core, solved
        // by hand through its null space (independent of the SVD).
        let core = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 3.0, 2.0, -1.0, 0.5, 3.0, 1.0, 3.5]);
        let (rows, cols) = ([0, 2, 3], [1, 2, 4]);
        let mut a = DMatrix::zeros(6, 5);
        for (i, &r) in rows.iter().enumerate() {
            for (j, &c) in cols.iter().enumerate() {
                a[(r, c)] = core[(i, j)];
            }
        }
        let b = DVector::from_column_slice(&[1.0, 7.0, -2.0, 0.5, 9.0, -4.0]);
        let thin = JacobiSvd::thin(&a);
        assert_eq!(thin.rank(), 2);
        let x = thin.solve(&b);
        for c in [0, 3] {
            assert_eq!(x[c], 0.0, "zero column {c}");
        }
        // x solves the normal equations Aᵀ A x = Aᵀ b and is orthogonal to the core's null
        // space, n = (−0.8, −1.1, 1) by hand (row 3 = row 1 + row 2 of the core; from rows 1
        // and 2, b = 2a + c/2 and 5a + 4c = 0).
        let normal = a.transpose() * (&a * &x - &b);
        assert!(
            normal.amax() <= 1e-12 * b.norm(),
            "normal equations {normal}"
        );
        let mut null = DVector::zeros(5);
        let n_core = DVector::from_column_slice(&[-0.8, -1.1, 1.0]);
        assert!((&core * &n_core).amax() < 1e-14);
        for (j, &c) in cols.iter().enumerate() {
            null[c] = n_core[j];
        }
        assert!(x.dot(&null).abs() <= 1e-12 * x.norm());
        // The transposed solve: zero rows get 0 multipliers, and Aᵀ y reproduces c when c is
        // in the range of Aᵀ.
        let c = a.transpose() * DVector::from_column_slice(&[1.0, 0.0, 2.0, -1.0, 0.0, 0.0]);
        let y = thin.solve_transposed_with(&c, thin.tolerance());
        for r in [1, 4, 5] {
            assert_eq!(y[r], 0.0, "zero row {r}");
        }
        assert!((a.transpose() * &y - &c).amax() <= 1e-12 * c.norm());
        // The pseudo-inverse has the full shape and gives the same solution.
        let pinv = thin.pseudo_inverse();
        assert_eq!(pinv.shape(), (5, 6));
        assert!((&pinv * &b - &x).amax() <= 1e-12 * x.norm());
        // All zeros: rank 0, zero solution.
        let zero = JacobiSvd::thin(&DMatrix::zeros(3, 2));
        assert_eq!(zero.rank(), 0);
        assert_eq!(
            zero.solve(&DVector::from_element(3, 1.0)),
            DVector::zeros(2)
        );
    }

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
    fn cholesky_on_both_sides_of_the_faer_crossover_factorises_solves_and_reports_pivots() {
        for n in [FAER_CHOLESKY_MIN - 1, FAER_CHOLESKY_MIN, 70] {
            // A = B Bᵀ + n I with |Bᵢⱼ| ≤ 1: eigenvalues in [n, n + ‖B‖²] ⊂ [n, n + n²], so
            // κ(A) ≤ 1 + n. Cholesky is backward stable, |L Lᵀ − A| ≤ c n ε |L||Lᵀ| (Higham,
            // thm. 10.3), and the solve's forward error is within c n ε κ |x|; c = 10 below.
            let b = DMatrix::from_fn(n, n, |i, j| (((i * 7 + j * 3) % 11) as f64 - 5.0) / 5.0);
            let a = &b * b.transpose() + DMatrix::identity(n, n) * n as f64;
            let mut l = a.clone();
            cholesky_in_place(&mut l).unwrap();
            let lower = l.lower_triangle();
            let tol = 10.0 * n as f64 * f64::EPSILON;
            assert!(
                (&lower * lower.transpose() - &a).norm() <= tol * a.norm(),
                "n = {n}"
            );
            let x_true = DVector::from_fn(n, |i, _| (i % 5) as f64 - 2.0);
            let mut rhs: Vec<f64> = (&a * &x_true).iter().copied().collect();
            cholesky_solve(&l, &mut rhs);
            let err = (DVector::from_vec(rhs) - &x_true).norm();
            assert!(
                err <= tol * (1.0 + n as f64) * x_true.norm(),
                "n = {n}: {err:e}"
            );
            // A zero pivot (row and column k of A zero) and a NaN one are reported at k.
            let k = n - 5;
            let mut singular = a.clone();
            singular.row_mut(k).fill(0.0);
            singular.column_mut(k).fill(0.0);
            assert_eq!(cholesky_in_place(&mut singular), Err(k), "n = {n}");
            let mut nan = a.clone();
            nan[(k, k)] = f64::NAN;
            assert_eq!(cholesky_in_place(&mut nan), Err(k), "n = {n}");
        }
    }

    /// Checks A = W Vᵀ, VᵀV = I and the orthogonality of W's columns, to `tol` relative to |A|.
    fn assert_decomposes(a: &DMatrix<f64>, tol: f64) -> JacobiSvd {
        let svd = JacobiSvd::new(a);
        let scale = a.norm().max(1.0);
        assert!((&svd.w * svd.v.transpose() - a).amax() <= tol * scale);
        let n = a.ncols();
        assert!((svd.v.transpose() * &svd.v - DMatrix::identity(n, n)).amax() <= tol);
        let gram = svd.w.transpose() * &svd.w;
        for i in 0..n {
            for j in 0..n {
                if i != j {
                    assert!(gram[(i, j)].abs() <= tol * scale * scale);
                }
            }
        }
        svd
    }

    #[test]
    fn jacobi_svd_decomposes_rank_deficient_matrices_to_round_off() {
        // nalgebra's SVD recomposes this one (dimforge/nalgebra#1072: a 2 × 2 matrix rebuilt with
        // singular values [1, 0]) with a visible error; Jacobi gets it to round-off and rank 1.
        let u = DMatrix::from_row_slice(2, 2, &[0.6, -0.8, 0.8, 0.6]);
        let v = DMatrix::from_row_slice(2, 2, &[0.28, 0.96, -0.96, 0.28]);
        let a = &u * DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 0.0])) * v.transpose();
        let svd = assert_decomposes(&a, 1e-14);
        assert_eq!(svd.rank(), 1);
        // Products of random factors of known rank, tall, square and wide (rows repeated as in
        // a colonnade's redundant closures).
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for (m, n, r) in [
            (12, 10, 8),
            (28, 10, 6),
            (10, 10, 10),
            (4, 9, 3),
            (12, 12, 8),
        ] {
            let left = DMatrix::from_fn(m, r, |_, _| next());
            let right = DMatrix::from_fn(r, n, |_, _| next());
            let a = left * right;
            let svd = assert_decomposes(&a, 1e-13);
            assert_eq!(svd.rank(), r, "{m}×{n} of rank {r}");
            // Moore–Penrose: A A⁺ A = A and A⁺ A A⁺ = A⁺.
            let p = svd.pseudo_inverse();
            assert!((&a * &p * &a - &a).amax() <= 1e-12 * a.norm());
            assert!((&p * &a * &p - &p).amax() <= 1e-12 * p.norm());
            // The minimum-norm solution lies in the row space: V_nullᵀ x = 0.
            let b = DVector::from_fn(m, |_, _| next());
            let x = svd.solve(&b);
            assert!((svd.null_space().transpose() * &x).amax() <= 1e-12 * x.norm());
            assert!((&x - &p * &b).amax() <= 1e-12 * x.norm());
            // (Aᵀ)⁺ c agrees with (A⁺)ᵀ c.
            let c = DVector::from_fn(n, |_, _| next());
            let y = svd.solve_transposed_with(&c, svd.tolerance());
            assert!((&y - p.transpose() * &c).amax() <= 1e-12 * y.norm().max(1.0));
            // The thin decomposition (of Aᵀ when A is wide) gives the same solves and rank. The
            // full decomposition of a wide A leaves its round-off columns (below 1000 ε‖A‖)
            // unrotated, so its solves carry errors up to about 1000 ε κ² relative, κ = σ_max/σ_r
            // of the nonzero part; the bound below is ten times that.
            let thin = JacobiSvd::thin(&a);
            assert_eq!(thin.rank(), r);
            let tol = svd.tolerance();
            let kept: Vec<f64> = svd
                .singular_values
                .iter()
                .copied()
                .filter(|s| *s > tol)
                .collect();
            let kappa = kept.iter().copied().fold(0.0, f64::max)
                / kept.iter().copied().fold(f64::INFINITY, f64::min);
            let agree = 1e4 * kappa * kappa * f64::EPSILON;
            assert!(
                (thin.solve(&b) - &x).amax() <= agree * x.norm(),
                "{m}×{n}, κ {kappa}"
            );
            let yt = thin.solve_transposed_with(&c, thin.tolerance());
            assert!((&yt - &y).amax() <= agree * y.norm(), "{m}×{n}, κ {kappa}");
            assert!(
                (thin.pseudo_inverse() - &p).amax() <= agree * p.norm(),
                "{m}×{n}, κ {kappa}"
            );
        }
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

    #[test]
    fn columns_chosen_above_a_threshold_span_the_rest_to_it() {
        // 12 columns in R⁵ from 4 random independent ones (seeded): copies, sums, a scaled copy,
        // a zero column and one 1e-10 off a sum. With the threshold 1e-7 (above the perturbation,
        // far below the independent ones' residuals, which are O(1)) 4 are chosen; every column
        // lies within the threshold of their span and the chosen ones are independent, both
        // checked by nalgebra's own SVD and least squares (not the Gram–Schmidt under test); and
        // they are the columns `pivot_columns` chooses given that rank.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let base = DMatrix::from_fn(5, 4, |_, _| uniform());
        let mut a = DMatrix::zeros(5, 12);
        let combos: [[f64; 4]; 12] = [
            [1.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 1.0, 1.0, 0.0],
            [0.5, 0.0, 0.0, 3.0],
            [0.0, 0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0, 1.0],
            [0.0, 0.0, 1.0, 0.0],
            [1.0, -1.0, 0.0, 0.0],
        ];
        for (j, c) in combos.iter().enumerate() {
            a.set_column(j, &(&base * DVector::from_row_slice(c)));
        }
        a[(2, 9)] += 1e-10;
        let threshold = 1e-7;
        let chosen = pivot_columns_above(&a, threshold);
        assert_eq!(chosen.len(), 4, "{chosen:?}");
        assert_eq!(chosen, pivot_columns(&a, 4));
        let s = DMatrix::from_fn(5, 4, |i, k| a[(i, chosen[k])]);
        let sv = s.clone().svd(true, true);
        assert!(sv.singular_values.min() > 1e-3, "{}", sv.singular_values);
        for j in 0..12 {
            let x = sv.solve(&a.column(j).into_owned(), 1e-12).unwrap();
            let residual = (&s * x - a.column(j)).norm();
            assert!(residual <= threshold, "column {j}: {residual:e}");
        }
        // The first column chosen is the longest.
        let longest = (0..12)
            .max_by(|&i, &j| a.column(i).norm().total_cmp(&a.column(j).norm()))
            .unwrap();
        assert_eq!(chosen[0], longest);
        // Nothing above a threshold larger than every column; all five directions below the
        // perturbation.
        assert!(pivot_columns_above(&a, 1e3).is_empty());
        assert_eq!(pivot_columns_above(&a, 1e-13).len(), 5);
    }
}
