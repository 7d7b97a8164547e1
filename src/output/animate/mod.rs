//! `crr animate RESULTS_DIR`: the bodies' motion of a `crr simulate` run as a ParaView series
//! (`frame_NNNNN.vtu` + `animation.pvd`, [`vtk`]) and an animated GIF (`animation.gif`,
//! [`render`] and [`gif`]), documented in `docs/animation.md`.
//!
//! The model is rebuilt from the copy `crr simulate` echoes into `summary.json` (`model`), the
//! states are read from `history.csv` (the angles q and the active pivots of the `_state`
//! columns), and every frame's body poses come from the engine's kinematics
//! ([`crr_kinematics::forward_kinematics`], [`crr_kinematics::body_points`]) applied to each
//! body's [`Surface`]. Everything is shown in the frame of the ground (the ground motion moves
//! the whole picture, which is not drawn). A face open at a sample gives its bodies' relative
//! rotation in history.csv and their offset in `openings.csv`: the bodies below an open face of
//! the model's tree are moved by it ([`crr_impact::simulation::body_offsets`]), so they are drawn
//! where they are.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use crr_impact::simulation::{FaceOpening, body_offsets};

use nalgebra::{DVector, Vector3};
use serde_json::Value;

use crr_kinematics::shapes::Surface;
use crr_kinematics::{ActivePivots, Data, Model, Side, body_points, forward_kinematics};

use crate::Error;
use crate::input::model_file::ModelFile;
use crate::output::text_lines::TextLines;

pub mod gif;
pub mod render;
pub mod vtk;

pub use render::View;

/// The folder, inside the results folder, that holds the animation by default.
pub const DEFAULT_DIR: &str = "animation";

/// The ParaView index of the series.
pub const PVD_FILE: &str = "animation.pvd";

/// The animated GIF.
pub const GIF_FILE: &str = "animation.gif";

/// Default simulated time between two frames (s) when `--every` is not given: 20 frames per
/// simulated second.
pub const DEFAULT_FRAME_INTERVAL: f64 = 0.05;

/// Default largest number of frames when `--every` is not given (the step K is raised to stay
/// below it): keeps the GIF of a long run small.
pub const DEFAULT_MAX_FRAMES: usize = 400;

/// Which files `crr animate` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// The ParaView series only.
    Vtk,
    /// The GIF only.
    Gif,
    /// Both (the default).
    Both,
}

impl std::str::FromStr for Format {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "vtk" => Ok(Format::Vtk),
            "gif" => Ok(Format::Gif),
            "both" => Ok(Format::Both),
            _ => Err(format!("unknown format `{s}`: give vtk, gif or both")),
        }
    }
}

/// Options of `crr animate`.
#[derive(Clone, Debug)]
pub struct AnimateOptions {
    /// Keep every K-th state of history.csv (after merging the two rows of an impact); None: a
    /// K giving about [`DEFAULT_FRAME_INTERVAL`] between frames and at most
    /// [`DEFAULT_MAX_FRAMES`] frames.
    pub every: Option<usize>,
    /// Output folder (default `RESULTS_DIR/animation`).
    pub out: Option<PathBuf>,
    /// The GIF's view direction.
    pub view: View,
    /// Which files to write.
    pub format: Format,
    /// GIF playback speed: a frame lasts its simulated time divided by this.
    pub speed: f64,
    /// Replace an earlier animation in the output folder.
    pub force: bool,
}

impl Default for AnimateOptions {
    fn default() -> Self {
        AnimateOptions {
            every: None,
            out: None,
            view: View::Iso,
            format: Format::Both,
            speed: 1.0,
            force: false,
        }
    }
}

/// One state of the run: time, angles and active pivots.
#[derive(Clone, Debug)]
pub struct State {
    /// Time (s).
    pub t: f64,
    /// Angles q (rad), in the order of the model's coordinates.
    pub q: DVector<f64>,
    /// The active pivot of every slot (`+`/`-` of the `_state` columns; a seated slot takes the
    /// side of its angle's sign, which does not move anything since its angle is 0).
    pub pivots: ActivePivots,
    /// The largest |q| of any coordinate over history.csv up to this row (rad).
    pub peak_so_far: f64,
    /// The row of history.csv (1 = first data row).
    pub row: usize,
    /// The faces open at this row, from `openings.csv` (empty when none is, or when the folder
    /// has no such file: a run of an earlier version).
    pub openings: Vec<FaceOpening>,
    /// The interfaces whose `_state` column is `open` at this row, in model order.
    pub open: Vec<usize>,
}

