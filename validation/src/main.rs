//! `crr-validation`: crr models run in rapier, and the validation report.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use crr::analysis::simulation::prepare;
use crr::{ModelInput, RunOptions};
use crr_validation::run::{run, write_history};
use crr_validation::scene::Settings;

/// crr-validation: cross-check crr models in rapier.
#[derive(Parser)]
#[command(name = "crr-validation", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a crr model file in rapier and write history.csv with crr's coordinate columns.
    Rapier {
        /// Model file (the one `crr simulate` reads).
        model: PathBuf,
        /// Output folder (default results/<model name>-rapier).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Rapier time step (s).
        #[arg(long, default_value_t = Settings::default().dt)]
        dt: f64,
        /// Solver substeps per step.
        #[arg(long, default_value_t = Settings::default().substeps)]
        substeps: usize,
        /// Friction coefficient.
        #[arg(long, default_value_t = Settings::default().friction)]
        friction: f64,
        /// Rapier's length unit as a fraction of the model size.
        #[arg(long, default_value_t = Settings::default().length_unit)]
        length_unit: f64,
        /// Duration (s), overriding the model's.
        #[arg(long)]
        duration: Option<f64>,
    },
    /// Run the validation cases in crr and rapier and write validation/REPORT.md with its
    /// figures in validation/report/.
    Report {
        /// Folder of REPORT.md (default: this package's folder, validation/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Size n of the n × n overturning map.
        #[arg(long, default_value_t = 20)]
        grid: usize,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Report { out, grid } => {
            let dir = out.unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")));
            let start = std::time::Instant::now();
            match crr_validation::report::write_report(&dir, grid.max(2), &Settings::default()) {
                Ok(path) => {
                    println!(
                        "wrote {} in {:.0} s",
                        path.display(),
                        start.elapsed().as_secs_f64()
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("crr-validation: report: {e}");
                    ExitCode::from(1)
                }
            }
        }
        Command::Rapier {
            model,
            out,
            dt,
            substeps,
            friction,
            length_unit,
            duration,
        } => {
            if !(dt.is_finite()
                && dt > 0.0
                && friction.is_finite()
                && friction >= 0.0
                && length_unit.is_finite()
                && length_unit > 0.0)
            {
                eprintln!(
                    "crr-validation: --dt and --length-unit must be positive, --friction \
                     non-negative"
                );
                return ExitCode::from(2);
            }
            let options = RunOptions {
                duration,
                ..Default::default()
            };
            let p = match ModelInput::read(&model).and_then(|m| prepare(&m, &options)) {
                Ok(p) => p,
                Err(e) => {
                    eprintln!("crr-validation: {e}");
                    return ExitCode::from(2);
                }
            };
            let settings = Settings {
                dt,
                substeps,
                friction,
                length_unit,
                ..Settings::default()
            };
            let out = out.unwrap_or_else(|| {
                let mut d =
                    crr::output::results_folder::default_out_dir(&p.file.name).into_os_string();
                d.push("-rapier");
                PathBuf::from(d)
            });
            let r = match run(&p, &settings) {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("crr-validation: {}: {e}", model.display());
                    return ExitCode::from(2);
                }
            };
            if let Err(e) = std::fs::create_dir_all(&out)
                .and_then(|_| write_history(&r, &out.join("history.csv")))
            {
                eprintln!("crr-validation: {}: {e}", out.display());
                return ExitCode::from(1);
            }
            println!(
                "{}: rapier, {} steps of {dt} s, collapse: {}, largest slip {:.3e} m; results in {}",
                model.display(),
                r.steps,
                r.collapse
                    .map_or("no".to_string(), |t| format!("yes at t = {t} s")),
                r.max_slip,
                out.display()
            );
            ExitCode::SUCCESS
        }
    }
}
