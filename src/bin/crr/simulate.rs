//! `crr simulate MODEL [--out DIR] [--duration T] [--record FILE …] [--plot] [--animate]`.

use std::io::IsTerminal;
use std::path::PathBuf;

use crr::analysis::simulation::prepare;
use crr::dynamics::ground_motion::{Axis, RecordFormat, Units};
use crr::output::plot::plot_results;
use crr::output::results_folder::check_out_dir;
use crr::output::simulate::{FolderOptions, SimulateResult, out_dir, write_run};
use crr::{Error, ModelInput, RecordFile, RunOptions};

use crate::failure::Failure;

/// The arguments of `crr simulate`.
#[derive(clap::Args)]
pub(crate) struct Args {
    /// Model file (TOML, or JSON when it ends in .json).
    pub(crate) model: PathBuf,
    /// Output folder (default results/<model name>).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
    /// Simulated time (s); default [analysis].duration, else the ground motion's duration
    /// + 5 s, else 10 s.
    #[arg(long, value_name = "T")]
    pub(crate) duration: Option<f64>,
    /// Accelerogram file driving one component (overrides the model's component).
    #[arg(long, value_name = "FILE")]
    pub(crate) record: Option<PathBuf>,
    /// Record format: peer-at2, csv or text.
    #[arg(long, value_name = "FORMAT", requires = "record")]
    pub(crate) format: Option<String>,
    /// Record units: g, m/s2 or cm/s2 (required for csv/text).
    #[arg(long, value_name = "UNITS", requires = "record")]
    pub(crate) units: Option<String>,
    /// Ground-motion component the record drives: x, y or z.
    #[arg(long, value_name = "AXIS", default_value = "x", requires = "record")]
    pub(crate) component: String,
    /// Factor on the record's accelerations.
    #[arg(long, value_name = "S", default_value_t = 1.0, requires = "record")]
    pub(crate) scale: f64,
    /// No progress indication.
    #[arg(long)]
    pub(crate) quiet: bool,
    /// Replace the results of an earlier run in the output folder (by default such a folder
    /// is left alone and the run refused).
    #[arg(long)]
    pub(crate) force: bool,
    /// Also draw coordinates, energy and phase plots (PNG and SVG) into the output folder.
    #[arg(long)]
    pub(crate) plot: bool,
    /// Also animate the run (ParaView series and GIF, default options of `crr animate`)
    /// into DIR/animation.
    #[arg(long)]
    pub(crate) animate: bool,
}

fn record_arg(
    record: Option<PathBuf>,
    format: Option<String>,
    units: Option<String>,
    component: &str,
    scale: f64,
) -> Result<Option<RecordFile>, Error> {
    let Some(file) = record else {
        return Ok(None);
    };
    let arg = |e: String| Error::Argument(e);
    let format: RecordFormat = match format {
        Some(f) => f.parse().map_err(|e| arg(format!("--format: {e}")))?,
        None => {
            return Err(arg(
                "--record needs --format peer-at2, csv or text".to_string()
            ));
        }
    };
    let units: Option<Units> = units
        .map(|u| u.parse().map_err(|e| arg(format!("--units: {e}"))))
        .transpose()?;
    let component: Axis = component
        .parse()
        .map_err(|e| arg(format!("--component: {e}")))?;
    if !scale.is_finite() {
        return Err(arg(format!("--scale must be finite, got {scale}")));
    }
    Ok(Some(RecordFile {
        file,
        format,
        units,
        component,
        scale,
    }))
}

pub(crate) fn run(a: Args) -> Result<(), Failure> {
    let Args {
        model,
        out,
        duration,
        record,
        format,
        units,
        component,
        scale,
        quiet,
        force,
        plot,
        animate,
    } = a;
    let cancel = crate::interrupt::interrupt_flag();
    let options = RunOptions {
        duration,
        record_file: record_arg(record, format, units, &component, scale)?,
        progress: !quiet && std::io::stderr().is_terminal(),
        cancel: Some(cancel.clone()),
        ..Default::default()
    };
    let folder = FolderOptions { out, force };
    let input = ModelInput::read(&model)?;
    // Worded for the command line (the library says "duration"), after the model is read.
    if let Some(d) = duration
        && !(d.is_finite() && d > 0.0)
    {
        return Err(Failure::Input(Error::Argument(format!(
            "--duration must be a positive number of seconds, got {d}"
        ))));
    }
    let prepared = prepare(&input, &options)?;
    let out = out_dir(&input, &folder);
    check_out_dir(&out, folder.force)?;
    // Before the run, so that a user who did not mean it can stop it at once.
    let early = prepared.history_size_warning();
    if let Some(w) = &early {
        eprintln!("crr: warning: {w}");
    }
    let result = write_run(&prepared, &out)?;
    // An interrupted run writes its partial results and nothing more.
    let (plot, animate) = (
        plot && !cancel.is_cancelled(),
        animate && !cancel.is_cancelled(),
    );
    if plot {
        let dir = match &result {
            SimulateResult::Done(dir, _) | SimulateResult::Failed(dir, _) => dir,
        };
        // After a failed run the failure is the news: a plot that cannot be drawn from the
        // partial results (a folder kept after failed writes may lack impacts.csv) is a
        // warning, not the error that would hide it.
        match (plot_results(dir), &result) {
            (Err(e), SimulateResult::Failed(..)) => {
                eprintln!("crr: warning: the partial results could not be plotted: {e}");
            }
            (plotted, _) => {
                plotted?;
            }
        }
    }
    if animate {
        let dir = match &result {
            SimulateResult::Done(dir, _) | SimulateResult::Failed(dir, _) => dir,
        };
        let opts = crr::output::animate::AnimateOptions {
            force,
            ..Default::default()
        };
        let report = crr::output::animate::animate(dir, &opts)?;
        if !quiet {
            crate::animate::print_animation(&report);
        }
    }
    match result {
        SimulateResult::Done(dir, summary) => {
            if !quiet {
                println!(
                    "{}: {} impact(s), collapse: {}, end time {} s; results in {}",
                    model.display(),
                    summary.impacts,
                    match (&summary.collapse.time, &summary.collapse.body) {
                        // As JSON: the body's name quoted, the numbers as in summary.json.
                        (Some(t), Some(body)) =>
                            format!("yes at t = {} s ({})", json(t), json(body)),
                        _ => "no".to_string(),
                    },
                    json(&summary.end_time),
                    dir.display()
                );
            }
            let warnings = &summary.warnings;
            for w in warnings.iter().filter(|w| Some(*w) != early.as_ref()) {
                eprintln!("crr: warning: {w}");
            }
            if !warnings.is_empty() {
                eprintln!(
                    "crr: the run completed with {} warning(s), listed in {}",
                    warnings.len(),
                    dir.join("summary.json").display()
                );
            }
        }
        SimulateResult::Failed(dir, e) => {
            return Err(Failure::Simulation(format!(
                "{}: the simulation failed: {e} (partial results written to {}, \"completed\": false)",
                model.display(),
                dir.display()
            )));
        }
    }
    Ok(())
}

/// A value as summary.json writes it (the printed line has always shown the JSON values).
fn json<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).expect("a number or a name serialises")
}
