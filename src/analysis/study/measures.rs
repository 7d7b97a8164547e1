//! One case of a study run to its end, keeping only its measures (peaks, collapse, impacts,
//! residual tilt, dissipated energy) with memory flat in the duration.

use crr_impact::Samples;

use crate::analysis::simulation::simulate;

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
}

/// Runs one case to its end (or collapse) by the same loop as `crr::run`, keeping only its
/// measures: the samples are drained after every step, so memory does not grow with the
/// duration.
pub fn run_case(study: &Study, case: &Case) -> Result<Measures, String> {
    let ground = study.ground_motion(case)?;
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
        None,
    )
    .map_err(|e| e.to_string())?;
    if let Some(e) = error {
        return Err(e.to_string());
    }
    let (residual, dissipated) = last.unwrap_or((0.0, 0.0));
    Ok(Measures {
        peak: t.peak_abs.clone(),
        collapse: t.collapse.as_ref().map(|c| c.t),
        impacts: t.impacts.len(),
        residual,
        dissipated,
        end_time: t.end_time,
    })
}
