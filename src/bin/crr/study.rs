//! `crr study STUDY [--out DIR] [--jobs N] [--shard i/n] [--plot]` and
//! `crr study merge DIR… --out DIR`.

use std::path::PathBuf;

use clap::Subcommand;

use crr::Error;
use crr::analysis::study::Study;
use crr::output::study::{Shard, StudyOptions, merge, run_study};

use crate::failure::Failure;

/// The arguments of `crr study`.
#[derive(clap::Args)]
pub(crate) struct Args {
    #[command(subcommand)]
    pub(crate) action: Option<StudyAction>,
    /// Study file (TOML).
    pub(crate) study: Option<PathBuf>,
    /// Output folder (default results/<study name>).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N")]
    pub(crate) jobs: Option<usize>,
    /// Run only the i-th of n disjoint parts (1 ≤ i ≤ n), e.g. one task of a job array.
    #[arg(long, value_name = "i/n")]
    pub(crate) shard: Option<String>,
    /// No progress bar.
    #[arg(long)]
    pub(crate) quiet: bool,
    /// Also draw the study's figures into the output folder (as `crr plot DIR`).
    #[arg(long)]
    pub(crate) plot: bool,
}

#[derive(Subcommand)]
pub(crate) enum StudyAction {
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

pub(crate) fn run(a: Args) -> Result<(), Failure> {
    if let Some(StudyAction::Merge { dirs, out }) = a.action {
        let n = merge(&dirs, &out)?;
        println!(
            "{n} case(s) merged into {}",
            out.join("cases.csv").display()
        );
        return Ok(());
    }
    let Args {
        study,
        out,
        jobs,
        shard,
        quiet,
        plot,
        ..
    } = a;
    let Some(path) = study else {
        return Err(Failure::Input(Error::Argument(
            "crr study needs a study file (or `merge DIR... --out DIR`)".into(),
        )));
    };
    if jobs == Some(0) {
        return Err(Failure::Input(Error::Argument(
            "--jobs must be at least 1".into(),
        )));
    }
    let shard = match shard {
        Some(s) => s.parse().map_err(Error::Argument)?,
        None => Shard::ALL,
    };
    let study = Study::load(&path)?;
    // Before any case runs, so that a study cut short can be stopped; with --quiet too.
    for w in &study.warnings {
        eprintln!("crr: warning: {}: {w}", path.display());
    }
    let out = out.unwrap_or_else(|| PathBuf::from("results").join(&study.name));
    let outcome = run_study(
        &study,
        &path,
        &StudyOptions {
            out: out.clone(),
            jobs,
            shard,
            quiet,
            cancel: Some(crate::interrupt::interrupt_flag()),
        },
    )?;
    if outcome.interrupted {
        return Err(Failure::Simulation(format!(
            "{}: interrupted: {} case(s) of this part in {}, {} to go; the same command resumes it",
            path.display(),
            outcome.skipped + outcome.ran,
            out.join("cases.csv").display(),
            outcome.cases - outcome.skipped - outcome.ran
        )));
    }
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
    // Warnings, as `crr simulate`'s: shown with --quiet too (a batch script that ran a study
    // with --quiet was told nothing of its failed cases).
    if outcome.failed > 0 {
        eprintln!(
            "crr: warning: {} of the {} case(s) of this part stopped with an error (status \
             `error`, the message in column `error` of {}): they have no outcome",
            outcome.failed,
            outcome.cases,
            out.join("cases.csv").display()
        );
    }
    if outcome.outside_model > 0 {
        eprintln!(
            "crr: warning: {} of the {} case(s) of this part left crr's model (the rigid-contact \
             hypotheses fail: a flight, a resultant outside its face, sliding, an impulse that \
             pulls or a lift-off it cannot follow; columns violation_time_s, violation, \
             violation_interface of {}): their results after that time are outside the model",
            outcome.outside_model,
            outcome.cases,
            out.join("cases.csv").display()
        );
    }
    if plot {
        let files = crr::output::plot::plot_study(&out)?;
        if !quiet {
            for f in files {
                println!("{}", f.display());
            }
        }
    }
    Ok(())
}
