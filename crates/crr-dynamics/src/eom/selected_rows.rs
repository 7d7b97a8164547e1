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
/// between ‖R_D‖ and that threshold (a margin for the round-off of both computations).
pub(super) const RANK_MARGIN: f64 = 10.0;

/// Workspace of [`solve_selected_rows`], kept in [`Dynamics`] so that the solve allocates
/// nothing once sized.
#[derive(Clone, Debug, Default)]
pub(super) struct SelectedRowsWork {
    /// Whether each row of B is selected.
    is_selected: Vec<bool>,
    /// The rows not selected, in order.
    others: Vec<usize>,
    /// L_G, the Cholesky factor of G = B_S B_Sᵀ (r × r).
    g: DMatrix<f64>,
    /// C, row-major (rows D × r): B_D ≈ C B_S.
    c: Vec<f64>,
    /// I + C Cᵀ, then its Cholesky factor.
    nn: DMatrix<f64>,
    /// Scratch of length max(r, rows D).
    e: Vec<f64>,
    /// y = −G⁻¹ e_S.
    y: Vec<f64>,
}

/// Gauss' principle on the rows `selected` of B, given as the columns of `bt` = Bᵀ
/// (n_f × m): with G = B_S B_Sᵀ = L_G L_Gᵀ, y = −G⁻¹ e_S and dz = B_Sᵀ y (e = B z + bias, the
/// constraint residual at z_free), and, when `min_norm`, the minimum-norm multipliers over all
/// rows, Bᵀλ = dz (otherwise λ_S = y, λ_D = 0: another solution of the same equations). Returns
/// false (use the SVD) unless the rank decision is provably the SVD's, within [`RANK_MARGIN`]:
/// σ_min(B_S)² ≥ 1/‖L_G⁻¹‖_F² must exceed the SVD's threshold
/// max(√RANK_TOLERANCE·σ_max(B), `floor`) (bounded above by √RANK_TOLERANCE·‖B‖_F), so the SVD
/// keeps r = |S| singular values; and the rows D not selected must lie in the span of B_S:
/// B_D = C B_S + R_D with ‖R_D‖_F ≤ [`DEPENDENT_ROW_TOLERANCE`]·‖B‖_F, which bounds
/// σ_{r+1}(B) ≤ ‖R_D‖₂ far below the threshold, so the SVD drops the rest.
///
/// The multipliers: λ_p = (y, 0) solves Bᵀλ = dz; the null space of Bᵀ is spanned by the
/// columns of N = [−Cᵀ; I] (rows S then D), so the minimum-norm solution is
/// λ = λ_p − N (NᵀN)⁻¹ Nᵀλ_p, with NᵀN = I + C Cᵀ and Nᵀλ_p = −C y: λ_S = y + Cᵀw,
/// λ_D = −w, w = −(I + C Cᵀ)⁻¹ C y. Work: O(m r n_f + r³) (+ O(d² r + d³) for the multipliers,
/// d = m − r), against a Jacobi SVD's sweeps of O(m² n_f) each.
#[allow(clippy::too_many_arguments)]
pub(super) fn solve_selected_rows(
    work: &mut SelectedRowsWork,
    bt: &DMatrix<f64>,
    residual: &DVector<f64>,
    selected: &[usize],
    floor: f64,
    min_norm: bool,
    dz: &mut DVector<f64>,
    lambda: &mut DVector<f64>,
) -> bool {
    let (nf, m) = (bt.nrows(), bt.ncols());
    let r = selected.len();
    let row = |i: usize| &bt.as_slice()[i * nf..(i + 1) * nf];
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let b_norm = bt.norm();
    let threshold = (RANK_TOLERANCE.sqrt() * b_norm).max(floor);
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
    if work.g.nrows() != r {
        work.g = DMatrix::zeros(r, r);
    }
    for k in 0..r {
        for l in 0..=k {
            work.g[(k, l)] = dot(row(selected[k]), row(selected[l]));
        }
    }
    if cholesky_in_place(&mut work.g).is_err() {
        return false;
    }
    // ‖L_G⁻¹‖_F² ≥ ‖G⁻¹‖₂ = 1/σ_min(B_S)².
    let mut inv_norm2 = 0.0;
    work.e.clear();
    work.e.resize(r.max(d), 0.0);
    for k in 0..r {
        let e = &mut work.e[..r];
        e.fill(0.0);
        e[k] = 1.0;
        forward_substitute(&work.g, e);
        inv_norm2 += e.iter().map(|x| x * x).sum::<f64>();
    }
    // A NaN fails the check too.
    let sigma_min = 1.0 / inv_norm2.sqrt();
    if r > 0 && (sigma_min.is_nan() || sigma_min <= RANK_MARGIN * threshold) {
        return false;
    }
    // C (rows D in the basis of B_S) and ‖R_D‖_F.
    work.c.clear();
    work.c.resize(d * r, 0.0);
    let mut outside = 0.0;
    for (a, &i) in work.others.iter().enumerate() {
        let coef = &mut work.c[a * r..(a + 1) * r];
        for (k, x) in coef.iter_mut().enumerate() {
            *x = dot(row(i), row(selected[k]));
        }
        cholesky_solve(&work.g, coef);
        for (j, &bij) in row(i).iter().enumerate() {
            let mut rest = bij;
            for (k, &ck) in coef.iter().enumerate() {
                rest -= ck * bt[(j, selected[k])];
            }
            outside += rest * rest;
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
    cholesky_solve(&work.g, &mut work.y);
    dz.resize_vertically_mut(nf, 0.0);
    dz.fill(0.0);
    for (k, &i) in selected.iter().enumerate() {
        for (x, b) in dz.iter_mut().zip(row(i)) {
            *x += work.y[k] * b;
        }
    }
    lambda.resize_vertically_mut(m, 0.0);
    lambda.fill(0.0);
    for (k, &i) in selected.iter().enumerate() {
        lambda[i] = work.y[k];
    }
    if min_norm && d > 0 {
        if work.nn.nrows() != d {
            work.nn = DMatrix::zeros(d, d);
        }
        let c = &work.c;
        for a in 0..d {
            for b in 0..=a {
                work.nn[(a, b)] =
                    dot(&c[a * r..(a + 1) * r], &c[b * r..(b + 1) * r]) + f64::from(a == b);
            }
        }
        if cholesky_in_place(&mut work.nn).is_err() {
            return false;
        }
        let w = &mut work.e[..d];
        for (a, x) in w.iter_mut().enumerate() {
            *x = -dot(&c[a * r..(a + 1) * r], &work.y);
        }
        cholesky_solve(&work.nn, w);
        for (a, &i) in work.others.iter().enumerate() {
            for (k, &s) in selected.iter().enumerate() {
                lambda[s] += c[a * r + k] * w[a];
            }
            lambda[i] = -w[a];
        }
    }
    true
}