/// A results folder read back for animation: the model, and the extent of its history, whose
/// states are read again, one at a time, when the frames are drawn ([`Run::states`]), so that a
/// history of any length is animated in memory proportional to the frames kept.
#[derive(Clone, Debug)]
pub struct Run {
    /// The model rebuilt from summary.json.
    pub model: Model,
    /// The run's history.csv.
    pub history: PathBuf,
    /// The states of history.csv (the two rows of an impact merged into one).
    pub count: usize,
    /// Time of the first and of the last state (s).
    pub span: (f64, f64),
    /// The faces open at each row of history.csv that has any (`openings.csv`).
    pub openings: BTreeMap<usize, Vec<FaceOpening>>,
    /// The time of the run's first hypotheses violation (`hypothesis_violation` of summary.json),
    /// after which the motion is outside crr's model: the frames after it say so.
    pub violation_time: Option<f64>,
}

impl Run {
    /// The states of history.csv, read again from the file.
    pub fn states(&self) -> Result<HistoryStates<'_, BufReader<File>>, Error> {
        HistoryStates::open(&self.model, &self.history)
    }
}

fn read_error(file: &Path, message: impl std::fmt::Display) -> Error {
    Error::Argument(format!("{}: {message}", file.display()))
}

/// Reads `summary.json` (for the model) and `history.csv` of a results folder, checking every row
/// of the history once (nothing is kept but its count and time span). A missing folder or file, a
/// run still being written (its hidden `.partial.NAME` files), a summary without the model, or a
/// history that does not fit the model is an error naming the file.
pub fn read_run(dir: &Path) -> Result<Run, Error> {
    if !dir.is_dir() {
        return Err(Error::Argument(format!(
            "{}: no such results folder (run `crr simulate MODEL --out DIR` first)",
            dir.display()
        )));
    }
    let summary_path = dir.join("summary.json");
    let history_path = dir.join("history.csv");
    for name in ["history.csv", "summary.json"] {
        if !dir.join(name).is_file() {
            let partial = crate::output::results_folder::partial_name(dir, name).exists();
            let why = if partial {
                "is missing and its temporary file is there: the run is still being written or \
                 was interrupted; animate a completed run"
            } else {
                "is missing: not a results folder of `crr simulate` (or an interrupted run)"
            };
            return Err(read_error(&dir.join(name), why));
        }
    }
    let limit = crr_dynamics::input::MODEL_FILE_LIMIT;
    let summary_text = crr_dynamics::input::read_regular_text(&summary_path, limit)
        .map_err(|e| read_error(&summary_path, format!("cannot read the file: {e}")))?;
    let summary: Value = serde_json::from_str(&summary_text)
        .map_err(|e| read_error(&summary_path, format!("not valid JSON: {e}")))?;
    let model = model_of(&summary, &summary_path)?;
    let openings_path = dir.join("openings.csv");
    let openings = read_openings(&model, &openings_path)?;
    let mut count = 0;
    let mut span = (0.0, 0.0);
    let mut rows = 0;
    let mut history = HistoryStates::open(&model, &history_path)?;
    if openings_path.is_file() {
        history = history.checked_against(&openings, &openings_path);
    }
    for state in history {
        let state = state?;
        if count == 0 {
            span.0 = state.t;
        }
        span.1 = state.t;
        count += 1;
        rows = state.row;
    }
    if count == 0 {
        return Err(read_error(&history_path, "holds no data rows"));
    }
    if let Some((&last, _)) = openings.last_key_value().filter(|(r, _)| **r > rows) {
        return Err(read_error(
            &openings_path,
            format!("row {last} is beyond the {rows} data rows of history.csv"),
        ));
    }
    Ok(Run {
        model,
        history: history_path,
        count,
        span,
        openings,
        violation_time: crate::output::results_folder::violation_time(&summary),
    })
}

