//! Event location inside an accepted step: Brent's root finder on the dense output, the rule
//! for a sign change that counts as a crossing in the event's direction, and the probe that
//! gives an event function starting at zero its sign.

use super::dense::dense_eval;
use super::{Direction, EventFunctions, Solver};

/// Brent's root finder on `[a, b]` with `f(a)·f(b) < 0`. Returns the final
/// bracket `(x, fx, x', fx')` where `x` is the best estimate and `x'` the
/// other end (`fx·fx' ≤ 0`), `|x - x'| ≤ 2·(2ε|x| + tol/2)`.
pub(super) fn brent(
    mut f: impl FnMut(f64) -> f64,
    a0: f64,
    fa0: f64,
    b0: f64,
    fb0: f64,
    tol: f64,
) -> (f64, f64, f64, f64) {
    let (mut a, mut fa, mut b, mut fb) = (a0, fa0, b0, fb0);
    let (mut c, mut fc) = (b, fb);
    let (mut d, mut e) = (b - a, b - a);
    for _ in 0..200 {
        if (fb > 0.0 && fc > 0.0) || (fb < 0.0 && fc < 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol1 = 2.0 * f64::EPSILON * b.abs() + 0.5 * tol;
        let xm = 0.5 * (c - b);
        if xm.abs() <= tol1 || fb == 0.0 {
            return (b, fb, c, fc);
        }
        if e.abs() >= tol1 && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * xm * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * xm * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            }
            p = p.abs();
            let min1 = 3.0 * xm * q - (tol1 * q).abs();
            let min2 = (e * q).abs();
            if 2.0 * p < min1.min(min2) {
                e = d;
                d = p / q;
            } else {
                d = xm;
                e = d;
            }
        } else {
            d = xm;
            e = d;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol1 { d } else { tol1.copysign(xm) };
        fb = f(b);
    }
    (b, fb, c, fc)
}

/// Whether a sign change from `ga` (non-zero) to `gb` is an allowed crossing.
pub(super) fn crosses(ga: f64, gb: f64, dir: Direction) -> bool {
    let rising = ga < 0.0 && gb >= 0.0;
    let falling = ga > 0.0 && gb <= 0.0;
    match dir {
        Direction::Any => rising || falling,
        Direction::Rising => rising,
        Direction::Falling => falling,
    }
}

/// Fraction of the first step at which the sign of an event function that
/// starts at zero is sampled.
pub(super) const ZERO_START_PROBE: f64 = 1e-3;

impl Solver {
    /// Locates the root of `g_i` on `[ta, tb_max]` (within the current
    /// dense step) given the crossing `ga → gb` over `[ta, t1]`. Returns the
    /// post-crossing end of the final bracket, or `None` if `g_i` does not
    /// cross before `tb_max` (when `tb_max < t1`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn locate(
        &mut self,
        events: &mut impl EventFunctions,
        i: usize,
        ta: f64,
        ga: f64,
        t1: f64,
        gb: f64,
        tb_max: f64,
        h: f64,
    ) -> Option<f64> {
        let Self {
            dense,
            y_tmp,
            g_tmp,
            t,
            dim,
            ..
        } = self;
        let (t0, dim) = (*t, *dim);
        let mut g = |tt: f64| {
            dense_eval(dense, dim, t0, h, tt, y_tmp);
            events.eval_one(i, tt, y_tmp, g_tmp)
        };
        let (tb, gb) = if tb_max < t1 {
            let gm = g(tb_max);
            if (ga < 0.0 && gm < 0.0) || (ga > 0.0 && gm > 0.0) {
                return None;
            }
            (tb_max, gm)
        } else {
            (t1, gb)
        };
        if gb == 0.0 {
            return Some(tb);
        }
        let tol = 1e-13 * tb.abs().max(1.0);
        let (x, fx, x2, _) = brent(&mut g, ta, ga, tb, gb, tol);
        // Post-crossing side: the sign differs from `ga` (or zero).
        if fx == 0.0 || fx.signum() != ga.signum() {
            Some(x)
        } else {
            Some(x2)
        }
    }
}
