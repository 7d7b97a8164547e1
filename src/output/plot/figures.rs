//! The figures added for issue 12: the energy levels of a one-DOF mechanism (`levels`), the
//! free-rocking frequency of several models against amplitude on one figure (`housner`), and the
//! frequency against size of `--size-sweep` (`size_sweep`). Documented in `docs/outputs.md`.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{
    Chart, DrawResult, PlotError, caption_style, colour, configure, err, headroom, legend,
    line_key, padded, register_fonts, tick, write_png, write_svg,
};
use crate::analysis::check::{CheckReport, housner_frequency};
use crate::analysis::levels::MechanismLevels;
use crate::analysis::size_sweep::SizeSweep;

/// Grey shades of the levels below the separatrix, lightest for the lowest energy.
fn level_colour(i: usize, n: usize) -> RGBColor {
    let t = if n > 1 {
        i as f64 / (n - 1) as f64
    } else {
        0.0
    };
    let v = (170.0 - 90.0 * t) as u8;
    RGBColor(v, v, v.saturating_add(40))
}

/// Draws the energy levels of `levels` on a chart: grey dashed levels, the separatrix solid black.
pub(super) fn draw_level_curves<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    levels: &MechanismLevels,
    k: u32,
) -> DrawResult {
    let drawn = levels.drawn();
    let n_below = drawn.iter().filter(|d| !d.1).count();
    for (i, (e, sep)) in drawn.iter().enumerate() {
        let curve = levels.curve(*e);
        if curve.is_empty() {
            continue;
        }
        if *sep {
            chart
                .draw_series(LineSeries::new(curve, BLACK.stroke_width(2 * k)))
                .map_err(err)?
                .label(format!(
                    "separatrix of {}, E = {e:.4e} J (overturning)",
                    levels.coordinate
                ))
                .legend(line_key(BLACK, k));
        } else {
            let c = level_colour(i, n_below);
            let s = chart
                .draw_series(DashedLineSeries::new(
                    curve,
                    8 * k,
                    5 * k,
                    c.stroke_width(k),
                ))
                .map_err(err)?;
            if i == 0 {
                s.label(format!(
                    "levels of {}, E = {} J",
                    levels.coordinate,
                    drawn
                        .iter()
                        .filter(|d| !d.1)
                        .map(|d| format!("{:.3e}", d.0))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
                .legend(line_key(c, k));
            }
        }
    }
    Ok(())
}

/// The (θ, θ̇) points of every drawn level (for the axis ranges).
pub(super) fn level_points(levels: &MechanismLevels) -> Vec<(f64, f64)> {
    levels
        .drawn()
        .iter()
        .flat_map(|(e, _)| levels.curve(*e))
        .collect()
}

/// The energy levels of a one-DOF mechanism in its phase plane (θ, θ̇).
pub fn draw_levels<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    data: &(String, MechanismLevels),
    k: u32,
) -> DrawResult {
    let (name, levels) = data;
    root.fill(&WHITE).map_err(err)?;
    let pts = level_points(levels);
    let ends = [levels.negative.last(), levels.positive.last()];
    let xr = padded(pts.iter().map(|p| p.0).chain(ends.iter().map(|s| s.theta)));
    let yr = headroom(padded(pts.iter().map(|p| p.1)), 0.3);
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "{name}: energy levels of {} (engine M, U)",
                levels.coordinate
            ),
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
        &format!("mechanism angle θ = {} (rad)", levels.coordinate),
        "rate dθ/dt (rad/s)",
        &|v| tick(*v, &xr),
        &|v| tick(*v, &yr),
    )?;
    draw_level_curves(&mut chart, levels, k)?;
    let red = colour(1);
    chart
        .draw_series(
            ends.iter()
                .map(|s| Circle::new((s.theta, 0.0), 6 * k, red.filled())),
        )
        .map_err(err)?
        .label(format!(
            "ends: θ = {:.4} / {:.4} rad",
            ends[0].theta, ends[1].theta
        ))
        .legend(move |(x, y)| Circle::new((x + 12 * k as i32, y), 6 * k, red.filled()));
    legend(&mut chart, k, SeriesLabelPosition::UpperRight)
}

/// F_H against θm/α_eq of several models on one figure: each model's eq-6 curve and its engine
/// points in one colour.
pub fn draw_housner_models<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    reports: &[CheckReport],
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let n = 300;
    let mut series = Vec::new();
    for r in reports {
        let Some(m) = &r.mechanism else { continue };
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
        series.push((r.model.clone(), m.alpha_eq, m.p_eq, curve, points));
    }
    let xr = 0f64..1f64;
    let yr = 0f64..headroom(
        padded(
            series
                .iter()
                .flat_map(|s| s.3.iter().chain(&s.4).map(|p| p.1)),
        ),
        0.1 * series.len() as f64,
    )
    .end;
    let mut chart = ChartBuilder::on(root)
        .caption("free-rocking frequency versus amplitude", caption_style(k))
        .margin(20 * k)
        .x_label_area_size(55 * k)
        .y_label_area_size(95 * k)
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(err)?;
    configure(
        &mut chart,
        k,
        "amplitude θm/α_eq (–)",
        "frequency (Hz)",
        &|v| tick(*v, &xr),
        &|v| tick(*v, &yr),
    )?;
    for (i, (name, alpha, p, curve, points)) in series.into_iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(curve, c.stroke_width(2 * k)))
            .map_err(err)?
            .label(format!(
                "{name}: F_H eq 6 (α_eq = {alpha:.4} rad, p_eq = {p:.4} rad/s); points: engine"
            ))
            .legend(line_key(c, k));
        chart
            .draw_series(
                points
                    .into_iter()
                    .map(|q| Circle::new(q, 6 * k, c.filled())),
            )
            .map_err(err)?;
    }
    legend(&mut chart, k, SeriesLabelPosition::UpperRight)
}