/// The rows of `openings.csv` by the row of history.csv they belong to; none when the file is
/// absent (a results folder of a version that did not write it: open faces of the tree are then
/// drawn turned about their pivot, not where they are). A row that does not fit the model (an
/// unknown interface, a row number below 1, a field that is not a finite number, an interface
/// listed twice at one row) is an error naming the file and the line.
fn read_openings(model: &Model, path: &Path) -> Result<BTreeMap<usize, Vec<FaceOpening>>, Error> {
    let mut out: BTreeMap<usize, Vec<FaceOpening>> = BTreeMap::new();
    if !path.is_file() {
        return Ok(out);
    }
    let text = crr_dynamics::input::read_regular_text(path, crr_dynamics::input::DATA_FILE_LIMIT)
        .map_err(|e| read_error(path, format!("cannot read the file: {e}")))?;
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, header)) if header == OPENINGS_COLUMNS => {}
        _ => {
            return Err(read_error(
                path,
                format!("line 1: the header is not `{OPENINGS_COLUMNS}`"),
            ));
        }
    }
    for (i, line) in lines {
        let line_no = i + 1;
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != 6 {
            return Err(read_error(
                path,
                format!("line {line_no}: {} fields, 6 expected", fields.len()),
            ));
        }
        let row = fields[0]
            .parse::<usize>()
            .ok()
            .filter(|&r| r >= 1)
            .ok_or_else(|| {
                read_error(
                    path,
                    format!("line {line_no}: `row` is `{}`, not a row number", fields[0]),
                )
            })?;
        let interface = model.interface_index(fields[2]).ok_or_else(|| {
            read_error(
                path,
                format!("line {line_no}: no interface `{}` in the model", fields[2]),
            )
        })?;
        let number = |field: usize| {
            fields[field]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    read_error(
                        path,
                        format!("line {line_no}: `{}` is not a finite number", fields[field]),
                    )
                })
        };
        number(1)?;
        let offset = [number(3)?, number(4)?, number(5)?];
        let at_row = out.entry(row).or_default();
        if at_row.iter().any(|o| o.interface == interface) {
            return Err(read_error(
                path,
                format!("line {line_no}: `{}` listed twice at row {row}", fields[2]),
            ));
        }
        at_row.push(FaceOpening { interface, offset });
    }
    Ok(out)
}

/// The header of `openings.csv`, without its line end.
const OPENINGS_COLUMNS: &str = crate::output::history::OPENINGS_HEADER.trim_ascii_end();

/// The model echoed in summary.json's `model`, validated.
fn model_of(summary: &Value, path: &Path) -> Result<Model, Error> {
    let echo = summary
        .get("model")
        .filter(|m| m.is_object())
        .ok_or_else(|| {
            read_error(
                path,
                "holds no `model` (the model file echoed by `crr simulate`): rerun the simulation \
             with this version of crr",
            )
        })?;
    let file: ModelFile = serde_json::from_value(echo.clone())
        .map_err(|e| read_error(path, format!("`model` is not a valid model: {e}")))?;
    Model::from_spec(&file.structure()).map_err(|e| read_error(path, format!("`model`: {e}")))
}

/// The states of history.csv (its angle and `_state` columns) one at a time, the two rows of an
/// impact (rates before, then after) merged into one state, the later: a history of any length
/// is read in constant memory. A row that does not fit the model is an error naming the file and
/// the line, after which the iterator ends.
pub struct HistoryStates<'m, R> {
    model: &'m Model,
    path: PathBuf,
    lines: TextLines<R>,
    header: Vec<String>,
    t_col: usize,
    q_cols: Vec<usize>,
    state_cols: Vec<usize>,
    peak: f64,
    pending: Option<State>,
    done: bool,
    /// The faces `openings.csv` lists at each row, and its path, when every row's `open`
    /// states are to be checked against it ([`HistoryStates::checked_against`]).
    expected_open: Option<(BTreeMap<usize, Vec<usize>>, PathBuf)>,
}

impl<'m> HistoryStates<'m, BufReader<File>> {
    /// Opens `path` and reads its header.
    pub fn open(model: &'m Model, path: &Path) -> Result<Self, Error> {
        let file = crr_dynamics::input::open_regular_file(path)
            .map_err(|e| read_error(path, format!("cannot read the file: {e}")))?;
        HistoryStates::new(model, BufReader::new(file), path)
    }
}

