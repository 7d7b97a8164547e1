//! `crr inspect MODEL [--q NAME=VALUE]… [--json]`.

use std::path::PathBuf;

use crr::analysis::inspect::{configuration, inspect, to_text};
use crr::load_model;

use crate::failure::Failure;

/// The arguments of `crr inspect`.
#[derive(clap::Args)]
pub(crate) struct Args {
    /// Model file (TOML, or JSON when it ends in .json).
    pub(crate) model: PathBuf,
    /// Set a coordinate, NAME=VALUE in radians (repeatable; others are 0).
    #[arg(long = "q", value_name = "NAME=VALUE")]
    pub(crate) q: Vec<String>,
    /// Print JSON (keys documented in docs/inspect.md) instead of text.
    #[arg(long)]
    pub(crate) json: bool,
}

pub(crate) fn run(a: Args) -> Result<(), Failure> {
    let (_, m) = load_model(&a.model)?;
    let q = configuration(&m, &a.q)?;
    let report = inspect(&m, &q);
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).expect("report serialises")
        );
    } else {
        print!("{}", to_text(&report));
    }
    Ok(())
}
