//! The solve on selected rows: independent rows S of B chosen once per seated set (by
//! Gram–Schmidt with pivoting, the SVD where that choice is not certified), then Gauss' principle
//! through the Cholesky factor of B_S B_Sᵀ while the SVD would make the same rank decision.

use super::*;

/// Independent rows of B, and the problem they were chosen for.
#[derive(Clone, Debug)]
pub(super) struct RowSelection {
    pub(super) rows: usize,
    pub(super) free: usize,
    pub(super) seated: Vec<usize>,
    pub(super) selected: Vec<usize>,
}

/// Number of seated sets whose row selections [`Dynamics`] keeps: the integration's set, and
/// the uplift test's single releases (two per seated slot, one per side) and active sets.
pub(super) const SELECTION_CACHE: usize = 256;

/// Largest ‖R_D‖_F/‖B‖_F accepted by the solve on selected rows, R_D the part of the rows not
/// selected outside the span of the selected ones. Redundant closures that are exactly closed
/// leave round-off there (1e-16 … 1e-14); the projection after each step closes the loops to
/// 1e-10 relative or better, so the rows are dependent to about that. Far below the SVD's rank
/// threshold √RANK_TOLERANCE/√rows ≥ 3e-6: the rank decision is the SVD's.
pub const DEPENDENT_ROW_TOLERANCE: f64 = 1e-9;

/// Safety factor between σ_min(B_S) and the SVD's rank threshold, and between ‖R_D‖ and that
/// threshold: a margin for round-off. σ_min(B_S) > margin·threshold is certified by the Cholesky
/// factorisation of G − (margin·threshold)² I succeeding, whose backward error (about r ε ‖G‖,
/// 1e-14 ‖B‖² for r = 60) is some 1e-5 of the shift (at least RANK_TOLERANCE ‖B‖_F²); a tenth
/// covers it. (It was 10 with a bound through ‖L_G⁻¹‖_F: on a row of 32 columns whose monitor
/// solve has σ_min(B_S) within a few tenths of the threshold, every output sample fell back to
/// the SVD.)
pub(super) const RANK_MARGIN: f64 = 1.1;

/// Rows of a matrix stored by their nonzeros (compressed rows of (column, value), columns
/// ascending): B's rows, whose patterns are a loop's coordinates, so that products run over them
/// and nothing is O(rows × columns).
#[derive(Clone, Debug, Default)]
pub(crate) struct SparseRows {
    /// Number of columns.
    pub(crate) cols: usize,
    ptr: Vec<usize>,
    entries: Vec<(usize, f64)>,
}

impl SparseRows {
    /// Empties the rows (keeping the storage) for a matrix of `cols` columns.
    pub(crate) fn clear(&mut self, cols: usize) {
        self.cols = cols;
        self.ptr.clear();
        self.ptr.push(0);
        self.entries.clear();
    }

    /// Appends a row from its (column, value) entries, columns ascending.
    pub(crate) fn push_row(&mut self, entries: impl Iterator<Item = (usize, f64)>) {
        let start = self.entries.len();
        self.entries.extend(entries);
        debug_assert!(self.entries[start..].windows(2).all(|w| w[0].0 < w[1].0));
        debug_assert!(self.entries[start..].iter().all(|e| e.0 < self.cols));
        self.ptr.push(self.entries.len());
    }

    /// Number of rows.
    pub(crate) fn rows(&self) -> usize {
        self.ptr.len() - 1
    }

    /// Row i's (column, value) entries.
    pub(crate) fn row(&self, i: usize) -> &[(usize, f64)] {
        &self.entries[self.ptr[i]..self.ptr[i + 1]]
    }

    /// Row i against a dense vector.
    pub(crate) fn dot(&self, i: usize, x: &[f64]) -> f64 {
        self.row(i).iter().map(|&(j, v)| v * x[j]).sum()
    }

    /// The rows of B given as the columns of Bᵀ (exact zeros left out).
    pub(crate) fn from_transposed(bt: &DMatrix<f64>) -> Self {
        let mut rows = Self::default();
        rows.clear(bt.nrows());
        for col in bt.column_iter() {
            rows.push_row(col.iter().copied().enumerate().filter(|(_, x)| *x != 0.0));
        }
        rows
    }

    /// Bᵀ as a dense matrix (columns × rows), for the SVD.
    pub(crate) fn dense_transposed(&self) -> DMatrix<f64> {
        let mut bt = DMatrix::zeros(self.cols, self.rows());
        for i in 0..self.rows() {
            for &(j, v) in self.row(i) {
                bt[(j, i)] = v;
            }
        }
        bt
    }

    /// ‖B‖_F.
    pub(crate) fn norm(&self) -> f64 {
        self.entries.iter().map(|e| e.1 * e.1).sum::<f64>().sqrt()
    }
}

