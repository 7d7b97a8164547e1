//! `crr check MODEL… [--json] [--plot DIR] [--size-sweep S0:S1:N] [--direction D]…`.

use std::path::{Path, PathBuf};

use crr::output::plot::{PlotError, plot_check, plot_housner_models, plot_levels, plot_size_sweep};
use crr::{Error, load_model};

use crate::failure::Failure;

/// The arguments of `crr check`.
#[derive(clap::Args)]
pub(crate) struct Args {
    /// Model file(s) (TOML, or JSON when it ends in .json); several models are reported one
    /// after the other and share the frequency figures.
    #[arg(required = true)]
    pub(crate) models: Vec<PathBuf>,
    /// Print JSON instead of text (an array of reports for several models).
    #[arg(long)]
    pub(crate) json: bool,
    /// Draw the frequency versus amplitude plot (housner.png, .svg) and the energy levels
    /// (levels.png, .svg, .csv) into DIR.
    #[arg(long, value_name = "DIR")]
    pub(crate) plot: Option<PathBuf>,
    /// Scale the model geometrically by n factors from s0 to s1 and report the frequency
    /// against size (size_sweep.png, .svg with --plot).
    #[arg(long, value_name = "S0:S1:N", allow_hyphen_values = true)]
    pub(crate) size_sweep: Option<String>,
    /// θm/α_eq of the size sweep's frequencies (between 0 and 1).
    #[arg(
        long,
        value_name = "R",
        allow_hyphen_values = true,
        requires = "size_sweep",
        default_value_t = crr::analysis::size_sweep::DEFAULT_AMPLITUDE_RATIO)]
    pub(crate) amplitude_ratio: f64,
    /// A direction of the ground acceleration for the static multiplier, instead of ±x and
    /// ±y: `+x`, `-y`, … or `X,Y,Z` (may have a vertical part); repeat for several.
    #[arg(long, value_name = "D", allow_hyphen_values = true)]
    pub(crate) direction: Vec<String>,
    /// Coulomb friction coefficient μ at every contact of the static multiplier (default: no
    /// sliding, and the report gives the μ each multiplier needs).
    #[arg(long, value_name = "MU")]
    pub(crate) friction: Option<f64>,
    /// The most sets of joints that may open and slide the exhaustive pass tries per direction
    /// (each one to three linear programs); where a structure has more, λ is an upper bound and
    /// the report says how many it has (up to 100 000)
    #[arg(long, value_name = "N", allow_hyphen_values = true,
          default_value_t = crr::impact::statics::EXHAUSTIVE_SETS)]
    pub(crate) exhaustive_sets: usize,
    /// Replace the plots of an earlier `crr check --plot` in DIR.
    #[arg(long)]
    pub(crate) force: bool,
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
pub(crate) fn run(a: Args) -> Result<(), Failure> {
    let paths = &a.models;
    let json = a.json;
    let plot = a.plot.as_deref();
    let size_sweep = a.size_sweep.as_deref();
    let (amplitude_ratio, directions, friction, force) =
        (a.amplitude_ratio, &a.direction, a.friction, a.force);
    use crr::analysis::levels::{DEFAULT_STEP, mechanism_levels};
    use crr::analysis::size_sweep::{check_amplitude_ratio, parse_sweep};
    let scales = size_sweep.map(parse_sweep).transpose()?;
    let ratio = check_amplitude_ratio(amplitude_ratio)?;
    let directions = if directions.is_empty() {
        crr::analysis::static_multiplier::horizontal_directions()
    } else {
        directions
            .iter()
            .map(|d| crr::analysis::static_multiplier::parse_direction(d))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| Failure::Input(Error::Argument(format!("--direction: {e}"))))?
    };
    if let Some(mu) = friction {
        crr::analysis::static_multiplier::check_friction(mu)
            .map_err(|e| Failure::Input(Error::Argument(format!("--friction {e}"))))?;
    }
    if let Some(dir) = plot
        && !force
        && let Some(earlier) = earlier_check_plot(dir)
    {
        return Err(Failure::Input(Error::Argument(format!(
            "{}: the folder holds the plots of an earlier `crr check --plot` ({}): pass --force to replace them",
            dir.display(),
            earlier.display()
        ))));
    }
    let asked = crr::analysis::static_multiplier::MultiplierOptions {
        friction,
        exhaustive_sets: a.exhaustive_sets,
        // Ctrl-C ends `crr check` at once (it has nothing to keep).
        cancel: None,
    };
    let loaded = paths
        .iter()
        .map(|p| load_model(p))
        .collect::<Result<Vec<_>, _>>()?;
    let reports: Vec<_> = loaded
        .iter()
        .map(|(_, m)| crr::analysis::check::check_with(m, &directions, &asked))
        .collect::<Result<_, _>>()
        .map_err(|e| Failure::Simulation(e.to_string()))?;
    // The sweep needs a one-DOF mechanism; its failure is reported after the reports.
    let mut sweeps: Vec<Option<crr::analysis::size_sweep::SizeSweep>> = vec![None; reports.len()];
    let mut sweep_error = None;
    if let Some(scales) = &scales {
        for (((file, _), report), slot) in loaded.iter().zip(&reports).zip(&mut sweeps) {
            let result = match &report.mechanism {
                None => Err(report
                    .note
                    .clone()
                    .unwrap_or_else(|| "not a one-DOF mechanism".into())),
                Some(_) => crr::analysis::size_sweep::size_sweep(&file.structure(), scales, ratio),
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
            print!("{}", crr::analysis::check::to_text(r));
            if let Some(s) = sweep {
                print!("{}", crr::analysis::size_sweep::to_text(s));
            }
        }
    }
    if let Some(e) = sweep_error {
        return Err(Failure::Input(Error::Argument(e)));
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
