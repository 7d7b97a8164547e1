//! The least-norm solution of an underdetermined sparse system, A δ = r with min ‖δ‖, for
//! matrices whose pattern repeats from one call to the next (the contact faces' equilibrium rows
//! while the same points touch).
//!
//! δ = Aᵀy with (AAᵀ + εI) y = r, ε = 1e-12 of the largest diagonal entry (rows that depend on
//! each other: the caller checks the equilibrium of the result), by a sparse LDLᵀ factorisation
//! of AAᵀ (`clarabel`'s QDLDL with its approximate-minimum-degree ordering). The ordering, the
//! symbolic analysis and the map from A's column products to AAᵀ's entries are kept while A's
//! pattern is the same, so a call costs one numerical factorisation and two solves; one step of
//! iterative refinement follows. QDLDL's own regularisation stays on: a pivot below 1e-12
//! (absolute) is replaced by 1e-7, which on a rank-deficient A only damps y along AAᵀ's null
//! space (Aᵀ maps it to nothing); on an A scaled far below 1 it would spoil the answer, so
//! callers pose A in units of order one (the faces' rows in W and W·size) and check the residual
//! of what they get.

use std::fmt;

use clarabel::algebra::CscMatrix;
use clarabel::qdldl::QDLDLFactorisation;

/// The factorisation kept from the last call ([`LeastNorm::solve`]).
#[derive(Default)]
pub struct LeastNorm {
    cached: Option<Cached>,
}

/// A new workspace: the factorisation is rebuilt at the next call.
impl Clone for LeastNorm {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl fmt::Debug for LeastNorm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("LeastNorm")
            .field("cached", &self.cached.as_ref().map(|c| c.pattern.len()))
            .finish()
    }
}

struct Cached {
    /// The pattern of A it was built for: (row, column) of every entry, in the caller's order.
    pattern: Vec<(usize, usize)>,
    /// The indices into `pattern` of every column's entries.
    by_column: Vec<Vec<usize>>,
    /// 0, 1, … nnz − 1: every entry of AAᵀ is updated at each call.
    indices: Vec<usize>,
    /// For every pair of entries (a, b) of one column with row(a) ≤ row(b), in the order
    /// [`products`] visits them, the index of AAᵀ's upper-triangle entry it adds to.
    map: Vec<usize>,
    /// The index of every diagonal entry of AAᵀ.
    diagonal: Vec<usize>,
    /// The number of entries of AAᵀ's upper triangle.
    nnz: usize,
    factor: QDLDLFactorisation<f64>,
}

impl LeastNorm {
    /// The least-norm δ (`columns` long) with A δ = `r`, A the `rows` × `columns` matrix of
    /// `entries` (row, column, value; each (row, column) once). None when an entry lies outside
    /// the matrix, `r` is not `rows` long, or the factorisation fails.
    pub fn solve(
        &mut self,
        rows: usize,
        columns: usize,
        entries: &[(usize, usize, f64)],
        r: &[f64],
    ) -> Option<Vec<f64>> {
        if r.len() != rows || entries.iter().any(|e| e.0 >= rows || e.1 >= columns) {
            return None;
        }
        let same = self.cached.as_ref().is_some_and(|c| {
            c.pattern.len() == entries.len()
                && c.pattern
                    .iter()
                    .zip(entries)
                    .all(|(p, e)| p.0 == e.0 && p.1 == e.1)
                && c.diagonal.len() == rows
                && c.by_column.len() == columns
        });
        if !same {
            self.cached = Some(Cached::new(rows, columns, entries)?);
        }
        let cached = self.cached.as_mut()?;
        let mut values = vec![0.0; cached.nnz];
        let mut next = 0;
        products(&cached.by_column, entries, |_, _, v| {
            values[cached.map[next]] += v;
            next += 1;
        });
        let epsilon = 1e-12
            * cached
                .diagonal
                .iter()
                .fold(0.0_f64, |m, &d| m.max(values[d]));
        for &d in &cached.diagonal {
            values[d] += epsilon;
        }
        cached.factor.update_values(&cached.indices, &values);
        cached.factor.refactor().ok()?;
        // δ = Aᵀy, then once more on the residual.
        let mut delta = vec![0.0; columns];
        let mut residual = r.to_vec();
        for _ in 0..2 {
            let mut y = residual.clone();
            cached.factor.solve(&mut y);
            if y.iter().any(|v| !v.is_finite()) {
                return None;
            }
            for &(row, c, v) in entries {
                delta[c] += v * y[row];
            }
            residual.copy_from_slice(r);
            for &(row, c, v) in entries {
                residual[row] -= v * delta[c];
            }
        }
        Some(delta)
    }
}

