//! `crr poincare`'s results folder: the section, bifurcation or basins table, `poincare.json`
//! and the plots, written by the folder convention of [`super::results_folder`] (documented in
//! `docs/poincare.md`).

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crr_impact::simulation::SlotState;
use crr_kinematics::Model;

use super::results_folder::{default_out_dir, partial_name, refuse_earlier_results};
use crate::Error;
use crate::analysis::poincare::{
    Computed, Outcome, PoincareOptions, Prepared, Range, SAME_POINT_TOLERANCE, Section,
    SectionKind, Sweep, compute, detect_period, distinct_points, prepare,
};
use crate::input::model_file::ModelFile;

/// Every file `crr poincare` writes: an earlier run's set is replaced whole with `--force`.
pub const RESULT_FILES: [&str; 10] = [
    "poincare.csv",
    "poincare.json",
    "bifurcation.csv",
    "basins.csv",
    "section.png",
    "section.svg",
    "bifurcation.png",
    "bifurcation.svg",
    "basins.png",
    "basins.svg",
];

/// The default output folder `results/<model name>_poincare`.
pub fn default_poincare_dir(model_name: &str) -> PathBuf {
    default_out_dir(&format!("{model_name}_poincare"))
}

fn check_out_dir(out: &Path, force: bool) -> Result<(), Error> {
    refuse_earlier_results(
        out,
        force,
        &RESULT_FILES,
        &format!("--out {}", out.display()),
    )
}

fn fmt_state(model: &Model, states: &[SlotState], s: &mut String) {
    for i in &model.interfaces {
        s.push(',');
        for (k, slot) in i.slots.clone().enumerate() {
            if k > 0 {
                s.push('/');
            }
            s.push_str(states.get(slot).map_or("?", |st| st.code()));
        }
    }
}

/// The header of `poincare.csv`: `k,t`, every coordinate, every rate `<name>_rate`, every
/// interface's slot states `<interface>_state`.
pub fn section_header(model: &Model) -> String {
    let mut s = String::from("k,t");
    for c in &model.coords {
        s.push(',');
        s.push_str(&c.name);
    }
    for c in &model.coords {
        s.push_str(&format!(",{}_rate", c.name));
    }
    for i in &model.interfaces {
        s.push_str(&format!(",{}_state", i.name));
    }
    s.push('\n');
    s
}

/// The text of `poincare.csv`.
pub fn section_csv(model: &Model, section: &Section) -> String {
    use std::fmt::Write;
    let mut s = section_header(model);
    for p in &section.points {
        let _ = write!(s, "{},{:e}", p.k, p.t);
        for v in p.q.iter().chain(&p.qdot) {
            let _ = write!(s, ",{v:e}");
        }
        fmt_state(model, &p.states, &mut s);
        s.push('\n');
    }
    s
}

/// `poincare.json`: the model, the settings and what the section (or every case of a sweep)
/// found (documented in `docs/poincare.md`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoincareSummary {
    /// The version of crr that ran it.
    pub crr_version: String,
    /// The model's path as given.
    pub model_file: String,
    /// The model as run.
    pub model: ModelFile,
    /// Coordinate names, in the order of the section's columns.
    pub coordinates: Vec<String>,
    /// The forcing, the section and the sweep.
    pub settings: PoincareSettings,
    /// One section's facts (no sweep).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub section: Option<SectionSummary>,
    /// Every case of a sweep.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cases: Option<Vec<CaseSummary>>,
}

/// What one section found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SectionSummary {
    /// Points kept.
    pub points: usize,
    /// Points distinct within the same-point tolerance.
    pub distinct_points: usize,
    /// The period of a periodic orbit, in forcing periods (or crossings).
    pub period: Option<usize>,
    /// The structure overturned.
    pub overturned: bool,
    /// When (s).
    pub overturn_time: Option<f64>,
    /// Which body.
    pub overturn_body: Option<String>,
    /// The structure came to rest.
    pub at_rest: bool,
    /// Time reached (s).
    pub end_time: f64,
    /// The error that stopped the run early.
    pub error: Option<String>,
    /// The first failure of the rigid-contact hypotheses.
    pub hypothesis_violation: Option<SectionViolation>,
}

