//! The results folder convention, in one place: the default folder `results/<name>`, an earlier
//! run's files replaced only when asked, every file written to a hidden temporary name
//! ([`partial_name`]) and renamed into place when all are written, so that a folder never holds a
//! set of files that looks complete and is not, nor mixes two runs. One writer at a time is
//! [`crate::output::folder_lock`]'s.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::Error;

/// The time of a run's first hypotheses violation as its summary.json records it
/// (`hypothesis_violation.time`), None where the run has none: what `--plot` shades and
/// `--animate` marks, read back from a results folder.
pub fn violation_time(summary: &serde_json::Value) -> Option<f64> {
    summary["hypothesis_violation"]["time"]
        .as_f64()
        .filter(|t| t.is_finite())
}

/// The files `crr simulate` writes, and those `--plot` and `--animate` add (the animation's
/// index and GIF; its frames go with them): an earlier run's set is replaced whole (with
/// `--force`), never mixed with a new one.
pub const RESULT_FILES: [&str; 13] = [
    "animation/animation.pvd",
    "animation/animation.gif",
    "history.csv",
    "openings.csv",
    "impacts.csv",
    "hops.csv",
    "summary.json",
    "coordinates.png",
    "coordinates.svg",
    "energy.png",
    "energy.svg",
    "phase.png",
    "phase.svg",
];

/// The default output folder `results/<name>`: the model's name with every character outside
/// `A–Z a–z 0–9 _ - .` replaced by `_` and leading dots too, so that a name can never lead out of
/// `results/` (`..`, `/`, an absolute path) or hide the folder.
pub fn default_out_dir(model_name: &str) -> PathBuf {
    let mut name: String = model_name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    let dots = name.len() - name.trim_start_matches('.').len();
    name.replace_range(..dots, &"_".repeat(dots));
    if name.is_empty() {
        name.push_str("model");
    }
    Path::new("results").join(name)
}

/// An output folder that already holds `crr simulate`'s results is only written to with `force`.
pub fn check_out_dir(out: &Path, force: bool) -> Result<(), Error> {
    refuse_earlier_results(out, force, &RESULT_FILES, &out.display().to_string())
}

/// Refuses an output folder that holds any of `files` from an earlier run unless `force`, or a
/// path that is not a folder; `label` names the folder in the message (e.g. `--out DIR`).
pub fn refuse_earlier_results(
    out: &Path,
    force: bool,
    files: &[&str],
    label: &str,
) -> Result<(), Error> {
    if !out.exists() {
        return Ok(());
    }
    if !out.is_dir() {
        return Err(Error::Argument(format!(
            "{label}: the output path exists and is not a folder"
        )));
    }
    let earlier: Vec<&str> = files
        .iter()
        .copied()
        .filter(|f| out.join(f).exists())
        .collect();
    if earlier.is_empty() || force {
        return Ok(());
    }
    Err(Error::Argument(format!(
        "{label}: the folder holds the results of an earlier run ({}): pass --force to replace \
         them, or --out DIR for another folder",
        earlier.join(", ")
    )))
}

/// Writes the files into `dir`: each to a hidden temporary name first; only when all are written
/// are the earlier run's files (data and plots) removed and the new ones renamed into place
/// (summary.json last), so an interrupted run never leaves a set of files that looks complete
/// and never mixes two runs.
pub fn write_outputs(dir: &Path, files: &[(&str, String)]) -> std::io::Result<()> {
    write_outputs_with(dir, &[], files)
}

/// [`write_outputs`] with files already written to their temporary names ([`partial_name`]),
/// renamed with the others.
pub fn write_outputs_with(
    dir: &Path,
    written: &[&str],
    files: &[(&str, String)],
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut temps: Vec<(PathBuf, PathBuf)> = written
        .iter()
        .map(|name| (partial_name(dir, name), dir.join(name)))
        .collect();
    for (name, text) in files {
        let tmp = partial_name(dir, name);
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(text.as_bytes())?;
        f.sync_all()?;
        temps.push((tmp, dir.join(name)));
    }
    for stale in RESULT_FILES {
        match std::fs::remove_file(dir.join(stale)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
    }
    // The earlier run's animation frames (only the files `crr animate` writes).
    crate::output::animate::remove_animation(&dir.join(crate::output::animate::DEFAULT_DIR))?;
    for (tmp, dst) in temps {
        std::fs::rename(tmp, dst)?;
    }
    Ok(())
}

/// The hidden temporary name `.partial.NAME` a result file (or the animation's folder) is
/// written to before it is renamed into place: every command uses this one. The name's
/// extension stays last, as the image encoders pick the format from it.
pub fn partial_name(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!(".partial.{name}"))
}
