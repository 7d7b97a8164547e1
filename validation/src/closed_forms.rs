//! Published closed forms of the rocking block that the report compares both engines with.
//!
//! A rectangular block of half-width b and half-height h: R = √(b² + h²), α = atan(b/h),
//! p² = 3g/(4R) (Housner 1963). Its rocking obeys θ̈ = −p²[sin(α sgnθ − θ) + (a_x/g)cos(α sgnθ − θ)].

/// Housner's block parameters.
#[derive(Clone, Copy, Debug)]
pub struct Block {
    /// Slenderness α = atan(b/h) (rad).
    pub alpha: f64,
    /// Frequency parameter p = √(3g/4R) (rad/s).
    pub p: f64,
}

impl Block {
    /// The block of half-width `b`, half-height `h` (m) under gravity `g`.
    pub fn new(b: f64, h: f64, g: f64) -> Self {
        let r = (b * b + h * h).sqrt();
        Self {
            alpha: (b / h).atan(),
            p: (3.0 * g / (4.0 * r)).sqrt(),
        }
    }

    /// A frame of identical columns (this block) under a cap beam of mass γ times the columns'
    /// (Makris & Vassiliou 2013): the single-block equation with p̂² = p²(1 + 2γ)/(1 + 3γ).
    pub fn with_cap_beam(&self, gamma: f64) -> Self {
        Self {
            alpha: self.alpha,
            p: self.p * ((1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma)).sqrt(),
        }
    }

    /// The frame's rate ratio of an impact (Makris & Vassiliou 2013), α of the columns:
    /// r = (1 − 1.5 sin²α + 3γ cos 2α)/(1 + 3γ).
    pub fn cap_beam_r(&self, gamma: f64) -> f64 {
        let a = self.alpha;
        (1.0 - 1.5 * a.sin().powi(2) + 3.0 * gamma * (2.0 * a).cos()) / (1.0 + 3.0 * gamma)
    }

    /// Housner's rate ratio of an impact, r = 1 − 1.5 sin²α (angular momentum about the new
    /// corner).
    pub fn housner_r(&self) -> f64 {
        1.0 - 1.5 * self.alpha.sin().powi(2)
    }