/// The first failure of the rigid-contact hypotheses in a section's run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SectionViolation {
    /// When (s).
    pub time: f64,
    /// The interface.
    pub interface: String,
    /// `tension` or `sliding`.
    pub kind: String,
}

/// One case of a sweep: its section and the parameter values that make it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseSummary {
    /// The section's facts.
    #[serde(flatten)]
    pub section: SectionSummary,
    /// A of a bifurcation sweep over amplitudes (m/s²).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<f64>,
    /// F of a bifurcation sweep over frequencies (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency: Option<f64>,
    /// θ₀ of a basins grid (rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f64>,
    /// θ̇₀ of a basins grid (rad/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate: Option<f64>,
    /// The basin it belongs to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcome: Option<String>,
}

/// The settings of a `crr poincare` run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoincareSettings {
    /// A.
    pub amplitude: f64,
    /// Always `m/s2`.
    pub amplitude_units: String,
    /// F (Hz).
    pub frequency: f64,
    /// T = 1/F (s).
    pub period: f64,
    /// φ (rad).
    pub phase: f64,
    /// The component driven.
    pub component: String,
    /// What is sampled.
    pub section: SectionKindSummary,
    /// M.
    pub transient: usize,
    /// N.
    pub periods: usize,
    /// Time limit of a crossing section (s).
    pub max_time: Option<f64>,
    /// `model` or `rest`.
    pub initial: String,
    /// The coordinate of the bifurcation diagram and the basins grid.
    pub coordinate: String,
    /// The sweep, if any.
    pub sweep: Option<SweepSummary>,
    /// Two section points closer than this (relative) are the same.
    pub same_point_tolerance: f64,
    /// The integrator's tolerances.
    pub solver: Tolerances,
}

/// What a section samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SectionKindSummary {
    /// `stroboscopic` or `crossing`.
    pub kind: String,
    /// The coordinate of a crossing section.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate: Option<String>,
}

/// A sweep: (first, last, count) of its values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepSummary {
    /// Amplitudes (m/s²).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitudes: Option<(f64, f64, usize)>,
    /// Frequencies (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequencies: Option<(f64, f64, usize)>,
    /// Initial angles of a basins grid (rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid_angle: Option<(f64, f64, usize)>,
    /// Initial rates of a basins grid (rad/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid_rate: Option<(f64, f64, usize)>,
}

/// The integrator's tolerances.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tolerances {
    /// Relative.
    pub rtol: f64,
    /// Absolute.
    pub atol: f64,
}

impl PoincareSummary {
    /// The text of `poincare.json`: pretty-printed, keys sorted, a final newline.
    pub fn to_json(&self) -> String {
        let value = serde_json::to_value(self).expect("a summary is plain data");
        serde_json::to_string_pretty(&value).expect("a JSON value prints") + "\n"
    }
}

/// The facts of one section.
pub fn section_summary(section: &Section) -> SectionSummary {
    SectionSummary {
        points: section.points.len(),
        distinct_points: distinct_points(&section.points, SAME_POINT_TOLERANCE),
        period: detect_period(&section.points, SAME_POINT_TOLERANCE),
        overturned: section.collapse.is_some(),
        overturn_time: section.collapse.as_ref().map(|c| c.t),
        overturn_body: section.collapse.as_ref().map(|c| c.body.clone()),
        at_rest: section.at_rest,
        end_time: section.end_time,
        error: section.error.clone(),
        hypothesis_violation: section.violation.as_ref().map(|v| SectionViolation {
            time: v.t,
            interface: v.interface.clone(),
            kind: v.kind.clone(),
        }),
    }
}

fn range(r: Range) -> Option<(f64, f64, usize)> {
    Some((r.start, r.end, r.count))
}

