//! The `crr` command line.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crr::dynamics::ground_motion::{Axis, RecordFormat, Units};
use crr::inspect::{configuration, inspect, to_text};
use crr::plot::{PlotError, plot_check, plot_results};
use crr::poincare::{
    PoincareOptions, PoincareResult, Sweep, parse_acceleration, parse_finite, parse_frequency,
    parse_range, poincare,
};
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
    /// Poincaré section under the harmonic ground acceleration A sin(2πF t + φ): the states at
    /// t = kT (T = 1/F), or where a coordinate crosses 0 upward (--section, or --amplitude 0);
    /// sweeps give a bifurcation diagram or basins (docs/poincare.md).
    Poincare {
        /// Model file (TOML, or JSON when it ends in .json).
        model: PathBuf,
        /// Amplitude A of the ground acceleration, in m/s² (or in g as `0.3g`, g = 9.80665 m/s²);
        /// it replaces the model's ground motion. 0: no ground motion, a crossing section.
        #[arg(
            long,
            value_name = "A",
            default_value = "0",
            allow_hyphen_values = true
        )]
        amplitude: String,
        /// Frequency F of the ground acceleration (Hz); the section is taken at t = k/F.
        #[arg(long, value_name = "F", allow_negative_numbers = true)]
        frequency: Option<f64>,
        /// Ground-motion component driven: x, y or z.
        #[arg(long, value_name = "AXIS", default_value = "x")]
        component: String,
        /// Phase φ of the sine (rad).
        #[arg(
            long,
            value_name = "PHI",
            default_value_t = 0.0,
            allow_negative_numbers = true
        )]
        phase: f64,
        /// N: section points kept (forcing periods, or crossings).
        #[arg(long, value_name = "N", default_value_t = 100)]
        periods: usize,
        /// M: forcing periods (or crossings) dropped first as the transient.
        #[arg(long, value_name = "M", default_value_t = 100)]
        transient: usize,
        /// Crossing section: the post-impact states where coordinate COORD crosses 0 from
        /// negative to positive.
        #[arg(long, value_name = "COORD")]
        section: Option<String>,
        /// The coordinate of the bifurcation diagram and of the --grid initial conditions
        /// (default the first).
        #[arg(long, value_name = "NAME")]
        coordinate: Option<String>,
        /// Time limit of a crossing section (s, default 1000).
        #[arg(long, value_name = "T")]
        duration: Option<f64>,
        /// Start from rest instead of the model's [initial] state.
        #[arg(long)]
        rest: bool,
        /// Bifurcation diagram against the amplitude: A0:A1:n (m/s², or g as 0.1g:0.3g:n).
        #[arg(
            long,
            value_name = "A0:A1:N",
            conflicts_with_all = ["frequencies", "grid"],
            allow_hyphen_values = true
        )]
        amplitudes: Option<String>,
        /// Bifurcation diagram against the frequency: F0:F1:n (Hz).
        #[arg(
            long,
            value_name = "F0:F1:N",
            conflicts_with = "grid",
            allow_hyphen_values = true
        )]
        frequencies: Option<String>,
        /// Basins: initial angle θ0:θ1:n (rad) × initial rate ω0:ω1:m (rad/s) of the coordinate.
        #[arg(long, value_name = "T0:T1:N,W0:W1:M", allow_hyphen_values = true)]
        grid: Option<String>,
        /// Worker threads of a sweep (default one per core); results do not depend on it.
        #[arg(long, value_name = "N")]
        jobs: Option<usize>,
        /// Output folder (default results/<model name>_poincare).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Replace the results of an earlier run in the output folder.
        #[arg(long)]
        force: bool,
        /// No progress indication and no summary line.
        #[arg(long)]
        quiet: bool,
        /// Also draw the section (or the bifurcation diagram, or the basins) as PNG and SVG.
        #[arg(long)]
        plot: bool,
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

