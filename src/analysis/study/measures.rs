//! One case of a study run to its end, keeping only its measures (peaks, collapse, impacts,
//! residual tilt, dissipated energy, the hypotheses monitor's first violation) with memory flat
//! in the duration.

use crr_impact::Samples;
use crr_impact::monitor::Violation;

use crate::analysis::simulation::{Cancel, simulate};
use crr_impact::simulation::SimulationError;

use super::cases::{Case, Study};

/// The measures of one case.
#[derive(Clone, Debug, PartialEq)]
pub struct Measures {
    /// Peak |φ| of every coordinate (rad).
    pub peak: Vec<f64>,
    /// Collapse time (s), if it collapsed.
    pub collapse: Option<f64>,
    /// Number of impacts.
    pub impacts: usize,
    /// Largest |q| at the end (rad): the residual rotation (0 when the structure is back at rest).
    pub residual: f64,
    /// Energy dissipated (J).
    pub dissipated: f64,
    /// Time reached (s).
    pub end_time: f64,
    /// The first failure of the rigid-contact hypotheses in the run (the hypotheses monitor's:
    /// a flight, a resultant outside its face, sliding, an impulse that pulls), if any: the
    /// case's results after its time are outside crr's model, as `crr simulate` warns.
    pub violation: Option<Violation>,
}

/// A case that stopped with an error.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseFailure {
    /// The error.
    pub message: String,
    /// The measures of its run up to the error, when the run started and stopped part-way (a
    /// flight the contact decision finds, impacts that do not settle…): computed results are
    /// kept. None when the case could not start (a record that cannot be read, an initial
    /// state that cannot be solved).
    pub reached: Option<Box<Measures>>,
}

impl CaseFailure {
    fn before_the_run(message: String) -> Self {
        Self {
            message,
            reached: None,
        }
    }
}

/// Runs one case to its end (or collapse) by the same loop as `crr::run`, keeping only its
/// measures: the samples are drained after every step, so memory does not grow with the
/// duration.
pub fn run_case(study: &Study, case: &Case) -> Result<Measures, CaseFailure> {
    run_case_cancellable(study, case, None).expect("a run without a flag is not cancelled")
}

/// [`run_case`] that stops when `cancel` is set: None when it was set before the case ended (its
/// measures would be those of a partial run, so it has none).
pub fn run_case_cancellable(
    study: &Study,
    case: &Case,
    cancel: Option<&Cancel>,
) -> Option<Result<Measures, CaseFailure>> {
    if cancel.is_some_and(Cancel::is_cancelled) {
        return None;
    }
    match measure(study, case, cancel) {
        Err(CaseStop::Cancelled) => None,
        Err(CaseStop::Failed(e)) => Some(Err(e)),
        Ok(m) => Some(Ok(m)),
    }
}

/// Why a case has no complete measures.
enum CaseStop {
    Failed(CaseFailure),
    Cancelled,
}

fn measure(study: &Study, case: &Case, cancel: Option<&Cancel>) -> Result<Measures, CaseStop> {
    let failed = |e: String| CaseStop::Failed(CaseFailure::before_the_run(e));
    let ground = study.ground_motion(case).map_err(failed)?;
    let mut params = study.params.clone();
    params.duration = study.duration(&ground);
    let variant = &study.variants[case.variant];
    // The last sample's largest |q| (the residual tilt) and dissipated energy.
    let mut last = None;
    let mut keep_last = |samples: &Samples| {
        if let Some(s) = samples.last() {
            last = Some((s.q.iter().fold(0.0f64, |m, q| m.max(q.abs())), s.dissipated));
        }
        Ok(())
    };
    let (t, error) = simulate(
        &variant.model,
        &ground,
        &variant.initial,
        &params,
        &mut keep_last,
        true,
        false,
        cancel,
        None,
    )
    .map_err(|e| failed(e.to_string()))?;
    let (residual, dissipated) = last.unwrap_or((0.0, 0.0));
    let measures = Measures {
        peak: t.peak_abs.clone(),
        collapse: t.collapse.as_ref().map(|c| c.t),
        impacts: t.impacts.len(),
        residual,
        dissipated,
        end_time: t.end_time,
        violation: t.violation.clone(),
    };
    match error {
        Some(SimulationError::Cancelled { .. }) => Err(CaseStop::Cancelled),
        Some(e) => Err(CaseStop::Failed(CaseFailure {
            message: e.to_string(),
            reached: Some(Box::new(measures)),
        })),
        None => Ok(measures),
    }
}
