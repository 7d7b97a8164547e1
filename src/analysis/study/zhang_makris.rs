//! The minimum overturning amplitude of a slender block under one-sine and one-cosine acceleration
//! pulses by the linearised theory of Zhang & Makris (2001, "Rocking response of free-standing
//! blocks under cycloidal pulses", J. Eng. Mech. 127(5)): the analytic boundary drawn on an
//! overturning map.
//!
//! In ψ = θ/tan α and τ = p t the linearised equation of a block rocking on the side σ that the
//! pulse a(t) = β g tan α f(ω_p t) drives (f = sin or cos on one period, β = a_p/(g tan α)) is
//! ψ″ = ψ − 1 + σβ f(Ωτ), Ω = ω_p/p, σ = +1 on the side of uplift and −1 after an impact. On
//! each side its solution is closed: ψ = A cosh(τ − τₐ) + B sinh(τ − τₐ) + 1 − σβ f(Ωτ)/(1 + Ω²).
//! Uplift happens when β f(Ωτ) first reaches 1 (tan α: the exact uplift of the block), an impact
//! at ψ = 0 multiplies the rate by the block's r and flips the side, and after the pulse the free
//! block overturns exactly when it is beyond the separatrix, ψ − 1 + ψ′ > 0, or when it comes
//! back to ψ = 0 fast enough that the impact leaves it beyond the other side's separatrix
//! (r|ψ′| > 1). Zhang & Makris's two modes are followed: overturning with no impact, and after
//! exactly one impact (during or after the pulse). A motion that needs more impacts to overturn
//! is outside the theory (counted as not overturning).

use super::spec::PulseKind;

/// The pulse shape f(x) and its derivative, on one period x ∈ [0, 2π].
fn shape(kind: PulseKind, x: f64) -> (f64, f64) {
    match kind {
        PulseKind::OneCosinePulse => (x.cos(), -x.sin()),
        _ => (x.sin(), x.cos()),
    }
}

/// Whether the linearised block overturns (modes 1 and 2) under the pulse of amplitude ratio β
/// and frequency ratio Ω, with restitution r.
pub fn overturns(kind: PulseKind, beta: f64, omega: f64, r: f64) -> bool {
    if beta.is_nan() || omega.is_nan() || beta <= 1.0 || omega <= 0.0 {
        return false;
    }
    let end = 2.0 * std::f64::consts::PI / omega;
    // Uplift: the first time β f(Ωτ) = 1.
    let start = match kind {
        PulseKind::OneCosinePulse => 0.0,
        _ => (1.0 / beta).asin() / omega,
    };
    let (mut t, mut psi, mut rate, mut side) = (start, 0.0, 0.0, 1.0);
    for impacts in 0..2 {
        let k = side * beta / (1.0 + omega * omega);
        let particular = |x: f64| {
            let (f, df) = shape(kind, omega * x);
            (1.0 - k * f, -k * omega * df)
        };
        let (p0, dp0) = particular(t);
        let (a, b) = (psi - p0, rate - dp0);
        let at = |x: f64| {
            let (c, s) = ((x - t).cosh(), (x - t).sinh());
            let (p, dp) = particular(x);
            (a * c + b * s + p, a * s + b * c + dp)
        };
        // The first return to ψ = 0 before the pulse ends, on a fine grid then by bisection.
        let n = 400;
        let mut prev = t;
        let mut hit = None;
        for i in 1..=n {
            let x = t + (end - t) * i as f64 / n as f64;
            if at(x).0 < 0.0 {
                let (mut lo, mut hi) = (prev, x);
                for _ in 0..60 {
                    let m = 0.5 * (lo + hi);
                    if at(m).0 < 0.0 {
                        hi = m;
                    } else {
                        lo = m;
                    }
                }
                hit = Some(hi);
                break;
            }
            prev = x;
        }
        match hit {
            None => {
                // After the pulse ψ″ = ψ − 1 conserves ψ′² − (ψ − 1)²: beyond the separatrix
                // ψ − 1 + ψ′ > 0 the block overturns; otherwise it comes back to ψ = 0 with
                // |ψ′|² = ψ′² − (ψ − 1)² + 1 and, if that impact is its first, overturns on the
                // other side when r|ψ′| > 1 (the separatrix at ψ = 0).
                let (p, dp) = at(end);
                if p - 1.0 + dp > 0.0 {
                    return true;
                }
                let back = dp * dp - (p - 1.0) * (p - 1.0) + 1.0;
                return impacts == 0 && back > 0.0 && r * back.sqrt() > 1.0;
            }
            Some(x) => {
                // Impact: the rate reverses, reduced by r, on the other side.
                let (_, dp) = at(x);
                t = x;
                psi = 0.0;
                rate = -r * dp;
                side = -side;
            }
        }
    }
    false
}

/// The smallest β = a_p/(g tan α) at which the linearised block overturns (modes 1 and 2) at
/// frequency ratio Ω = ω_p/p, searched in steps of 0.01 up to `beta_max` and refined by
/// bisection to 1e-6; None when none overturns below `beta_max` or for a Ricker pulse (no closed
/// form).
pub fn minimum_overturning_ratio(
    kind: PulseKind,
    omega: f64,
    r: f64,
    beta_max: f64,
) -> Option<f64> {
    if kind == PulseKind::Ricker {
        return None;
    }
    let mut lo = 1.0;
    let mut beta = 1.0;
    while beta <= beta_max {
        if overturns(kind, beta, omega, r) {
            let mut hi = beta;
            while hi - lo > 1e-6 {
                let m = 0.5 * (lo + hi);
                if overturns(kind, m, omega, r) {
                    hi = m;
                } else {
                    lo = m;
                }
            }
            return Some(hi);
        }
        lo = beta;
        beta += 0.01;
    }
    None
}

