//! Cholesky factorisation A = L Lᵀ of a symmetric positive definite matrix on its nonzero
//! pattern: the mass matrix of a tree (M_ij ≠ 0 only when one coordinate carries the other's
//! bodies) and the Gram matrix of loop closures that share few coordinates are mostly zeros, and
//! a dense factorisation and dense triangular solves spend their time on them.
//!
//! The pattern of L is found first (the elimination tree and the row patterns, by Liu's
//! algorithm as in Davis, *Direct Methods for Sparse Linear Systems*, SIAM 2006, §4.1–4.2),
//! then the numbers row by row (up-looking), with L kept in dense storage that is zero outside
//! the pattern. Ordered with every coordinate after its descendants (Featherstone's L^T L order,
//! *Rigid Body Dynamics Algorithms*, 2008, §6.5), a tree's mass matrix has no fill: row k of L
//! holds k's descendants only. The triangular solves skip zero entries of the right-hand side,
//! so a closure row touching a few coordinates costs what those coordinates carry.
//!
//! When the pattern is nearly full (a single long chain) the dense blocked factorisation of
//! [`crate::linalg`] is faster and is used instead.

use nalgebra::DMatrix;

use crate::linalg::{back_substitute_transposed, cholesky_in_place, forward_substitute};

/// Fraction of the lower triangle from which the pattern counts as full: the factorisation
/// then runs [`cholesky_in_place`] (faer's blocked kernel from 32 rows) and dense solves.
const DENSE_FRACTION: f64 = 0.5;

/// L of A = L Lᵀ on A's pattern, with the patterns of its rows and columns.
#[derive(Clone, Debug, Default)]
pub struct SparseCholesky {
    /// Order n.
    n: usize,
    /// L in dense storage (n × n): zero outside the pattern and above the diagonal.
    l: DMatrix<f64>,
    /// Row k's nonzero columns j < k, ascending: `row_idx[row_ptr[k]..row_ptr[k + 1]]`.
    row_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Column j's nonzero rows k > j, ascending: `col_idx[col_ptr[j]..col_ptr[j + 1]]`.
    col_ptr: Vec<usize>,
    col_idx: Vec<usize>,
    /// The pattern is nearly full: dense factorisation and solves.
    dense: bool,
    /// Scratch of [`Self::analyse`]: elimination-tree parents, visit marks, a row's entries.
    parent: Vec<usize>,
    mark: Vec<usize>,
    entries: Vec<usize>,
}

impl SparseCholesky {
    /// The pattern of L for a matrix of order `n` whose strictly lower nonzeros are, for each row
    /// k, the columns `lower(k)` (j < k, any order, repeats allowed). Keeps the numbers of a
    /// previous pattern out of the new one.
    pub fn analyse(&mut self, n: usize, mut lower: impl FnMut(usize, &mut Vec<usize>)) {
        const NONE: usize = usize::MAX;
        if self.l.nrows() != n {
            self.l = DMatrix::zeros(n, n);
        } else if self.dense {
            self.l.fill(0.0);
        } else {
            // Only the old pattern below the diagonal holds numbers (the diagonal is rewritten).
            for k in 0..self.n {
                for &j in &self.row_idx[self.row_ptr[k]..self.row_ptr[k + 1]] {
                    self.l[(k, j)] = 0.0;
                }
            }
        }
        self.n = n;
        self.row_ptr.clear();
        self.row_idx.clear();
        self.row_ptr.push(0);
        let (parent, mark, entries) = (&mut self.parent, &mut self.mark, &mut self.entries);
        parent.clear();
        parent.resize(n, NONE);
        mark.clear();
        mark.resize(n, NONE);
        for k in 0..n {
            mark[k] = k;
            let start = self.row_idx.len();
            entries.clear();
            lower(k, entries);
            // Row k of L: every node on the elimination-tree paths from A's nonzeros up to k.
            for &i in entries.iter() {
                debug_assert!(i < k, "lower pattern of row {k} holds column {i}");
                let mut j = i;
                while mark[j] != k {
                    mark[j] = k;
                    self.row_idx.push(j);
                    if parent[j] == NONE {
                        parent[j] = k;
                    }
                    j = parent[j];
                }
            }
            self.row_idx[start..].sort_unstable();
            self.row_ptr.push(self.row_idx.len());
        }
        // Columns from rows (a counting sort keeps each column's rows ascending).
        let mut count = vec![0usize; n + 1];
        for &j in &self.row_idx {
            count[j + 1] += 1;
        }
        for j in 0..n {
            count[j + 1] += count[j];
        }
        self.col_ptr.clone_from(&count);
        self.col_idx.clear();
        self.col_idx.resize(self.row_idx.len(), 0);
        for k in 0..n {
            for &j in &self.row_idx[self.row_ptr[k]..self.row_ptr[k + 1]] {
                self.col_idx[count[j]] = k;
                count[j] += 1;
            }
        }
        let lower_entries = (n * n.saturating_sub(1) / 2).max(1);
        self.dense = self.row_idx.len() as f64 > DENSE_FRACTION * lower_entries as f64;
    }

