//! Running a study: every case of this shard on a pool of threads, one row of `cases.csv` per
//! finished case, appended and flushed as it finishes (an interrupted run loses only the cases in
//! flight); a rerun into the same folder skips the cases already there. When every case of the
//! shard is done the file is rewritten in case-id order, so that a run's `cases.csv` does not
//! depend on the number of threads, and merged shards equal a single run byte for byte.

use std::collections::BTreeMap;
use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use rayon::prelude::*;

use super::info::{MergedStudyInfo, ScaleInfo, StudyInfo, to_json};
use crate::Error;
use crate::analysis::simulation::Cancel;
use crate::analysis::simulation::coordinate_alpha;
use crate::analysis::study::cases::case_id;
use crate::analysis::study::{
    Case, CaseFailure, IntensityMeasure, Measures, Motion, Study, run_case_cancellable,
};
use crate::output::replace_file::replace_file;

/// `i/n`: the i-th (1-based) of n disjoint parts of a study; case k belongs to part k mod n + 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// 1 … n.
    pub index: usize,
    /// Number of parts.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("--shard must be i/n (e.g. 2/8), got `{s}`"))?;
        let parse = |x: &str| x.trim().parse::<usize>().ok();
        match (parse(i), parse(n)) {
            (Some(index), Some(count)) if count >= 1 && (1..=count).contains(&index) => {
                Ok(Shard { index, count })
            }
            _ => Err(format!(
                "--shard must be i/n with 1 ≤ i ≤ n (e.g. 2/8), got `{s}`"
            )),
        }
    }
}

impl Shard {
    /// The whole study.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// Whether case `k` is in this shard.
    pub fn contains(&self, k: usize) -> bool {
        k % self.count + 1 == self.index
    }
}

/// How to run a study.
#[derive(Clone, Debug)]
pub struct StudyOptions {
    /// Output folder.
    pub out: PathBuf,
    /// Worker threads (None: one per core).
    pub jobs: Option<usize>,
    /// The part to run.
    pub shard: Shard,
    /// No progress bar.
    pub quiet: bool,
    /// A flag polled by every case: once set, no case starts, the running ones stop without a
    /// row, and the run returns with [`StudyOutcome::interrupted`] (the rows written stay, and
    /// running the study again into the same folder resumes it).
    pub cancel: Option<Cancel>,
}

/// What a run did.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyOutcome {
    /// Cases of this shard.
    pub cases: usize,
    /// Cases found done in the folder and skipped.
    pub skipped: usize,
    /// Cases run now.
    pub ran: usize,
    /// Cases whose row holds an error.
    pub failed: usize,
    /// Cases whose run left crr's model (the hypotheses monitor's first violation in its
    /// `violation_*` columns): their results after that time are outside the model.
    pub outside_model: usize,
    /// The run was cancelled ([`StudyOptions::cancel`]): `ran` counts the rows written before,
    /// cases.csv is left in the order they ended and study.json is not written.
    pub interrupted: bool,
}

/// Shortest text that reads back as the same f64.
fn num(x: f64) -> String {
    format!("{x}")
}

fn quoted(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "\"\""))
}

/// The column of `cases.csv` that holds the time of a case's first hypotheses violation (empty
/// when its run kept every hypothesis): a case whose column is filled left crr's model then.
pub const VIOLATION_TIME_COLUMN: &str = "violation_time_s";

/// The rows among `rows` (of `cases.csv`, under `header`) of cases whose runs left crr's model:
/// their `violation_time_s` is filled.
fn count_outside_model<'a>(header: &str, rows: impl IntoIterator<Item = &'a String>) -> usize {
    let columns = super::products::split_csv(header);
    let Some(at) = columns.iter().position(|c| c == VIOLATION_TIME_COLUMN) else {
        return 0;
    };
    rows.into_iter()
        .filter(|r| {
            super::products::split_csv(r)
                .get(at)
                .is_some_and(|f| !f.is_empty())
        })
        .count()
}

/// Whether a records study's rows have a `factor` column besides the level's: not for a
/// `factors` study, whose level is the factor applied (its header had `factor` twice, which csv
/// readers keep as one column and pandas renames `factor.1`).
fn applies_a_factor_of_its_own(study: &Study) -> bool {
    study.intensity != IntensityMeasure::Factor
}