    /// The exact time from amplitude θ₀ (at rest) to θ = 0, by the energy quadrature
    /// t = ∫₀^θ₀ dθ / √(2p²(cos(α − θ₀) − cos(α − θ))) with θ = θ₀ − s² (Simpson, 20 000 panels).
    pub fn quarter_period(&self, theta0: f64) -> f64 {
        let (a, p) = (self.alpha, self.p);
        let smax = theta0.sqrt();
        let f = |s: f64| {
            if s == 0.0 {
                return 2.0 / (p * (2.0 * (a - theta0).sin()).sqrt());
            }
            let th = theta0 - s * s;
            2.0 * s / (2.0 * p * p * ((a - theta0).cos() - (a - th).cos())).sqrt()
        };
        let n = 20_000;
        let h = smax / n as f64;
        let mut sum = f(0.0) + f(smax);
        for i in 1..n {
            sum += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * h / 3.0
    }

    /// The amplitude after an impact from amplitude θₙ with rate ratio r (exact):
    /// cos(α − θₙ₊₁) − cos α = r²[cos(α − θₙ) − cos α].
    pub fn next_amplitude(&self, theta: f64, r: f64) -> f64 {
        let a = self.alpha;
        let c = a.cos() + r * r * ((a - theta).cos() - a.cos());
        a - c.min(1.0).acos()
    }

    /// Free rocking from rest at θ₀ with rate ratio r: the impact times and the amplitudes
    /// between them, until the amplitude falls below `rest` (rad). The last time is the time to
    /// rest (the series converges: infinitely many impacts in finite time).
    pub fn free_rocking(&self, theta0: f64, r: f64, rest: f64) -> (Vec<f64>, Vec<f64>) {
        let mut times = Vec::new();
        let mut amplitudes = vec![theta0];
        let mut t = self.quarter_period(theta0);
        let mut theta = theta0;
        while theta > rest && times.len() < 10_000 {
            times.push(t);
            theta = self.next_amplitude(theta, r);
            amplitudes.push(theta);
            t += 2.0 * self.quarter_period(theta);
        }
        (times, amplitudes)
    }

    /// Overturning without impact under a one-sine pulse a_x = A sin(ω t), 0 ≤ t ≤ 2π/ω, of the
    /// linearised block (Zhang & Makris 2001, mode 1): uplift when A sin(ω t) first exceeds g α,
    /// then φ̈ = p²(φ − α) + p²(A/g) sin ωt, solved in closed form; the block overturns without
    /// impact when φ stays positive through the pulse and ends it with φ − α + φ̇/p > 0 (on its
    /// way past the unstable equilibrium φ = α). `amplitude` is A/(g α), `omega` is ω/p.
    pub fn overturns_without_impact(&self, amplitude: f64, omega: f64) -> bool {
        if amplitude <= 1.0 {
            return false;
        }
        let (a, p) = (self.alpha, self.p);
        let w = omega * p;
        let ag = amplitude * a; // A/g
        let tu = (1.0 / amplitude).asin() / w;
        let tp = 2.0 * std::f64::consts::PI / w;
        // φ = α − k sin ωt + C cosh p(t − tu) + D sinh p(t − tu), k = (A/g)p²/(p² + ω²).
        let k = ag * p * p / (p * p + w * w);
        let c = -(a - k * (w * tu).sin());
        let d = k * w * (w * tu).cos() / p;
        let phi = |t: f64| {
            let s = p * (t - tu);
            a - k * (w * t).sin() + c * s.cosh() + d * s.sinh()
        };
        let phid = |t: f64| {
            let s = p * (t - tu);
            -k * w * (w * t).cos() + p * (c * s.sinh() + d * s.cosh())
        };
        // No return to the seat during the pulse (checked on a fine grid).
        let steps = 2000;
        for i in 1..=steps {
            let t = tu + (tp - tu) * i as f64 / steps as f64;
            if phi(t) <= 0.0 {
                return false;
            }
        }
        // After the pulse x = φ − α obeys ẍ = p²x: it passes 0 upward iff its component on
        // e^{pt}, x + ẋ/p, is positive.
        let (f, fd) = (phi(tp), phid(tp));
        f - a + fd / p > 0.0
    }

    /// The smallest A/(g α) (to 1e-4) at which the block overturns without impact at ω/p = `omega`,
    /// scanned upward from 1 to `max`; None if it does not below `max`.
    pub fn mode1_boundary(&self, omega: f64, max: f64) -> Option<f64> {
        let mut lo = 1.0;
        let step = 0.01;
        let mut a = lo;
        while a <= max {
            if self.overturns_without_impact(a, omega) {
                // Refine between the last safe and the first overturning amplitude.
                let mut hi = a;
                for _ in 0..30 {
                    let mid = 0.5 * (lo + hi);
                    if self.overturns_without_impact(mid, omega) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                return Some(hi);
            }
            lo = a;
            a += step;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_period_tends_to_the_linearised_one_for_small_amplitudes() {
        // Linearised (Housner): T/4 = (1/p) arccosh(1/(1 − θ₀/α)); the exact one differs by
        // O(α²) relative: for α = 0.05, θ₀ = 0.5α, below 1e-3.
        let b = Block::new(0.05, 1.0, 9.81);
        let th = 0.5 * b.alpha;
        let lin = (1.0 / (1.0 - th / b.alpha)).acosh() / b.p;
        let exact = b.quarter_period(th);
        assert!(((exact - lin) / lin).abs() < 1e-3, "{exact} vs {lin}");
    }

    #[test]
    fn overturning_without_impact_needs_more_than_a_rectangular_threshold() {
        // Below uplift nothing happens; a very strong long pulse overturns.
        let b = Block::new(0.2, 1.0, 9.81);
        assert!(!b.overturns_without_impact(0.9, 2.0));
        assert!(b.overturns_without_impact(20.0, 1.0));
        // The boundary rises with the pulse frequency (shorter pulses need more).
        let b2 = b.mode1_boundary(2.0, 50.0).unwrap();
        let b6 = b.mode1_boundary(6.0, 50.0).unwrap();
        assert!(b6 > b2 && b2 > 1.0, "{b2} {b6}");
    }
}