    /// The pattern of a dense matrix's nonzeros (exact zeros left out) and its factorisation.
    pub fn factor_dense(&mut self, a: &DMatrix<f64>) -> Result<(), usize> {
        let n = a.nrows();
        self.analyse(n, |k, out| out.extend((0..k).filter(|&j| a[(k, j)] != 0.0)));
        self.factor(|i, j| a[(i, j)])
    }

    /// Factorises A (its lower triangle given by `a(i, j)`, i ≥ j, on the analysed pattern:
    /// entries outside it must be zero). Returns the failing pivot on a non-positive or
    /// non-finite one.
    pub fn factor(&mut self, a: impl Fn(usize, usize) -> f64) -> Result<(), usize> {
        let n = self.n;
        if self.dense {
            for j in 0..n {
                for i in j..n {
                    self.l[(i, j)] = a(i, j);
                }
            }
            cholesky_in_place(&mut self.l)?;
            // faer's blocked kernel leaves scratch above the diagonal; the solves read below.
            return Ok(());
        }
        for k in 0..n {
            let row = &self.row_idx[self.row_ptr[k]..self.row_ptr[k + 1]];
            let mut d = a(k, k);
            for &j in row {
                let mut s = a(k, j);
                for &i in &self.row_idx[self.row_ptr[j]..self.row_ptr[j + 1]] {
                    s -= self.l[(k, i)] * self.l[(j, i)];
                }
                let x = s / self.l[(j, j)];
                self.l[(k, j)] = x;
                d -= x * x;
            }
            if !(d > 0.0 && d.is_finite()) {
                return Err(k);
            }
            self.l[(k, k)] = d.sqrt();
        }
        Ok(())
    }

    /// Order n.
    pub fn order(&self) -> usize {
        self.n
    }

    /// Nonzeros of L below the diagonal.
    pub fn lower_nonzeros(&self) -> usize {
        self.row_idx.len()
    }

    /// Solves L y = b in place; zero entries of b cost nothing until fill reaches them.
    pub fn forward(&self, b: &mut [f64]) {
        if self.dense {
            return forward_substitute(&self.l, b);
        }
        for j in 0..self.n {
            if b[j] == 0.0 {
                continue;
            }
            let x = b[j] / self.l[(j, j)];
            b[j] = x;
            for &k in &self.col_idx[self.col_ptr[j]..self.col_ptr[j + 1]] {
                b[k] -= self.l[(k, j)] * x;
            }
        }
    }