/// F_H (eq 6) and the engine's frequency against the scale factor, one colour per model.
pub fn draw_size_sweep<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    sweeps: &[SizeSweep],
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let all = sweeps.iter().flat_map(|s| s.rows.iter());
    // Against the structure's height (the paper's Fig. 10) when every row has one, else s.
    let by_height = all.clone().all(|r| r.height.is_some());
    let x = move |r: &crate::analysis::size_sweep::SizeRow| {
        if by_height {
            r.height.unwrap_or(r.scale)
        } else {
            r.scale
        }
    };
    let xr = padded(all.clone().map(x));
    let xr = 0f64.min(xr.start)..xr.end;
    let yr = 0f64..headroom(
        padded(
            all.flat_map(|r| [Some(r.housner_hz), r.engine_hz])
                .flatten(),
        ),
        0.1 * sweeps.len() as f64,
    )
    .end;
    let ratio = sweeps.first().map_or(0.5, |s| s.amplitude_ratio);
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!("free-rocking frequency versus size (θm/α_eq = {ratio})"),
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
        if by_height {
            "height of the structure H (m), every length × s"
        } else {
            "scale factor s (every length × s)"
        },
        "frequency (Hz)",
        &|v| tick(*v, &xr),
        &|v| tick(*v, &yr),
    )?;
    for (i, sw) in sweeps.iter().enumerate() {
        let c = colour(i);
        chart
            .draw_series(LineSeries::new(
                sw.rows.iter().map(|r| (x(r), r.housner_hz)),
                c.stroke_width(2 * k),
            ))
            .map_err(err)?
            .label(format!("{}: F_H eq 6; points: engine 1/(4τ)", sw.model))
            .legend(line_key(c, k));
        chart
            .draw_series(
                sw.rows
                    .iter()
                    .filter_map(|r| r.engine_hz.map(|e| (x(r), e)))
                    .map(|q| Circle::new(q, 6 * k, c.filled())),
            )
            .map_err(err)?;
    }
    legend(&mut chart, k, SeriesLabelPosition::UpperRight)
}

/// Creates `dir` and registers the fonts before drawing into it.
fn prepare(dir: &Path) -> Result<(), PlotError> {
    register_fonts();
    std::fs::create_dir_all(dir).map_err(|e| PlotError::Draw {
        file: dir.to_path_buf(),
        message: format!("cannot create the folder: {e}"),
    })
}

/// Draws one plot into `DIR/STEM.png` and `DIR/STEM.svg` (`STEM` a String); evaluates to the two
/// paths.
macro_rules! both_named {
    ($dir:expr, $stem:expr, $draw:ident, $data:expr) => {{
        prepare($dir)?;
        let png = $dir.join(format!("{}.png", $stem));
        let svg = $dir.join(format!("{}.svg", $stem));
        write_png(&png, |root, k| $draw(root, $data, k))?;
        write_svg(&svg, |root, k| $draw(root, $data, k))?;
        vec![png, svg]
    }};
}

/// Writes `PREFIXlevels.png`, `.svg` and `PREFIXlevels.csv` (θ, U, dU/dθ, M) into `dir`.
pub fn plot_levels(
    dir: &Path,
    prefix: &str,
    model_name: &str,
    levels: &MechanismLevels,
) -> Result<Vec<PathBuf>, PlotError> {
    let data = (model_name.to_string(), levels.clone());
    let mut files: Vec<PathBuf> = both_named!(dir, &format!("{prefix}levels"), draw_levels, &data);
    let csv = dir.join(format!("{prefix}levels.csv"));
    crate::output::replace_file::replace_file(&csv, levels.to_csv()).map_err(|e| {
        PlotError::Draw {
            file: csv.clone(),
            message: format!("cannot write the file: {e}"),
        }
    })?;
    files.push(csv);
    Ok(files)
}

/// Writes `housner.png` and `.svg` with the curves of several models into `dir`.
pub fn plot_housner_models(dir: &Path, reports: &[CheckReport]) -> Result<Vec<PathBuf>, PlotError> {
    if let Some(r) = reports.iter().find(|r| r.mechanism.is_none()) {
        return Err(PlotError::NoMechanism(format!(
            "{}: {}",
            r.model,
            r.note.as_deref().unwrap_or("not a one-DOF mechanism")
        )));
    }
    Ok(both_named!(dir, "housner", draw_housner_models, reports))
}

/// Writes `size_sweep.png` and `.svg` into `dir`.
pub fn plot_size_sweep(dir: &Path, sweeps: &[SizeSweep]) -> Result<Vec<PathBuf>, PlotError> {
    Ok(both_named!(dir, "size_sweep", draw_size_sweep, sweeps))
}