/// The header of `cases.csv`.
pub fn header(study: &Study) -> String {
    let mut cols: Vec<String> = vec!["id".into()];
    if study.sized {
        cols.extend(["scale", "height_m"].map(String::from));
    }
    if study.pulse_kind.is_some() {
        cols.extend(
            [
                "amplitude_m_s2",
                "period_s",
                "amplitude_ratio",
                "frequency_ratio",
            ]
            .map(String::from),
        );
    } else {
        cols.extend(["record".into(), study.intensity.name().into()]);
        if applies_a_factor_of_its_own(study) {
            cols.push("factor".into());
        }
    }
    cols.extend(["status", "collapse", "collapse_time_s", "impacts"].map(String::from));
    for c in &study.model.coords {
        cols.push(format!("peak_{}_rad", c.name));
    }
    for k in 0..study.model.dof() {
        if coordinate_alpha(&study.model, k).is_some() {
            cols.push(format!("peak_{}_over_alpha", study.model.coords[k].name));
        }
    }
    cols.extend(
        [
            "residual_rad",
            "dissipated_j",
            "end_time_s",
            VIOLATION_TIME_COLUMN,
            "violation",
            "violation_interface",
            "error",
        ]
        .map(String::from),
    );
    cols.join(",")
}

/// The row of a case (without its newline).
pub fn row(study: &Study, case: &Case, result: &Result<Measures, CaseFailure>) -> String {
    let mut cols: Vec<String> = vec![case.id.clone()];
    let opt = |x: Option<f64>| x.map(num).unwrap_or_default();
    if study.sized {
        let v = &study.variants[case.variant];
        cols.extend([num(v.scale), opt(v.height)]);
    }
    match &case.motion {
        Motion::Pulse {
            amplitude,
            period,
            amplitude_ratio,
            frequency_ratio,
        } => {
            cols.extend([
                num(*amplitude),
                num(*period),
                opt(*amplitude_ratio),
                opt(*frequency_ratio),
            ]);
        }
        Motion::Record {
            record,
            level,
            factor,
        } => {
            cols.extend([
                quoted(&study.records[*record].file.display().to_string()),
                num(*level),
            ]);
            if applies_a_factor_of_its_own(study) {
                cols.push(opt(*factor));
            }
        }
    }
    let n = study.model.dof();
    let alphas: Vec<Option<f64>> = (0..n).map(|k| coordinate_alpha(&study.model, k)).collect();
    let with_alpha = alphas.iter().filter(|a| a.is_some()).count();
    // The measures of a run: complete, or up to the error that stopped it (its collapse columns
    // empty: it neither collapsed nor survived).
    let measures = |m: &Measures, cols: &mut Vec<String>| {
        cols.extend(m.peak.iter().map(|p| num(*p)));
        for (k, a) in alphas.iter().enumerate() {
            if let Some(a) = a {
                cols.push(num(m.peak[k] / a));
            }
        }
        cols.extend([num(m.residual), num(m.dissipated), num(m.end_time)]);
        match &m.violation {
            Some(v) => cols.extend([num(v.t), v.kind.clone(), quoted(&v.interface)]),
            None => cols.extend([String::new(), String::new(), String::new()]),
        }
    };
    match result {
        Ok(m) => {
            cols.extend([
                "ok".into(),
                if m.collapse.is_some() { "1" } else { "0" }.into(),
                opt(m.collapse),
                m.impacts.to_string(),
            ]);
            measures(m, &mut cols);
            cols.push(String::new());
        }
        Err(failure) => {
            cols.extend(["error".into(), String::new(), String::new()]);
            match &failure.reached {
                Some(m) => {
                    cols.push(m.impacts.to_string());
                    measures(m, &mut cols);
                }
                None => cols.extend(std::iter::repeat_n(String::new(), 1 + n + with_alpha + 6)),
            }
            cols.push(quoted(&failure.message));
        }
    }
    cols.join(",")
}

