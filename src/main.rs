//! The `crr` command line.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crr::dynamics::ground_motion::{Axis, RecordFormat, Units};
use crr::inspect::{configuration, inspect, to_text};
use crr::plot::{
    PlotError, plot_check, plot_housner_models, plot_levels, plot_results, plot_size_sweep,
};
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
        /// Also animate the run (ParaView series and GIF, default options of `crr animate`)
        /// into DIR/animation.
        #[arg(long)]
        animate: bool,
    },
    /// Animate a results folder written by `crr simulate`: a ParaView series (frame_NNNNN.vtu
    /// and animation.pvd) and an animated GIF (docs/animation.md).
    Animate {
        /// The results folder (history.csv and summary.json).
        #[arg(value_name = "RESULTS_DIR")]
        dir: PathBuf,
        /// Keep every K-th state of history.csv (default: about 0.05 s between frames, at most
        /// 400 frames).
        #[arg(long, value_name = "K")]
        every: Option<usize>,
        /// Output folder (default RESULTS_DIR/animation).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// The GIF's view: x, y, z (orthographic along that axis) or iso (isometric).
        #[arg(long, value_name = "VIEW", default_value = "iso")]
        view: String,
        /// Files to write: vtk (the ParaView series), gif, or both.
        #[arg(long, value_name = "FORMAT", default_value = "both")]
        format: String,
        /// GIF playback speed: 1 is real time, 0.5 half speed.
        #[arg(long, value_name = "S", default_value_t = 1.0)]
        speed: f64,
        /// Replace an earlier animation in the output folder.
        #[arg(long)]
        force: bool,
    },
    /// Draw the plots of a results folder written by `crr simulate`: coordinates, energy and
    /// phase (.png and .svg, docs/outputs.md); of a study folder (cases.csv and study.json): the
    /// overturning map, rocking spectrum and fragility curves (docs/studies.md).
    Plot {
        /// The results folder (history.csv, impacts.csv, summary.json; or cases.csv and
        /// study.json).
        dir: PathBuf,
    },
    /// Mobility report; for a one-DOF mechanism λ, the equivalent block, r and the free-rocking
    /// frequencies (docs/outputs.md).
    Check {
        /// Model file(s) (TOML, or JSON when it ends in .json); several models are reported one
        /// after the other and share the frequency figures.
        #[arg(required = true)]
        models: Vec<PathBuf>,
        /// Print JSON instead of text (an array of reports for several models).
        #[arg(long)]
        json: bool,
        /// Draw the frequency versus amplitude plot (housner.png, .svg) and the energy levels
        /// (levels.png, .svg, .csv) into DIR.
        #[arg(long, value_name = "DIR")]
        plot: Option<PathBuf>,
        /// Scale the model geometrically by n factors from s0 to s1 and report the frequency
        /// against size (size_sweep.png, .svg with --plot).
        #[arg(long, value_name = "S0:S1:N", allow_hyphen_values = true)]
        size_sweep: Option<String>,
        /// θm/α_eq of the size sweep's frequencies (between 0 and 1).
        #[arg(
            long,
            value_name = "R",
            allow_hyphen_values = true,
            requires = "size_sweep",
            default_value_t = crr::size_sweep::DEFAULT_AMPLITUDE_RATIO)]
        amplitude_ratio: f64,
        /// A direction of the ground acceleration for the static multiplier, instead of ±x and
        /// ±y: `+x`, `-y`, … or `X,Y,Z` (may have a vertical part); repeat for several.
        #[arg(long, value_name = "D", allow_hyphen_values = true)]
        direction: Vec<String>,
        /// Coulomb friction coefficient μ at every contact of the static multiplier (default: no
        /// sliding, and the report gives the μ each multiplier needs).
        #[arg(long, value_name = "MU")]
        friction: Option<f64>,
        /// Replace the plots of an earlier `crr check --plot` in DIR.
        #[arg(long)]
        force: bool,
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
        /// Also draw the study's figures into the output folder (as `crr plot DIR`).
        #[arg(long)]
        plot: bool,
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