impl<'m, R: BufRead> HistoryStates<'m, R> {
    /// Reads the header of a history read from `reader` (`path` names it in messages).
    pub fn new(model: &'m Model, reader: R, path: &Path) -> Result<Self, Error> {
        let mut states = HistoryStates {
            model,
            path: path.to_path_buf(),
            lines: TextLines::new(reader),
            header: Vec::new(),
            t_col: 0,
            q_cols: Vec::new(),
            state_cols: Vec::new(),
            peak: 0.0,
            pending: None,
            done: false,
            expected_open: None,
        };
        let header = states
            .next_line()?
            .ok_or_else(|| read_error(path, "empty file"))?;
        let header: Vec<String> = header.split(',').map(str::to_string).collect();
        let column = |name: &str| {
            header
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| read_error(path, format!("no column `{name}`")))
        };
        states.t_col = column("t")?;
        states.q_cols = model
            .coords
            .iter()
            .map(|c| column(&c.name))
            .collect::<Result<Vec<_>, _>>()?;
        states.state_cols = model
            .interfaces
            .iter()
            .map(|i| column(&format!("{}_state", i.name)))
            .collect::<Result<Vec<_>, _>>()?;
        states.header = header;
        Ok(states)
    }

    fn error(&self, message: impl std::fmt::Display) -> Error {
        read_error(&self.path, message)
    }

    /// Checks every row's `open` states against the faces `openings.csv` (at `path`) lists at
    /// that row: the offsets drawn are those of the faces open there, or the two files are not
    /// of one run (an error naming both and the row).
    pub fn checked_against(
        mut self,
        openings: &BTreeMap<usize, Vec<FaceOpening>>,
        path: &Path,
    ) -> Self {
        let listed = openings
            .iter()
            .map(|(&row, faces)| {
                let mut interfaces: Vec<usize> = faces.iter().map(|o| o.interface).collect();
                interfaces.sort_unstable();
                (row, interfaces)
            })
            .collect();
        self.expected_open = Some((listed, path.to_path_buf()));
        self
    }

    /// An error where the faces open at `state`'s row are not those `openings.csv` lists there.
    fn check_open(&self, state: &State) -> Result<(), Error> {
        let Some((listed, openings_path)) = &self.expected_open else {
            return Ok(());
        };
        let expected = listed.get(&state.row).map_or(&[][..], Vec::as_slice);
        if expected == state.open.as_slice() {
            return Ok(());
        }
        let names = |faces: &[usize]| {
            if faces.is_empty() {
                "none".to_string()
            } else {
                faces
                    .iter()
                    .map(|&i| format!("`{}`", self.model.interfaces[i].name))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        };
        Err(self.error(format!(
            "line {}: the faces open there ({}) are not those {} lists at row {} ({}): the two \
             files are not of one run",
            self.lines.number(),
            names(&state.open),
            openings_path.display(),
            state.row,
            names(expected)
        )))
    }

    /// The next line without its line end; None at the end of the file. A last line without
    /// its line end is a half-written file.
    fn next_line(&mut self) -> Result<Option<&str>, Error> {
        match self.lines.next_line() {
            Ok(Some(line)) if !line.ended => Err(read_error(
                &self.path,
                "the last line is not complete (no line end): a half-written file",
            )),
            Ok(line) => Ok(line.map(|l| l.text)),
            Err(message) => Err(read_error(&self.path, message)),
        }
    }

    /// Parses one data row into a state.
    fn parse_row(&self, line: &str) -> Result<State, Error> {
        let line_no = self.lines.number();
        let header = &self.header;
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != header.len() {
            return Err(self.error(format!(
                "line {line_no}: {} fields, {} expected (a damaged or half-written file)",
                fields.len(),
                header.len()
            )));
        }
        let number = |c: usize| -> Result<f64, Error> {
            fields[c]
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    self.error(format!(
                        "line {line_no}: column `{}` is not a finite number",
                        header[c]
                    ))
                })
        };
        let t = number(self.t_col)?;
        let q = DVector::from_iterator(
            self.q_cols.len(),
            self.q_cols
                .iter()
                .map(|&c| number(c))
                .collect::<Result<Vec<_>, _>>()?,
        );
        let model = self.model;
        let mut pivots = ActivePivots::uniform(model, Side::Positive);
        let mut open = Vec::new();
        for (index, (iface, &c)) in model.interfaces.iter().zip(&self.state_cols).enumerate() {
            let codes: Vec<&str> = fields[c].split('/').collect();
            if codes.len() != iface.slots.len() {
                return Err(self.error(format!(
                    "line {line_no}: column `{}` is `{}`, {} code(s) expected",
                    header[c],
                    fields[c],
                    iface.slots.len()
                )));
            }
            for (k, (slot, code)) in iface.slots.clone().zip(codes).enumerate() {
                pivots.sides[slot] = match code {
                    "+" => Side::Positive,
                    "-" => Side::Negative,
                    // A face that lifted off has no pivot. A loop-closing one places no body; on a
                    // tree interface of the file q is its bodies' relative rotation about P⁺, and
                    // openings.csv moves the bodies below it to where they are (`pose_vertices`).
                    "open" => {
                        if open.last() != Some(&index) {
                            open.push(index);
                        }
                        Side::Positive
                    }
                    "seated" => {
                        // A seated tree angle is 0: either side gives the same pose.
                        let angle = match iface.role {
                            crr_kinematics::Role::Tree { first_coord } => q[first_coord + k],
                            crr_kinematics::Role::Closure { .. } => 0.0,
                        };
                        Side::of(angle, Side::Positive)
                    }
                    other => {
                        return Err(self.error(format!(
                            "line {line_no}: column `{}` holds `{other}`, not +, -, seated or open",
                            header[c]
                        )));
                    }
                };
            }
        }
        Ok(State {
            t,
            q,
            pivots,
            peak_so_far: 0.0,
            row: line_no - 1,
            openings: Vec::new(),
            open,
        })
    }

    /// The next merged state: rows are read until one has a later time than the pending state.
    fn advance(&mut self) -> Result<Option<State>, Error> {
        loop {
            let Some(line) = self.next_line()? else {
                return Ok(self.pending.take());
            };
            let line = line.to_string();
            let mut state = self.parse_row(&line)?;
            self.check_open(&state)?;
            self.peak = state.q.iter().fold(self.peak, |m, v| m.max(v.abs()));
            state.peak_so_far = self.peak;
            match self.pending.take() {
                Some(last) if state.t < last.t => {
                    return Err(self.error(format!(
                        "line {}: time {} goes backwards",
                        self.lines.number(),
                        state.t
                    )));
                }
                // The two rows of an impact (rates before, then after): one state, the later.
                Some(last) if state.t == last.t => self.pending = Some(state),
                Some(last) => {
                    self.pending = Some(state);
                    return Ok(Some(last));
                }
                None => self.pending = Some(state),
            }
        }
    }
}