/// The text of `cases.csv` from its header and rows (without newlines, in any order): the rows in
/// case-id order, as `crr study` writes the file when every case is done; a row given twice is
/// written once.
pub fn cases_csv<'a>(header: &str, rows: impl IntoIterator<Item = &'a str>) -> String {
    let sorted: BTreeMap<&str, &str> = rows
        .into_iter()
        .map(|r| (r.split_once(',').map_or(r, |(id, _)| id), r))
        .collect();
    let mut text = String::with_capacity(
        header.len() + 1 + sorted.values().map(|r| r.len() + 1).sum::<usize>(),
    );
    text.push_str(header);
    text.push('\n');
    for r in sorted.values() {
        text.push_str(r);
        text.push('\n');
    }
    text
}

/// Runs `cases` on `jobs` threads (None: one per core) and returns their rows of `cases.csv`
/// (without newlines) in the order given, writing nothing: what an embedding program or a
/// cluster's worker computes of a study, joined afterwards by [`cases_csv`].
pub fn case_rows(
    study: &Study,
    cases: &[&Case],
    jobs: Option<usize>,
) -> Result<Vec<String>, Error> {
    case_rows_cancellable(study, cases, jobs, None)
        .map(|rows| rows.expect("a run without a flag is not cancelled"))
}

/// [`case_rows`] that stops when `cancel` is set: Ok(None) then (the rows of a cancelled run
/// would miss cases).
pub fn case_rows_cancellable(
    study: &Study,
    cases: &[&Case],
    jobs: Option<usize>,
    cancel: Option<&Cancel>,
) -> Result<Option<Vec<String>>, Error> {
    if jobs == Some(0) {
        return Err(Error::Argument("--jobs must be at least 1".into()));
    }
    crate::analysis::check_max_jobs(jobs)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.unwrap_or(0))
        .build()
        .map_err(|e| Error::Argument(format!("--jobs: {e}")))?;
    Ok(pool.install(|| {
        cases
            .par_iter()
            .map(|case| {
                run_case_cancellable(study, case, cancel).map(|result| row(study, case, &result))
            })
            .collect()
    }))
}

/// The file in a study folder that says which study computed its `cases.csv` ([`fingerprint`]).
pub const FINGERPRINT_FILE: &str = "study.fingerprint";

/// FNV-1a, 64 bits: a hash whose value is fixed by its definition (not by the Rust version), so
/// that a fingerprint written by one build is read by the next.
struct Fnv(u64);

impl std::fmt::Write for Fnv {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        for b in s.bytes() {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
        Ok(())
    }
}

/// The revision of what a row of `cases.csv` holds, part of the [`fingerprint`]: a folder written
/// by a crr whose rows meant something else is not resumed or merged into. 2 (2026-12-01): the
/// `violation_*` columns, and the measures a case stopped by an error reached.
pub const CASES_FORMAT: u32 = 2;

/// The fingerprint of a study (16 hex digits): a hash of the crr version and of the rows' format
/// ([`CASES_FORMAT`]), the study file as read,
/// the model at every scale with its initial state, every case and every record's samples. Two
/// runs may share a folder only when their fingerprints agree: a resume after the study file, its
/// model or a record was edited (or with another crr) would otherwise keep the old rows under
/// the new labels. The shard is not part of it (the shards of one study share it).
pub fn fingerprint(study: &Study) -> String {
    use std::fmt::Write as _;
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    // Debug output of f64 is exact (it reads back to the same bits), and these types hold no
    // hash maps, so the text is the same on every run.
    let spec = serde_json::to_string(&study.spec).unwrap_or_default();
    let _ = write!(
        h,
        "crr {} rows {CASES_FORMAT}\n{spec}\n",
        env!("CARGO_PKG_VERSION")
    );
    for v in &study.variants {
        let _ = write!(h, "{:?}\n{:?}\n{:?}\n", v.scale, v.model, v.initial);
    }
    let _ = write!(h, "{:?}\n{:?}\n", study.params, study.cases);
    for r in &study.records {
        let _ = writeln!(h, "{:?}", r.record);
    }
    format!("{:016x}", h.0)
}

