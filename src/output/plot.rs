//! Plots of the results of `crr simulate` (`crr plot DIR`, `crr simulate … --plot`) and of the
//! frequency table of `crr check` (`crr check MODEL --plot DIR`), as PNG and SVG (documented in
//! `docs/outputs.md`, section "Plots").
//!
//! The text is drawn with DejaVu Sans, embedded in the binary (crate `dejavu`) and registered with
//! plotters as the `sans-serif` family by [`register_fonts`]: no system font is needed.

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;
use serde_json::Value;

use crr_dynamics::{horizontal_direction, reported_side};
use crr_kinematics::{ActivePivots, Model, Side};

use crate::analysis::check::{CheckReport, housner_frequency};
use crate::analysis::levels::{DEFAULT_STEP, MechanismLevels, mechanism_levels};
use crate::input::model_file::ModelFile;
use crate::output::replace_file::replace_file_with;
use crate::output::text_lines::TextLines;

pub mod decimate;
mod figures;
mod study;
pub use figures::{
    draw_housner_models, draw_levels, draw_size_sweep, plot_housner_models, plot_levels,
    plot_size_sweep,
};
pub use study::{FragilityFigure, draw_fragility, draw_map, draw_spectrum, plot_study};

/// Size of every image (pixels; the SVG uses the same user units).
pub const SIZE: (u32, u32) = (1000, 700);

/// The font family every text of the plots uses.
pub const FONT: &str = "sans-serif";

pub use crate::error::PlotError;

/// Registers the embedded DejaVu Sans faces as the `sans-serif` family (once per process).
pub fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let faces = [
            (FontStyle::Normal, dejavu::sans::regular()),
            (FontStyle::Bold, dejavu::sans::bold()),
            (FontStyle::Oblique, dejavu::sans::oblique()),
            (FontStyle::Italic, dejavu::sans::oblique()),
        ];
        for (style, bytes) in faces {
            // The bytes are a valid TrueType font shipped by the crate.
            assert!(
                plotters::style::register_font(FONT, style, bytes).is_ok(),
                "embedded DejaVu Sans is a valid font"
            );
        }
    });
}

/// The free-rocking energy levels of a single block (paper Fig. 6):
/// θ̇² = 2p²[cos(α − |θ_m|) − cos(α − |θ|)].
#[derive(Clone, Copy, Debug)]
pub struct FreeRocking {
    /// p (rad/s): p² = U′(0)² + U″(0)² over M(0), i.e. mgR/I₀ for a block.
    pub p: f64,
    /// α (rad).
    pub alpha: f64,
}

impl FreeRocking {
    /// θ̇ ≥ 0 on the level of amplitude θ_m at angle θ (0 outside |θ| ≤ θ_m).
    pub fn rate(&self, theta_m: f64, theta: f64) -> f64 {
        let v = 2.0
            * self.p
            * self.p
            * ((self.alpha - theta_m.abs()).cos() - (self.alpha - theta.abs()).cos());
        v.max(0.0).sqrt()
    }
}

/// The results of one run, read back from its folder.
#[derive(Clone, Debug)]
pub struct Results {
    /// Model name (`summary.model.name`).
    pub model_name: String,
    /// Coordinate names, in the order of q.
    pub coordinates: Vec<String>,
    /// Sample times (s) of the rows drawn: all of them, or for a long history those that keep
    /// every series' envelope at the figures' width ([`decimate`]).
    pub t: Vec<f64>,
    /// Angles (rad), one vector per coordinate.
    pub q: Vec<Vec<f64>>,
    /// Rates (rad/s), one vector per coordinate.
    pub qdot: Vec<Vec<f64>>,
    /// T (J).
    pub kinetic: Vec<f64>,
    /// U − U(rest) (J).
    pub potential: Vec<f64>,
    /// W (J).
    pub work_in: Vec<f64>,
    /// D (J).
    pub dissipated: Vec<f64>,
    /// Impacts: time (s) and the impacting interfaces.
    pub impacts: Vec<(f64, Vec<String>)>,
    /// The free-rocking energy levels, when the model is a one-coordinate block.
    pub free_rocking: Option<FreeRocking>,
    /// The energy levels of the first coordinate from the engine's M(θ) and U(θ), when the model
    /// is any other one-DOF mechanism (DOF(2) = 1, e.g. a trilithon or an arch).
    pub levels: Option<MechanismLevels>,
    /// The run's first failure of the rigid-contact hypotheses (`hypothesis_violation` of
    /// summary.json): its time (s) and "kind at interface". The figures shade the time after it,
    /// which crr's model does not describe.
    pub violation: Option<(f64, String)>,
}

