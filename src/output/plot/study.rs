//! The figures of a study folder (`crr plot STUDY_DIR`, `crr study … --plot`): the overturning
//! map of a pulse study, the rocking spectra of a study with a size axis, and the fragility curves
//! of a records study (with `fragility.csv`). Documented in `docs/studies.md`.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{
    DrawResult, PlotError, caption_style, colour, configure, err, headroom, legend, line_key,
    padded, register_fonts, tick, write_png, write_svg,
};
use crate::analysis::study::fragility::normal_cdf;
use crate::output::study::folder::BOUNDARY_FILE;
use crate::output::study::products::{FragilityCurve, StudyResults, fragility_csv};

/// Colour of a survivor's peak θ/α (0 pale yellow … 1 and above dark red).
fn ratio_colour(r: f64) -> RGBColor {
    let t = r.clamp(0.0, 1.0);
    let mix = |a: f64, b: f64| (a + (b - a) * t) as u8;
    RGBColor(mix(255.0, 170.0), mix(235.0, 20.0), mix(160.0, 30.0))
}

/// Colour of the collapsed cells.
const COLLAPSE: RGBColor = RGBColor(35, 35, 35);

/// Half the smallest gap between sorted distinct values (the half-width of a map cell).
fn half_gap(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.dedup();
    let gap = v
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    if gap.is_finite() {
        0.5 * gap
    } else {
        0.05 * v.first().map_or(1.0, |x| x.abs().max(1e-9))
    }
}

/// The headroom (a fraction of the data's range, [`headroom`]) that leaves a legend of `rows` rows
/// above the data in a figure of [`super::SIZE`]: the legend takes 22 px a row, 15 px of padding
/// and the 12 px margin from the top of the plotting area (plus 8 px to spare), out of the
/// plotting area's 565 px (700 px less the caption, the margins and the x labels), all scaled
/// alike with the figure. A share f of the plotting area is a headroom of f/(1 − f).
fn legend_headroom(rows: usize) -> f64 {
    let share = (22.0 * rows as f64 + 15.0 + 12.0 + 8.0) / 565.0;
    share / (1.0 - share)
}