/// The number of fields of a `cases.csv` line (commas outside double quotes, plus one).
fn field_count(line: &str) -> usize {
    let mut quoted = false;
    let mut count = 1;
    for c in line.chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => count += 1,
            _ => {}
        }
    }
    count
}

/// Checks one row of a `cases.csv` (line `number`, 1-based) against its header: the number of
/// fields, and an id that is new in the file. Returns the id.
fn checked_row<'a>(
    path: &Path,
    number: usize,
    body: &'a str,
    header: &str,
    seen: impl Fn(&str) -> bool,
) -> Result<&'a str, Error> {
    let fields = field_count(header);
    let bad = |what: String| {
        Error::Argument(format!(
            "{}: line {number}: {what}; the file is damaged or was written by another program \
             (remove the line, or use another --out folder)",
            path.display()
        ))
    };
    let found = field_count(body);
    if found != fields {
        return Err(bad(format!("{found} fields where the header has {fields}")));
    }
    let id = body.split_once(',').map_or(body, |(id, _)| id);
    if seen(id) {
        return Err(bad(format!("case {id} appears a second time")));
    }
    let columns = super::products::split_csv(header);
    let values = super::products::split_csv(body);
    if let Some(why) = columns
        .iter()
        .zip(&values)
        .find_map(|(column, value)| invalid_field(column, value))
    {
        return Err(bad(why));
    }
    Ok(id)
}

/// Why `value` cannot be in the column `column` of a `cases.csv` as `crr study` writes it, if it
/// cannot: `status` is `ok` or `error`, `collapse` 0 or 1 (or empty), `impacts` a count, and
/// every other column but the id and the texts (`record`, `violation`, `violation_interface`,
/// `error`) empty or a finite number. (A row edited to `status = banana`, `collapse = 7`, a NaN
/// peak or an infinite amplitude was resumed and plotted as it was.)
pub(crate) fn invalid_field(column: &str, value: &str) -> Option<String> {
    let valid = match column {
        "id" | "record" | "violation" | "violation_interface" | "error" => true,
        "status" => matches!(value, "ok" | "error"),
        "collapse" => matches!(value, "" | "0" | "1"),
        "impacts" => value.is_empty() || value.parse::<u64>().is_ok(),
        _ => value.is_empty() || value.parse::<f64>().is_ok_and(f64::is_finite),
    };
    (!valid).then(|| format!("`{column}` holds `{value}`, which crr study does not write there"))
}

/// The ids of the complete rows of an existing `cases.csv` (a row is complete when its line ends
/// with a newline), and the length of the file up to the last complete row. A file whose header
/// differs is an error: it belongs to another study.
fn done_rows(path: &Path, header: &str) -> Result<(BTreeMap<String, String>, u64), Error> {
    // Only a regular file, and at most 1 GiB (a cases.csv linked to /dev/zero, or a FIFO, is
    // refused instead of read without end).
    let text =
        match crr_dynamics::input::read_regular_text(path, crr_dynamics::input::DATA_FILE_LIMIT) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok((BTreeMap::new(), 0)),
            Err(source) => {
                return Err(Error::Io {
                    file: path.to_path_buf(),
                    source,
                });
            }
        };
    let mut rows = BTreeMap::new();
    let mut complete = 0u64;
    let mut first = true;
    for (number, line) in text.split_inclusive('\n').enumerate() {
        if !line.ends_with('\n') {
            break;
        }
        let body = line.trim_end_matches('\n');
        if first {
            if body != header {
                return Err(Error::Argument(format!(
                    "{}: the folder holds the cases of another study, or of another version of \
                     crr (different columns); use another --out folder",
                    path.display()
                )));
            }
            first = false;
        } else {
            let id = checked_row(path, number + 1, body, header, |id| rows.contains_key(id))?;
            rows.insert(id.to_string(), body.to_string());
        }
        complete += line.len() as u64;
    }
    Ok((rows, complete))
}