/// A file of an earlier `crr check --plot` in `dir` (the frequency plot, the energy levels, the
/// size sweep), if any.
fn earlier_check_plot(dir: &Path) -> Option<PathBuf> {
    let entries = std::fs::read_dir(dir).ok()?;
    entries.flatten().map(|e| e.path()).find(|p| {
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        let stem = name.split('.').next().unwrap_or("");
        (stem == "housner" || stem == "levels" || stem.ends_with("_levels") || stem == "size_sweep")
            && [".png", ".svg", ".csv"].iter().any(|e| name.ends_with(e))
    })
}

/// `crr check MODEL… [--json] [--plot DIR] [--size-sweep s0:s1:n] [--amplitude-ratio R]`.
fn check_models(
    paths: &[PathBuf],
    json: bool,
    plot: Option<&Path>,
    size_sweep: Option<&str>,
    amplitude_ratio: f64,
    directions: &[String],
    friction: Option<f64>,
    force: bool,
) -> Result<(), Failure> {
    use crr::levels::{DEFAULT_STEP, mechanism_levels};
    use crr::size_sweep::{check_amplitude_ratio, parse_sweep};
    let scales = size_sweep.map(parse_sweep).transpose()?;
    let ratio = check_amplitude_ratio(amplitude_ratio)?;
    let directions = if directions.is_empty() {
        crr::static_multiplier::horizontal_directions()
    } else {
        directions
            .iter()
            .map(|d| crr::static_multiplier::parse_direction(d))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| Failure::Input(InputError::Argument(format!("--direction: {e}"))))?
    };
    if let Some(mu) = friction
        && !(mu.is_finite() && mu >= 0.0)
    {
        return Err(Failure::Input(InputError::Argument(format!(
            "--friction must be a finite number ≥ 0, got {mu}"
        ))));
    }
    if let Some(dir) = plot
        && !force
        && let Some(earlier) = earlier_check_plot(dir)
    {
        return Err(Failure::Input(InputError::Argument(format!(
            "{}: the folder holds the plots of an earlier `crr check --plot` ({}): pass --force to replace them",
            dir.display(),
            earlier.display()
        ))));
    }
    let loaded = paths
        .iter()
        .map(|p| load_model(p))
        .collect::<Result<Vec<_>, _>>()?;
    let reports: Vec<_> = loaded
        .iter()
        .map(|(_, m)| crr::check::check_with(m, &directions, friction))
        .collect();
    // The sweep needs a one-DOF mechanism; its failure is reported after the reports.
    let mut sweeps: Vec<Option<crr::size_sweep::SizeSweep>> = vec![None; reports.len()];
    let mut sweep_error = None;
    if let Some(scales) = &scales {
        for (((file, _), report), slot) in loaded.iter().zip(&reports).zip(&mut sweeps) {
            let result = match &report.mechanism {
                None => Err(report
                    .note
                    .clone()
                    .unwrap_or_else(|| "not a one-DOF mechanism".into())),
                Some(_) => crr::size_sweep::size_sweep(&file.structure(), scales, ratio),
            };
            match result {
                Ok(s) => *slot = Some(s),
                Err(e) => {
                    sweep_error.get_or_insert(format!("--size-sweep: {}: {e}", report.model));
                }
            }
        }
    }
    if json {
        let values: Vec<serde_json::Value> = reports
            .iter()
            .zip(&sweeps)
            .map(|(r, sweep)| {
                let mut v = serde_json::to_value(r).expect("report serialises");
                if let Some(s) = sweep {
                    v["size_sweep"] = serde_json::to_value(s).expect("sweep serialises");
                }
                v
            })
            .collect();
        let out = if values.len() == 1 {
            values.into_iter().next().expect("one report")
        } else {
            serde_json::Value::Array(values)
        };
        println!(
            "{}",
            serde_json::to_string_pretty(&out).expect("report serialises")
        );
    } else {
        for (i, (r, sweep)) in reports.iter().zip(&sweeps).enumerate() {
            if i > 0 {
                println!();
            }
            print!("{}", crr::check::to_text(r));
            if let Some(s) = sweep {
                print!("{}", crr::size_sweep::to_text(s));
            }
        }
    }
    if let Some(e) = sweep_error {
        return Err(Failure::Input(InputError::Argument(e)));
    }
    let Some(dir) = plot else {
        return Ok(());
    };
    if reports.len() == 1 {
        plot_check(dir, &reports[0])?;
    } else {
        plot_housner_models(dir, &reports)?;
    }
    let mut used = Vec::new();
    for ((_, m), r) in loaded.iter().zip(&reports) {
        let levels = mechanism_levels(m, DEFAULT_STEP)
            .map_err(|e| PlotError::NoLevels(format!("{}: {e}", r.model)))?;
        let prefix = if reports.len() == 1 {
            String::new()
        } else {
            let mut p: String = r
                .model
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            while used.contains(&p) {
                p.push('_');
            }
            used.push(p.clone());
            p + "_"
        };
        plot_levels(dir, &prefix, &r.model, &levels)?;
        if !json {
            println!(
                "energy levels of {} ({}): {}",
                r.model,
                levels.coordinate,
                levels.ends_text()
            );
        }
    }
    let sweeps: Vec<_> = sweeps.into_iter().flatten().collect();
    if !sweeps.is_empty() {
        plot_size_sweep(dir, &sweeps)?;
    }
    Ok(())
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

