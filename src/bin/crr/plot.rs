//! `crr plot DIR`: the plots of a results folder or of a study folder.

use std::path::PathBuf;

use crr::output::plot::{plot_results, plot_study};
use crr::output::study::products::is_study_dir;

use crate::failure::Failure;

/// The arguments of `crr plot`.
#[derive(clap::Args)]
pub(crate) struct Args {
    /// The results folder (history.csv, impacts.csv, summary.json; or cases.csv and
    /// study.json).
    pub(crate) dir: PathBuf,
}

pub(crate) fn run(a: Args) -> Result<(), Failure> {
    let files = if is_study_dir(&a.dir) {
        plot_study(&a.dir)?
    } else {
        plot_results(&a.dir)?
    };
    for f in files {
        println!("{}", f.display());
    }
    Ok(())
}