/// Refuses to resume into a folder whose `cases.csv` (with `rows` cases) was computed for another
/// study, or for a study that has changed since ([`fingerprint`]).
fn same_study(csv: &Path, print_path: &Path, print: &str, rows: usize) -> Result<(), Error> {
    match crr_dynamics::input::read_regular_text(print_path, 1 << 10) {
        Ok(text) if text.trim() == print => Ok(()),
        Ok(_) => Err(Error::Argument(format!(
            "{}: its {rows} case(s) were computed for another version of this study (the study \
             file, its model, its records or the crr version changed since, {} differs); use \
             another --out folder, or remove this one to start again",
            csv.display(),
            print_path.display()
        ))),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(Error::Argument(format!(
            "{}: holds {rows} case(s) but no {} saying which study computed them; use another \
             --out folder, or remove this one to start again",
            csv.display(),
            print_path.display()
        ))),
        Err(source) => Err(Error::Io {
            file: print_path.to_path_buf(),
            source,
        }),
    }
}

/// A progress line on stderr: cases done, rate and estimated time left, at most 5 times a second.
struct Progress {
    total: usize,
    done: usize,
    start: Instant,
    shown: Instant,
    quiet: bool,
}

impl Progress {
    fn tick(&mut self, force: bool) {
        self.done += 1;
        if self.quiet || (!force && self.shown.elapsed().as_secs_f64() < 0.2) {
            return;
        }
        self.shown = Instant::now();
        let elapsed = self.start.elapsed().as_secs_f64();
        let eta = if self.done > 0 {
            elapsed / self.done as f64 * (self.total - self.done) as f64
        } else {
            0.0
        };
        let width = 30;
        let filled = (width * self.done) / self.total.max(1);
        eprint!(
            "\rcrr: study [{}{}] {}/{} cases, {:.0} s elapsed, ETA {:.0} s   ",
            "#".repeat(filled),
            "-".repeat(width - filled),
            self.done,
            self.total,
            elapsed,
            eta
        );
        if self.done == self.total {
            eprintln!();
        }
    }
}