fn read_text(file: &Path) -> Result<String, PlotError> {
    crr_dynamics::input::read_regular_text(file, crr_dynamics::input::DATA_FILE_LIMIT).map_err(
        |e| PlotError::Read {
            file: file.to_path_buf(),
            message: format!("cannot read the file: {e}"),
        },
    )
}

/// p and α of a one-coordinate model (a single block on a hinge with two pivot lines) rebuilt
/// from the model echoed in summary.json; None otherwise.
fn free_rocking(summary: &Value) -> Option<FreeRocking> {
    let coords = summary["coordinates"].as_array()?;
    if coords.len() != 1 || coords[0]["alpha"].as_f64().is_none() {
        return None;
    }
    let file: ModelFile = serde_json::from_value(summary["model"].clone()).ok()?;
    let model = Model::from_spec(&file.structure()).ok()?;
    if model.dof() != 1 || !model.closures.is_empty() {
        return None;
    }
    // The side `crr check` reports (reported_side).
    let (_, _, eq) = reported_side(&model, 0, &horizontal_direction(&model, 0)).ok()?;
    (eq.p_squared > 0.0 && eq.alpha > 0.0).then(|| FreeRocking {
        p: eq.p_squared.sqrt(),
        alpha: eq.alpha,
    })
}

/// The energy levels of a one-DOF mechanism rebuilt from the model echoed in summary.json, when
/// it is not a single block (those have [`FreeRocking`]); None otherwise or when they cannot be
/// followed.
fn mechanism_levels_of(summary: &Value) -> Option<MechanismLevels> {
    let file: ModelFile = serde_json::from_value(summary["model"].clone()).ok()?;
    let model = Model::from_spec(&file.structure()).ok()?;
    let zero = nalgebra::DVector::zeros(model.dof());
    let mob = crr_dynamics::mobility(
        &model,
        &zero,
        &ActivePivots::uniform(&model, Side::Positive),
    );
    if mob.dof2 != 1 {
        return None;
    }
    mechanism_levels(&model, DEFAULT_STEP).ok()
}

/// Reads `history.csv`, `impacts.csv` and `summary.json` of a results folder; history.csv is read
/// line by line (only its numbers are kept, not its text).
pub fn read_results(dir: &Path) -> Result<Results, PlotError> {
    if !dir.is_dir() {
        return Err(PlotError::MissingDir(dir.to_path_buf()));
    }
    let history_file = dir.join("history.csv");
    let history =
        crr_dynamics::input::open_regular_file(&history_file).map_err(|e| PlotError::Read {
            file: history_file.clone(),
            message: format!("cannot read the file: {e}"),
        });
    let [summary, impacts] = ["summary.json", "impacts.csv"].map(|f| read_text(&dir.join(f)));
    let (summary, history, impacts) = (summary?, history?, impacts?);
    parse_results(dir, &summary, std::io::BufReader::new(history), &impacts)
}

