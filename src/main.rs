//! The `crr` command line.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crr::dynamics::ground_motion::{Axis, RecordFormat, Units};
use crr::inspect::{configuration, inspect, to_text};
use crr::plot::{PlotError, plot_check, plot_results};
use crr::simulate::{RecordArg, SimulateOptions, SimulateResult, simulate};
use crr::{InputError, load_model};

/// crr: dynamics of rigid-block masonry structures by coupled rocking rotations.
#[derive(Parser)]
#[command(name = "crr", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the coordinates, mass properties, M(q), gravity forces, U and Φ at a configuration.
    Inspect {
        /// Model file (TOML, or JSON when it ends in .json).
        model: PathBuf,
        /// Set a coordinate, NAME=VALUE in radians (repeatable; others are 0).
        #[arg(long = "q", value_name = "NAME=VALUE")]
        q: Vec<String>,
        /// Print JSON (keys documented in docs/inspect.md) instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Run the simulation and write history.csv, impacts.csv and summary.json
    /// (docs/outputs.md).
    Simulate {
        /// Model file (TOML, or JSON when it ends in .json).
        model: PathBuf,
        /// Output folder (default results/<model name>).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Simulated time (s); default [analysis].duration, else the ground motion's duration
        /// + 5 s, else 10 s.
        #[arg(long, value_name = "T")]
        duration: Option<f64>,
        /// Accelerogram file driving one component (overrides the model's component).
        #[arg(long, value_name = "FILE")]
        record: Option<PathBuf>,
        /// Record format: peer-at2, csv or text.
        #[arg(long, value_name = "FORMAT", requires = "record")]
        format: Option<String>,
        /// Record units: g, m/s2 or cm/s2 (required for csv/text).
        #[arg(long, value_name = "UNITS", requires = "record")]
        units: Option<String>,
        /// Ground-motion component the record drives: x, y or z.
        #[arg(long, value_name = "AXIS", default_value = "x", requires = "record")]
        component: String,
        /// Factor on the record's accelerations.
        #[arg(long, value_name = "S", default_value_t = 1.0, requires = "record")]
        scale: f64,
        /// No progress indication.
        #[arg(long)]
        quiet: bool,
        /// Replace the results of an earlier run in the output folder (by default such a folder
        /// is left alone and the run refused).
        #[arg(long)]
        force: bool,
        /// Also draw coordinates, energy and phase plots (PNG and SVG) into the output folder.
        #[arg(long)]
        plot: bool,
    },
    /// Draw the plots of a results folder written by `crr simulate`: coordinates, energy and
    /// phase (.png and .svg, docs/outputs.md).
    Plot {
        /// The results folder (history.csv, impacts.csv, summary.json).
        dir: PathBuf,
    },
    /// Mobility report; for a one-DOF mechanism λ, the equivalent block, r and the free-rocking
    /// frequencies (docs/outputs.md).
    Check {
        /// Model file (TOML, or JSON when it ends in .json).
        model: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
        /// Draw the frequency versus amplitude plot (housner.png, housner.svg) into DIR.
        #[arg(long, value_name = "DIR")]
        plot: Option<PathBuf>,
    },
    /// Run every case of a study file (a pulse family's amplitude × frequency grid, or records
    /// scaled to intensity levels) in parallel into cases.csv and study.json (docs/studies.md);
    /// rerunning into the same folder resumes. `crr study merge DIR... --out DIR` joins shards.
    #[command(args_conflicts_with_subcommands = true)]
    Study {
        #[command(subcommand)]
        action: Option<StudyAction>,
        /// Study file (TOML).
        study: Option<PathBuf>,
        /// Output folder (default results/<study name>).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Worker threads (default: one per core).
        #[arg(long, value_name = "N")]
        jobs: Option<usize>,
        /// Run only the i-th of n disjoint parts (1 ≤ i ≤ n), e.g. one task of a job array.
        #[arg(long, value_name = "i/n")]
        shard: Option<String>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
}

#[derive(Subcommand)]
enum StudyAction {
    /// Join the cases.csv of shard folders (same study) into one folder, in case-id order.
    Merge {
        /// The shards' output folders.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Folder of the merged cases.csv and study.json.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
}

/// Input problems and plots that cannot be drawn exit with 2, a simulation that failed part-way
/// with 1.
enum Failure {
    Input(InputError),
    Plot(PlotError),
    Simulation(String),
}

impl From<PlotError> for Failure {
    fn from(e: PlotError) -> Self {
        Failure::Plot(e)
    }
}

impl From<InputError> for Failure {
    fn from(e: InputError) -> Self {
        Failure::Input(e)
    }
}

fn record_arg(
    record: Option<PathBuf>,
    format: Option<String>,
    units: Option<String>,
    component: &str,
    scale: f64,
) -> Result<Option<RecordArg>, InputError> {
    let Some(file) = record else {
        return Ok(None);
    };
    let arg = |e: String| InputError::Argument(e);
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
    Ok(Some(RecordArg {
        file,
        format,
        units,
        component,
        scale,
    }))
}

fn run(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Inspect { model, q, json } => {
            let (_, m) = load_model(&model)?;
            let q = configuration(&m, &q)?;
            let report = inspect(&m, &q);
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&report).expect("report serialises")
                );
            } else {
                print!("{}", to_text(&report));
            }
        }
        Command::Simulate {
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
        } => {
            let opts = SimulateOptions {
                out,
                duration,
                record: record_arg(record, format, units, &component, scale)?,
                quiet,
                force,
            };
            let result = simulate(&model, &opts)?;
            if plot {
                let dir = match &result {
                    SimulateResult::Done(dir, _) | SimulateResult::Failed(dir, _) => dir,
                };
                plot_results(dir)?;
            }
            match result {
                SimulateResult::Done(dir, summary) => {
                    if !quiet {
                        println!(
                            "{}: {} impact(s), collapse: {}, end time {} s; results in {}",
                            model.display(),
                            summary["impacts"],
                            if summary["collapse"]["collapsed"] == true {
                                format!(
                                    "yes at t = {} s ({})",
                                    summary["collapse"]["time"], summary["collapse"]["body"]
                                )
                            } else {
                                "no".to_string()
                            },
                            summary["end_time"],
                            dir.display()
                        );
                    }
                    let warnings = summary["warnings"].as_array().cloned().unwrap_or_default();
                    for w in &warnings {
                        eprintln!("crr: warning: {}", w.as_str().unwrap_or_default());
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
        }
        Command::Check { model, json, plot } => {
            let (_, m) = load_model(&model)?;
            let report = crr::check::check(&m);
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&report).expect("report serialises")
                );
            } else {
                print!("{}", crr::check::to_text(&report));
            }
            if let Some(dir) = plot {
                plot_check(&dir, &report)?;
            }
        }
        Command::Study {
            action: Some(StudyAction::Merge { dirs, out }),
            ..
        } => {
            let n = crr::study::merge(&dirs, &out)?;
            println!(
                "{n} case(s) merged into {}",
                out.join("cases.csv").display()
            );
        }
        Command::Study {
            action: None,
            study,
            out,
            jobs,
            shard,
            quiet,
        } => {
            let Some(path) = study else {
                return Err(Failure::Input(InputError::Argument(
                    "crr study needs a study file (or `merge DIR... --out DIR`)".into(),
                )));
            };
            if jobs == Some(0) {
                return Err(Failure::Input(InputError::Argument(
                    "--jobs must be at least 1".into(),
                )));
            }
            let shard = match shard {
                Some(s) => s.parse().map_err(InputError::Argument)?,
                None => crr::study::Shard::ALL,
            };
            let study = crr::study::Study::load(&path)?;
            let out = out.unwrap_or_else(|| PathBuf::from("results").join(&study.name));
            let outcome = crr::study::run_study(
                &study,
                &path,
                &crr::study::StudyOptions {
                    out: out.clone(),
                    jobs,
                    shard,
                    quiet,
                },
            )?;
            if !quiet {
                println!(
                    "{}: {} case(s) in this part, {} already done, {} run, {} with an error; results in {}",
                    path.display(),
                    outcome.cases,
                    outcome.skipped,
                    outcome.ran,
                    outcome.failed,
                    out.display()
                );
            }
        }
        Command::Plot { dir } => {
            for f in plot_results(&dir)? {
                println!("{}", f.display());
            }
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("crr: error: {e}");
            ExitCode::from(2)
        }
        Err(Failure::Plot(e)) => {
            eprintln!("crr: error: {e}");
            ExitCode::from(2)
        }
        Err(Failure::Simulation(e)) => {
            eprintln!("crr: error: {e}");
            ExitCode::from(1)
        }
    }
}