/// The overturning map: one cell per case of the first size, black when it collapsed, else
/// coloured by its peak θ/α.
pub fn draw_map<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    r: &StudyResults,
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let first = r
        .cases
        .iter()
        .map(|c| c.scale)
        .fold(f64::INFINITY, f64::min);
    let cells: Vec<(f64, f64, bool, f64)> = r
        .cases
        .iter()
        .filter(|c| c.scale == first)
        .filter_map(|c| {
            let (x, y) = c.pulse?;
            Some((x, y, c.collapse?, c.peak_ratio.unwrap_or(0.0)))
        })
        .collect();
    // The cells of cases whose runs left crr's model, marked with a cross.
    let outside: Vec<(f64, f64)> = r
        .cases
        .iter()
        .filter(|c| c.scale == first && c.outside_model)
        .filter_map(|c| c.pulse)
        .collect();
    let hx = half_gap(cells.iter().map(|c| c.0).collect());
    let hy = half_gap(cells.iter().map(|c| c.1).collect());
    let xr = padded(cells.iter().flat_map(|c| [c.0 - hx, c.0 + hx]));
    // Zhang & Makris's analytic minimum overturning amplitude (`boundary.csv`, written by the
    // study for a single block on dimensionless axes), inside the plotted columns.
    let boundary: Vec<(f64, f64)> = if r.ratios {
        std::fs::read_to_string(r.dir.join(BOUNDARY_FILE))
            .unwrap_or_default()
            .lines()
            .skip(1)
            .filter_map(|l| {
                let (x, y) = l.split_once(',')?;
                Some((x.parse().ok()?, y.parse().ok()?))
            })
            .filter(|&(x, _): &(f64, f64)| xr.contains(&x))
            .collect()
    } else {
        Vec::new()
    };
    // Room above the cells for the legend (its rows: the four keys, the boundary's line and the
    // cross of the cases outside crr's model), so that it hides none of them.
    let rows = 4 + usize::from(!boundary.is_empty()) + usize::from(!outside.is_empty());
    let yr = headroom(
        padded(cells.iter().flat_map(|c| [c.1 - hy, c.1 + hy])),
        legend_headroom(rows),
    );
    let sized = if r.sized {
        format!(", scale {first}")
    } else {
        String::new()
    };
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "{}: overturning map{sized}{}",
                r.name,
                outside_note(outside.len(), cells.len())
            ),
            caption_style(k),
        )
        .margin(20 * k)
        .x_label_area_size(55 * k)
        .y_label_area_size(85 * k)
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(err)?;
    let (xd, yd) = if r.ratios {
        ("ω_p / p", "a_p / (g tan α)")
    } else {
        ("pulse period T_p (s)", "pulse amplitude a_p (m/s²)")
    };
    configure(&mut chart, k, xd, yd, &|v| tick(*v, &xr), &|v| {
        tick(*v, &yr)
    })?;
    chart
        .draw_series(cells.iter().map(|&(x, y, collapse, ratio)| {
            let c = if collapse {
                COLLAPSE
            } else {
                ratio_colour(ratio)
            };
            Rectangle::new([(x - hx, y - hy), (x + hx, y + hy)], c.filled())
        }))
        .map_err(err)?;
    let boundary: Vec<(f64, f64)> = boundary.into_iter().filter(|p| yr.contains(&p.1)).collect();
    if !boundary.is_empty() {
        let blue = RGBColor(30, 90, 200);
        chart
            .draw_series(LineSeries::new(boundary, blue.stroke_width(3 * k)))
            .map_err(err)?
            .label("Zhang & Makris (2001), linearised: minimum overturning")
            .legend(line_key(blue, k));
    }
    if !outside.is_empty() {
        let arm = (hx * 0.45, hy * 0.45);
        let cross = move |(x, y): (f64, f64)| {
            [
                PathElement::new(
                    vec![(x - arm.0, y - arm.1), (x + arm.0, y + arm.1)],
                    OUTSIDE_MARK.stroke_width(3 * k),
                ),
                PathElement::new(
                    vec![(x - arm.0, y + arm.1), (x + arm.0, y - arm.1)],
                    OUTSIDE_MARK.stroke_width(3 * k),
                ),
            ]
        };
        let w = 8 * k as i32;
        chart
            .draw_series(outside.iter().flat_map(|&p| cross(p)))
            .map_err(err)?
            .label("left crr's model (a hypotheses violation)")
            .legend(move |(x, y): (i32, i32)| {
                let style = OUTSIDE_MARK.stroke_width(3 * k);
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(2, -w), (2 + 2 * w, w)], style)
                    + PathElement::new(vec![(2, w), (2 + 2 * w, -w)], style)
            });
    }
    let key = |c: RGBColor| {
        let w = 20 * k as i32;
        move |(x, y): (i32, i32)| Rectangle::new([(x, y - w / 2), (x + w, y + w / 2)], c.filled())
    };
    for (label, c) in [
        ("collapse".to_string(), COLLAPSE),
        ("survives, peak θ/α = 0".to_string(), ratio_colour(0.0)),
        ("survives, peak θ/α = 0.5".to_string(), ratio_colour(0.5)),
        ("survives, peak θ/α ≥ 1".to_string(), ratio_colour(1.0)),
    ] {
        chart
            .draw_series(std::iter::empty::<Rectangle<(f64, f64)>>())
            .map_err(err)?
            .label(label)
            .legend(key(c));
    }
    legend(&mut chart, k, SeriesLabelPosition::UpperLeft)
}