/// Parses the three files of a results folder, history.csv from a reader, read twice: once to
/// check every row, once to keep the rows drawn (every row of a history of at most
/// [`decimate::ROWS_KEPT_WHOLE`], else those of [`decimate::Decimator`]). `dir` names the files in
/// messages.
pub fn parse_results(
    dir: &Path,
    summary_text: &str,
    history: impl std::io::BufRead + std::io::Seek,
    impacts_text: &str,
) -> Result<Results, PlotError> {
    let summary_file = dir.join("summary.json");
    let summary: Value = serde_json::from_str(summary_text).map_err(|e| PlotError::Read {
        file: summary_file.clone(),
        message: format!("not valid JSON: {e}"),
    })?;
    let coordinates: Vec<String> = summary["coordinates"]
        .as_array()
        .ok_or_else(|| PlotError::Read {
            file: summary_file.clone(),
            message: "no `coordinates` list".into(),
        })?
        .iter()
        .filter_map(|c| c["name"].as_str().map(str::to_string))
        .collect();
    let model_name = summary["model"]["name"]
        .as_str()
        .unwrap_or("model")
        .to_string();

    let history_file = dir.join("history.csv");
    let bad = |message: String| PlotError::Read {
        file: history_file.clone(),
        message,
    };
    let mut lines = TextLines::new(history);
    let header: Vec<String> = lines
        .next_line()
        .map_err(&bad)?
        .ok_or_else(|| bad("empty file".into()))?
        .text
        .split(',')
        .map(str::to_string)
        .collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| bad(format!("no column `{name}`")))
    };
    let t_col = column("t")?;
    let q_cols = coordinates
        .iter()
        .map(|c| column(c))
        .collect::<Result<Vec<_>, _>>()?;
    let rate_cols = coordinates
        .iter()
        .map(|c| column(&format!("{c}_rate")))
        .collect::<Result<Vec<_>, _>>()?;
    let energy_cols = ["kinetic", "potential", "work_in", "dissipated"]
        .iter()
        .map(|c| column(c))
        .collect::<Result<Vec<_>, _>>()?;
    let n = coordinates.len();
    let mut r = Results {
        model_name,
        coordinates,
        t: Vec::new(),
        q: vec![Vec::new(); n],
        qdot: vec![Vec::new(); n],
        kinetic: Vec::new(),
        potential: Vec::new(),
        work_in: Vec::new(),
        dissipated: Vec::new(),
        impacts: Vec::new(),
        free_rocking: free_rocking(&summary),
        levels: None,
        violation: crate::output::results_folder::violation_time(&summary).map(|t| {
            let v = &summary["hypothesis_violation"];
            let (kind, at) = (
                v["kind"].as_str().unwrap_or("violation"),
                v["interface"].as_str().unwrap_or("?"),
            );
            (t, format!("{kind} at {at}"))
        }),
    };
    if r.free_rocking.is_none() {
        r.levels = mechanism_levels_of(&summary);
    }
    // The numbers of a row in the order [t, q…, q̇…, T, U, W, D].
    let columns: Vec<usize> = std::iter::once(t_col)
        .chain(q_cols.iter().copied())
        .chain(rate_cols.iter().copied())
        .chain(energy_cols.iter().copied())
        .collect();
    let parse_row = |line: &str, line_no: usize| -> Result<Vec<f64>, PlotError> {
        let fields: Vec<&str> = line.split(',').collect();
        columns
            .iter()
            .map(|&c| {
                fields
                    .get(c)
                    .and_then(|f| f.trim().parse::<f64>().ok())
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        bad(format!(
                            "line {line_no}: column `{}` is not a finite number",
                            header[c]
                        ))
                    })
            })
            .collect()
    };
    // First pass: every row checked, its count and time span kept.
    let mut rows = 0usize;
    let mut span = (0.0, 0.0);
    while let Some(line) = lines.next_line().map_err(&bad)? {
        if line.text.trim().is_empty() {
            continue;
        }
        let line_no = line.number;
        let t = parse_row(line.text, line_no)?[0];
        if rows > 0 && t < span.1 {
            return Err(bad(format!("line {line_no}: time {t} goes backwards")));
        }
        if rows == 0 {
            span.0 = t;
        }
        span.1 = t;
        rows += 1;
    }
    if rows == 0 {
        return Err(bad("no data rows after the header".into()));
    }
    // Second pass: the rows drawn, every one or those a figure's width can show.
    let mut reader = lines.into_inner();
    reader
        .seek(std::io::SeekFrom::Start(0))
        .map_err(|e| bad(format!("cannot read the file again: {e}")))?;
    let mut lines = TextLines::new(reader);
    lines.next_line().map_err(&bad)?;
    let mut kept = Vec::with_capacity(rows.min(decimate::ROWS_KEPT_WHOLE));
    let mut decimator =
        (rows > decimate::ROWS_KEPT_WHOLE).then(|| decimate::Decimator::new(span.0, span.1));
    let mut index = 0;
    while let Some(line) = lines.next_line().map_err(&bad)? {
        if line.text.trim().is_empty() {
            continue;
        }
        let mut row = parse_row(line.text, line.number)?;
        match decimator.as_mut() {
            Some(d) => {
                // The energy balance T + U − W + D is drawn too: its envelope is kept as well.
                let e = row[1 + 2 * n] + row[2 + 2 * n] - row[3 + 2 * n] + row[4 + 2 * n];
                row.push(e);
                d.push(index, row)
            }
            None => kept.push(row),
        }
        index += 1;
    }
    if let Some(d) = decimator {
        kept = d.finish();
    }
    for row in kept {
        r.t.push(row[0]);
        for k in 0..n {
            r.q[k].push(row[1 + k]);
            r.qdot[k].push(row[1 + n + k]);
        }
        r.kinetic.push(row[1 + 2 * n]);
        r.potential.push(row[2 + 2 * n]);
        r.work_in.push(row[3 + 2 * n]);
        r.dissipated.push(row[4 + 2 * n]);
    }

    let impacts_file = dir.join("impacts.csv");
    let text = impacts_text;
    for (row, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let mut fields = line.split(',');
        let t = fields
            .next()
            .and_then(|f| f.trim().parse::<f64>().ok())
            .ok_or_else(|| PlotError::Read {
                file: impacts_file.clone(),
                message: format!("line {}: `t` is not a number", row + 1),
            })?;
        let interfaces = fields
            .next()
            .unwrap_or("")
            .split(';')
            .filter(|s| !s.is_empty())
            .map(str::to_string)
            .collect();
        r.impacts.push((t, interfaces));
    }
    Ok(r)
}

