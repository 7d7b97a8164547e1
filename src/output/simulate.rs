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
use super::results_folder::{
    RESULT_FILES, check_out_dir, default_out_dir, partial_name, write_outputs_with,
};
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
    // The headers on disk before the run: a folder kept after a failed write is then readable.
    history.flush().map_err(output_error)?;
    openings.flush().map_err(output_error)?;
    let (mut rows, mut opening_rows) = (String::new(), String::new());
    let mut row = 0;
    let mut sink_failed = false;
    let sink = |samples: &Samples| -> std::io::Result<()> {
        rows.clear();
        opening_rows.clear();
        for x in samples {
            row += 1;
            push_history_row(&mut rows, &p.model, &x);
            push_openings_rows(&mut opening_rows, &p.model, row, &x);
        }
        let written = history
            .write_all(rows.as_bytes())
            .and_then(|()| openings.write_all(opening_rows.as_bytes()));
        sink_failed |= written.is_err();
        written
    };
    let run = p.run_streaming(sink);
    let files = [
        ("impacts.csv", impacts_csv(&p.model, &run.trajectory)),
        (
            "hops.csv",
            hops_csv(&run.trajectory, run.summary.solver.hop_tolerance),
        ),
        ("summary.json", run.summary.to_json()),
    ];
    let flushed = [history, openings]
        .into_iter()
        .try_for_each(|writer| writer.into_inner().map_err(|e| e.into_error())?.sync_all());
    if sink_failed || flushed.is_err() {
        // A write cut short (a full disk, a file size limit) may have left half a row.
        for streamed in [&history_tmp, &openings_tmp] {
            let _ = truncate_to_last_line(streamed);
        }
    }
    let written =
        flushed.and_then(|()| write_outputs_with(out, &["history.csv", "openings.csv"], &files));
    if let Err(source) = written {
        return keep_what_was_written(out, source, &run.summary, &files);
    }
    Ok(match run.summary.error.clone() {
        None => SimulateResult::Done(out.to_path_buf(), Box::new(run.summary)),
        Some(e) => SimulateResult::Failed(out.to_path_buf(), e),
    })
}

/// The results could not all be written (a full disk, a file size limit): the rows already
/// streamed are results the run computed, so they are kept under their own names rather than
/// left hidden (the history cut at its last whole row, the openings at the history's last row),
/// then each file computed in memory (`files`: impacts, hops, and summary.json marked as not
/// completed) is written where there is room, and the run counts as failed part-way. An earlier
/// run's files go first (they would mix with this one's, and removing them frees room). Where
/// not even the history is left, the error stands.
fn keep_what_was_written(
    out: &Path,
    source: std::io::Error,
    summary: &Summary,
    files: &[(&str, String)],
) -> Result<SimulateResult, Error> {
    for stale in RESULT_FILES {
        let _ = std::fs::remove_file(out.join(stale));
    }
    let _ =
        crate::output::animate::remove_animation(&out.join(crate::output::animate::DEFAULT_DIR));
    let mut kept: Vec<&str> = Vec::new();
    for name in ["history.csv", "openings.csv"] {
        if std::fs::rename(partial_name(out, name), out.join(name)).is_ok() {
            let _ = truncate_to_last_line(&out.join(name));
            kept.push(name);
        }
    }
    if !kept.contains(&"history.csv") {
        return Err(Error::Output {
            dir: out.to_path_buf(),
            source,
        });
    }
    if kept.contains(&"openings.csv") {
        let _ = cut_openings_at_history(out);
    }
    // The files computed in memory, each written whole or not at all (a stale temporary of an
    // earlier run under the same name is overwritten, never renamed into place).
    let write_whole = |name: &str, text: &str| {
        let tmp = partial_name(out, name);
        let written =
            std::fs::write(&tmp, text).and_then(|()| std::fs::rename(&tmp, out.join(name)));
        if written.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        written
    };
    let mut missing: Vec<&str> = Vec::new();
    for (name, text) in files.iter().filter(|(name, _)| *name != "summary.json") {
        match write_whole(name, text) {
            Ok(()) => kept.push(name),
            Err(_) => missing.push(name),
        }
    }
    let mut why = format!(
        "the results could not all be written ({source}): the rows written before are kept in \
         history.csv"
    );
    if kept.contains(&"openings.csv") {
        why.push_str(" and openings.csv (its rows up to the history's last)");
    }
    let others: Vec<&str> = kept
        .iter()
        .copied()
        .filter(|n| !matches!(*n, "history.csv" | "openings.csv"))
        .collect();
    if !others.is_empty() {
        why.push_str(&format!(", with {}", others.join(" and ")));
    }
    if !missing.is_empty() {
        why.push_str(&format!("; {} could not be written", missing.join(" and ")));
    }
    let mut marked = summary.clone();
    marked.completed = false;
    marked.error = Some(match &summary.error {
        Some(e) => format!("{e}; {why}"),
        None => why.clone(),
    });
    let said = match write_whole("summary.json", &marked.to_json()) {
        Ok(()) => format!("{why}; summary.json says so"),
        Err(e) => format!("{why} (summary.json could not be written either: {e})"),
    };
    Ok(SimulateResult::Failed(out.to_path_buf(), said))
}

