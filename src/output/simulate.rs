//! `crr simulate`'s results folder: [`crate::run`] with the history streamed to `history.csv`
//! and the open faces' offsets to `openings.csv` while it runs, then `impacts.csv` and
//! `summary.json` (documented in `docs/outputs.md`), all renamed into place together.

use std::io::Write;
use std::path::{Path, PathBuf};

use crr_impact::simulation::Samples;

use super::folder_lock::FolderLock;
use super::history::{
    OPENINGS_HEADER, history_header, hops_csv, impacts_csv, push_history_row, push_openings_rows,
};
use super::results_folder::{check_out_dir, default_out_dir, partial_name, write_outputs_with};
use crate::Error;
use crate::analysis::simulation::{Prepared, RunOptions, prepare};
use crate::analysis::summary::Summary;
use crate::input::model_file::ModelInput;

/// Where and how `crr simulate` writes.
#[derive(Clone, Debug, Default)]
pub struct FolderOptions {
    /// Output folder (default [`default_out_dir`] of the model's name).
    pub out: Option<PathBuf>,
    /// Replace the results of an earlier run in the output folder.
    pub force: bool,
}

/// What `crr simulate` did.
pub enum SimulateResult {
    /// The run completed; the output folder and the summary.
    Done(PathBuf, Box<Summary>),
    /// The run failed part-way; the partial results were written to the folder.
    Failed(PathBuf, String),
}

/// The folder a model's results go to: `folder.out`, else `results/<name>`.
pub fn out_dir(model: &ModelInput, folder: &FolderOptions) -> PathBuf {
    folder
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir(&model.file.name))
}

/// `crr simulate` end to end. Input problems are `Err`; a simulation failure is
/// `Ok(SimulateResult::Failed)` after writing what was computed.
pub fn simulate(
    path: &Path,
    options: &RunOptions,
    folder: &FolderOptions,
) -> Result<SimulateResult, Error> {
    let model = ModelInput::read(path)?;
    let prepared = prepare(&model, options)?;
    let out = out_dir(&model, folder);
    check_out_dir(&out, folder.force)?;
    write_run(&prepared, &out)
}

/// Runs `p` into the folder `out`: the history streamed to its temporary name while the run goes
/// (memory stays flat in the duration), then the other files, all renamed into place at the end.
pub fn write_run(p: &Prepared, out: &Path) -> Result<SimulateResult, Error> {
    let output_error = |source| Error::Output {
        dir: out.to_path_buf(),
        source,
    };
    // One writer per folder: another run writing here would rename these files away.
    let _lock = FolderLock::acquire(out)?;
    std::fs::create_dir_all(out).map_err(output_error)?;
    let history_tmp = partial_name(out, "history.csv");
    let mut history =
        std::io::BufWriter::new(std::fs::File::create(&history_tmp).map_err(output_error)?);
    history
        .write_all(history_header(&p.model).as_bytes())
        .map_err(output_error)?;
    // The open faces' offsets, streamed beside it (rows only while faces are open).
    let openings_tmp = partial_name(out, "openings.csv");
    let mut openings =
        std::io::BufWriter::new(std::fs::File::create(&openings_tmp).map_err(output_error)?);
    openings
        .write_all(OPENINGS_HEADER.as_bytes())
        .map_err(output_error)?;
    let (mut rows, mut opening_rows) = (String::new(), String::new());
    let mut row = 0;
    let sink = |samples: &Samples| -> std::io::Result<()> {
        rows.clear();
        opening_rows.clear();
        for x in samples {
            row += 1;
            push_history_row(&mut rows, &p.model, &x);
            push_openings_rows(&mut opening_rows, &p.model, row, &x);
        }
        history.write_all(rows.as_bytes())?;
        openings.write_all(opening_rows.as_bytes())
    };
    let run = p.run_streaming(sink);
    for writer in [history, openings] {
        let file = writer
            .into_inner()
            .map_err(|e| output_error(e.into_error()))?;
        file.sync_all().map_err(output_error)?;
    }
    let files = [
        ("impacts.csv", impacts_csv(&p.model, &run.trajectory)),
        (
            "hops.csv",
            hops_csv(&run.trajectory, run.summary.solver.hop_tolerance),
        ),
        ("summary.json", run.summary.to_json()),
    ];
    write_outputs_with(out, &["history.csv", "openings.csv"], &files).map_err(output_error)?;
    Ok(match run.summary.error.clone() {
        None => SimulateResult::Done(out.to_path_buf(), Box::new(run.summary)),
        Some(e) => SimulateResult::Failed(out.to_path_buf(), e),
    })
}