// ---------------------------------------------------------------------------------------------
// Drawing helpers.

/// Colours of the series, distinguishable on a screen and in grey print.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
];

fn colour(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

/// A range covering the values with 5% padding on each side (never empty).
fn padded(values: impl IntoIterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return -1.0..1.0;
    }
    let span = hi - lo;
    let pad = if span > 1e-12 * (lo.abs().max(hi.abs()).max(1e-300)) {
        0.05 * span
    } else {
        // Constant values: a window around them.
        0.5 * lo.abs().max(1e-12)
    };
    (lo - pad)..(hi + pad)
}

/// The range with its top raised by `fraction` of its span: room for the legend.
fn headroom(r: std::ops::Range<f64>, fraction: f64) -> std::ops::Range<f64> {
    r.start..r.end + fraction * (r.end - r.start)
}

/// Tick label text: fixed-point with as many decimals as the tick spacing needs, scientific
/// notation for very small or large numbers.
fn tick(v: f64, range: &std::ops::Range<f64>) -> String {
    let span = (range.end - range.start).abs();
    let big = range.start.abs().max(range.end.abs());
    if v.abs() <= 1e-9 * span {
        return "0".into();
    }
    if span < 1e-3 || big >= 1e5 {
        return format!("{v:.2e}");
    }
    let decimals = (-(span / 8.0).log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// What a drawing function returns: the backend's error as text.
pub type DrawResult = Result<(), String>;

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

fn caption_style(k: u32) -> TextStyle<'static> {
    (FONT, 26 * k).into_font().style(FontStyle::Bold).into()
}

/// The charts: f64 on both axes.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Axis and mesh styles shared by every chart.
fn configure<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    k: u32,
    x_desc: &str,
    y_desc: &str,
    x_fmt: &dyn Fn(&f64) -> String,
    y_fmt: &dyn Fn(&f64) -> String,
) -> DrawResult {
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FONT, 17 * k))
        .axis_desc_style((FONT, 20 * k))
        .light_line_style(RGBColor(238, 238, 238).stroke_width(k))
        .bold_line_style(RGBColor(205, 205, 205).stroke_width(k))
        .axis_style(BLACK.stroke_width(k))
        .set_all_tick_mark_size(5 * k as i32)
        .x_label_offset(0)
        .x_labels(10)
        .y_labels(9)
        .x_label_formatter(x_fmt)
        .y_label_formatter(y_fmt)
        .draw()
        .map_err(err)
}

fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    k: u32,
    position: SeriesLabelPosition,
) -> DrawResult {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(150, 150, 150).stroke_width(k))
        .label_font((FONT, 17 * k))
        .margin(12 * k)
        .legend_area_size(34 * k)
        .draw()
        .map_err(err)
}

fn line_key(c: RGBColor, k: u32) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    let w = 24 * k as i32;
    move |(x, y)| PathElement::new(vec![(x, y), (x + w, y)], c.stroke_width(3 * k))
}

/// Line width of coordinate `i` of `n`: the first ones are drawn wider, so that coordinates
/// moving together (a symmetric mechanism) stay visible under the later ones.
fn coordinate_width(i: usize, n: usize, k: u32) -> u32 {
    let rank = (n - 1 - i).min(3) as u32;
    (4 + 3 * rank) * k / 2
}

/// The value of a sampled series at time `t` (the last sample at or before `t`).
fn at_time(t: &[f64], v: &[f64], time: f64) -> f64 {
    let i = t.partition_point(|x| *x <= time);
    v[i.saturating_sub(1).min(v.len().saturating_sub(1))]
}

// ---------------------------------------------------------------------------------------------
// The four plots.