impl<R: BufRead> Iterator for HistoryStates<'_, R> {
    type Item = Result<State, Error>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let next = self.advance().transpose();
        if !matches!(next, Some(Ok(_))) {
            self.done = true;
        }
        next
    }
}

/// The step K between frames: `every` when given (at least 1), else about
/// [`DEFAULT_FRAME_INTERVAL`] of simulated time between frames and at most
/// [`DEFAULT_MAX_FRAMES`] frames, for `count` states spanning `span` (s).
pub fn frame_step(count: usize, span: (f64, f64), every: Option<usize>) -> Result<usize, Error> {
    match every {
        Some(0) => Err(Error::Argument(
            "--every must be at least 1 (keep every K-th state)".into(),
        )),
        Some(k) => Ok(k),
        None => {
            let n = count.max(1);
            let dt = if n > 1 {
                (span.1 - span.0) / (n - 1) as f64
            } else {
                1.0
            };
            let by_time = if dt > 0.0 {
                (DEFAULT_FRAME_INTERVAL / dt).round().max(1.0) as usize
            } else {
                1
            };
            Ok(by_time.max(n.div_ceil(DEFAULT_MAX_FRAMES)))
        }
    }
}

/// The states kept as frames: the first and every K-th after it, read from the history again.
/// Every row is read (an error anywhere stops it), only the frames are kept.
pub fn frame_states(run: &Run, k: usize) -> Result<Vec<State>, Error> {
    let mut frames = Vec::with_capacity(run.count.div_ceil(k.max(1)).min(DEFAULT_MAX_FRAMES));
    for (i, state) in run.states()?.enumerate() {
        let mut state = state?;
        if i % k.max(1) == 0 {
            if let Some(open) = run.openings.get(&state.row) {
                state.openings.clone_from(open);
            }
            frames.push(state);
        }
    }
    Ok(frames)
}

