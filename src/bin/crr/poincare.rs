//! `crr poincare MODEL --amplitude A --frequency F [sweeps] [--plot]`.

use std::path::PathBuf;

use crr::Error;
use crr::analysis::poincare::{PoincareOptions, parse_acceleration, parse_sweep};
use crr::dynamics::ground_motion::Axis;
use crr::output::poincare::{PoincareResult, poincare};

use crate::failure::Failure;

/// The arguments of `crr poincare`.
#[derive(clap::Args)]
pub(crate) struct Args {
    /// Model file (TOML, or JSON when it ends in .json).
    pub(crate) model: PathBuf,
    /// Amplitude A of the ground acceleration, in m/s² (or in g as `0.3g`, g = 9.80665 m/s²);
    /// it replaces the model's ground motion. 0: no ground motion, a crossing section.
    #[arg(
        long,
        value_name = "A",
        default_value = "0",
        allow_hyphen_values = true
    )]
    pub(crate) amplitude: String,
    /// Frequency F of the ground acceleration (Hz); the section is taken at t = k/F.
    #[arg(long, value_name = "F", allow_negative_numbers = true)]
    pub(crate) frequency: Option<f64>,
    /// Ground-motion component driven: x, y or z.
    #[arg(long, value_name = "AXIS", default_value = "x")]
    pub(crate) component: String,
    /// Phase φ of the sine (rad).
    #[arg(
        long,
        value_name = "PHI",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub(crate) phase: f64,
    /// N: section points kept (forcing periods, or crossings).
    #[arg(long, value_name = "N", default_value_t = 100)]
    pub(crate) periods: usize,
    /// M: forcing periods (or crossings) dropped first as the transient.
    #[arg(long, value_name = "M", default_value_t = 100)]
    pub(crate) transient: usize,
    /// Crossing section: the post-impact states where coordinate COORD crosses 0 from
    /// negative to positive.
    #[arg(long, value_name = "COORD")]
    pub(crate) section: Option<String>,
    /// The coordinate of the bifurcation diagram and of the --grid initial conditions
    /// (default the first).
    #[arg(long, value_name = "NAME")]
    pub(crate) coordinate: Option<String>,
    /// Time limit of a crossing section (s, default 1000).
    #[arg(long, value_name = "T")]
    pub(crate) duration: Option<f64>,
    /// Start from rest instead of the model's [initial] state.
    #[arg(long)]
    pub(crate) rest: bool,
    /// Bifurcation diagram against the amplitude: A0:A1:n (m/s², or g as 0.1g:0.3g:n).
    #[arg(
        long,
        value_name = "A0:A1:N",
        conflicts_with_all = ["frequencies", "grid"],
        allow_hyphen_values = true
    )]
    pub(crate) amplitudes: Option<String>,
    /// Bifurcation diagram against the frequency: F0:F1:n (Hz).
    #[arg(
        long,
        value_name = "F0:F1:N",
        conflicts_with = "grid",
        allow_hyphen_values = true
    )]
    pub(crate) frequencies: Option<String>,
    /// Basins: initial angle θ0:θ1:n (rad) × initial rate ω0:ω1:m (rad/s) of the coordinate.
    #[arg(long, value_name = "T0:T1:N,W0:W1:M", allow_hyphen_values = true)]
    pub(crate) grid: Option<String>,
    /// Worker threads of a sweep (default one per core); results do not depend on it.
    #[arg(long, value_name = "N")]
    pub(crate) jobs: Option<usize>,
    /// Output folder (default results/<model name>_poincare).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
    /// Replace the results of an earlier run in the output folder.
    #[arg(long)]
    pub(crate) force: bool,
    /// No progress indication and no summary line.
    #[arg(long)]
    pub(crate) quiet: bool,
    /// Also draw the section (or the bifurcation diagram, or the basins) as PNG and SVG.
    #[arg(long)]
    pub(crate) plot: bool,
}