/// The analytic boundary to draw on a study's overturning map: (ω_p/p, minimum a_p/(g tan α))
/// at `count` frequency ratios from `from` to `to`, for a study of one-sine or one-cosine pulses
/// with dimensionless axes on a single block (one coordinate), with the block's r from the
/// momentum law (`crr check`). None for any other study.
pub fn map_boundary(
    study: &super::Study,
    from: f64,
    to: f64,
    count: usize,
) -> Option<Vec<(f64, f64)>> {
    map_boundary_up_to(study, from, to, count, 50.0)
}

/// [`map_boundary`] searched up to a_p/(g tan α) = `beta_max` (the frequencies above which the
/// minimum is larger are left out).
pub fn map_boundary_up_to(
    study: &super::Study,
    from: f64,
    to: f64,
    count: usize,
    beta_max: f64,
) -> Option<Vec<(f64, f64)>> {
    let kind = study.pulse_kind?;
    let pulses = study.spec.pulses.as_ref()?;
    if kind == PulseKind::Ricker
        || study.model.dof() != 1
        || pulses.amplitude_ratios.is_none()
        || pulses.frequency_ratios.is_none()
        || count < 2
    {
        return None;
    }
    let r = crate::analysis::check::check(&study.model).mechanism?.r;
    Some(
        (0..count)
            .filter_map(|k| {
                let w = from + (to - from) * k as f64 / (count - 1) as f64;
                minimum_overturning_ratio(kind, w, r, beta_max).map(|b| (w, b))
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same linearised block integrated numerically (RK4, Δτ = 1e-4, impacts located to the
    /// step) for at most one impact, then classified as in Zhang & Makris: overturned when ψ
    /// passes 50 (far beyond the separatrix, where the linear motion never returns) within the
    /// pulse and 40 free units after it.
    fn overturns_numerically(kind: PulseKind, beta: f64, omega: f64, r: f64) -> bool {
        let end = 2.0 * std::f64::consts::PI / omega;
        let force = |t: f64| {
            if t <= end {
                beta * shape(kind, omega * t).0
            } else {
                0.0
            }
        };
        let mut t = match kind {
            PulseKind::OneCosinePulse => 0.0,
            _ => (1.0 / beta).asin() / omega,
        };
        let (mut psi, mut rate, mut side, mut impacts) = (0.0f64, 0.0f64, 1.0f64, 0);
        let h = 1e-4;
        while t < end + 40.0 {
            let acc = |t: f64, p: f64| p - 1.0 + side * force(t);
            let (k1p, k1v) = (rate, acc(t, psi));
            let (k2p, k2v) = (rate + 0.5 * h * k1v, acc(t + 0.5 * h, psi + 0.5 * h * k1p));
            let (k3p, k3v) = (rate + 0.5 * h * k2v, acc(t + 0.5 * h, psi + 0.5 * h * k2p));
            let (k4p, k4v) = (rate + h * k3v, acc(t + h, psi + h * k3p));
            psi += h / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
            rate += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            t += h;
            if psi > 50.0 {
                return true;
            }
            if psi < 0.0 {
                if impacts == 1 {
                    return false;
                }
                impacts += 1;
                psi = 0.0;
                rate *= -r;
                side = -side;
            }
        }
        false
    }

    /// The closed-form segments agree with the numerical integration away from the boundary
    /// (cases whose decision flips within ±2 % of β are skipped: there the two are allowed to
    /// differ by the integration error).
    #[test]
    fn closed_form_and_numerical_integration_agree() {
        let r = 0.94;
        let mut checked = 0;
        for kind in [PulseKind::OneSinePulse, PulseKind::OneCosinePulse] {
            for omega in [1.0, 2.0, 3.5, 5.0, 6.5] {
                for beta in [1.2, 1.5, 2.0, 3.0, 4.0, 6.0, 9.0] {
                    let closed = overturns(kind, beta, omega, r);
                    if overturns(kind, 0.98 * beta, omega, r) != closed
                        || overturns(kind, 1.02 * beta, omega, r) != closed
                    {
                        continue;
                    }
                    assert_eq!(
                        closed,
                        overturns_numerically(kind, beta, omega, r),
                        "{kind:?}, β = {beta}, Ω = {omega}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 50, "{checked}");
    }

    /// A pulse that only just uplifts the block does not overturn it, and the minimum
    /// overturning amplitude rises with the pulse's frequency (short pulses must be stronger).
    #[test]
    fn the_boundary_starts_above_uplift_and_rises_with_frequency() {
        assert!(!overturns(PulseKind::OneSinePulse, 1.0, 2.0, 0.9));
        let low = minimum_overturning_ratio(PulseKind::OneSinePulse, 1.5, 0.94, 20.0).unwrap();
        let high = minimum_overturning_ratio(PulseKind::OneSinePulse, 5.0, 0.94, 20.0).unwrap();
        assert!(1.0 < low && low < high, "{low} {high}");
        assert!(minimum_overturning_ratio(PulseKind::Ricker, 2.0, 0.94, 20.0).is_none());
    }
}