/// Workspace of [`solve_selected_rows`], kept in [`Dynamics`] so that the solve allocates
/// nothing once sized.
#[derive(Clone, Debug, Default)]
pub(crate) struct SelectedRowsWork {
    /// Whether each row of B is selected.
    is_selected: Vec<bool>,
    /// The rows not selected, in order.
    others: Vec<usize>,
    /// B_S by columns: the selected rows (by position k in `selected`) with a nonzero in column
    /// j, and their values, at `by_col_*[by_col_ptr[j]..by_col_ptr[j + 1]]`.
    by_col_ptr: Vec<usize>,
    by_col_row: Vec<usize>,
    by_col_val: Vec<f64>,
    /// Scratch of the counting sort into `by_col_*`.
    by_col_next: Vec<usize>,
    /// G = B_S B_Sᵀ (r × r, lower triangle).
    g_dense: DMatrix<f64>,
    /// L_G, the Cholesky factor of G on its pattern (closures sharing no coordinate do not
    /// couple).
    g: SparseCholesky,
    /// C, row-major (rows D × r): B_D ≈ C B_S.
    c: Vec<f64>,
    /// The rows D with a nonzero row of C (by position in `others`): a zero row of B (a planar
    /// loop's out-of-plane closure rows) has a zero row of C and a zero multiplier.
    coupled: Vec<usize>,
    /// I + C Cᵀ over the coupled rows (BᵀB when B has full column rank), then its Cholesky
    /// factor.
    nn: DMatrix<f64>,
    /// Scratch of length max(r, rows D).
    e: Vec<f64>,
    /// Scratch over the free coordinates (zero between uses): a row of R_D.
    rest: Vec<f64>,
    /// y = −G⁻¹ e_S.
    y: Vec<f64>,
    /// (BᵀB)⁻¹ dz, for the minimum-norm multipliers of a B of full column rank.
    v: Vec<f64>,
}