    /// [`Self::forward`] on a right-hand side whose nonzeros lie in `pattern` (ascending), a set
    /// closed under the elimination tree's parents (every row below a pattern entry in L's
    /// columns is in the pattern): then x has the same pattern, and only its entries are
    /// visited. The same operations in the same order as [`Self::forward`], which skips the
    /// zeros outside the pattern. On a tree-ordered mass matrix the coordinates on the paths
    /// to the ground of a loop's two frames are such a set (a closure row's pattern).
    pub fn forward_on(&self, pattern: &[usize], b: &mut [f64]) {
        if self.dense {
            return forward_substitute(&self.l, b);
        }
        for &j in pattern {
            if b[j] == 0.0 {
                continue;
            }
            let x = b[j] / self.l[(j, j)];
            b[j] = x;
            for &k in &self.col_idx[self.col_ptr[j]..self.col_ptr[j + 1]] {
                debug_assert!(
                    pattern.binary_search(&k).is_ok(),
                    "pattern not closed at {k}"
                );
                b[k] -= self.l[(k, j)] * x;
            }
        }
    }

    /// Solves Lᵀ x = y in place.
    pub fn backward_transposed(&self, b: &mut [f64]) {
        if self.dense {
            return back_substitute_transposed(&self.l, b);
        }
        for i in (0..self.n).rev() {
            let mut s = b[i];
            for &k in &self.col_idx[self.col_ptr[i]..self.col_ptr[i + 1]] {
                s -= self.l[(k, i)] * b[k];
            }
            b[i] = s / self.l[(i, i)];
        }
    }