/// Runs the study's cases of `opts.shard` into `opts.out` (resuming), then writes `cases.csv` in
/// id order and `study.json`.
pub fn run_study(
    study: &Study,
    study_file: &Path,
    opts: &StudyOptions,
) -> Result<StudyOutcome, Error> {
    crate::analysis::check_max_jobs(opts.jobs)?;
    let out_err = |source: std::io::Error| Error::Output {
        dir: opts.out.clone(),
        source,
    };
    // One writer per folder: two runs appending to one cases.csv would interleave their rows.
    let _lock = crate::output::folder_lock::FolderLock::acquire(&opts.out)?;
    let csv = opts.out.join("cases.csv");
    let header = header(study);
    let (done, complete_len) = done_rows(&csv, &header)?;
    let print = fingerprint(study);
    let print_path = opts.out.join(FINGERPRINT_FILE);
    if complete_len > 0 {
        same_study(&csv, &print_path, &print, done.len())?;
    }
    replace_file(&print_path, format!("{print}\n")).map_err(out_err)?;
    let mine: Vec<&Case> = study
        .cases
        .iter()
        .filter(|c| opts.shard.contains(c.index))
        .collect();
    // A set: a study of a million cases resumed half way compares each row once.
    let mine_ids: std::collections::BTreeSet<&str> = mine.iter().map(|c| c.id.as_str()).collect();
    if let Some(id) = done.keys().find(|id| !mine_ids.contains(id.as_str())) {
        return Err(Error::Argument(format!(
            "{}: case {id} is not one of this study's cases for shard {}/{}; use another --out \
             folder",
            csv.display(),
            opts.shard.index,
            opts.shard.count
        )));
    }
    let todo: Vec<&Case> = mine
        .iter()
        .copied()
        .filter(|c| !done.contains_key(&c.id))
        .collect();
    // Drop a partial last row (a run killed while writing it), then append.
    let mut file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&csv)
        .map_err(out_err)?;
    file.set_len(complete_len).map_err(out_err)?;
    if complete_len == 0 {
        writeln!(file, "{header}").map_err(out_err)?;
    }
    let started = Instant::now();
    let progress = Mutex::new(Progress {
        total: todo.len(),
        done: 0,
        start: started,
        shown: started,
        quiet: opts.quiet || todo.is_empty(),
    });
    let sink = Mutex::new(file);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs.unwrap_or(0))
        .build()
        .map_err(|e| Error::Argument(format!("--jobs: {e}")))?;
    let cancel = opts.cancel.as_ref();
    let write_result: Result<(), std::io::Error> = pool.install(|| {
        todo.par_iter().try_for_each(|case| {
            // A cancelled case writes nothing: the folder resumes it next time.
            let Some(result) = run_case_cancellable(study, case, cancel) else {
                return Ok(());
            };
            let line = row(study, case, &result);
            {
                let mut f = sink.lock().expect("the cases file");
                writeln!(f, "{line}")?;
                f.flush()?;
            }
            let mut p = progress.lock().expect("progress");
            let last = p.done + 1 == p.total;
            p.tick(last);
            Ok(())
        })
    });
    write_result.map_err(out_err)?;
    let wall = started.elapsed().as_secs_f64();
    drop(sink);
    if cancel.is_some_and(Cancel::is_cancelled) {
        let (rows, _) = done_rows(&csv, &header)?;
        return Ok(StudyOutcome {
            cases: mine.len(),
            skipped: done.len(),
            ran: rows.len() - done.len(),
            failed: rows.values().filter(|r| r.contains(",error,")).count(),
            outside_model: count_outside_model(&header, rows.values()),
            interrupted: true,
        });
    }
    // Every case of the shard is done: rewrite in id order.
    let (rows, _) = done_rows(&csv, &header)?;
    let text = cases_csv(&header, rows.values().map(String::as_str));
    let tmp = crate::output::results_folder::partial_name(&opts.out, "cases.csv");
    std::fs::write(&tmp, &text).map_err(out_err)?;
    std::fs::rename(&tmp, &csv).map_err(out_err)?;
    let failed = rows.values().filter(|r| r.contains(",error,")).count();
    let outside_model = count_outside_model(&header, rows.values());
    let info = StudyInfo {
        study: study.spec.clone(),
        study_file: study_file.display().to_string(),
        name: study.name.clone(),
        crr_version: env!("CARGO_PKG_VERSION").to_string(),
        fingerprint: print,
        model: study.model.name.clone(),
        cases_in_study: study.cases.len(),
        shard: format!("{}/{}", opts.shard.index, opts.shard.count),
        cases_in_shard: mine.len(),
        cases_skipped: done.len(),
        cases_run: todo.len(),
        cases_failed: failed,
        cases_outside_model: outside_model,
        warnings: study.warnings.clone(),
        threads: pool.current_num_threads(),
        wall_time_s: wall,
        lambda: study.lambda_p.map(|x| x.0),
        p_eq_rad_s: study.lambda_p.map(|x| x.1),
        alpha_eq_rad: study.alpha_eq,
        scales: study
            .variants
            .iter()
            .map(|v| ScaleInfo {
                scale: v.scale,
                height_m: v.height,
                lambda: v.lambda_p.map(|x| x.0),
                p_eq_rad_s: v.lambda_p.map(|x| x.1),
            })
            .collect(),
    };
    replace_file(&opts.out.join("study.json"), to_json(&info)).map_err(out_err)?;
    if let Some(text) = boundary_csv(study) {
        replace_file(&opts.out.join(BOUNDARY_FILE), text).map_err(out_err)?;
    }
    Ok(StudyOutcome {
        cases: mine.len(),
        skipped: done.len(),
        ran: todo.len(),
        failed,
        outside_model,
        interrupted: false,
    })
}

/// Whether `id` names one of the `total` cases of a study.
fn is_case_id(id: &str, total: usize) -> bool {
    id.strip_prefix('c')
        .and_then(|d| d.parse::<usize>().ok())
        .is_some_and(|i| i < total && id == case_id(i))
}