/// The bodies' surfaces at rest (the frame of the mass properties), in body order.
pub fn body_surfaces(model: &Model) -> Result<Vec<Surface>, Error> {
    model
        .bodies
        .iter()
        .map(|b| {
            b.shape
                .surface()
                .map_err(|e| Error::Argument(format!("body \"{}\": no surface: {e}", b.name)))
        })
        .collect()
}

/// World positions of every body's surface vertices at one state (one vector per body, in
/// the order of its surface's vertices).
pub fn pose_vertices(
    model: &Model,
    data: &mut Data,
    surfaces: &[Surface],
    state: &State,
) -> Vec<Vec<Vector3<f64>>> {
    forward_kinematics(model, data, &state.q, &state.pivots);
    let offsets = body_offsets(model, &state.openings);
    surfaces
        .iter()
        .enumerate()
        .map(|(b, s)| {
            let mut out = Vec::with_capacity(s.vertices.len());
            body_points(model, data, b, &s.vertices, &mut out);
            for v in &mut out {
                *v += offsets[b];
            }
            out
        })
        .collect()
}

/// The ground drawn under the structure: the rectangle at the lowest height of the bodies at
/// rest, covering their footprint with a margin of a quarter of the model size.
#[derive(Clone, Debug)]
pub struct Ground {
    /// Its four corners (m), counter-clockwise seen from above.
    pub corners: [Vector3<f64>; 4],
}