/// The raw options of `crr poincare`.
struct PoincareArgs {
    amplitude: String,
    frequency: Option<f64>,
    component: String,
    phase: f64,
    periods: usize,
    transient: usize,
    section: Option<String>,
    coordinate: Option<String>,
    duration: Option<f64>,
    rest: bool,
    amplitudes: Option<String>,
    frequencies: Option<String>,
    grid: Option<String>,
    jobs: Option<usize>,
    out: Option<PathBuf>,
    force: bool,
    quiet: bool,
}

fn poincare_options(a: PoincareArgs) -> Result<PoincareOptions, InputError> {
    let arg = InputError::Argument;
    let amplitude = parse_acceleration(&a.amplitude, "--amplitude").map_err(arg)?;
    let axis: Axis = a
        .component
        .parse()
        .map_err(|e| arg(format!("--component: {e}")))?;
    let sweep = if let Some(r) = &a.amplitudes {
        Sweep::Amplitudes(
            parse_range(r, "--amplitudes", |v| parse_acceleration(v, "--amplitudes"))
                .map_err(arg)?,
        )
    } else if let Some(r) = &a.frequencies {
        Sweep::Frequencies(
            parse_range(r, "--frequencies", |v| parse_frequency(v, "--frequencies"))
                .map_err(arg)?,
        )
    } else if let Some(g) = &a.grid {
        let Some((angle, rate)) = g.split_once(',') else {
            return Err(arg(format!(
                "--grid must be T0:T1:N,W0:W1:M (angles in rad, rates in rad/s), got `{g}`"
            )));
        };
        Sweep::Grid {
            angle: parse_range(angle, "--grid (angles)", |v| {
                parse_finite(v, "--grid (angles)")
            })
            .map_err(arg)?,
            rate: parse_range(rate, "--grid (rates)", |v| {
                parse_finite(v, "--grid (rates)")
            })
            .map_err(arg)?,
        }
    } else {
        Sweep::None
    };
    if a.amplitudes.is_some() && amplitude != 0.0 {
        return Err(arg(
            "--amplitude and --amplitudes cannot be given together".into()
        ));
    }
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
    if let Some(sec) = s.get("section") {
        if sec["overturned"] == true {
            eprintln!(
                "crr: {}: the structure overturned at t = {} s ({}): the section ends there, \
                 with {} point(s)",
                model.display(),
                sec["overturn_time"],
                sec["overturn_body"].as_str().unwrap_or_default(),
                sec["points"]
            );
        }
        let v = &sec["hypothesis_violation"];
        if !v.is_null() {
            eprintln!(
                "crr: warning: the rigid-contact hypotheses fail at t = {} s: interface \"{}\" \
                 ({}); the points after that time are outside crr's model",
                v["time"],
                v["interface"].as_str().unwrap_or_default(),
                v["kind"].as_str().unwrap_or_default()
            );
        }
        if let Some(e) = sec["error"].as_str() {
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
                sec["points"],
                sec["distinct_points"],
                if sec["period"].is_null() {
                    "not found".to_string()
                } else {
                    sec["period"].to_string()
                },
                r.out.display()
            );
        }
    } else if let Some(cases) = s["cases"].as_array() {
        let overturned = cases.iter().filter(|c| c["overturned"] == true).count();
        let failed = cases.iter().filter(|c| !c["error"].is_null()).count();
        if overturned > 0 {
            eprintln!(
                "crr: {}: {overturned} of {} case(s) overturned",
                model.display(),
                cases.len()
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
        Command::Poincare {
            model,
            amplitude,
            frequency,
            component,
            phase,
            periods,
            transient,
            section,
            coordinate,
            duration,
            rest,
            amplitudes,
            frequencies,
            grid,
            jobs,
            out,
            force,
            quiet,
            plot,
        } => {
            let opts = poincare_options(PoincareArgs {
                amplitude,
                frequency,
                component,
                phase,
                periods,
                transient,
                section,
                coordinate,
                duration,
                rest,
                amplitudes,
                frequencies,
                grid,
                jobs,
                out,
                force,
                quiet,
            })?;
            let result = poincare(&model, &opts, plot)?;
            if let Some(e) = report_poincare(&model, &result, quiet) {
                return Err(Failure::Simulation(e));
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