/// `crr study merge`: joins the `cases.csv` of shard folders into `out` (rows by id; the same id
/// twice must be the same row), checking that they come from the same study.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<usize, Error> {
    // The merged folder replaces its files: merging into one of the shards would turn that
    // shard into a merge, and a later merge of the shards would no longer find it.
    let same_folder =
        |a: &Path, b: &Path| match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
            (Ok(a), Ok(b)) => a == b,
            _ => a == b,
        };
    if let Some(shard) = dirs.iter().find(|d| same_folder(d, out)) {
        return Err(Error::Argument(format!(
            "--out {}: it is one of the shards being merged ({}); merge into another folder",
            out.display(),
            shard.display()
        )));
    }
    let mut header: Option<String> = None;
    let mut study: Option<serde_json::Value> = None;
    let mut first_json: Option<serde_json::Value> = None;
    let mut rows: BTreeMap<String, String> = BTreeMap::new();
    let mut shards: Vec<(usize, usize)> = Vec::new();
    for dir in dirs {
        let csv = dir.join("cases.csv");
        let text =
            crr_dynamics::input::read_regular_text(&csv, crr_dynamics::input::DATA_FILE_LIMIT)
                .map_err(|source| Error::Io {
                    file: csv.clone(),
                    source,
                })?;
        let json_path = dir.join("study.json");
        let json: serde_json::Value = crr_dynamics::input::read_regular_text(
            &json_path,
            crr_dynamics::input::MODEL_FILE_LIMIT,
        )
        .map_err(|source| Error::Io {
            file: json_path.clone(),
            source,
        })
        .and_then(|t| {
            serde_json::from_str(&t).map_err(|e| Error::Parse {
                file: json_path.clone(),
                message: e.to_string(),
            })
        })?;
        if first_json.is_none() {
            first_json = Some(json.clone());
        }
        match &study {
            None => study = Some(json["study"].clone()),
            Some(s) if *s != json["study"] => {
                return Err(Error::Argument(format!(
                    "{}: a different study from {}'s",
                    json_path.display(),
                    dirs[0].display()
                )));
            }
            _ => {}
        }
        if let Some(first) = &first_json
            && json["fingerprint"] != first["fingerprint"]
        {
            return Err(Error::Argument(format!(
                "{}: computed for another version of the study than {}'s (the fingerprints \
                 differ: the study file, its model, its records or the crr version changed \
                 between the shards); run the shards again with one study",
                json_path.display(),
                dirs[0].display()
            )));
        }
        shards.push(shard_of(&json, &json_path)?);
        let mut lines = text.lines();
        let h = lines.next().unwrap_or_default().to_string();
        match &header {
            None => header = Some(h),
            Some(x) if *x != h => {
                return Err(Error::Argument(format!(
                    "{}: columns differ from {}'s",
                    csv.display(),
                    dirs[0].display()
                )));
            }
            _ => {}
        }
        let in_study = json["cases_in_study"].as_u64().map(|n| n as usize);
        let mut in_file = std::collections::BTreeSet::new();
        for (number, line) in lines.enumerate() {
            let columns = header.as_deref().expect("set by the first folder");
            let id = checked_row(&csv, number + 2, line, columns, |id| in_file.contains(id))?;
            if let Some(total) = in_study
                && !is_case_id(id, total)
            {
                return Err(Error::Argument(format!(
                    "{}: line {}: case {id} is not one of the study's {total} cases ({} to {}): \
                     the file is damaged or comes from another study",
                    csv.display(),
                    number + 2,
                    case_id(0),
                    case_id(total.saturating_sub(1))
                )));
            }
            in_file.insert(id.to_string());
            if let Some(prev) = rows.get(id)
                && prev != line
            {
                return Err(Error::Argument(format!(
                    "{}: case {id} differs from the same case in another folder",
                    csv.display()
                )));
            }
            rows.insert(id.to_string(), line.to_string());
        }
    }
    complete_shards(&shards, dirs)?;
    let in_study = first_json
        .as_ref()
        .and_then(|j| j["cases_in_study"].as_u64())
        .map(|n| n as usize);
    if let Some(total) = in_study
        && rows.len() != total
    {
        return Err(Error::Argument(format!(
            "the shards hold {} of the study's {total} cases: {} are missing (a shard that did \
             not finish: run it again, it resumes, then merge)",
            rows.len(),
            total.saturating_sub(rows.len())
        )));
    }
    let out_err = |source: std::io::Error| Error::Output {
        dir: out.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(out).map_err(out_err)?;
    let _lock = crate::output::folder_lock::FolderLock::acquire(out)?;
    let header = header.unwrap_or_default();
    let mut text = header.clone() + "\n";
    for r in rows.values() {
        text.push_str(r);
        text.push('\n');
    }
    replace_file(&out.join("cases.csv"), text).map_err(out_err)?;
    let info = MergedStudyInfo {
        study,
        name: first_json.as_ref().map(|j| j["name"].clone()),
        alpha_eq_rad: first_json.as_ref().map(|j| j["alpha_eq_rad"].clone()),
        fingerprint: first_json.as_ref().map(|j| j["fingerprint"].clone()),
        merged_from: dirs.iter().map(|d| d.display().to_string()).collect(),
        cases: rows.len(),
        cases_outside_model: count_outside_model(&header, rows.values()),
        warnings: first_json
            .as_ref()
            .and_then(|j| j["warnings"].as_array())
            .map(|w| {
                w.iter()
                    .filter_map(|x| x.as_str().map(String::from))
                    .collect()
            })
            .unwrap_or_default(),
        crr_version: env!("CARGO_PKG_VERSION").to_string(),
    };
    replace_file(&out.join("study.json"), to_json(&info)).map_err(out_err)?;
    if let Ok(text) = std::fs::read_to_string(dirs[0].join(BOUNDARY_FILE)) {
        replace_file(&out.join(BOUNDARY_FILE), text).map_err(out_err)?;
    }
    Ok(rows.len())
}