/// (a) The coordinate time histories, impacts marked.
pub fn draw_coordinates<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    r: &Results,
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let xr = padded(r.t.iter().copied());
    let xr = 0f64.min(xr.start)..r.t.last().copied().unwrap_or(1.0).max(1e-9);
    let yr = headroom(
        padded(r.q.iter().flatten().copied().chain([0.0])),
        0.06 * (r.coordinates.len() + 1 + usize::from(r.violation.is_some())) as f64,
    );
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!("{}: coordinate time histories", r.model_name),
            caption_style(k),
        )
        .margin(20 * k)
        .x_label_area_size(55 * k)
        .y_label_area_size(95 * k)
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(err)?;
    configure(
        &mut chart,
        k,
        "time t (s)",
        "angle (rad)",
        &|v| tick(*v, &xr),
        &|v| tick(*v, &yr),
    )?;
    shade_outside_model(&mut chart, r, &xr, &yr, k)?;
    let n = r.coordinates.len();
    for (i, name) in r.coordinates.iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(
                r.t.iter().copied().zip(r.q[i].iter().copied()),
                c.stroke_width(coordinate_width(i, n, k)),
            ))
            .map_err(err)?
            .label(format!("{name} (rad)"))
            .legend(line_key(c, k));
    }
    if !r.impacts.is_empty() {
        let mut marks = Vec::new();
        for (t, ifaces) in &r.impacts {
            let mut any = false;
            for (j, name) in r.coordinates.iter().enumerate() {
                let hit = ifaces.iter().any(|i| {
                    name == i
                        || name
                            .strip_prefix(i.as_str())
                            .is_some_and(|s| s.starts_with('.'))
                });
                if hit {
                    marks.push((*t, at_time(&r.t, &r.q[j], *t)));
                    any = true;
                }
            }
            if !any {
                marks.push((*t, 0.0));
            }
        }
        chart
            .draw_series(
                marks
                    .into_iter()
                    .map(|p| Circle::new(p, 5 * k, BLACK.stroke_width(2 * k))),
            )
            .map_err(err)?
            .label(format!("impact ({})", r.impacts.len()))
            .legend(|(x, y)| Circle::new((x + 12 * k as i32, y), 5 * k, BLACK.stroke_width(2 * k)));
    }
    legend(&mut chart, k, SeriesLabelPosition::UpperRight)
}

/// The grey of the time after a run's first hypotheses violation.
const OUTSIDE_MODEL: RGBColor = RGBColor(150, 150, 150);

/// Shades the time after the run's first hypotheses violation ([`Results::violation`]), with a
/// legend entry naming it: what the figure shows there is outside crr's model.
fn shade_outside_model<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    r: &Results,
    xr: &std::ops::Range<f64>,
    yr: &std::ops::Range<f64>,
    k: u32,
) -> DrawResult {
    let Some((t, what)) = &r.violation else {
        return Ok(());
    };
    // (A violation at the last sample shades nothing but is still named.)
    let from = t.clamp(xr.start, xr.end);
    let fill = OUTSIDE_MODEL.mix(0.25).filled();
    let w = 10 * k as i32;
    chart
        .draw_series(std::iter::once(Rectangle::new(
            [(from, yr.start), (xr.end, yr.end)],
            fill,
        )))
        .map_err(err)?
        .label(format!("outside crr's model from t = {t:.4} s ({what})"))
        .legend(move |(x, y): (i32, i32)| {
            Rectangle::new([(x, y - w / 2), (x + 2 * w, y + w / 2)], fill)
        });
    Ok(())
}