/// The lines `crr animate` prints: what was written.
fn print_animation(r: &crr::animate::AnimateReport) {
    println!(
        "{} frame(s) (every {} state(s) of history.csv) in {}",
        r.frames,
        r.every,
        r.out.display()
    );
    if let Some(bytes) = r.gif_bytes {
        println!(
            "{} ({:.1} kB)",
            r.out.join(crr::animate::GIF_FILE).display(),
            bytes as f64 / 1000.0
        );
    }
    if r.files.iter().any(|f| f.ends_with(crr::animate::PVD_FILE)) {
        println!("{}", r.out.join(crr::animate::PVD_FILE).display());
    }
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
            animate,
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
            if animate {
                let dir = match &result {
                    SimulateResult::Done(dir, _) | SimulateResult::Failed(dir, _) => dir,
                };
                let opts = crr::animate::AnimateOptions {
                    force,
                    ..Default::default()
                };
                let report = crr::animate::animate(dir, &opts)?;
                if !quiet {
                    print_animation(&report);
                }
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
        Command::Check {
            models,
            json,
            plot,
            size_sweep,
            amplitude_ratio,
            direction,
            friction,
            force,
        } => check_models(
            &models,
            json,
            plot.as_deref(),
            size_sweep.as_deref(),
            amplitude_ratio,
            &direction,
            friction,
            force,
        )?,
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
            plot,
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
            if plot {
                let files = crr::plot::plot_study(&out)?;
                if !quiet {
                    for f in files {
                        println!("{}", f.display());
                    }
                }
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
        Command::Animate {
            dir,
            every,
            out,
            view,
            format,
            speed,
            force,
        } => {
            let arg = InputError::Argument;
            let opts = crr::animate::AnimateOptions {
                every,
                out,
                view: view.parse().map_err(|e| arg(format!("--view: {e}")))?,
                format: format.parse().map_err(|e| arg(format!("--format: {e}")))?,
                speed,
                force,
            };
            let report = crr::animate::animate(&dir, &opts)?;
            print_animation(&report);
        }
        Command::Plot { dir } => {
            let files = if crr::study::products::is_study_dir(&dir) {
                crr::plot::plot_study(&dir)?
            } else {
                plot_results(&dir)?
            };
            for f in files {
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