/// The shard (index, count) a study folder's `study.json` says it holds.
fn shard_of(json: &serde_json::Value, path: &Path) -> Result<(usize, usize), Error> {
    json["shard"]
        .as_str()
        .and_then(|s| s.split_once('/'))
        .and_then(|(i, n)| Some((i.parse().ok()?, n.parse().ok()?)))
        .ok_or_else(|| Error::Parse {
            file: path.to_path_buf(),
            message: "no \"shard\": \"i/n\" entry: not a folder written by `crr study`".into(),
        })
}

/// Every shard of the study must be among the folders merged (each `i/n` with the same n).
fn complete_shards(shards: &[(usize, usize)], dirs: &[PathBuf]) -> Result<(), Error> {
    let Some(&(_, count)) = shards.first() else {
        return Ok(());
    };
    if let Some((k, &(i, n))) = shards.iter().enumerate().find(|(_, s)| s.1 != count) {
        return Err(Error::Argument(format!(
            "{}: shard {i}/{n}, where {} holds a shard of {count}",
            dirs[k].display(),
            dirs[0].display()
        )));
    }
    let missing: Vec<String> = (1..=count)
        .filter(|i| !shards.iter().any(|s| s.0 == *i))
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(Error::Argument(format!(
            "shard(s) {} missing: give the folder of every shard of the study",
            missing.join(", ")
        )));
    }
    Ok(())
}

/// The file holding the analytic overturning boundary of a block map (`boundary.csv`).
pub const BOUNDARY_FILE: &str = "boundary.csv";

/// `boundary.csv` for a map of a single block under one-sine or one-cosine pulses on
/// dimensionless axes: Zhang & Makris's minimum a_p/(g tan α) at twice as many ω_p/p as the map
/// has, over its range, up to 1.2 times its largest amplitude ratio (`study::zhang_makris`).
fn boundary_csv(study: &Study) -> Option<String> {
    let (mut w, mut a): (Vec<f64>, Vec<f64>) = study
        .cases
        .iter()
        .filter_map(|c| match c.motion {
            Motion::Pulse {
                amplitude_ratio: Some(a),
                frequency_ratio: Some(w),
                ..
            } => Some((w, a)),
            _ => None,
        })
        .unzip();
    w.sort_by(f64::total_cmp);
    w.dedup();
    a.sort_by(f64::total_cmp);
    let (lo, hi, top) = (*w.first()?, *w.last()?, *a.last()?);
    let points = crate::analysis::study::zhang_makris::map_boundary_up_to(
        study,
        lo,
        hi,
        2 * w.len(),
        1.2 * top,
    )?;
    let mut text = String::from("frequency_ratio,amplitude_ratio\n");
    for (x, y) in points {
        text += &format!("{x},{y}\n");
    }
    Some(text)
}