    /// Solves A x = b in place.
    pub fn solve(&self, b: &mut [f64]) {
        self.forward(b);
        self.backward_transposed(b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mass-matrix pattern of a tree given by parents (parent < child): i and j related when
    /// one is an ancestor of the other. Filled with a diagonally dominant matrix on it.
    fn tree_matrix(parents: &[Option<usize>]) -> DMatrix<f64> {
        let n = parents.len();
        let mut a = DMatrix::zeros(n, n);
        for c in 0..n {
            let mut p = parents[c];
            while let Some(q) = p {
                let v = 0.3 + 0.1 * ((c * 7 + q * 3) % 5) as f64;
                a[(c, q)] = v;
                a[(q, c)] = v;
                p = parents[q];
            }
        }
        for i in 0..n {
            a[(i, i)] = 1.0 + a.row(i).iter().map(|x: &f64| x.abs()).sum::<f64>();
        }
        a
    }

    #[test]
    fn a_tree_in_descendants_first_order_factorises_without_fill_and_solves_as_dense_does() {
        // A tree with branching: 0 → {1, 2}, 1 → {3, 4}, 2 → 5, 5 → {6, 7}, 4 → 8.
        let parents = [
            None,
            Some(0),
            Some(0),
            Some(1),
            Some(1),
            Some(2),
            Some(5),
            Some(5),
            Some(4),
        ];
        let a = tree_matrix(&parents);
        let n = a.nrows();
        // Descendants first: reverse the (parents-first) order.
        let perm: Vec<usize> = (0..n).rev().collect();
        let pa = DMatrix::from_fn(n, n, |i, j| a[(perm[i], perm[j])]);
        let mut chol = SparseCholesky::default();
        chol.factor_dense(&pa).unwrap();
        assert!(!chol.dense);
        // No fill: L's lower nonzeros are the ancestor pairs, Σ depth = 0+1+1+2+2+2+3+3+3.
        assert_eq!(chol.lower_nonzeros(), 17);
        // L Lᵀ = A to round-off (backward stability, Higham thm. 10.3: c n ε |L||Lᵀ|).
        let l = chol.l.lower_triangle();
        assert!((&l * l.transpose() - &pa).amax() <= 10.0 * n as f64 * f64::EPSILON * pa.amax());
        // Solves agree with the dense Cholesky to round-off (κ(A) < 10 here).
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        let mut x = b.clone();
        chol.solve(&mut x);
        let mut dense = pa.clone();
        cholesky_in_place(&mut dense).unwrap();
        let mut y = b.clone();
        crate::linalg::cholesky_solve(&dense, &mut y);
        for i in 0..n {
            assert!((x[i] - y[i]).abs() <= 1e-14, "x[{i}] {} vs {}", x[i], y[i]);
        }
        // A right-hand side with one nonzero: the forward solve touches its ancestors only.
        let mut e = vec![0.0; n];
        e[perm.iter().position(|&c| c == 6).unwrap()] = 1.0;
        chol.forward(&mut e);
        let touched: Vec<usize> = (0..n).filter(|&i| e[i] != 0.0).map(|i| perm[i]).collect();
        let mut expected = vec![0, 2, 5, 6];
        expected.sort_unstable();
        let mut touched = touched;
        touched.sort_unstable();
        assert_eq!(touched, expected);
        // A right-hand side on the paths of nodes 8 and 6 to the root (a closure row between
        // their frames: 8, 4, 1, 0 and 6, 5, 2, 0): the solve over that pattern alone gives the
        // full solve's result to the last bit.
        let on_paths = [8, 4, 1, 0, 6, 5, 2];
        let mut pattern: Vec<usize> = on_paths
            .iter()
            .map(|c| perm.iter().position(|p| p == c).unwrap())
            .collect();
        pattern.sort_unstable();
        let mut full = vec![0.0; n];
        for (k, &i) in pattern.iter().enumerate() {
            full[i] = 0.4 - 0.13 * k as f64;
        }
        let mut on = full.clone();
        chol.forward(&mut full);
        chol.forward_on(&pattern, &mut on);
        assert_eq!(full, on);
        assert!((0..n).all(|i| pattern.contains(&i) || on[i] == 0.0));
    }

    #[test]
    fn parents_first_order_fills_between_siblings_and_still_factorises_exactly() {
        // Root-first, a node with two children fills between their subtrees (Liu): the pattern
        // is found by the elimination tree and the factor is still exact.
        let parents = [None, Some(0), Some(0), Some(1), Some(2)];
        let a = tree_matrix(&parents);
        let mut chol = SparseCholesky::default();
        chol.factor_dense(&a).unwrap();
        let l = chol.l.lower_triangle();
        assert!((&l * l.transpose() - &a).amax() <= 50.0 * f64::EPSILON * a.amax());
        // Ancestor pairs 1-0, 2-0, 3-1, 3-0, 4-2, 4-0 and fill 2-1, 3-2, 4-1, 4-3 (the
        // elimination tree is the path 0-1-2-3-4).
        assert_eq!(chol.lower_nonzeros(), 10);
    }

    #[test]
    fn a_full_pattern_uses_the_dense_kernel_and_a_failing_pivot_is_reported() {
        let n = 40;
        let b = DMatrix::from_fn(n, n, |i, j| (((i * 7 + j * 3) % 11) as f64 - 5.0) / 5.0);
        let a = &b * b.transpose() + DMatrix::identity(n, n) * n as f64;
        let mut chol = SparseCholesky::default();
        chol.factor_dense(&a).unwrap();
        assert!(chol.dense);
        let x_true: Vec<f64> = (0..n).map(|i| i as f64 - 3.0).collect();
        let mut x = (&a * DMatrix::from_column_slice(n, 1, &x_true))
            .as_slice()
            .to_vec();
        chol.solve(&mut x);
        // κ(A) ≤ 1 + n (see linalg's test): forward error within 10 n ε κ |x|.
        let tol = 10.0 * (n * (n + 1)) as f64 * f64::EPSILON * 40.0;
        for i in 0..n {
            assert!((x[i] - x_true[i]).abs() <= tol);
        }
        // Sparse and singular: [[1, 1, 0], [1, 1, 0], [0, 0, 1]] fails at pivot 1.
        let s = DMatrix::from_row_slice(3, 3, &[1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(chol.factor_dense(&s), Err(1));
    }
}
