//! One Runge–Kutta step of the [`Solver`]: the stage inputs y + h Σ aⱼkⱼ and their right-hand
//! sides, the error estimate, the FSAL stage and the dense-output coefficients; and Hairer's
//! initial step size. The small dimensions (4, 6 and 8 components: one to three coordinates)
//! run the stage sums on code of their own with the partial sums in registers, the same
//! operations in the same order as the general loops.

use crr_kinematics::short_copy::copy_short;

use super::tableau::*;
use super::{Method, OdeSystem, SolveError, Solver, Stats};

/// `out = Σ_j a_j k_j` over the stages `k` (rows of `dim`), skipping the zero coefficients of
/// the tableau. The sum runs stage by stage over contiguous slices: the same order of additions
/// for every component as a component-by-component loop, so the same result to the last bit.
#[inline]
pub(super) fn stage_sum(k: &[f64], dim: usize, a: &[f64], out: &mut [f64]) {
    match dim {
        0 => return,
        4 => return stage_sum_fixed::<4>(k, a, out),
        6 => return stage_sum_fixed::<6>(k, a, out),
        8 => return stage_sum_fixed::<8>(k, a, out),
        _ => {}
    }
    let out = &mut out[..dim];
    out.fill(0.0);
    for (kj, &aj) in k.chunks_exact(dim).zip(a) {
        if aj != 0.0 {
            for (o, &x) in out.iter_mut().zip(kj) {
                *o += aj * x;
            }
        }
    }
}

/// [`stage_sum`] for a dimension known at compile time, with the sums in registers (as the dense
/// output's `dense_eval_fixed`): 0 + a₁k₁ + a₂k₂ + … in the same order, the same result to the
/// last bit.
#[inline]
fn stage_sum_fixed<const D: usize>(k: &[f64], a: &[f64], out: &mut [f64]) {
    let mut acc = [0.0; D];
    for (kj, &aj) in k.chunks_exact(D).zip(a) {
        if aj != 0.0 {
            for (s, &x) in acc.iter_mut().zip(kj) {
                *s += aj * x;
            }
        }
    }
    out[..D].copy_from_slice(&acc);
}

/// [`stage_sum_fixed`] for R coefficient rows at once into the R rows of `out`: R independent
/// sums per component advance together, so their additions overlap instead of waiting on one
/// another (the dense output's four rows of DOP853). Each row's sum is the same as alone.
#[inline]
pub(super) fn stage_sums_fixed<const D: usize, const R: usize>(
    k: &[f64],
    a: &[[f64; DOP853_STAGES]; R],
    out: &mut [f64],
) {
    let mut acc = [[0.0; D]; R];
    for (j, kj) in k.chunks_exact(D).enumerate().take(DOP853_STAGES) {
        for (acc_r, a_r) in acc.iter_mut().zip(a) {
            let aj = a_r[j];
            if aj != 0.0 {
                for (s, &x) in acc_r.iter_mut().zip(kj) {
                    *s += aj * x;
                }
            }
        }
    }
    for (o, acc_r) in out.chunks_exact_mut(D).zip(&acc) {
        o.copy_from_slice(acc_r);
    }
}

/// `out = y + h Σ_j a_j k_j` ([`stage_sum`]).
#[inline]
fn stage_input(y: &[f64], k: &[f64], dim: usize, h: f64, a: &[f64], out: &mut [f64]) {
    stage_sum(k, dim, a, out);
    for (o, &yi) in out[..dim].iter_mut().zip(&y[..dim]) {
        *o = yi + h * *o;
    }
}

/// Calls the right-hand side, counting and mapping errors.
pub(super) fn call_rhs(
    sys: &mut impl OdeSystem,
    stats: &mut Stats,
    t: f64,
    y: &[f64],
    out: &mut [f64],
) -> Result<(), SolveError> {
    stats.rhs_evals += 1;
    sys.rhs(t, y, out)
        .map_err(|source| SolveError::Rhs { t, source })
}

