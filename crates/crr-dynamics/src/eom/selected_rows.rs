//! The solve on selected rows: independent rows S of B chosen once by the SVD, then Gauss'
//! principle through the Cholesky factor of B_S B_Sᵀ while the SVD would make the same rank
//! decision.

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

/// Safety factor between the lower bound on σ_min(B_S) and the SVD's rank threshold, and
/// between ‖R_D‖ and that threshold: a margin for the round-off of both computations. The bound
/// on σ_min(B_S) is certified (an upper bound on ‖G⁻¹‖₂, not an estimate), and the round-off of
/// G = B_S B_Sᵀ moves its eigenvalues by about r ε σ_max(B)² (1e-14 σ_max² for r = 60), far below
/// the squared threshold RANK_TOLERANCE σ_max² = 1e-9 σ_max²: a factor 2 covers it. (It was 10
/// with the looser trace bound; on a row of 16 columns σ_min(B_S) sits 7.6 times above the
/// threshold and every output sample fell back to the SVD.)
pub(super) const RANK_MARGIN: f64 = 2.0;

/// Workspace of [`solve_selected_rows`], kept in [`Dynamics`] so that the solve allocates
/// nothing once sized.
#[derive(Clone, Debug, Default)]
pub(crate) struct SelectedRowsWork {
    /// Whether each row of B is selected.
    is_selected: Vec<bool>,
    /// The rows not selected, in order.
    others: Vec<usize>,
    /// The nonzero columns of each row of B: `nz_idx[nz_ptr[i]..nz_ptr[i + 1]]`.
    nz_ptr: Vec<usize>,
    nz_idx: Vec<usize>,
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
    /// I + C Cᵀ over the coupled rows, then its Cholesky factor.
    nn: DMatrix<f64>,
    /// Scratch of length max(r, rows D).
    e: Vec<f64>,
    /// The absolute row sums of L_G⁻¹.
    row_sums: Vec<f64>,
    /// Scratch over the free coordinates (zero between uses): a row of R_D.
    rest: Vec<f64>,
    /// y = −G⁻¹ e_S.
    y: Vec<f64>,
}