/// Gauss' principle on the rows `selected` of B, given as the columns of `bt` = Bᵀ
/// (n_f × m): with G = B_S B_Sᵀ = L_G L_Gᵀ, y = −G⁻¹ e_S and dz = B_Sᵀ y (e = B z + bias, the
/// constraint residual at z_free), and, when `min_norm`, the minimum-norm multipliers over all
/// rows, Bᵀλ = dz (otherwise λ_S = y, λ_D = 0: another solution of the same equations). Returns
/// false (use the SVD) unless the rank decision is provably the SVD's, within [`RANK_MARGIN`]:
/// σ_min(B_S) must exceed the margin times the SVD's threshold max(`relative`·σ_max(B),
/// `floor`) (‖B‖_F standing for σ_max(B), which it bounds above; the equations of motion use
/// √RANK_TOLERANCE, the projections RANK_TOLERANCE), certified by the Cholesky factorisation of
/// G − (margin·threshold)² I succeeding, so the SVD keeps r = |S| singular values; and the rows
/// D not selected must lie in the span of B_S:
/// B_D = C B_S + R_D with ‖R_D‖_F ≤ [`DEPENDENT_ROW_TOLERANCE`]·‖B‖_F, which bounds
/// σ_{r+1}(B) ≤ ‖R_D‖₂ far below the threshold, so the SVD drops the rest. With r = n_f
/// (B_S square) R_D = 0 by dimension and C is not formed.
///
/// The multipliers: λ_p = (y, 0) solves Bᵀλ = dz; the null space of Bᵀ is spanned by the
/// columns of N = [−Cᵀ; I] (rows S then D), so the minimum-norm solution is
/// λ = λ_p − N (NᵀN)⁻¹ Nᵀλ_p, with NᵀN = I + C Cᵀ and Nᵀλ_p = −C y: λ_S = y + Cᵀw,
/// λ_D = −w, w = −(I + C Cᵀ)⁻¹ C y. A zero row of C gives w = 0 there, so only the coupled
/// rows enter I + C Cᵀ.
///
/// Rows of B are sparse (a closure row touches the coordinates of its loop, and L⁻¹ spreads it
/// to their ancestors only; [`SparseRows`]): every product runs over a row's nonzeros, G is
/// accumulated column by column of B over the pairs of selected rows there, and factorised on
/// its pattern (banded on a row of columns), against O(m r n_f + r³) dense. What is still
/// O(r²): G's dense storage and the scan for its pattern, and C's r entries per row not
/// selected.
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_selected_rows(
    work: &mut SelectedRowsWork,
    b: &SparseRows,
    residual: &DVector<f64>,
    selected: &[usize],
    relative: f64,
    floor: f64,
    min_norm: bool,
    dz: &mut DVector<f64>,
    lambda: &mut DVector<f64>,
) -> bool {
    let (nf, m) = (b.cols, b.rows());
    let r = selected.len();
    let b_norm = b.norm();
    // A NaN or an infinity in B: the SVD reports it (a non-finite solve); an infinite
    // threshold would certify the empty selection, a NaN norm would fall back to the floor.
    if !b_norm.is_finite() {
        return false;
    }
    let threshold = (relative * b_norm).max(floor);
    work.is_selected.clear();
    work.is_selected.resize(m, false);
    for &i in selected {
        if i >= m || work.is_selected[i] {
            return false;
        }
        work.is_selected[i] = true;
    }
    work.others.clear();
    work.others.extend((0..m).filter(|&i| !work.is_selected[i]));
    let d = work.others.len();
    // B_S by columns (a counting sort over the selected rows' entries).
    work.by_col_ptr.clear();
    work.by_col_ptr.resize(nf + 1, 0);
    for &i in selected {
        for &(j, _) in b.row(i) {
            work.by_col_ptr[j + 1] += 1;
        }
    }
    for j in 0..nf {
        work.by_col_ptr[j + 1] += work.by_col_ptr[j];
    }
    let entries = work.by_col_ptr[nf];
    work.by_col_row.clear();
    work.by_col_row.resize(entries, 0);
    work.by_col_val.clear();
    work.by_col_val.resize(entries, 0.0);
    {
        let next = &mut work.by_col_next;
        next.clone_from(&work.by_col_ptr);
        for (k, &i) in selected.iter().enumerate() {
            for &(j, v) in b.row(i) {
                work.by_col_row[next[j]] = k;
                work.by_col_val[next[j]] = v;
                next[j] += 1;
            }
        }
    }
    let (by_ptr, by_row, by_val) = (&work.by_col_ptr, &work.by_col_row, &work.by_col_val);
    // out[k] = b_i · b_{S_k} for every k, over row i's columns and the selected rows there.
    let products = |i: usize, out: &mut [f64]| {
        out.fill(0.0);
        for &(j, v) in b.row(i) {
            for e in by_ptr[j]..by_ptr[j + 1] {
                out[by_row[e]] += v * by_val[e];
            }
        }
    };
    // G = B_S B_Sᵀ column of B by column of B: Σ_j over the pairs of selected rows in column j.
    if work.g_dense.nrows() != r {
        work.g_dense = DMatrix::zeros(r, r);
    } else {
        work.g_dense.fill(0.0);
    }
    for j in 0..nf {
        for e in by_ptr[j]..by_ptr[j + 1] {
            for f in by_ptr[j]..=e {
                let (k, l) = (by_row[e], by_row[f]);
                let v = by_val[e] * by_val[f];
                if k >= l {
                    work.g_dense[(k, l)] += v;
                } else {
                    work.g_dense[(l, k)] += v;
                }
            }
        }
    }
    // σ_min(B_S)² = λ_min(G) > τ exactly when G − τI is positive definite: its Cholesky
    // factorisation succeeding certifies the rank decision, provided τ is well above the
    // factorisation's backward error (about r ε ‖G‖ ≤ r ε ‖B‖_F²). The equations of motion's
    // τ = (margin·√RANK_TOLERANCE·‖B‖_F)² is 1e-9 ‖B‖_F², far above it; the projections'
    // RANK_TOLERANCE threshold squared (1e-18) is not, so τ is raised to ten times that error
    // there: rows closer to dependent than that go to the SVD. Then G itself is factorised on
    // the same pattern for the solves.
    let rounding = 10.0 * r.max(1) as f64 * f64::EPSILON * b_norm * b_norm;
    let tau = (RANK_MARGIN * threshold).powi(2).max(rounding);
    let g_dense = &work.g_dense;
    work.g.analyse(r, |k, out| {
        out.extend((0..k).filter(|&j| g_dense[(k, j)] != 0.0));
    });
    if r > 0
        && (!tau.is_finite()
            || work
                .g
                .factor(|i, j| g_dense[(i, j)] - if i == j { tau } else { 0.0 })
                .is_err())
    {
        return false;
    }
    if work.g.factor(|i, j| g_dense[(i, j)]).is_err() {
        return false;
    }
    work.e.clear();
    work.e.resize(r.max(d), 0.0);
    // C (rows D in the basis of B_S) and ‖R_D‖_F; a zero row of B has a zero row of C and R_D.
    work.c.clear();
    work.c.resize(d * r, 0.0);
    work.coupled.clear();
    work.rest.clear();
    work.rest.resize(nf, 0.0);
    let mut outside = 0.0;
    // With r = n_f, B_S is square and (certified above) nonsingular: every row lies in its
    // span, R_D = 0 by dimension, and the multipliers below need BᵀB, not C. Computing C there
    // (a solve of r² per row not selected, d r² in all: 510 × 105² on the 10 × 10 wall held on
    // every seat, at each output sample) is what this skips.
    let square = r > 0 && r == nf;
    for (a, &i) in work.others.iter().enumerate() {
        if b.row(i).is_empty() {
            continue;
        }
        work.coupled.push(a);
        if square {
            continue;
        }
        let coef = &mut work.c[a * r..(a + 1) * r];
        products(i, coef);
        work.g.solve(coef);
        // R_D's row i = b_i − Σ_k c_k b_{S_k}, on the union of their patterns.
        for &(j, v) in b.row(i) {
            work.rest[j] = v;
        }
        for (k, &ck) in coef.iter().enumerate() {
            if ck != 0.0 {
                for &(j, v) in b.row(selected[k]) {
                    work.rest[j] -= ck * v;
                }
            }
        }
        // Summed and cleared once per index (a cleared entry adds 0 when met again).
        let mut take = |j: usize| {
            outside += work.rest[j] * work.rest[j];
            work.rest[j] = 0.0;
        };
        b.row(i).iter().for_each(|&(j, _)| take(j));
        for (k, &ck) in coef.iter().enumerate() {
            if ck != 0.0 {
                b.row(selected[k]).iter().for_each(|&(j, _)| take(j));
            }
        }
    }
    let outside = outside.sqrt();
    // With no row selected (r = 0) R_D is B itself, of round-off size against the whole
    // Jacobian's floor (a free coordinate that no loop's row sees): the SVD keeps nothing where
    // ‖B‖_F, which bounds σ_max(B), is below the threshold, and both solves give dz = 0, λ = 0.
    // The test relative to ‖B‖_F is for rows dependent on selected ones.
    if outside.is_nan()
        || (r > 0 && outside > DEPENDENT_ROW_TOLERANCE * b_norm)
        || RANK_MARGIN * outside > threshold
    {
        return false;
    }
    work.y.clear();
    work.y.extend(selected.iter().map(|&i| -residual[i]));
    work.g.solve(&mut work.y);
    dz.resize_vertically_mut(nf, 0.0);
    dz.fill(0.0);
    for (k, &i) in selected.iter().enumerate() {
        for &(j, v) in b.row(i) {
            dz[j] += work.y[k] * v;
        }
    }
    lambda.resize_vertically_mut(m, 0.0);
    lambda.fill(0.0);
    for (k, &i) in selected.iter().enumerate() {
        lambda[i] = work.y[k];
    }
    let dc = work.coupled.len();
    if min_norm && dc > 0 && square {
        // B has full column rank (r = n_f independent rows): the minimum-norm λ with Bᵀλ = dz
        // is B (BᵀB)⁻¹ dz, one factorisation of n_f × n_f, where the general form below needs
        // I + C Cᵀ over the dependent rows (a structure held on every seat: d ≫ r).
        if work.nn.nrows() != nf {
            work.nn = DMatrix::zeros(nf, nf);
        } else {
            work.nn.fill(0.0);
        }
        for i in 0..m {
            let row = b.row(i);
            for (a, &(ja, va)) in row.iter().enumerate() {
                for &(jb, vb) in &row[..=a] {
                    work.nn[(ja, jb)] += va * vb;
                }
            }
        }
        if cholesky_in_place(&mut work.nn).is_err() {
            return false;
        }
        work.v.clear();
        work.v.extend(dz.iter());
        cholesky_solve(&work.nn, &mut work.v);
        for i in 0..m {
            lambda[i] = b.dot(i, &work.v);
        }
    } else if min_norm && dc > 0 {
        if work.nn.nrows() != dc {
            work.nn = DMatrix::zeros(dc, dc);
        }
        let c = &work.c;
        let c_row = |a: usize| &c[a * r..(a + 1) * r];
        let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
        for (p, &a) in work.coupled.iter().enumerate() {
            for (q, &b) in work.coupled.iter().enumerate().take(p + 1) {
                work.nn[(p, q)] = dot(c_row(a), c_row(b)) + f64::from(p == q);
            }
        }
        if cholesky_in_place(&mut work.nn).is_err() {
            return false;
        }
        let w = &mut work.e[..dc];
        for (p, x) in w.iter_mut().enumerate() {
            *x = -dot(c_row(work.coupled[p]), &work.y);
        }
        cholesky_solve(&work.nn, w);
        for (p, &a) in work.coupled.iter().enumerate() {
            let i = work.others[a];
            for (k, &s) in selected.iter().enumerate() {
                lambda[s] += c[a * r + k] * w[p];
            }
            lambda[i] = -w[p];
        }
    }
    true
}