impl Solver {
    /// Hairer's initial step-size heuristic.
    pub(super) fn initial_step(&mut self, sys: &mut impl OdeSystem) -> Result<f64, SolveError> {
        let order = match self.method {
            Method::Dop853 => 8.0,
            _ => 5.0,
        };
        let d = self.dim;
        let (rtol, atol) = (self.opts.rtol, self.opts.atol);
        let (mut dnf, mut dny) = (0.0, 0.0);
        for i in 0..d {
            let sk = atol + rtol * self.y[i].abs();
            dnf += (self.f[i] / sk).powi(2);
            dny += (self.y[i] / sk).powi(2);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            (dny / dnf).sqrt() * 0.01
        };
        h = h.min(self.opts.h_max);
        for i in 0..d {
            self.y_tmp[i] = self.y[i] + h * self.f[i];
        }
        let (k1, _) = self.k.split_at_mut(d);
        call_rhs(sys, &mut self.stats, self.t + h, &self.y_tmp, k1)?;
        let mut der2 = 0.0;
        for i in 0..d {
            let sk = atol + rtol * self.y[i].abs();
            der2 += ((k1[i] - self.f[i]) / sk).powi(2);
        }
        let der2 = der2.sqrt() / h;
        let der12 = der2.abs().max(dnf.sqrt());
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(1.0 / order)
        };
        let h = (100.0 * h).min(h1).min(self.opts.h_max);
        Ok(if h > 0.0 && h.is_finite() { h } else { 1e-6 })
    }

    /// Computes one step of size `h` from `(t, y)` with derivative `f` into
    /// `y_new` (ending at `t1`, which is `t + h` up to rounding). Returns
    /// the scaled error norm (0 for RK4).
    pub(super) fn rk_step(
        &mut self,
        sys: &mut impl OdeSystem,
        h: f64,
        t1: f64,
    ) -> Result<f64, SolveError> {
        // A new step overwrites the stages a pending dense output would need.
        self.dense_pending = None;
        let Self {
            method,
            opts,
            dim,
            t,
            y,
            f,
            y_new,
            y_tmp,
            k,
            stats,
            ..
        } = self;
        let (d, t) = (*dim, *t);
        copy_short(&mut k[..d], f);
        let stage_t = |c: f64| if c == 1.0 { t1 } else { t + c * h };
        match *method {
            Method::Dop853 => {
                for s in 1..DOP853_MAIN {
                    stage_input(y, k, d, h, DOP853_A[s], y_tmp);
                    let (_, ks) = k.split_at_mut(s * d);
                    call_rhs(sys, stats, stage_t(DOP853_C[s]), y_tmp, &mut ks[..d])?;
                }
                stage_input(y, k, d, h, &DOP853_B, y_new);
                let (mut err5, mut err3) = (0.0, 0.0);
                for i in 0..d {
                    let sk = opts.atol + opts.rtol * y[i].abs().max(y_new[i].abs());
                    let mut e5 = 0.0;
                    let mut bk = 0.0;
                    for j in 0..DOP853_MAIN {
                        let kj = k[j * d + i];
                        e5 += DOP853_ER[j] * kj;
                        bk += DOP853_B[j] * kj;
                    }
                    let e3 = bk
                        - DOP853_BHH[0] * k[i]
                        - DOP853_BHH[1] * k[8 * d + i]
                        - DOP853_BHH[2] * k[11 * d + i];
                    err5 += (e5 / sk).powi(2);
                    err3 += (e3 / sk).powi(2);
                }
                if d == 0 {
                    return Ok(0.0);
                }
                let mut deno = err5 + 0.01 * err3;
                if deno <= 0.0 {
                    deno = 1.0;
                }
                Ok(h.abs() * err5 * (1.0 / (deno * d as f64)).sqrt())
            }
            Method::Dopri5 => {
                for s in 1..DOPRI5_STAGES {
                    stage_input(y, k, d, h, DOPRI5_A[s], y_tmp);
                    let (_, ks) = k.split_at_mut(s * d);
                    call_rhs(sys, stats, stage_t(DOPRI5_C[s]), y_tmp, &mut ks[..d])?;
                }
                // The last stage input is the 5th-order solution (FSAL).
                copy_short(y_new, y_tmp);
                let mut err = 0.0;
                for i in 0..d {
                    let sk = opts.atol + opts.rtol * y[i].abs().max(y_new[i].abs());
                    let mut e = 0.0;
                    for j in 0..DOPRI5_STAGES {
                        e += DOPRI5_E[j] * k[j * d + i];
                    }
                    err += (h * e / sk).powi(2);
                }
                if d == 0 {
                    return Ok(0.0);
                }
                Ok((err / d as f64).sqrt())
            }
            Method::Rk4 { .. } => {
                let half = 0.5 * h;
                let tm = t + half;
                stage_input(y, k, d, half, &[1.0], y_tmp);
                call_rhs(sys, stats, tm, y_tmp, &mut k[d..2 * d])?;
                stage_input(y, k, d, half, &[0.0, 1.0], y_tmp);
                call_rhs(sys, stats, tm, y_tmp, &mut k[2 * d..3 * d])?;
                stage_input(y, k, d, h, &[0.0, 0.0, 1.0], y_tmp);
                call_rhs(sys, stats, t1, y_tmp, &mut k[3 * d..4 * d])?;
                const W: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
                stage_input(y, k, d, h, &W, y_new);
                Ok(0.0)
            }
        }
    }

    /// After a step accepted into `y_new`: computes the FSAL stage (where
    /// not yet done) and the dense-output coefficients, except DOP853's last
    /// four rows, which need three more stages: those wait for
    /// [`Self::complete_dense`] (a step whose interpolant nobody reads costs
    /// no more than its error-controlled stages and its FSAL stage).
    pub(super) fn finish_step(
        &mut self,
        sys: &mut impl OdeSystem,
        h: f64,
        t1: f64,
    ) -> Result<(), SolveError> {
        let Self {
            method,
            dim,
            y,
            y_new,
            k,
            dense,
            stats,
            dense_pending,
            ..
        } = self;
        let d = *dim;
        let fsal = match *method {
            Method::Dop853 => DOP853_FSAL,
            Method::Dopri5 => DOPRI5_FSAL,
            Method::Rk4 { .. } => 4,
        };
        if !matches!(method, Method::Dopri5) {
            call_rhs(sys, stats, t1, y_new, &mut k[fsal * d..(fsal + 1) * d])?;
        }
        for i in 0..d {
            let ydiff = y_new[i] - y[i];
            let bspl = h * k[i] - ydiff;
            dense[i] = y[i];
            dense[d + i] = ydiff;
            dense[2 * d + i] = bspl;
            dense[3 * d + i] = ydiff - h * k[fsal * d + i] - bspl;
        }
        match *method {
            Method::Dop853 => *dense_pending = Some(h),
            Method::Dopri5 => {
                for i in 0..d {
                    let mut s = 0.0;
                    for (j, &dj) in DOPRI5_D.iter().enumerate() {
                        s += dj * k[j * d + i];
                    }
                    dense[4 * d + i] = h * s;
                }
            }
            Method::Rk4 { .. } => {}
        }
        Ok(())
    }

    /// Completes the dense output of the step just finished (not yet committed: `y` is still its
    /// start): DOP853's three extra stages and its last four coefficient rows, the same
    /// operations in the same order as when they were computed with the step. Nothing to do for
    /// the other methods, or when already done.
    pub(super) fn complete_dense(&mut self, sys: &mut impl OdeSystem) -> Result<(), SolveError> {
        let Some(h) = self.dense_pending.take() else {
            return Ok(());
        };
        let Self {
            dim,
            t,
            y,
            y_tmp,
            k,
            dense,
            stats,
            ..
        } = self;
        let (d, t) = (*dim, *t);
        for s in DOP853_FSAL + 1..DOP853_STAGES {
            stage_input(y, k, d, h, DOP853_A[s], y_tmp);
            let (_, ks) = k.split_at_mut(s * d);
            call_rhs(sys, stats, t + DOP853_C[s] * h, y_tmp, &mut ks[..d])?;
        }
        let rows = &mut dense[4 * d..8 * d];
        match d {
            4 => stage_sums_fixed::<4, 4>(k, &DOP853_D, rows),
            6 => stage_sums_fixed::<6, 4>(k, &DOP853_D, rows),
            8 => stage_sums_fixed::<8, 4>(k, &DOP853_D, rows),
            _ => {
                for (row, out) in DOP853_D.iter().zip(rows.chunks_exact_mut(d)) {
                    stage_sum(k, d, row, out);
                }
            }
        }
        rows.iter_mut().for_each(|x| *x *= h);
        Ok(())
    }
}
