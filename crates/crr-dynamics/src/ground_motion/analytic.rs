//! Built (validated) signals: analytic closed forms and records.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::Side;
use super::record::Record;

/// Number of Ricker "widths" `1/f` after the centre beyond which the wavelet is
/// treated as over for [`Signal::end_time`]; there `|a| < 1e-35 |A|`.
pub(super) const RICKER_TAIL_PERIODS: f64 = 3.0;

/// A validated single-component signal (values in m/s², unscaled).
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Signal {
    /// `A sin(2π(t − start)/T + φ)` on `[start, end]` (`end = None`: forever).
    Sine {
        amplitude: f64,
        period: f64,
        phase: f64,
        start: f64,
        end: Option<f64>,
    },
    /// `A cos(2π(t − start)/T)` on `[start, start + T]`.
    CosinePulse {
        amplitude: f64,
        period: f64,
        start: f64,
    },
    /// `A (1 − 2π²f²u²) exp(−π²f²u²)`, `u = t − center`.
    Ricker {
        amplitude: f64,
        frequency: f64,
        center: f64,
    },
    /// `A` on `[start, start + duration]`.
    Rectangular {
        amplitude: f64,
        start: f64,
        duration: f64,
    },
    /// `value` at all times.
    Constant { value: f64 },
    /// Linearly interpolated record.
    Record(Record),
}

/// Is `t` in the closed window `[start, end]`, or the matching one-sided version?
fn in_window(t: f64, start: f64, end: f64, side: Option<Side>) -> bool {
    match side {
        None => start <= t && t <= end,
        Some(Side::Before) => start < t && t <= end,
        Some(Side::After) => start <= t && t < end,
    }
}

fn first_after(t: f64, candidates: &[f64]) -> Option<f64> {
    candidates.iter().copied().find(|&c| c > t)
}

impl Signal {
    /// The shortest time over which the signal changes shape (a sine's or pulse's period, a
    /// Ricker wavelet's 1/f); `None` for signals that are constant or affine between their
    /// breakpoints (constant, rectangular pulses, records).
    pub(super) fn time_scale(&self) -> Option<f64> {
        match self {
            Signal::Sine { period, .. } | Signal::CosinePulse { period, .. } => Some(*period),
            Signal::Ricker { frequency, .. } => Some(1.0 / frequency),
            Signal::Rectangular { .. } | Signal::Constant { .. } | Signal::Record(_) => None,
        }
    }

    fn window_end(&self) -> f64 {
        match self {
            Signal::Sine { end, .. } => end.unwrap_or(f64::INFINITY),
            Signal::CosinePulse { period, start, .. } => start + period,
            Signal::Rectangular {
                start, duration, ..
            } => start + duration,
            Signal::Ricker { .. } | Signal::Constant { .. } => f64::INFINITY,
            Signal::Record(r) => r.end_time(),
        }
    }

    /// True if the signal is affine in t on [t0, t1], an interval with no breakpoint inside:
    /// records (linear interpolation between samples), rectangular pulses and constants always;
    /// sines, cosine pulses and Ricker wavelets only outside their windows.
    pub(super) fn is_affine_on(&self, t0: f64, t1: f64) -> bool {
        match self {
            Signal::Record(_) | Signal::Rectangular { .. } | Signal::Constant { .. } => true,
            Signal::Sine { start, .. } | Signal::CosinePulse { start, .. } => {
                t1 <= *start || t0 >= self.window_end()
            }
            Signal::Ricker { .. } => t0 >= self.end_time(),
        }
    }