fn settings(p: &Prepared, opts: &PoincareOptions) -> PoincareSettings {
    let s = &p.settings;
    let none = SweepSummary {
        amplitudes: None,
        frequencies: None,
        grid_angle: None,
        grid_rate: None,
    };
    let sweep = match opts.sweep {
        Sweep::None => None,
        Sweep::Amplitudes(r) => Some(SweepSummary {
            amplitudes: range(r),
            ..none
        }),
        Sweep::Frequencies(r) => Some(SweepSummary {
            frequencies: range(r),
            ..none
        }),
        Sweep::Grid { angle, rate } => Some(SweepSummary {
            grid_angle: range(angle),
            grid_rate: range(rate),
            ..none
        }),
    };
    let (kind, coordinate, max_time) = match s.kind {
        SectionKind::Stroboscopic => ("stroboscopic", None, None),
        SectionKind::Crossing(c) => (
            "crossing",
            Some(p.model.coords[c].name.clone()),
            Some(s.max_time),
        ),
    };
    PoincareSettings {
        amplitude: s.forcing.amplitude,
        amplitude_units: "m/s2".into(),
        frequency: s.forcing.frequency,
        period: s.forcing.period(),
        phase: s.forcing.phase,
        component: s.forcing.axis.name().into(),
        section: SectionKindSummary {
            kind: kind.into(),
            coordinate,
        },
        transient: s.transient,
        periods: s.points,
        max_time,
        initial: if opts.rest { "rest" } else { "model" }.into(),
        coordinate: p.model.coords[p.coordinate].name.clone(),
        sweep,
        same_point_tolerance: SAME_POINT_TOLERANCE,
        solver: Tolerances {
            rtol: p.params.options.rtol,
            atol: p.params.options.atol,
        },
    }
}

/// The text of `bifurcation.csv`: one row per section point of every case,
/// `case,<parameter>,k,t,<coordinate>,<coordinate>_rate`.
pub fn bifurcation_csv(
    model: &Model,
    coordinate: usize,
    parameter: &str,
    cases: &[(f64, Section)],
) -> String {
    use std::fmt::Write;
    let name = &model.coords[coordinate].name;
    let mut s = format!("case,{parameter},k,t,{name},{name}_rate\n");
    for (i, (v, sec)) in cases.iter().enumerate() {
        for p in &sec.points {
            let _ = writeln!(
                s,
                "{i},{v:e},{},{:e},{:e},{:e}",
                p.k, p.t, p.q[coordinate], p.qdot[coordinate]
            );
        }
    }
    s
}

/// The text of `basins.csv`: one row per initial condition,
/// `angle,rate,outcome,end_time,points,overturn_time`.
pub fn basins_csv(cases: &[(f64, f64, Section)]) -> String {
    use std::fmt::Write;
    let mut s = String::from("angle,rate,outcome,end_time,points,overturn_time\n");
    for (a, w, sec) in cases {
        let _ = writeln!(
            s,
            "{a:e},{w:e},{},{:e},{},{}",
            Outcome::of(sec).name(),
            sec.end_time,
            sec.points.len(),
            sec.collapse
                .as_ref()
                .map(|c| format!("{:e}", c.t))
                .unwrap_or_default()
        );
    }
    s
}

/// The data file of what was computed: its name (`poincare.csv`, `bifurcation.csv` or
/// `basins.csv`) and its text.
pub fn data_file(p: &Prepared, computed: &Computed) -> (&'static str, String) {
    match computed {
        Computed::Section(s) => ("poincare.csv", section_csv(&p.model, s)),
        Computed::Bifurcation { parameter, cases } => (
            "bifurcation.csv",
            bifurcation_csv(&p.model, p.coordinate, parameter, cases),
        ),
        Computed::Basins(cases) => ("basins.csv", basins_csv(cases)),
    }
}

