//! The plots of `crr poincare --plot` (PNG and SVG, `docs/poincare.md`): the section in the
//! (θ, θ̇) plane of every coordinate (`section`), with the free-rocking energy levels behind it
//! when the model is a single block; the bifurcation diagram (`bifurcation`); the basins of the
//! initial conditions (`basins`).

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;

use crr_dynamics::{horizontal_direction, reported_side};
use crr_kinematics::Model;

use crate::analysis::poincare::{Computed, Outcome, Prepared, Section, SectionKind};
use crate::output::plot::{
    DrawResult, FONT, FreeRocking, LEVELS, PlotError, register_fonts, write_png, write_svg,
};

/// The free-rocking levels of a model that is a single block (one coordinate, no loop, a hinge
/// with two pivot lines): p and α of its equivalent block; None for any other model, whose
/// levels are not drawn.
pub fn single_block_levels(model: &Model) -> Option<FreeRocking> {
    if model.dof() != 1 || !model.closures.is_empty() || model.bodies.len() != 1 {
        return None;
    }
    // The side `crr check` reports (reported_side).
    let (_, _, eq) = reported_side(model, 0, &horizontal_direction(model, 0)).ok()?;
    (eq.p_squared > 0.0 && eq.alpha > 0.0).then(|| FreeRocking {
        p: eq.p_squared.sqrt(),
        alpha: eq.alpha,
    })
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

fn padded(values: impl IntoIterator<Item = f64>) -> Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return -1.0..1.0;
    }
    let span = hi - lo;
    let pad = if span > 1e-12 * lo.abs().max(hi.abs()).max(1e-300) {
        0.06 * span
    } else {
        0.5 * lo.abs().max(1e-3)
    };
    (lo - pad)..(hi + pad)
}

/// Tick text with as many decimals as the spacing needs ("0" at zero, never "-0.000").
fn tick(v: f64, range: &Range<f64>) -> String {
    let span = (range.end - range.start).abs();
    if v.abs() <= 1e-9 * span {
        return "0".into();
    }
    if span < 1e-4 || range.start.abs().max(range.end.abs()) >= 1e5 {
        return format!("{v:.3e}");
    }
    let decimals = (-(span / 8.0).log10().floor()).max(0.0) as usize + 1;
    format!("{v:.decimals$}")
}

const POINT: RGBColor = RGBColor(31, 119, 180);
const GREY: RGBColor = RGBColor(150, 150, 150);

fn chart<'a, DB: DrawingBackend + 'a>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    x: Range<f64>,
    y: Range<f64>,
    x_desc: &str,
    y_desc: &str,
    k: u32,
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String> {
    let mut c = ChartBuilder::on(area)
        .caption(caption, (FONT, 22 * k).into_font().style(FontStyle::Bold))
        .margin(15 * k)
        .x_label_area_size(50 * k)
        .y_label_area_size(80 * k)
        .build_cartesian_2d(x.clone(), y.clone())
        .map_err(err)?;
    c.configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FONT, 15 * k))
        .axis_desc_style((FONT, 18 * k))
        .light_line_style(RGBColor(238, 238, 238).stroke_width(k))
        .bold_line_style(RGBColor(205, 205, 205).stroke_width(k))
        .axis_style(BLACK.stroke_width(k))
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&|v| tick(*v, &x))
        .y_label_formatter(&|v| tick(*v, &y))
        .draw()
        .map_err(err)?;
    Ok(c)
}

/// The data of the section plot.
pub struct SectionPlot<'a> {
    /// The model.
    pub model: &'a Model,
    /// The section.
    pub section: &'a Section,
    /// Caption.
    pub title: String,
}