/// Gauss' principle on the rows `selected` of B, given as the columns of `bt` = Bᵀ
/// (n_f × m): with G = B_S B_Sᵀ = L_G L_Gᵀ, y = −G⁻¹ e_S and dz = B_Sᵀ y (e = B z + bias, the
/// constraint residual at z_free), and, when `min_norm`, the minimum-norm multipliers over all
/// rows, Bᵀλ = dz (otherwise λ_S = y, λ_D = 0: another solution of the same equations). Returns
/// false (use the SVD) unless the rank decision is provably the SVD's, within [`RANK_MARGIN`]:
/// σ_min(B_S)² ≥ 1/b, b an upper bound of ‖G⁻¹‖₂ from L_G⁻¹, must exceed the SVD's threshold
/// max(`relative`·σ_max(B), `floor`) (bounded above by `relative`·‖B‖_F; the equations of motion
/// use √RANK_TOLERANCE, the projections RANK_TOLERANCE), so the SVD keeps r = |S| singular
/// values; and the rows D not selected must lie in the span of B_S:
/// B_D = C B_S + R_D with ‖R_D‖_F ≤ [`DEPENDENT_ROW_TOLERANCE`]·‖B‖_F, which bounds
/// σ_{r+1}(B) ≤ ‖R_D‖₂ far below the threshold, so the SVD drops the rest.
///
/// The multipliers: λ_p = (y, 0) solves Bᵀλ = dz; the null space of Bᵀ is spanned by the
/// columns of N = [−Cᵀ; I] (rows S then D), so the minimum-norm solution is
/// λ = λ_p − N (NᵀN)⁻¹ Nᵀλ_p, with NᵀN = I + C Cᵀ and Nᵀλ_p = −C y: λ_S = y + Cᵀw,
/// λ_D = −w, w = −(I + C Cᵀ)⁻¹ C y. A zero row of C gives w = 0 there, so only the coupled
/// rows enter I + C Cᵀ.
///
/// Rows of B are sparse (a closure row touches the coordinates of its loop, and L⁻¹ spreads it
/// to their ancestors only): every product runs over a row's nonzeros. Work on a colonnade of k
/// columns: O(k) for the rows and G's banded factor, against O(m r n_f + r³) dense.
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_selected_rows(
    work: &mut SelectedRowsWork,
    bt: &DMatrix<f64>,
    residual: &DVector<f64>,
    selected: &[usize],
    relative: f64,
    floor: f64,
    min_norm: bool,
    dz: &mut DVector<f64>,
    lambda: &mut DVector<f64>,
) -> bool {
    let (nf, m) = (bt.nrows(), bt.ncols());
    let r = selected.len();
    let row = |i: usize| &bt.as_slice()[i * nf..(i + 1) * nf];
    let b_norm = bt.norm();
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
    work.nz_ptr.clear();
    work.nz_idx.clear();
    work.nz_ptr.push(0);
    for i in 0..m {
        work.nz_idx.extend(
            row(i)
                .iter()
                .enumerate()
                .filter(|(_, x)| **x != 0.0)
                .map(|(j, _)| j),
        );
        work.nz_ptr.push(work.nz_idx.len());
    }
    let (nz_ptr, nz_idx) = (&work.nz_ptr, &work.nz_idx);
    let nz = |i: usize| &nz_idx[nz_ptr[i]..nz_ptr[i + 1]];
    // Row i of B against a dense vector, over i's nonzeros.
    let sdot = |i: usize, other: &[f64]| {
        let ri = row(i);
        nz(i).iter().map(|&j| ri[j] * other[j]).sum::<f64>()
    };
    if work.g_dense.nrows() != r {
        work.g_dense = DMatrix::zeros(r, r);
    }
    for k in 0..r {
        for l in 0..=k {
            let (a, b) = (selected[k], selected[l]);
            // Over the shorter pattern.
            work.g_dense[(k, l)] = if nz(a).len() <= nz(b).len() {
                sdot(a, row(b))
            } else {
                sdot(b, row(a))
            };
        }
    }
    if work.g.factor_dense(&work.g_dense).is_err() {
        return false;
    }
    // ‖G⁻¹‖₂ = ‖L_G⁻¹‖₂² = 1/σ_min(B_S)², bounded above by both ‖L_G⁻¹‖_F² (the trace of G⁻¹)
    // and ‖L_G⁻¹‖₁‖L_G⁻¹‖_∞ (‖A‖₂² ≤ ‖A‖₁‖A‖_∞), from the columns of L_G⁻¹ alone. The trace
    // counts every eigenvalue, r times too much on a flat spectrum (a long row of loops); the
    // product of the column and row sums is close to ‖L_G⁻¹‖₂² when L_G⁻¹ is near diagonal.
    let (mut frobenius2, mut column_sum) = (0.0f64, 0.0f64);
    work.e.clear();
    work.e.resize(r.max(d), 0.0);
    work.row_sums.clear();
    work.row_sums.resize(r, 0.0);
    for k in 0..r {
        let e = &mut work.e[..r];
        e.fill(0.0);
        e[k] = 1.0;
        work.g.forward(e);
        let mut sum = 0.0;
        for (x, row_sum) in e[k..].iter().zip(&mut work.row_sums[k..]) {
            frobenius2 += x * x;
            sum += x.abs();
            *row_sum += x.abs();
        }
        column_sum = column_sum.max(sum);
    }
    let row_sum = work.row_sums.iter().fold(0.0f64, |a, &b| a.max(b));
    let inv_norm2 = frobenius2.min(column_sum * row_sum);
    // A NaN fails the check too.
    let sigma_min = 1.0 / inv_norm2.sqrt();
    if r > 0 && (sigma_min.is_nan() || sigma_min <= RANK_MARGIN * threshold) {
        return false;
    }
    // C (rows D in the basis of B_S) and ‖R_D‖_F; a zero row of B has a zero row of C and R_D.
    work.c.clear();
    work.c.resize(d * r, 0.0);
    work.coupled.clear();
    work.rest.clear();
    work.rest.resize(nf, 0.0);
    let mut outside = 0.0;
    for (a, &i) in work.others.iter().enumerate() {
        if nz(i).is_empty() {
            continue;
        }
        work.coupled.push(a);
        let coef = &mut work.c[a * r..(a + 1) * r];
        for (k, x) in coef.iter_mut().enumerate() {
            *x = sdot(i, row(selected[k]));
        }
        work.g.solve(coef);
        // R_D's row i = b_i − Σ_k c_k b_{S_k}, on the union of their patterns.
        let ri = row(i);
        for &j in nz(i) {
            work.rest[j] = ri[j];
        }
        for (k, &ck) in coef.iter().enumerate() {
            if ck != 0.0 {
                let rk = row(selected[k]);
                for &j in nz(selected[k]) {
                    work.rest[j] -= ck * rk[j];
                }
            }
        }
        // Summed and cleared once per index (a cleared entry adds 0 when met again).
        let mut take = |j: usize| {
            outside += work.rest[j] * work.rest[j];
            work.rest[j] = 0.0;
        };
        nz(i).iter().for_each(|&j| take(j));
        for (k, &ck) in coef.iter().enumerate() {
            if ck != 0.0 {
                nz(selected[k]).iter().for_each(|&j| take(j));
            }
        }
    }
    let outside = outside.sqrt();
    if outside.is_nan()
        || outside > DEPENDENT_ROW_TOLERANCE * b_norm
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
        let ri = row(i);
        for &j in nz(i) {
            dz[j] += work.y[k] * ri[j];
        }
    }
    lambda.resize_vertically_mut(m, 0.0);
    lambda.fill(0.0);
    for (k, &i) in selected.iter().enumerate() {
        lambda[i] = work.y[k];
    }
    let dc = work.coupled.len();
    if min_norm && dc > 0 {
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