pub(crate) fn run(a: Args) -> Result<(), Failure> {
    let (model, plot, quiet) = (a.model.clone(), a.plot, a.quiet);
    let opts = poincare_options(a)?;
    let result = poincare(&model, &opts, plot)?;
    if let Some(e) = report_poincare(&model, &result, quiet) {
        return Err(Failure::Simulation(e));
    }
    Ok(())
}

fn poincare_options(a: Args) -> Result<PoincareOptions, Error> {
    let arg = Error::Argument;
    let amplitude = parse_acceleration(&a.amplitude, "--amplitude").map_err(arg)?;
    let axis: Axis = a
        .component
        .parse()
        .map_err(|e| arg(format!("--component: {e}")))?;
    let sweep = parse_sweep(
        a.amplitudes.as_deref(),
        a.frequencies.as_deref(),
        a.grid.as_deref(),
    )
    .map_err(arg)?;
    Ok(PoincareOptions {
        amplitude,
        frequency: a.frequency,
        phase: a.phase,
        axis,
        periods: a.periods,
        transient: a.transient,
        section: a.section,
        coordinate: a.coordinate,
        duration: a.duration,
        rest: a.rest,
        sweep,
        jobs: a.jobs,
        out: a.out,
        force: a.force,
        quiet: a.quiet,
    })
}

/// The summary line of `crr poincare` on stdout, and its overturning on stderr; a section that
/// stopped early with an error is returned (exit code 1, as `crr simulate`).
fn report_poincare(model: &std::path::Path, r: &PoincareResult, quiet: bool) -> Option<String> {
    let s = &r.summary;
    if let Some(sec) = &s.section {
        if sec.overturned {
            eprintln!(
                "crr: {}: the structure overturned at t = {} s ({}): the section ends there, \
                 with {} point(s)",
                model.display(),
                json(&sec.overturn_time),
                sec.overturn_body.as_deref().unwrap_or_default(),
                sec.points
            );
        }
        if let Some(v) = &sec.hypothesis_violation {
            eprintln!(
                "crr: warning: the rigid-contact hypotheses fail at t = {} s: interface \"{}\" \
                 ({}); the points after that time are outside crr's model",
                json(&v.time),
                v.interface,
                v.kind
            );
        }
        if let Some(e) = &sec.error {
            return Some(format!(
                "{}: the run stopped early: {e} (the points until then are written to {})",
                model.display(),
                r.out.display()
            ));
        }
        if !quiet {
            println!(
                "{}: {} section point(s), {} distinct, period {}; results in {}",
                model.display(),
                sec.points,
                sec.distinct_points,
                sec.period
                    .map_or_else(|| "not found".to_string(), |p| p.to_string()),
                r.out.display()
            );
        }
    } else if let Some(cases) = &s.cases {
        let overturned = cases.iter().filter(|c| c.section.overturned).count();
        let failed = cases.iter().filter(|c| c.section.error.is_some()).count();
        if overturned > 0 {
            eprintln!(
                "crr: {}: {overturned} of {} case(s) overturned",
                model.display(),
                cases.len()
            );
        }
        let outside = cases
            .iter()
            .filter(|c| c.section.hypothesis_violation.is_some())
            .count();
        if outside > 0 {
            eprintln!(
                "crr: warning: {}: {outside} of {} case(s) left crr's model (the rigid-contact \
                 hypotheses fail: their `hypothesis_violation` in {}): their points after that \
                 time are outside the model",
                model.display(),
                cases.len(),
                r.out.join("poincare.json").display()
            );
        }
        if failed > 0 {
            eprintln!(
                "crr: {}: {failed} of {} case(s) stopped early with an error (listed in {})",
                model.display(),
                cases.len(),
                r.out.join("poincare.json").display()
            );
        }
        if !quiet {
            println!(
                "{}: {} case(s); results in {}",
                model.display(),
                cases.len(),
                r.out.display()
            );
        }
    }
    None
}

/// A number as poincare.json writes it (the printed lines have always shown the JSON values).
fn json<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).expect("a number serialises")
}