impl Cached {
    /// AAᵀ's pattern, the map of the column products onto it, and its symbolic and first
    /// numerical factorisation (of the pattern with a unit diagonal; the caller refactors with
    /// the values).
    fn new(rows: usize, columns: usize, entries: &[(usize, usize, f64)]) -> Option<Self> {
        let by_column = column_lists(columns, entries);
        let (mut ri, mut ci) = (Vec::new(), Vec::new());
        products(&by_column, entries, |i, j, _| {
            ri.push(i);
            ci.push(j);
        });
        let pairs = ri.len();
        ri.extend(0..rows);
        ci.extend(0..rows);
        let values = (0..ri.len())
            .map(|k| if k >= pairs { 1.0 } else { 0.0 })
            .collect();
        let aat = CscMatrix::new_from_triplets(rows, rows, ri.clone(), ci.clone(), values);
        // Every (i, j) is in the pattern built from them (rows sorted within each column).
        let position = |i: usize, j: usize| {
            let (start, end) = (aat.colptr[j], aat.colptr[j + 1]);
            aat.rowval[start..end]
                .binary_search(&i)
                .ok()
                .map(|k| start + k)
        };
        let map = (0..pairs)
            .map(|k| position(ri[k], ci[k]))
            .collect::<Option<Vec<_>>>()?;
        let diagonal = (0..rows)
            .map(|i| position(i, i))
            .collect::<Option<Vec<_>>>()?;
        let nnz = aat.nzval.len();
        let factor = QDLDLFactorisation::new(&aat, None).ok()?;
        Some(Self {
            pattern: entries.iter().map(|e| (e.0, e.1)).collect(),
            by_column,
            indices: (0..nnz).collect(),
            map,
            diagonal,
            nnz,
            factor,
        })
    }
}

/// The indices into `entries` of every column's entries.
fn column_lists(columns: usize, entries: &[(usize, usize, f64)]) -> Vec<Vec<usize>> {
    let mut by_column = vec![Vec::new(); columns];
    for (k, e) in entries.iter().enumerate() {
        by_column[e.1].push(k);
    }
    by_column
}