    /// Value at `t` (closed windows) or a one-sided limit.
    pub(super) fn value(&self, t: f64, side: Option<Side>) -> f64 {
        if t.is_nan() {
            return f64::NAN;
        }
        match self {
            Signal::Sine {
                amplitude,
                period,
                phase,
                start,
                ..
            } => {
                if in_window(t, *start, self.window_end(), side) {
                    amplitude * (TAU * (t - start) / period + phase).sin()
                } else {
                    0.0
                }
            }
            Signal::CosinePulse {
                amplitude,
                period,
                start,
            } => {
                if in_window(t, *start, self.window_end(), side) {
                    amplitude * (TAU * (t - start) / period).cos()
                } else {
                    0.0
                }
            }
            Signal::Ricker {
                amplitude,
                frequency,
                center,
            } => {
                let x = (PI * frequency * (t - center)).powi(2);
                amplitude * (1.0 - 2.0 * x) * (-x).exp()
            }
            Signal::Rectangular {
                amplitude, start, ..
            } => {
                if in_window(t, *start, self.window_end(), side) {
                    *amplitude
                } else {
                    0.0
                }
            }
            Signal::Constant { value } => *value,
            Signal::Record(r) => match side {
                None => r.acceleration(t),
                Some(s) => r.acceleration_limit(t, s),
            },
        }
    }

    /// A primitive `F` with `F' = a` (closed form); `∫_0^t a = F(t) − F(0)`.
    pub(super) fn primitive(&self, t: f64) -> f64 {
        if t.is_nan() {
            return f64::NAN;
        }
        match self {
            Signal::Sine {
                amplitude,
                period,
                phase,
                start,
                ..
            } => {
                if t <= *start {
                    return 0.0;
                }
                let u = t.min(self.window_end()) - start;
                amplitude * period / TAU * (phase.cos() - (TAU * u / period + phase).cos())
            }
            Signal::CosinePulse {
                amplitude,
                period,
                start,
            } => {
                if t <= *start {
                    return 0.0;
                }
                if t >= self.window_end() {
                    return 0.0; // a full cosine cycle integrates to 0
                }
                amplitude * period / TAU * (TAU * (t - start) / period).sin()
            }
            Signal::Ricker {
                amplitude,
                frequency,
                center,
            } => {
                let u = t - center;
                amplitude * u * (-(PI * frequency * u).powi(2)).exp()
            }
            Signal::Rectangular {
                amplitude,
                start,
                duration,
            } => {
                if t <= *start {
                    0.0
                } else {
                    amplitude * (t - start).min(*duration)
                }
            }
            Signal::Constant { value } => value * t,
            Signal::Record(r) => r.integral(t),
        }
    }

    /// First kink/jump strictly after `t`.
    pub(super) fn next_breakpoint(&self, t: f64) -> Option<f64> {
        if t.is_nan() {
            return None;
        }
        match self {
            Signal::Sine { start, end, .. } => match end {
                Some(e) => first_after(t, &[*start, *e]),
                None => first_after(t, &[*start]),
            },
            Signal::CosinePulse { start, .. } | Signal::Rectangular { start, .. } => {
                first_after(t, &[*start, self.window_end()])
            }
            Signal::Ricker { .. } | Signal::Constant { .. } => None,
            Signal::Record(r) => r.next_sample_time(t),
        }
    }

    /// Time after which the signal is 0 forever (∞ if never). For a Ricker wavelet:
    /// `center + 3/frequency`, after which `|a| < 1e-35 |A|`.
    pub(super) fn end_time(&self) -> f64 {
        match self {
            Signal::Ricker {
                frequency, center, ..
            } => center + RICKER_TAIL_PERIODS / frequency,
            _ => self.window_end(),
        }
    }

    /// Exact peak |a| (unscaled).
    pub(super) fn peak(&self) -> f64 {
        match self {
            Signal::Sine {
                amplitude,
                period,
                phase,
                start,
                end,
            } => {
                let Some(end) = end else {
                    return amplitude.abs();
                };
                // sin over the argument range [φ, φ + 2π(end − start)/T].
                let lo = *phase;
                let hi = phase + TAU * (end - start) / period;
                let k = ((lo - FRAC_PI_2) / PI).ceil();
                let interior_peak = FRAC_PI_2 + k * PI <= hi;
                let m = if interior_peak {
                    1.0
                } else {
                    lo.sin().abs().max(hi.sin().abs())
                };
                amplitude.abs() * m
            }
            Signal::CosinePulse { amplitude, .. }
            | Signal::Ricker { amplitude, .. }
            | Signal::Rectangular { amplitude, .. } => amplitude.abs(),
            Signal::Constant { value } => value.abs(),
            Signal::Record(r) => r.peak(),
        }
    }
}