/// The rocking spectra: peak θ/α against size for each motion (thin), their median (thick
/// black); collapsed cases as crosses at the top of the plot.
pub fn draw_spectrum<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    r: &StudyResults,
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let (series, median) = r.spectra();
    let by_height = r.cases.iter().all(|c| c.height.is_some());
    let xr = padded(series.iter().flat_map(|(_, s)| s.iter().map(|p| p.0)));
    let top = series
        .iter()
        .flat_map(|(_, s)| s.iter().map(|p| p.1))
        .filter(|y| y.is_finite())
        .fold(1.0f64, f64::max)
        * 1.08;
    let yr = 0.0..headroom(0.0..top, 0.45).end;
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "{}: rocking spectrum (peak θ/α against size){}",
                r.name,
                outside_note(r.outside_model, r.cases.len())
            ),
            caption_style(k),
        )
        .margin(20 * k)
        .x_label_area_size(55 * k)
        .y_label_area_size(85 * k)
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(err)?;
    configure(
        &mut chart,
        k,
        if by_height {
            "height of the structure H (m), every length × s"
        } else {
            "scale factor s"
        },
        "peak θ/α (× at the top: collapse)",
        &|v| tick(*v, &xr),
        &|v| tick(*v, &yr),
    )?;
    let many = series.len() > 10;
    for (i, (name, s)) in series.iter().enumerate() {
        let c = if many {
            RGBColor(150, 150, 150)
        } else {
            colour(i)
        };
        // Lines through the survivors, broken at collapses.
        let mut run: Vec<(f64, f64)> = Vec::new();
        let mut runs = Vec::new();
        for &(x, y) in s {
            if y.is_finite() {
                run.push((x, y));
            } else if !run.is_empty() {
                runs.push(std::mem::take(&mut run));
            }
        }
        runs.push(run);
        let mut first = true;
        for run in runs.into_iter().filter(|r| !r.is_empty()) {
            let drawn = chart
                .draw_series(LineSeries::new(run, c.stroke_width(2 * k)))
                .map_err(err)?;
            if first && !many {
                drawn.label(name.clone()).legend(line_key(c, k));
            }
            first = false;
        }
        chart
            .draw_series(s.iter().filter(|p| !p.1.is_finite()).map(|p| {
                // Staggered per motion, so that collapses at the same size stay visible.
                let lift = if many { 0.0 } else { 0.035 * i as f64 };
                Cross::new((p.0, top * (1.0 + lift)), 6 * k, c.stroke_width(2 * k))
            }))
            .map_err(err)?;
    }
    let finite: Vec<(f64, f64)> = median.iter().copied().filter(|p| p.1.is_finite()).collect();
    chart
        .draw_series(LineSeries::new(finite, BLACK.stroke_width(4 * k)))
        .map_err(err)?
        .label(format!("median of {} motions (collapse = ∞)", series.len()))
        .legend(line_key(BLACK, k));
    legend(&mut chart, k, SeriesLabelPosition::UpperRight)
}

/// The data of the fragility figure.
pub struct FragilityFigure {
    /// Title.
    pub name: String,
    /// The intensity's axis label.
    pub intensity: String,
    /// The curves.
    pub curves: Vec<FragilityCurve>,
    /// The finished cases.
    pub cases: usize,
    /// Those of them whose runs left crr's model.
    pub outside_model: usize,
}

/// The colour of the crosses on the cells of cases whose runs left crr's model: a blue that
/// shows on the black of a collapse and on the pale to dark reds of the survivors.
const OUTSIDE_MARK: RGBColor = RGBColor(0, 140, 255);

/// The caption's note when some of the `cases` left crr's model: empty when none did.
fn outside_note(outside: usize, cases: usize) -> String {
    if outside == 0 {
        String::new()
    } else {
        format!(" ({outside} of {cases} cases outside crr's model)")
    }
}