/// Calls `add(i, j, aᵢ aⱼ)` for every pair of entries of one column with rows i ≤ j: the terms
/// of AAᵀ's upper triangle, in a fixed order for a fixed pattern.
fn products(
    by_column: &[Vec<usize>],
    entries: &[(usize, usize, f64)],
    mut add: impl FnMut(usize, usize, f64),
) {
    for column in by_column {
        for &a in column {
            for &b in column {
                let (i, j) = (entries[a].0, entries[b].0);
                if i <= j {
                    add(i, j, entries[a].2 * entries[b].2);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// A deterministic sequence in (−1, 1).
    fn wobble(seed: usize) -> f64 {
        ((seed as f64 * 12.9898).sin() * 43_758.545_3).fract()
    }

    /// A sparse `rows` × `columns` matrix whose column c touches rows c mod rows and
    /// (3c + 1) mod rows (the equilibrium rows of two bodies a contact joins), values from `seed`.
    fn sparse(rows: usize, columns: usize, seed: usize) -> Vec<(usize, usize, f64)> {
        let mut entries = Vec::new();
        for c in 0..columns {
            let (a, b) = (c % rows, (3 * c + 1) % rows);
            entries.push((a, c, 1.0 + wobble(seed + 2 * c)));
            if b != a {
                entries.push((b, c, wobble(seed + 2 * c + 1)));
            }
        }
        entries
    }

    /// The least-norm solution of the dense matrix by a Householder QR of Aᵀ = QR (full row
    /// rank): δ = Q R⁻ᵀ r lies in the row space of A and solves A δ = Rᵀ Qᵀ Q R⁻ᵀ r = r.
    fn qr_solution(
        rows: usize,
        columns: usize,
        entries: &[(usize, usize, f64)],
        r: &[f64],
    ) -> DVector<f64> {
        let mut a = DMatrix::zeros(rows, columns);
        for &(i, j, v) in entries {
            a[(i, j)] = v;
        }
        let qr = a.transpose().qr();
        let z = qr
            .r()
            .transpose()
            .solve_lower_triangular(&DVector::from_column_slice(r))
            .expect("full row rank");
        qr.q() * z
    }

    /// Against a QR of the dense matrix to 1e-12 relative, on a first pattern (factorised anew), the
    /// same pattern with other values (the kept ordering and symbolic analysis, refactorised),
    /// and a different pattern (built again); the result also solves A δ = r to round-off.
    #[test]
    fn the_least_norm_solution_is_the_qr_one() {
        let mut solver = LeastNorm::default();
        let (rows, columns) = (30, 80);
        for (case, (cols, seed)) in [(columns, 1), (columns, 500), (columns + 7, 900)]
            .into_iter()
            .enumerate()
        {
            let entries = sparse(rows, cols, seed);
            let r: Vec<f64> = (0..rows).map(|i| wobble(seed + 7919 + i)).collect();
            let delta = solver.solve(rows, cols, &entries, &r).expect("solves");
            let expected = qr_solution(rows, cols, &entries, &r);
            let error = (DVector::from_column_slice(&delta) - &expected).norm();
            assert!(
                error <= 1e-12 * expected.norm(),
                "case {case}: {error:e} of {:e}",
                expected.norm()
            );
            let mut residual = r.clone();
            for &(i, j, v) in &entries {
                residual[i] -= v * delta[j];
            }
            let worst = residual.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
            assert!(worst <= 1e-13, "case {case}: residual {worst:e}");
        }
    }

    /// A rank-deficient A (row 6 a copy of row 5, row 7 zero: a face's rows that depend on
    /// others) with a consistent right-hand side r = A x₀: δ solves A δ = r to round-off and lies
    /// in the row space of A, the two conditions that define the least-norm solution, checked
    /// with the row space from an SVD of the dense matrix (singular values above 1e-10).
    #[test]
    fn a_rank_deficient_consistent_system_gets_its_least_norm_solution() {
        let (rows, columns) = (30, 80);
        let entries: Vec<(usize, usize, f64)> = sparse(rows, columns, 7)
            .into_iter()
            .filter(|e| e.0 != 6 && e.0 != 7)
            .flat_map(|e| {
                let copy = (e.0 == 5).then_some((6, e.1, e.2));
                std::iter::once(e).chain(copy)
            })
            .collect();
        let mut a = DMatrix::zeros(rows, columns);
        for &(i, j, v) in &entries {
            a[(i, j)] = v;
        }
        let x0 = DVector::from_fn(columns, |j, _| wobble(31 + j));
        let r: Vec<f64> = (&a * &x0).iter().copied().collect();
        let delta = DVector::from_column_slice(
            &LeastNorm::default()
                .solve(rows, columns, &entries, &r)
                .expect("solves"),
        );
        let residual = (&a * &delta - DVector::from_column_slice(&r)).amax();
        assert!(residual <= 1e-13, "residual {residual:e}");
        let svd = a.svd(false, true);
        let v_t = svd.v_t.expect("V");
        let kept: Vec<usize> = (0..svd.singular_values.len())
            .filter(|&k| svd.singular_values[k] > 1e-10)
            .collect();
        assert_eq!(kept.len(), rows - 2, "rank");
        let mut in_row_space = DVector::zeros(columns);
        for &k in &kept {
            let v = v_t.row(k).transpose();
            in_row_space += &v * v.dot(&delta);
        }
        let outside = (&delta - in_row_space).norm();
        assert!(
            outside <= 1e-12 * delta.norm(),
            "{outside:e} of {:e} outside the row space",
            delta.norm()
        );
    }
}
