//! The sign change of a scalar function located to adjacent doubles: how a run finds the turning
//! points of a rocking angle (the instants where q̇ₖ of a step's dense output changes sign, the
//! peaks of the response).

/// Halvings [`sign_change`] makes at most: enough to reach adjacent doubles from a bracket as
/// wide as a step anywhere but within about 1e-3 s of t = 0, where doubles are denser.
const MAX_HALVINGS: usize = 60;

/// Chord-and-probe rounds [`sign_change`] makes at most before it only halves.
const MAX_ROUNDS: usize = 20;

/// Width, in units of the bracket's ulp, below which [`sign_change`] stops its chord-and-probe
/// rounds and halves: three halvings then reach adjacent doubles.
const FINISH_ULPS: f64 = 8.0;

/// The least distance of a probe from the chord's zero, in ulps: when the chord's estimate is
/// below the rounding of f, a probe this far still lands across the crossing.
const PROBE_ULPS: f64 = 4.0;

/// The widest bracket, in units of the spacing of doubles at its end nearest 0, from which
/// [`MAX_HALVINGS`] halvings surely reach adjacent doubles: 2⁵², eight halvings to spare for the
/// rounding of the midpoints. A wider bracket (one near t = 0) is only halved, so that the answer
/// is the bisection's there too: the bracket after 60 halvings.
const CHORD_MAX_WIDTH: f64 = 4_503_599_627_370_496.0;

/// The bracket `(lo, hi)` of adjacent doubles across which `f` changes sign, inside the bracket
/// `[lo, hi]` given with `flo = f(lo)` and `fhi = f(hi)` of different signs. Signs are those of
/// `f64::signum`: +0 counts as positive, −0 as negative, and a NaN as the side of `hi` (not the
/// sign of `flo`).
///
/// The answer is the bisection's (halve, keep the half whose ends differ in sign, until the ends
/// are adjacent doubles) whenever `f` changes sign once among the doubles near the crossing, as
/// a smooth function crossing 0 with a slope does when its rounding error is below its change
/// over one ulp. It takes fewer evaluations of `f`: rounds of a chord's zero (regula falsi) and
/// a probe past it shrink the bracket to 8 ulps, and halvings finish. From a step's width a
/// bisection takes 42–50 evaluations, this 6–9 (`tests/roots.rs`). If `f` changes sign more than
/// once in `[lo, hi]`, one of the crossings is returned. Halvings stop after 60, as the
/// bisection's do: from a bracket wider than 2⁵² times the spacing of doubles at its end nearest
/// 0 (a step starting near t = 0) they may not reach adjacent doubles, and such a bracket is only
/// halved, which gives the bisection's answer there too.
pub fn sign_change(
    mut f: impl FnMut(f64) -> f64,
    mut lo: f64,
    mut flo: f64,
    mut hi: f64,
    mut fhi: f64,
) -> (f64, f64) {
    let sign_lo = flo.signum();
    let nearest_zero = if lo <= 0.0 && hi >= 0.0 {
        0.0
    } else {
        lo.abs().min(hi.abs())
    };
    // Half the spacing of doubles at `nearest_zero` is a lower bound of the spacing in [lo, hi].
    let spacing = 0.5 * f64::EPSILON * nearest_zero;
    let rounds = if hi - lo <= CHORD_MAX_WIDTH * spacing {
        MAX_ROUNDS
    } else {
        0
    };
    // Moves the end of [lo, hi] on t's side of the crossing to t.
    let narrow = |t: f64, ft: f64, lo: &mut f64, flo: &mut f64, hi: &mut f64, fhi: &mut f64| {
        if ft.signum() == sign_lo {
            (*lo, *flo) = (t, ft);
        } else {
            (*hi, *fhi) = (t, ft);
        }
    };
    for _ in 0..rounds {
        let ulp = f64::EPSILON * lo.abs().max(hi.abs());
        if hi - lo <= FINISH_ULPS * ulp {
            break;
        }
        // The chord's zero, or the midpoint when it is not inside (lo, hi) (NaN: equal values,
        // −0 against +0, a NaN of f).
        let mut m = lo + (hi - lo) * (flo / (flo - fhi));
        if !(m > lo && m < hi) {
            m = 0.5 * (lo + hi);
            if m <= lo || m >= hi {
                break;
            }
        }
        let fm = f(m);
        let m_is_lo = fm.signum() == sign_lo;
        narrow(m, fm, &mut lo, &mut flo, &mut hi, &mut fhi);
        // A chord of a convex or concave f lands on the same side of the crossing again and
        // again: probe from m towards the crossing, twice the chord's estimate of the distance
        // and at least a few ulps, so that the bracket closes from both sides.
        let slope = (fhi - flo) / (hi - lo);
        let step = -2.0 * fm / slope;
        let least = PROBE_ULPS * ulp;
        let p = if m_is_lo {
            m + step.max(least)
        } else {
            m + step.min(-least)
        };
        if p > lo && p < hi {
            let fp = f(p);
            narrow(p, fp, &mut lo, &mut flo, &mut hi, &mut fhi);
        }
    }
    for _ in 0..MAX_HALVINGS {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid).signum() == sign_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, hi)
}
