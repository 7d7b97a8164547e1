//! Dense output of a step: its interpolant read at any time of the step, as the whole state
//! ([`DenseStep::eval`]) or one component ([`DenseStep::eval_component`],
//! [`DenseStep::component`]), all three the same polynomial evaluated in the same order, so
//! that they agree to the last bit (DOP853's 8 coefficient rows, Dopri5's 5, a cubic Hermite
//! for RK4).

/// The exact states at the ends of an accepted step `[t0, t1]` (the integrator's own values,
/// not read from the interpolant), given to the step's observer before its dense output is
/// computed ([`crate::integrator::Solver::advance_lazily`]).
#[derive(Debug, Clone, Copy)]
pub struct StepEnds<'a> {
    /// Start of the step.
    pub t0: f64,
    /// End of the step.
    pub t1: f64,
    /// The state at `t0`.
    pub y0: &'a [f64],
    /// The state at `t1`.
    pub y1: &'a [f64],
}

/// Dense output of one step `[t0, t1]`, valid for `t0 ≤ t ≤ t1`.
#[derive(Debug, Clone, Copy)]
pub struct DenseStep<'a> {
    pub(super) t0: f64,
    pub(super) t1: f64,
    pub(super) h: f64,
    pub(super) dim: usize,
    pub(super) coef: &'a [f64],
}

impl DenseStep<'_> {
    /// Start of the step.
    pub fn t0(&self) -> f64 {
        self.t0
    }
    /// End of the step.
    pub fn t1(&self) -> f64 {
        self.t1
    }
    /// State dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }
    /// Interpolates the state at `t` into `out` (length `dim`). `t` should
    /// lie in `[t0, t1]`; outside that interval the polynomial extrapolates.
    pub fn eval(&self, t: f64, out: &mut [f64]) {
        dense_eval(self.coef, self.dim, self.t0, self.h, t, out);
    }
    /// Interpolates component `i` of the state at `t`.
    pub fn eval_component(&self, t: f64, i: usize) -> f64 {
        let ncoef = self.coef.len() / self.dim;
        let s = (t - self.t0) / self.h;
        let col = |j: usize| self.coef[j * self.dim + i];
        nested(ncoef, s, col)
    }

    /// Component `i` of the interpolant with its coefficients gathered once, for repeated
    /// evaluations (a bisection): [`DenseComponent::eval`] equals [`Self::eval_component`] to
    /// the last bit.
    pub fn component(&self, i: usize) -> DenseComponent {
        let ncoef = self.coef.len() / self.dim;
        let mut coef = [0.0; MAX_DENSE_COEF];
        for (j, c) in coef.iter_mut().enumerate().take(ncoef) {
            *c = self.coef[j * self.dim + i];
        }
        DenseComponent {
            t0: self.t0,
            h: self.h,
            ncoef,
            coef,
        }
    }
}

/// Most coefficients of a dense output per component (DOP853's 8).
const MAX_DENSE_COEF: usize = 8;

/// One component of a step's dense output ([`DenseStep::component`]).
#[derive(Debug, Clone, Copy)]
pub struct DenseComponent {
    t0: f64,
    h: f64,
    ncoef: usize,
    coef: [f64; MAX_DENSE_COEF],
}

impl DenseComponent {
    /// The component at `t` (in the step; outside it the polynomial extrapolates).
    pub fn eval(&self, t: f64) -> f64 {
        let s = (t - self.t0) / self.h;
        nested(self.ncoef, s, |j| self.coef[j])
    }
}

/// Evaluates `r1 + s(r2 + (1-s)(r3 + s(r4 + (1-s)(...))))`: row j (0-based) is multiplied by s
/// when j is even, by 1 − s when odd (a table lookup, no branch).
#[inline]
fn nested(ncoef: usize, s: f64, r: impl Fn(usize) -> f64) -> f64 {
    let m = [s, 1.0 - s];
    if ncoef == 8 {
        // DOP853's eight rows written out (the loop below, unrolled: the same operations).
        let s1 = m[1];
        let mut acc = r(7);
        acc = r(6) + s * acc;
        acc = r(5) + s1 * acc;
        acc = r(4) + s * acc;
        acc = r(3) + s1 * acc;
        acc = r(2) + s * acc;
        acc = r(1) + s1 * acc;
        return r(0) + s * acc;
    }
    let mut acc = r(ncoef - 1);
    for j in (0..ncoef - 1).rev() {
        acc = r(j) + m[j & 1] * acc;
    }
    acc
}

/// [`nested`] for every component, row by row over contiguous slices of `coef` (`ncoef × dim`):
/// the same operations in the same order for each component, so the same result to the last bit.
pub(super) fn dense_eval(coef: &[f64], dim: usize, t0: f64, h: f64, t: f64, out: &mut [f64]) {
    if dim == 0 {
        return;
    }
    let ncoef = coef.len() / dim;
    let s = (t - t0) / h;
    let m = [s, 1.0 - s];
    match dim {
        4 => return dense_eval_fixed::<4>(&coef[..ncoef * 4], m, out),
        6 => return dense_eval_fixed::<6>(&coef[..ncoef * 6], m, out),
        8 => return dense_eval_fixed::<8>(&coef[..ncoef * 8], m, out),
        _ => {}
    }
    let out = &mut out[..dim];
    let mut rows = coef[..ncoef * dim].chunks_exact(dim).enumerate().rev();
    if let Some((_, last)) = rows.next() {
        for (o, &c) in out.iter_mut().zip(last) {
            *o = c;
        }
    }
    for (j, row) in rows {
        let mj = m[j & 1];
        for (o, &c) in out.iter_mut().zip(row) {
            *o = c + mj * *o;
        }
    }
}

/// [`dense_eval`] for a dimension known at compile time (the small systems: one to three
/// coordinates): the partial sums stay in registers from row to row, where the general loop
/// stores and reloads them, a store-to-load round trip on the critical path at every row. The
/// same operations in the same order, so the same result to the last bit.
#[inline]
fn dense_eval_fixed<const D: usize>(coef: &[f64], m: [f64; 2], out: &mut [f64]) {
    let mut rows = coef.chunks_exact(D).enumerate().rev();
    let mut acc = [0.0; D];
    if let Some((_, last)) = rows.next() {
        acc.copy_from_slice(last);
    }
    for (j, row) in rows {
        let mj = m[j & 1];
        for (a, &c) in acc.iter_mut().zip(row) {
            *a = c + mj * *a;
        }
    }
    out[..D].copy_from_slice(&acc);
}