/// (b) The energy balance: T, U, W, D on the upper panel, T + U − W + D − E(0) on the lower one.
pub fn draw_energy<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    r: &Results,
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let (upper, lower) = root.split_vertically(SIZE.1 * k * 62 / 100);
    let xr = 0f64..r.t.last().copied().unwrap_or(1.0).max(1e-9);
    let series: [(&str, &Vec<f64>); 4] = [
        ("kinetic T", &r.kinetic),
        ("potential U", &r.potential),
        ("work in W", &r.work_in),
        ("dissipated D", &r.dissipated),
    ];
    let yr = headroom(
        padded(
            series
                .iter()
                .flat_map(|(_, v)| v.iter().copied())
                .chain([0.0]),
        ),
        if r.violation.is_some() { 0.45 } else { 0.35 },
    );
    let mut chart = ChartBuilder::on(&upper)
        .caption(
            format!("{}: energy balance", r.model_name),
            caption_style(k),
        )
        .margin(20 * k)
        .margin_bottom(5 * k)
        .x_label_area_size(45 * k)
        .y_label_area_size(95 * k)
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(err)?;
    configure(
        &mut chart,
        k,
        "time t (s)",
        "energy (J)",
        &|v| tick(*v, &xr),
        &|v| tick(*v, &yr),
    )?;
    shade_outside_model(&mut chart, r, &xr, &yr, k)?;
    for (i, (name, v)) in series.iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(
                r.t.iter().copied().zip(v.iter().copied()),
                c.stroke_width(2 * k),
            ))
            .map_err(err)?
            .label(format!("{name} (J)"))
            .legend(line_key(c, k));
    }
    legend(&mut chart, k, SeriesLabelPosition::UpperRight)?;

    let e0 = match (
        r.kinetic.first(),
        r.potential.first(),
        r.work_in.first(),
        r.dissipated.first(),
    ) {
        (Some(t), Some(u), Some(w), Some(d)) => t + u - w + d,
        _ => 0.0,
    };
    let balance: Vec<(f64, f64)> = (0..r.t.len())
        .map(|i| {
            (
                r.t[i],
                r.kinetic[i] + r.potential[i] - r.work_in[i] + r.dissipated[i] - e0,
            )
        })
        .collect();
    let big = balance.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
    let lim = if big > 0.0 { 1.15 * big } else { 1e-12 };
    let yr = -lim..lim;
    let mut chart = ChartBuilder::on(&lower)
        .margin(20 * k)
        .margin_top(5 * k)
        .x_label_area_size(55 * k)
        .y_label_area_size(95 * k)
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(err)?;
    configure(
        &mut chart,
        k,
        "time t (s)",
        "balance error (J)",
        &|v| tick(*v, &xr),
        &|v| {
            if v.abs() <= 1e-9 * lim {
                "0".into()
            } else {
                format!("{v:.1e}")
            }
        },
    )?;
    shade_outside_model(&mut chart, r, &xr, &yr, k)?;
    let c = RGBColor(0, 0, 0);
    chart
        .draw_series(LineSeries::new(balance, c.stroke_width(2 * k)))
        .map_err(err)?
        .label("T + U − W + D − E(0) (J)")
        .legend(line_key(c, k));
    legend(&mut chart, k, SeriesLabelPosition::UpperRight)
}

/// The amplitudes θ_m/α of the free-rocking energy levels drawn on the phase portrait.
pub const LEVELS: [f64; 4] = [0.25, 0.5, 0.75, 1.0];

/// (c) The phase portraits θ̇ versus θ, with the free-rocking energy levels of a single block, or
/// the engine's energy levels of the first coordinate for any other one-DOF mechanism.
pub fn draw_phase<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    r: &Results,
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    // Energy level curves: the upper half from −θ_m to θ_m, then the lower half back.
    let levels: Vec<Vec<(f64, f64)>> = match r.free_rocking {
        Some(f) => LEVELS
            .iter()
            .map(|ratio| {
                let m = ratio * f.alpha;
                let n = 400;
                let upper = (0..=n).map(|i| {
                    let x = -m + 2.0 * m * i as f64 / n as f64;
                    (x, f.rate(m, x))
                });
                let lower = (0..=n).map(|i| {
                    let x = m - 2.0 * m * i as f64 / n as f64;
                    (x, -f.rate(m, x))
                });
                upper.chain(lower).collect()
            })
            .collect(),
        None => Vec::new(),
    };
    let mech: Vec<(f64, f64)> = r
        .levels
        .as_ref()
        .map(figures::level_points)
        .unwrap_or_default();
    let xr = padded(
        r.q.iter()
            .flatten()
            .copied()
            .chain(levels.iter().flatten().map(|p| p.0))
            .chain(mech.iter().map(|p| p.0)),
    );
    let yr = headroom(
        padded(
            r.qdot
                .iter()
                .flatten()
                .copied()
                .chain(levels.iter().flatten().map(|p| p.1))
                .chain(mech.iter().map(|p| p.1)),
        ),
        0.1 * (r.coordinates.len()
            + 2 * usize::from(r.free_rocking.is_some() || r.levels.is_some())) as f64,
    );
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!("{}: phase portrait", r.model_name),
            caption_style(k),
        )
        .margin(20 * k)
        .x_label_area_size(55 * k)
        .y_label_area_size(95 * k)
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(err)?;
    configure(
        &mut chart,
        k,
        "angle θ (rad)",
        "rate dθ/dt (rad/s)",
        &|v| tick(*v, &xr),
        &|v| tick(*v, &yr),
    )?;
    if let Some(f) = r.free_rocking {
        let grey = RGBColor(120, 120, 120);
        for (i, curve) in levels.into_iter().enumerate() {
            let s = chart
                .draw_series(DashedLineSeries::new(
                    curve,
                    8 * k,
                    5 * k,
                    grey.stroke_width(k),
                ))
                .map_err(err)?;
            if i == 0 {
                s.label(format!(
                    "free rocking, θm/α = {} (α = {:.4} rad, p = {:.4} rad/s)",
                    LEVELS.map(|x| x.to_string()).join(", "),
                    f.alpha,
                    f.p
                ))
                .legend(move |(x, y)| {
                    PathElement::new(
                        vec![(x, y), (x + 24 * k as i32, y)],
                        grey.stroke_width(2 * k),
                    )
                });
            }
        }
    }
    if let Some(l) = &r.levels {
        figures::draw_level_curves(&mut chart, l, k)?;
    }
    let n = r.coordinates.len();
    for (i, name) in r.coordinates.iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(
                r.q[i].iter().copied().zip(r.qdot[i].iter().copied()),
                c.stroke_width(coordinate_width(i, n, k)),
            ))
            .map_err(err)?
            .label(name.clone())
            .legend(line_key(c, k));
    }
    legend(&mut chart, k, SeriesLabelPosition::UpperRight)
}