/// Cuts `openings.csv` in `out` before its first row whose history row (its `row` column, from
/// 1) is beyond the last row of `history.csv`: after a failed write the two end at one row.
fn cut_openings_at_history(out: &Path) -> std::io::Result<()> {
    use std::io::BufRead;
    let history = std::io::BufReader::new(std::fs::File::open(out.join("history.csv"))?);
    let mut rows = 0u64;
    for line in history.split(b'\n') {
        line?;
        rows += 1;
    }
    // The header is not a sample.
    let samples = rows.saturating_sub(1);
    let path = out.join("openings.csv");
    let openings = std::io::BufReader::new(std::fs::File::open(&path)?);
    let mut offset = 0u64;
    for (k, line) in openings.split(b'\n').enumerate() {
        let line = line?;
        let row = std::str::from_utf8(&line)
            .ok()
            .and_then(|l| l.split(',').next())
            .and_then(|r| r.parse::<u64>().ok());
        if k > 0 && row.is_none_or(|r| r > samples) {
            break;
        }
        offset += line.len() as u64 + 1;
    }
    let file = std::fs::OpenOptions::new().write(true).open(&path)?;
    if offset < file.metadata()?.len() {
        file.set_len(offset)?;
    }
    Ok(())
}

/// Cuts the file at `path` after its last line break (a row written in part goes).
fn truncate_to_last_line(path: &Path) -> std::io::Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let mut file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)?;
    let len = file.metadata()?.len();
    // Rows are far shorter than this: the last line break is within the tail.
    let tail = len.min(1 << 20);
    file.seek(SeekFrom::Start(len - tail))?;
    let mut bytes = Vec::with_capacity(tail as usize);
    file.read_to_end(&mut bytes)?;
    let keep = match bytes.iter().rposition(|&b| b == b'\n') {
        Some(i) => len - tail + i as u64 + 1,
        None if tail == len => 0,
        None => return Ok(()),
    };
    file.set_len(keep)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The writes cut short by a full disk: the streamed rows are renamed into place, the history
    /// cut at its last whole line and the openings at the history's last row; the files computed
    /// in memory are written whole (never an earlier run's temporaries of the same name); an
    /// earlier run's files go; summary.json says the run did not complete and why. With no
    /// history left the error stands.
    #[test]
    fn what_was_written_before_a_write_failed_is_kept() {
        let out = std::env::temp_dir().join(format!("crr_keep_written_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        std::fs::create_dir_all(out.join("animation")).unwrap();
        // Two whole rows and half a third.
        std::fs::write(
            partial_name(&out, "history.csv"),
            "t,base\n0e0,1e-1\n1e-2,9.9e-2\n2e-2,9.",
        )
        .unwrap();
        // Openings of rows 1 to 3: the third's goes with the history's half row.
        std::fs::write(
            partial_name(&out, "openings.csv"),
            "row,t\n1,0e0\n2,1e-2\n3,2e-2\n",
        )
        .unwrap();
        std::fs::write(
            partial_name(&out, "impacts.csv"),
            "an earlier run's temporary",
        )
        .unwrap();
        std::fs::write(out.join("energy.png"), "an earlier run's plot").unwrap();
        std::fs::write(out.join("animation/frame_00000.vtu"), "an earlier frame").unwrap();
        let block = ModelInput::read(Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/models/single_block.toml"
        )))
        .unwrap();
        let options = RunOptions {
            duration: Some(0.05),
            ..Default::default()
        };
        let summary = prepare(&block, &options).unwrap().run().summary;
        let files = [
            ("impacts.csv", "this run's impacts\n".to_string()),
            ("hops.csv", "this run's hops\n".to_string()),
            ("summary.json", summary.to_json()),
        ];
        let full = || std::io::Error::other("No space left on device");
        let SimulateResult::Failed(_, said) =
            keep_what_was_written(&out, full(), &summary, &files).expect("the history is kept")
        else {
            panic!("a failed run");
        };
        assert!(
            said.contains("No space left on device")
                && said.contains("kept in history.csv and openings.csv")
                && said.contains("with impacts.csv and hops.csv; summary.json says so"),
            "{said}"
        );
        let read = |name: &str| std::fs::read_to_string(out.join(name)).unwrap();
        assert_eq!(read("history.csv"), "t,base\n0e0,1e-1\n1e-2,9.9e-2\n");
        assert_eq!(read("openings.csv"), "row,t\n1,0e0\n2,1e-2\n");
        assert_eq!(read("impacts.csv"), "this run's impacts\n");
        assert!(!out.join("energy.png").exists());
        assert!(!out.join("animation/frame_00000.vtu").exists());
        let kept: serde_json::Value = serde_json::from_str(&read("summary.json")).unwrap();
        assert_eq!(kept["completed"], false);
        assert!(kept["error"].as_str().unwrap().contains("No space left"));
        let hidden = std::fs::read_dir(&out)
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .starts_with(".partial.")
            })
            .count();
        assert_eq!(hidden, 0);
        // Nothing streamed left: the error stands.
        let empty = out.join("empty");
        std::fs::create_dir_all(&empty).unwrap();
        assert!(matches!(
            keep_what_was_written(&empty, full(), &summary, &files),
            Err(Error::Output { .. })
        ));
        std::fs::remove_dir_all(&out).unwrap();
    }
}
