//! The `crr` command line.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crr::inspect::{configuration, inspect, to_text};
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
}

fn run(cli: Cli) -> Result<(), InputError> {
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
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("crr: error: {e}");
            ExitCode::from(2)
        }
    }
}