impl Ground {
    /// The ground of a model whose bodies have these surfaces at rest.
    pub fn of(model: &Model, surfaces: &[Surface]) -> Ground {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for v in surfaces.iter().flat_map(|s| &s.vertices) {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        let m = 0.25 * model.size;
        let z = lo.z;
        Ground {
            corners: [
                Vector3::new(lo.x - m, lo.y - m, z),
                Vector3::new(hi.x + m, lo.y - m, z),
                Vector3::new(hi.x + m, hi.y + m, z),
                Vector3::new(lo.x - m, hi.y + m, z),
            ],
        }
    }
}

/// The file name of frame `j` of the series.
pub fn frame_name(j: usize) -> String {
    format!("frame_{j:05}.vtu")
}

/// Is `name` a file of an animation (a frame, the index or the GIF)?
fn is_animation_file(name: &str) -> bool {
    name == PVD_FILE
        || name == GIF_FILE
        || (name.starts_with("frame_")
            && name.ends_with(".vtu")
            && name["frame_".len()..name.len() - 4]
                .bytes()
                .all(|b| b.is_ascii_digit()))
}

/// The animation files in `dir` (sorted), none when it does not exist.
pub fn animation_files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .filter_map(|e| e.file_name().into_string().ok())
                .filter(|n| is_animation_file(n))
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// Removes the animation files of `dir` (frames, index, GIF; nothing else), and the folder
/// itself when that leaves it empty.
pub fn remove_animation(dir: &Path) -> std::io::Result<()> {
    for name in animation_files(dir) {
        std::fs::remove_file(dir.join(name))?;
    }
    if dir.is_dir() && std::fs::read_dir(dir)?.next().is_none() {
        std::fs::remove_dir(dir)?;
    }
    Ok(())
}

/// The hidden folder inside the output folder where an animation is written before its files
/// are moved into place.
fn partial_dir(out: &Path) -> PathBuf {
    crate::output::results_folder::partial_name(out, DEFAULT_DIR)
}

/// What `crr animate` wrote.
#[derive(Clone, Debug)]
pub struct AnimateReport {
    /// The output folder.
    pub out: PathBuf,
    /// Frames written.
    pub frames: usize,
    /// The step K used.
    pub every: usize,
    /// The files written (paths), the index and GIF last.
    pub files: Vec<PathBuf>,
    /// Size of the GIF (bytes), when written.
    pub gif_bytes: Option<u64>,
}

/// `crr animate` end to end: reads the run, writes the frames (VTK) and the GIF into a hidden
/// folder, then moves them into the output folder (an earlier animation there is refused
/// without `force`, and removed with it, only after the new files are complete).
pub fn animate(dir: &Path, opts: &AnimateOptions) -> Result<AnimateReport, Error> {
    if !(opts.speed.is_finite() && opts.speed > 0.0) {
        return Err(Error::Argument(format!(
            "--speed must be a positive number, got {}",
            opts.speed
        )));
    }
    let out = opts.out.clone().unwrap_or_else(|| dir.join(DEFAULT_DIR));
    let label = out.display().to_string();
    if out.exists() && !out.is_dir() {
        return Err(Error::Argument(format!(
            "{label}: the output path exists and is not a folder"
        )));
    }
    let earlier = animation_files(&out);
    if !earlier.is_empty() && !opts.force {
        let shown: Vec<&str> = earlier.iter().take(3).map(String::as_str).collect();
        return Err(Error::Argument(format!(
            "{label}: the folder holds an earlier animation ({}{}): pass --force to replace \
             it, or --out DIR for another folder",
            shown.join(", "),
            if earlier.len() > 3 {
                format!(" and {} more", earlier.len() - 3)
            } else {
                String::new()
            }
        )));
    }
    let run = read_run(dir)?;
    let k = frame_step(run.count, run.span, opts.every)?;
    let frames = frame_states(&run, k)?;
    let surfaces = body_surfaces(&run.model)?;
    let ground = Ground::of(&run.model, &surfaces);
    let model = &run.model;
    let mut data = Data::new(model);

    let output_error = |source| Error::Output {
        dir: out.clone(),
        source,
    };
    // One writer per folder: another animation into it would remove this one's frames.
    let _lock = crate::output::folder_lock::FolderLock::acquire(&out)?;
    let tmp = partial_dir(&out);
    if tmp.exists() {
        // Left by an interrupted animation: ours to remove (the lock says no one writes it).
        std::fs::remove_dir_all(&tmp).map_err(output_error)?;
    }
    std::fs::create_dir_all(&tmp).map_err(output_error)?;
    let vtk = matches!(opts.format, Format::Vtk | Format::Both);
    let mut gif_writer = None;
    if matches!(opts.format, Format::Gif | Format::Both) {
        // The picture's framing is fixed: fitted to every frame first (poses recomputed below,
        // one frame at a time, rather than kept).
        let (slab, _) = gif::ground_faces(&ground);
        let points = frames
            .iter()
            .flat_map(|s| pose_vertices(model, &mut data, &surfaces, s))
            .flatten()
            .chain(slab.vertices.iter().copied());
        let renderer = render::Renderer::new(opts.view, points);
        let file = std::fs::File::create(tmp.join(GIF_FILE)).map_err(output_error)?;
        let times: Vec<f64> = frames.iter().map(|s| s.t).collect();
        gif_writer = Some(gif::GifWriter::new(
            std::io::BufWriter::new(file),
            renderer,
            &ground,
            &times,
            opts.speed,
            run.violation_time,
        )?);
    }
    let names_of_bodies: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    let mut names: Vec<String> = Vec::new();
    for (j, state) in frames.iter().enumerate() {
        let pose = pose_vertices(model, &mut data, &surfaces, state);
        if vtk {
            let text = vtk::vtu(&names_of_bodies, &surfaces, &pose, &ground, state.t);
            let name = frame_name(j);
            std::fs::write(tmp.join(&name), text).map_err(output_error)?;
            names.push(name);
        }
        if let Some(g) = gif_writer.as_mut() {
            g.add(state, &surfaces, &pose)?;
        }
    }
    let mut gif_bytes = None;
    if let Some(g) = gif_writer {
        let file = g
            .finish()?
            .into_inner()
            .map_err(|e| output_error(e.into_error()))?;
        file.sync_all().map_err(output_error)?;
        gif_bytes = Some(file.metadata().map_err(output_error)?.len());
        names.push(GIF_FILE.to_string());
    }
    if vtk {
        let entries: Vec<(f64, String)> = frames
            .iter()
            .enumerate()
            .map(|(j, s)| (s.t, frame_name(j)))
            .collect();
        std::fs::write(tmp.join(PVD_FILE), vtk::pvd(&entries)).map_err(output_error)?;
        // The index last: a folder with an index holds all its frames.
        names.push(PVD_FILE.to_string());
    }
    // Complete: replace the earlier animation, the index and GIF last.
    for name in &earlier {
        std::fs::remove_file(out.join(name)).map_err(output_error)?;
    }
    let mut files = Vec::with_capacity(names.len());
    for name in &names {
        std::fs::rename(tmp.join(name), out.join(name)).map_err(output_error)?;
        files.push(out.join(name));
    }
    std::fs::remove_dir_all(&tmp).map_err(output_error)?;
    Ok(AnimateReport {
        out,
        frames: frames.len(),
        every: k,
        files,
        gif_bytes,
    })
}
