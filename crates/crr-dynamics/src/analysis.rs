//! Solver settings a user gives in the `[analysis]` table of a model file.

use serde::{Deserialize, Serialize};

use crate::integrator::{Method, Options};

/// Integration method by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MethodName {
    /// Dormand–Prince 8(5,3) with 7th-order dense output (default).
    #[default]
    Dop853,
    /// Dormand–Prince 5(4) with 4th-order dense output.
    Dopri5,
    /// Classical fixed-step Runge–Kutta 4 (step `rk4_step`).
    Rk4,
}

/// Largest `rtol` accepted: above it the step control keeps no digit of a rocking motion.
pub const RTOL_MAX: f64 = 1e-2;

/// `rtol` above which a run warns that its results need a smaller tolerance to be trusted (at
/// 1e-3 the bundled trilithon's loops opened and, before the run's invariant, it reported a
/// false collapse).
pub const RTOL_WARNING: f64 = 1e-6;

/// `[analysis]`: duration, output interval and integrator settings, with documented defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AnalysisSpec {
    /// Simulated time (s). Default 10, or the ground motion's duration plus 5 s when it ends.
    pub duration: Option<f64>,
    /// Interval between output samples (s). Default 0.01.
    pub output_interval: f64,
    /// `"dop853"` (default), `"dopri5"` or `"rk4"`.
    pub method: MethodName,
    /// Fixed step of `"rk4"` (s). Default 1e-4.
    pub rk4_step: f64,
    /// Relative tolerance of the adaptive methods. Default 1e-10.
    pub rtol: f64,
    /// Absolute tolerance (rad, rad/s). Default 1e-12.
    pub atol: f64,
    /// Largest step (s). Default: unlimited.
    pub max_step: Option<f64>,
    /// An interface whose rate after an impact is below this seats (rad/s). Default 1e-4.
    pub seat_rate: f64,
    /// An interface impacting again within this time seats (s). Default 1e-6.
    pub min_impact_interval: f64,
    /// Rocking angles within this of 0 at an impact impact together (rad). Default 1e-8.
    pub simultaneity: f64,
    /// Largest number of impacts before the run stops with an error. Default 1 000 000.
    pub max_impacts: usize,
    /// Friction coefficient μ of every contact, for the hypotheses monitor (none: not checked).
    pub friction: Option<f64>,
    /// Collapse when U drops below rest by this fraction of weight × model size. Default 1e-3.
    pub collapse_drop: f64,
    /// Keep every seated joint seated through a momentum-law impact even where that pulls at
    /// its contacts (the paper's "other hinges persisting", recorded as `impulse_tension`),
    /// instead of opening those joints by Moreau's impact. Default false.
    pub hold_seated_at_impacts: bool,
    /// A face that pulls on its pivot where a segment starts (just after an impact) and whose
    /// bound on how far it would open stays within this (m) is not reported as a flight: a hop
    /// of that size is below what the rigid-contact idealisation resolves. Default 0: every
    /// such pull is reported, with its separation.
    pub hop_tolerance: f64,
    /// End the run at the first failure of the rigid-contact hypotheses (the monitor's first
    /// violation), within a step or two of it (a pull at a pivot being measured is measured to
    /// its end first), instead of going on outside the model. Default false.
    pub stop_at_violation: bool,
}

impl Default for AnalysisSpec {
    fn default() -> Self {
        Self {
            duration: None,
            output_interval: 0.01,
            method: MethodName::Dop853,
            rk4_step: 1e-4,
            rtol: 1e-10,
            atol: 1e-12,
            max_step: None,
            seat_rate: 1e-4,
            min_impact_interval: 1e-6,
            simultaneity: 1e-8,
            max_impacts: 1_000_000,
            friction: None,
            collapse_drop: 1e-3,
            hold_seated_at_impacts: false,
            hop_tolerance: 0.0,
            stop_at_violation: false,
        }
    }
}

impl AnalysisSpec {
    /// The integrator method and options, or a message naming the bad field.
    pub fn solver(&self) -> Result<(Method, Options), String> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "analysis.{name} must be a positive number, got {v}"
                ))
            }
        };
        positive("output_interval", self.output_interval)?;
        positive("rtol", self.rtol)?;
        if self.rtol > RTOL_MAX {
            return Err(format!(
                "analysis.rtol must be at most {RTOL_MAX:e}: a step control at rtol = {} keeps no \
                 digit of the motion (default 1e-10; above 1e-6 the run warns)",
                self.rtol
            ));
        }
        positive("atol", self.atol)?;
        positive("rk4_step", self.rk4_step)?;
        positive("seat_rate", self.seat_rate)?;
        positive("min_impact_interval", self.min_impact_interval)?;
        positive("simultaneity", self.simultaneity)?;
        positive("collapse_drop", self.collapse_drop)?;
        if !(self.hop_tolerance.is_finite() && self.hop_tolerance >= 0.0) {
            return Err(format!(
                "analysis.hop_tolerance must be a length of 0 or more (m), got {}",
                self.hop_tolerance
            ));
        }
        if let Some(mu) = self.friction {
            positive("friction", mu)?;
        }
        if let Some(d) = self.duration {
            positive("duration", d)?;
        }
        if let Some(h) = self.max_step {
            positive("max_step", h)?;
        }
        let method = match self.method {
            MethodName::Dop853 => Method::Dop853,
            MethodName::Dopri5 => Method::Dopri5,
            MethodName::Rk4 => Method::Rk4 {
                step: self.rk4_step,
            },
        };
        let options = Options {
            rtol: self.rtol,
            atol: self.atol,
            h_max: self.max_step.unwrap_or(f64::INFINITY),
            ..Options::default()
        };
        options.validate().map_err(|e| format!("analysis: {e}"))?;
        Ok((method, options))
    }
}