/// (d) The generalized Housner frequency versus amplitude (paper eq 6 and Fig. 10) against the
/// engine's free rocking, from the report of `crr check`. Err when the model is not a one-DOF
/// mechanism.
pub fn draw_housner<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    report: &CheckReport,
    k: u32,
) -> DrawResult {
    let m = report.mechanism.as_ref().ok_or_else(|| {
        format!(
            "no frequency plot: {}",
            report
                .note
                .as_deref()
                .unwrap_or("the model is not a one-DOF mechanism")
        )
    })?;
    root.fill(&WHITE).map_err(err)?;
    let n = 300;
    let curve: Vec<(f64, f64)> = (0..=n)
        .map(|i| {
            let ratio = 0.05 + 0.93 * i as f64 / n as f64;
            (
                ratio,
                housner_frequency(m.p_eq, m.alpha_eq, ratio * m.alpha_eq),
            )
        })
        .collect();
    let points: Vec<(f64, f64)> = m
        .frequencies
        .iter()
        .filter_map(|f| f.engine_hz.map(|e| (f.amplitude_ratio, e)))
        .collect();
    let xr = 0f64..1f64;
    let yr = 0f64..padded(curve.iter().chain(&points).map(|p| p.1)).end;
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!("{}: free-rocking frequency versus amplitude", report.model),
            caption_style(k),
        )
        .margin(20 * k)
        .x_label_area_size(55 * k)
        .y_label_area_size(95 * k)
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(err)?;
    configure(
        &mut chart,
        k,
        &format!("amplitude θm/α_eq (–), α_eq = {:.4} rad", m.alpha_eq),
        "frequency (Hz)",
        &|v| tick(*v, &xr),
        &|v| tick(*v, &yr),
    )?;
    let c = colour(0);
    chart
        .draw_series(LineSeries::new(curve, c.stroke_width(2 * k)))
        .map_err(err)?
        .label(format!(
            "Housner F_H = p/(4 arccosh(1/(1 − θm/α))), eq 6, p = {:.4} rad/s",
            m.p_eq
        ))
        .legend(line_key(c, k));
    let e = colour(1);
    chart
        .draw_series(
            points
                .into_iter()
                .map(|p| Circle::new(p, 6 * k, e.filled())),
        )
        .map_err(err)?
        .label(format!("engine 1/(4τ), free rocking of {}", m.coordinate))
        .legend(move |(x, y)| Circle::new((x + 12 * k as i32, y), 6 * k, e.filled()));
    legend(&mut chart, k, SeriesLabelPosition::UpperRight)
}

/// Supersampling factor of the PNG images: drawn at this scale, then averaged down, so that the
/// lines and the text are anti-aliased.
const SUPERSAMPLE: u32 = 3;

/// Averages `k` × `k` blocks of an RGB image of `w k` × `h k` pixels.
fn downsample(big: &[u8], w: u32, h: u32, k: u32) -> Vec<u8> {
    let (w, h, k) = (w as usize, h as usize, k as usize);
    let mut small = vec![0u8; w * h * 3];
    let area = (k * k) as u32;
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let mut sum = 0u32;
                for dy in 0..k {
                    let row = (y * k + dy) * w * k;
                    for dx in 0..k {
                        sum += big[(row + x * k + dx) * 3 + c] as u32;
                    }
                }
                small[(y * w + x) * 3 + c] = ((sum + area / 2) / area) as u8;
            }
        }
    }
    small
}