/// The section of each coordinate in its (θ, θ̇) plane, one panel per coordinate; the
/// free-rocking levels θ_m/α = [`LEVELS`] of a single block behind it.
pub fn draw_section<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    d: &SectionPlot,
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let n = d.model.dof();
    if n == 0 {
        return Ok(());
    }
    let cols = n.min(2);
    let rows = n.div_ceil(cols);
    let panels = root.split_evenly((rows, cols));
    let levels = single_block_levels(d.model);
    for (i, area) in panels.iter().enumerate().take(n) {
        let curves: Vec<Vec<(f64, f64)>> = match levels {
            Some(f) => LEVELS
                .iter()
                .map(|ratio| {
                    let m = ratio * f.alpha;
                    let steps = 300;
                    let upper = (0..=steps).map(|j| {
                        let x = -m + 2.0 * m * j as f64 / steps as f64;
                        (x, f.rate(m, x))
                    });
                    let lower = (0..=steps).map(|j| {
                        let x = m - 2.0 * m * j as f64 / steps as f64;
                        (x, -f.rate(m, x))
                    });
                    upper.chain(lower).collect()
                })
                .collect(),
            None => Vec::new(),
        };
        let pts: Vec<(f64, f64)> = d
            .section
            .points
            .iter()
            .map(|p| (p.q[i], p.qdot[i]))
            .collect();
        let xr = padded(
            pts.iter()
                .map(|p| p.0)
                .chain(curves.iter().flatten().map(|p| p.0)),
        );
        let yr = padded(
            pts.iter()
                .map(|p| p.1)
                .chain(curves.iter().flatten().map(|p| p.1)),
        );
        let name = &d.model.coords[i].name;
        let caption = if i == 0 {
            d.title.clone()
        } else {
            name.clone()
        };
        let mut c = chart(
            area,
            &caption,
            xr,
            yr,
            &format!("{name} θ (rad)"),
            &format!("{name} dθ/dt (rad/s)"),
            k,
        )?;
        if let Some(f) = levels {
            for (j, curve) in curves.into_iter().enumerate() {
                let s = c
                    .draw_series(LineSeries::new(curve, GREY.stroke_width(k)))
                    .map_err(err)?;
                if j == 0 {
                    s.label(format!(
                        "free rocking E levels, θm/α = {} (α = {:.4} rad, p = {:.4} rad/s)",
                        LEVELS.map(|x| x.to_string()).join(", "),
                        f.alpha,
                        f.p
                    ))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20 * k as i32, y)], GREY.stroke_width(k))
                    });
                }
            }
        }
        c.draw_series(pts.iter().map(|&p| Circle::new(p, 3 * k, POINT.filled())))
            .map_err(err)?
            .label(format!("{} section point(s)", pts.len()))
            .legend(move |(x, y)| Circle::new((x + 10 * k as i32, y), 3 * k, POINT.filled()));
        c.configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.85))
            .border_style(GREY.stroke_width(k))
            .label_font((FONT, 14 * k))
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

/// The data of the bifurcation diagram.
pub struct BifurcationPlot<'a> {
    /// Coordinate index.
    pub coordinate: usize,
    /// Coordinate name.
    pub name: &'a str,
    /// "amplitude" or "frequency".
    pub parameter: &'a str,
    /// The cases.
    pub cases: &'a [(f64, Section)],
    /// Caption.
    pub title: String,
}

/// The section values of one coordinate against the swept parameter; overturned cases marked
/// with a red cross at θ = 0.
pub fn draw_bifurcation<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    d: &BifurcationPlot,
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let pts: Vec<(f64, f64)> = d
        .cases
        .iter()
        .flat_map(|(v, s)| s.points.iter().map(move |p| (*v, p.q[d.coordinate])))
        .collect();
    let over: Vec<f64> = d
        .cases
        .iter()
        .filter(|(_, s)| s.collapse.is_some())
        .map(|(v, _)| *v)
        .collect();
    let xr = padded(d.cases.iter().map(|c| c.0));
    let yr = padded(pts.iter().map(|p| p.1).chain([0.0]));
    let units = if d.parameter == "amplitude" {
        "A (m/s²)"
    } else {
        "F (Hz)"
    };
    let mut c = chart(
        root,
        &d.title,
        xr,
        yr,
        &format!("{} {units}", d.parameter),
        &format!("{} θ at the section (rad)", d.name),
        k,
    )?;
    c.draw_series(pts.iter().map(|&p| Circle::new(p, 2 * k, POINT.filled())))
        .map_err(err)?
        .label("section points")
        .legend(move |(x, y)| Circle::new((x + 10 * k as i32, y), 3 * k, POINT.filled()));
    if !over.is_empty() {
        c.draw_series(
            over.iter()
                .map(|&v| Cross::new((v, 0.0), 6 * k, RED.stroke_width(2 * k))),
        )
        .map_err(err)?
        .label("overturned")
        .legend(move |(x, y)| Cross::new((x + 10 * k as i32, y), 6 * k, RED.stroke_width(2 * k)));
    }
    c.configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(GREY.stroke_width(k))
        .label_font((FONT, 15 * k))
        .draw()
        .map_err(err)
}

/// The data of the basins plot.
pub struct BasinsPlot<'a> {
    /// Coordinate name.
    pub name: &'a str,
    /// The cases.
    pub cases: &'a [(f64, f64, Section)],
    /// Caption.
    pub title: String,
}