/// The fragility curves: the empirical fractions as points, the lognormal fits as lines.
pub fn draw_fragility<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    f: &FragilityFigure,
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let hi = f
        .curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.im))
        .fold(0.0f64, f64::max)
        * 1.05;
    let xr = 0.0..hi.max(1e-9);
    let yr = -0.02..1.45;
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "{}: fragility curves{}",
                f.name,
                outside_note(f.outside_model, f.cases)
            ),
            caption_style(k),
        )
        .margin(20 * k)
        .x_label_area_size(55 * k)
        .y_label_area_size(85 * k)
        .build_cartesian_2d(xr.clone(), yr.clone())
        .map_err(err)?;
    configure(
        &mut chart,
        k,
        &f.intensity,
        "probability of exceedance",
        &|v| tick(*v, &xr),
        &|v| tick(*v, &(0.0..1.0)),
    )?;
    for (i, c) in f.curves.iter().enumerate() {
        let col = colour(i);
        chart
            .draw_series(
                c.points
                    .iter()
                    .map(|p| Circle::new((p.im, p.exceed / p.trials), 5 * k, col.filled())),
            )
            .map_err(err)?;
        let label = match c.fit {
            Some(fit) => format!(
                "{}: median {:.3}, β {:.2}",
                c.label(),
                fit.median,
                fit.dispersion
            ),
            None => format!("{}: no transition, no fit", c.label()),
        };
        if let Some(fit) = c.fit {
            let n = 300;
            let pts = (1..=n).map(|j| {
                let x = xr.end * j as f64 / n as f64;
                (x, normal_cdf((x / fit.median).ln() / fit.dispersion))
            });
            chart
                .draw_series(LineSeries::new(pts, col.stroke_width(3 * k)))
                .map_err(err)?
                .label(label)
                .legend(line_key(col, k));
        } else {
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(err)?
                .label(label)
                .legend(line_key(col, k));
        }
    }
    legend(&mut chart, k, SeriesLabelPosition::UpperLeft)
}

fn write_text(file: &Path, text: &str) -> Result<(), PlotError> {
    crate::output::replace_file::replace_file(file, text).map_err(|e| PlotError::Draw {
        file: file.to_path_buf(),
        message: format!("cannot write the file: {e}"),
    })
}

macro_rules! pair {
    ($dir:expr, $stem:expr, $draw:ident, $data:expr) => {{
        let png = $dir.join(concat!($stem, ".png"));
        let svg = $dir.join(concat!($stem, ".svg"));
        write_png(&png, |root, k| $draw(root, $data, k))?;
        write_svg(&svg, |root, k| $draw(root, $data, k))?;
        [png, svg]
    }};
}

/// `crr plot STUDY_DIR`: the products of a study folder, written into it: `map` (pulse studies),
/// `spectrum` (studies with a size axis), `fragility` and `fragility.csv` +
/// `fragility_points.csv` (records studies of one size with at least two positive levels).
/// Returns the files written; an error when the folder has no case to draw.
pub fn plot_study(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    register_fonts();
    let r = StudyResults::read(dir).map_err(|e| PlotError::Read {
        file: dir.to_path_buf(),
        message: e.to_string(),
    })?;
    if r.cases.is_empty() {
        return Err(PlotError::Read {
            file: dir.join("cases.csv"),
            message: format!("no finished case to plot ({} with an error)", r.errors),
        });
    }
    let mut files = Vec::new();
    if r.pulses {
        files.extend(pair!(dir, "map", draw_map, &r));
    }
    if r.sized {
        files.extend(pair!(dir, "spectrum", draw_spectrum, &r));
    }
    if let Some(im) = r.intensity.clone().filter(|_| !r.pulses && !r.sized) {
        let curves = r.fragility();
        if curves.first().is_some_and(|c| c.points.len() >= 2) {
            let (fits, points) = fragility_csv(&curves, &im);
            let (a, b) = (dir.join("fragility.csv"), dir.join("fragility_points.csv"));
            write_text(&a, &fits)?;
            write_text(&b, &points)?;
            files.extend([a, b]);
            let fig = FragilityFigure {
                name: r.name.clone(),
                intensity: match im.as_str() {
                    "pga_g" => "peak ground acceleration (g)".into(),
                    "pgv_m_s" => "peak ground velocity (m/s)".into(),
                    "sa_g" => "spectral acceleration Sa(T₁) (g)".into(),
                    _ => "factor on the records".into(),
                },
                curves,
                cases: r.cases.len(),
                outside_model: r.outside_model,
            };
            files.extend(pair!(dir, "fragility", draw_fragility, &fig));
        }
    }
    Ok(files)
}