/// Writes one PNG: drawn at `SUPERSAMPLE` times [`SIZE`] in memory, averaged down, encoded.
pub fn write_png(
    file: &Path,
    draw: impl Fn(&DrawingArea<BitMapBackend<'_>, Shift>, u32) -> DrawResult,
) -> Result<(), PlotError> {
    let fail = |message: String| PlotError::Draw {
        file: file.to_path_buf(),
        message,
    };
    let (w, h, k) = (SIZE.0, SIZE.1, SUPERSAMPLE);
    let mut big = vec![255u8; (w * k * h * k * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut big, (w * k, h * k)).into_drawing_area();
        draw(&root, k).map_err(fail)?;
        root.present().map_err(|e| fail(e.to_string()))?;
    }
    let small = downsample(&big, w, h, k);
    // Through a temporary file renamed over `file` (a FIFO there would block the writer).
    replace_file_with(
        file,
        |tmp| {
            let mut out = BitMapBackend::new(tmp, SIZE);
            out.blit_bitmap((0, 0), SIZE, &small)
                .map_err(|e| fail(e.to_string()))?;
            out.present().map_err(|e| fail(e.to_string()))
        },
        |e| fail(format!("cannot write the file: {e}")),
    )
}

/// Writes one SVG of [`SIZE`].
pub fn write_svg(
    file: &Path,
    draw: impl Fn(&DrawingArea<SVGBackend<'_>, Shift>, u32) -> DrawResult,
) -> Result<(), PlotError> {
    let fail = |message: String| PlotError::Draw {
        file: file.to_path_buf(),
        message,
    };
    replace_file_with(
        file,
        |tmp| {
            let root = SVGBackend::new(tmp, SIZE).into_drawing_area();
            draw(&root, 1).map_err(fail)?;
            root.present().map_err(|e| fail(e.to_string()))
        },
        |e| fail(format!("cannot write the file: {e}")),
    )
}

/// Draws one plot into `DIR/STEM.png` and `DIR/STEM.svg`; evaluates to the two paths.
macro_rules! both {
    ($dir:expr, $stem:expr, $draw:ident, $data:expr) => {{
        let png = $dir.join(concat!($stem, ".png"));
        let svg = $dir.join(concat!($stem, ".svg"));
        write_png(&png, |root, k| $draw(root, $data, k))?;
        write_svg(&svg, |root, k| $draw(root, $data, k))?;
        [png, svg]
    }};
}

/// `crr plot DIR`: reads the results in `dir` and writes `coordinates`, `energy` and `phase`
/// (`.png` and `.svg`) there. Returns the files written.
pub fn plot_results(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    register_fonts();
    let r = read_results(dir)?;
    let mut files = Vec::new();
    files.extend(both!(dir, "coordinates", draw_coordinates, &r));
    files.extend(both!(dir, "energy", draw_energy, &r));
    files.extend(both!(dir, "phase", draw_phase, &r));
    Ok(files)
}

/// `crr check MODEL --plot DIR`: writes `housner.png` and `housner.svg` into `dir` (created).
pub fn plot_check(dir: &Path, report: &CheckReport) -> Result<Vec<PathBuf>, PlotError> {
    if report.mechanism.is_none() {
        return Err(PlotError::NoMechanism(
            report
                .note
                .clone()
                .unwrap_or_else(|| "the model is not a one-DOF mechanism".into()),
        ));
    }
    register_fonts();
    std::fs::create_dir_all(dir).map_err(|e| PlotError::Draw {
        file: dir.to_path_buf(),
        message: format!("cannot create the folder: {e}"),
    })?;
    Ok(both!(dir, "housner", draw_housner, report).to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The free-rocking level has zero rate at ±θ_m and its maximum 2p²[1 − cos θ_m]… at θ = 0:
    /// θ̇² = 2p²[cos(α − θ_m) − cos α].
    #[test]
    fn free_rocking_level_turning_points_and_peak() {
        let f = FreeRocking { p: 2.0, alpha: 0.2 };
        let m = 0.1;
        assert!(f.rate(m, m).abs() < 1e-12);
        assert!(f.rate(m, -m).abs() < 1e-12);
        let peak = (2.0 * 4.0 * ((0.2f64 - 0.1).cos() - 0.2f64.cos())).sqrt();
        assert!((f.rate(m, 0.0) - peak).abs() < 1e-12 * peak);
        // Outside the level there is no motion.
        assert_eq!(f.rate(m, 0.15), 0.0);
    }

    #[test]
    fn padded_range_is_never_empty() {
        let r = padded([1.0, 1.0]);
        assert!(r.start < 1.0 && r.end > 1.0);
        let r = padded(std::iter::empty());
        assert!(r.start < r.end);
        let r = padded([0.0, 10.0]);
        assert!((r.start + 0.5).abs() < 1e-12 && (r.end - 10.5).abs() < 1e-12);
    }
}