fn outcome_colour(o: Outcome) -> RGBColor {
    match o {
        Outcome::Settles => RGBColor(44, 160, 44),
        Outcome::Orbits => RGBColor(31, 119, 180),
        Outcome::Overturns => RGBColor(214, 39, 40),
        Outcome::Fails => RGBColor(60, 60, 60),
    }
}

/// Each initial condition (θ₀, θ̇₀) as a square coloured by its outcome.
pub fn draw_basins<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    d: &BasinsPlot,
    k: u32,
) -> DrawResult {
    root.fill(&WHITE).map_err(err)?;
    let xr = padded(d.cases.iter().map(|c| c.0));
    let yr = padded(d.cases.iter().map(|c| c.1));
    let mut c = chart(
        root,
        &d.title,
        xr,
        yr,
        &format!("initial {} θ₀ (rad)", d.name),
        &format!("initial {} dθ/dt₀ (rad/s)", d.name),
        k,
    )?;
    for o in [
        Outcome::Settles,
        Outcome::Orbits,
        Outcome::Overturns,
        Outcome::Fails,
    ] {
        let col = outcome_colour(o);
        let pts: Vec<(f64, f64)> = d
            .cases
            .iter()
            .filter(|(_, _, s)| Outcome::of(s) == o)
            .map(|(a, w, _)| (*a, *w))
            .collect();
        if pts.is_empty() {
            continue;
        }
        let half = 4 * k as i32;
        c.draw_series(pts.iter().map(|&p| {
            EmptyElement::at(p)
                + plotters::element::Rectangle::new([(-half, -half), (half, half)], col.filled())
        }))
        .map_err(err)?
        .label(o.name())
        .legend(move |(x, y)| {
            plotters::element::Rectangle::new([(x + 4, y - 5), (x + 14, y + 5)], col.filled())
        });
    }
    c.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(GREY.stroke_width(k))
        .label_font((FONT, 15 * k))
        .draw()
        .map_err(err)
}

/// Draws the plot of `computed` into `dir` under the temporary names of
/// [`super::poincare::write_files`] (`.partial.<name>`); returns the final names.
pub fn plot(p: &Prepared, computed: &Computed, dir: &Path) -> Result<Vec<String>, PlotError> {
    register_fonts();
    std::fs::create_dir_all(dir).map_err(|e| PlotError::Draw {
        file: dir.to_path_buf(),
        message: format!("cannot create the folder: {e}"),
    })?;
    let s = &p.settings;
    let forcing = format!(
        "A = {} m/s², F = {} Hz",
        s.forcing.amplitude, s.forcing.frequency
    );
    let stem = match computed {
        Computed::Section(section) => {
            let what = match s.kind {
                SectionKind::Stroboscopic => format!("section t = kT, {forcing}"),
                SectionKind::Crossing(c) => {
                    format!("section {} = 0 upward", p.model.coords[c].name)
                }
            };
            let d = SectionPlot {
                model: &p.model,
                section,
                title: format!("{}: {what}", p.file.name),
            };
            let png = super::poincare::partial(dir, "section.png");
            let svg = super::poincare::partial(dir, "section.svg");
            write_png(&png, |root, k| draw_section(root, &d, k))?;
            write_svg(&svg, |root, k| draw_section(root, &d, k))?;
            "section"
        }
        Computed::Bifurcation { parameter, cases } => {
            let d = BifurcationPlot {
                coordinate: p.coordinate,
                name: &p.model.coords[p.coordinate].name,
                parameter,
                cases,
                title: format!("{}: bifurcation diagram", p.file.name),
            };
            let png = super::poincare::partial(dir, "bifurcation.png");
            let svg = super::poincare::partial(dir, "bifurcation.svg");
            write_png(&png, |root, k| draw_bifurcation(root, &d, k))?;
            write_svg(&svg, |root, k| draw_bifurcation(root, &d, k))?;
            "bifurcation"
        }
        Computed::Basins(cases) => {
            let d = BasinsPlot {
                name: &p.model.coords[p.coordinate].name,
                cases,
                title: format!("{}: basins, {forcing}", p.file.name),
            };
            let png = super::poincare::partial(dir, "basins.png");
            let svg = super::poincare::partial(dir, "basins.svg");
            write_png(&png, |root, k| draw_basins(root, &d, k))?;
            write_svg(&svg, |root, k| draw_basins(root, &d, k))?;
            "basins"
        }
    };
    Ok(vec![format!("{stem}.png"), format!("{stem}.svg")])
}