/// The content of poincare.json.
pub fn summary(
    path: &Path,
    p: &Prepared,
    opts: &PoincareOptions,
    computed: &Computed,
) -> PoincareSummary {
    let mut echo = p.file.clone();
    echo.gravity = p.model.gravity;
    let case = |section: &Section| CaseSummary {
        section: section_summary(section),
        amplitude: None,
        frequency: None,
        angle: None,
        rate: None,
        outcome: None,
    };
    let (section, cases) = match computed {
        Computed::Section(s) => (Some(section_summary(s)), None),
        Computed::Bifurcation { parameter, cases } => {
            let amplitude = *parameter == "amplitude";
            let cases = cases
                .iter()
                .map(|(x, s)| CaseSummary {
                    amplitude: amplitude.then_some(*x),
                    frequency: (!amplitude).then_some(*x),
                    ..case(s)
                })
                .collect();
            (None, Some(cases))
        }
        Computed::Basins(cases) => {
            let cases = cases
                .iter()
                .map(|(a, w, s)| CaseSummary {
                    angle: Some(*a),
                    rate: Some(*w),
                    outcome: Some(Outcome::of(s).name().into()),
                    ..case(s)
                })
                .collect();
            (None, Some(cases))
        }
    };
    PoincareSummary {
        crr_version: env!("CARGO_PKG_VERSION").into(),
        model_file: path.display().to_string(),
        model: echo,
        coordinates: p.model.coords.iter().map(|c| c.name.clone()).collect(),
        settings: settings(p, opts),
        section,
        cases,
    }
}

/// The hidden temporary name a result file is written to before it is renamed into place
/// ([`partial_name`], the convention of every command).
pub fn partial(dir: &Path, name: &str) -> PathBuf {
    partial_name(dir, name)
}

/// Writes `files` into `dir`, each to its temporary name ([`partial`]); then the earlier run's
/// files are removed and the new ones, with those already `written` to their temporary names,
/// renamed into place (poincare.json last), so that two runs are never mixed.
pub fn write_files(
    dir: &Path,
    written: &[String],
    files: &[(String, Vec<u8>)],
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut temps: Vec<(PathBuf, PathBuf)> = written
        .iter()
        .map(|name| (partial(dir, name), dir.join(name)))
        .collect();
    for (name, bytes) in files {
        let tmp = partial(dir, name);
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        temps.push((tmp, dir.join(name)));
    }
    for stale in RESULT_FILES {
        match std::fs::remove_file(dir.join(stale)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
    }
    temps.sort_by_key(|(_, dst)| dst.ends_with("poincare.json"));
    for (tmp, dst) in temps {
        std::fs::rename(tmp, dst)?;
    }
    Ok(())
}

/// What `crr poincare` did: the output folder, the summary and the files written.
#[derive(Clone, Debug)]
pub struct PoincareResult {
    /// The output folder.
    pub out: PathBuf,
    /// poincare.json's content.
    pub summary: PoincareSummary,
    /// The files written (data first, then plots).
    pub files: Vec<PathBuf>,
}

/// `crr poincare` end to end: checks the inputs, runs, writes the data files (and the plot with
/// `plot`). Input problems are `Err`; a run that overturns or fails part-way is written and
/// reported in the summary (`section.overturned`, `section.error`).
pub fn poincare(path: &Path, opts: &PoincareOptions, plot: bool) -> Result<PoincareResult, Error> {
    let p = prepare(path, opts)?;
    let out = opts
        .out
        .clone()
        .unwrap_or_else(|| default_poincare_dir(&p.file.name));
    check_out_dir(&out, opts.force)?;
    let progress = !opts.quiet && std::io::stderr().is_terminal();
    // One writer per folder for the whole computation (files and plots are renamed into place).
    let _lock = crate::output::folder_lock::FolderLock::acquire(&out)?;
    let computed = compute(&p, opts, progress).map_err(Error::Argument)?;
    let sum = summary(path, &p, opts, &computed);
    let (name, text) = data_file(&p, &computed);
    let mut files: Vec<(String, Vec<u8>)> = vec![(name.into(), text.into_bytes())];
    files.push(("poincare.json".into(), sum.to_json().into_bytes()));
    let output_error = |source| Error::Output {
        dir: out.clone(),
        source,
    };
    let written = if plot {
        crate::output::poincare_plot::plot(&p, &computed, &out)
            .map_err(|e| Error::Argument(format!("--plot: {e}")))?
    } else {
        Vec::new()
    };
    write_files(&out, &written, &files).map_err(output_error)?;
    let mut names: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
    names.extend(written);
    Ok(PoincareResult {
        files: names.iter().map(|n| out.join(n)).collect(),
        out,
        summary: sum,
    })
}
