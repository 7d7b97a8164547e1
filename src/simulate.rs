//! `crr simulate`: run the event-driven simulation of a model file and write `history.csv`,
//! `impacts.csv` and `summary.json` (documented in `docs/outputs.md`).

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use serde_json::{Value, json};

use crr_dynamics::ground_motion::{Axis, GroundMotion, RecordFormat, Units, read_record};
use crr_dynamics::{AnalysisSpec, InitialState, solve_initial};
use crr_impact::simulation::{
    ImpactRecord, Parameters, Sample, Samples, Simulation, SimulationError, StopReason, Trajectory,
    check_initial_state,
};
use crr_kinematics::{InterfaceKind, Model};

use crate::model_file::{InputError, ModelFile, load_model};

/// A record given on the command line (`--record`), overriding one component.
#[derive(Clone, Debug)]
pub struct RecordArg {
    /// The file.
    pub file: PathBuf,
    /// Its format.
    pub format: RecordFormat,
    /// Units (required for csv/text).
    pub units: Option<Units>,
    /// The component it drives.
    pub component: Axis,
    /// Factor on the accelerations.
    pub scale: f64,
}

/// Options of `crr simulate`.
#[derive(Clone, Debug, Default)]
pub struct SimulateOptions {
    /// Output folder (default [`default_out_dir`] of the model's name).
    pub out: Option<PathBuf>,
    /// Duration (s), overriding `[analysis].duration`.
    pub duration: Option<f64>,
    /// A record overriding one ground-motion component.
    pub record: Option<RecordArg>,
    /// No progress indication.
    pub quiet: bool,
    /// Replace the results of an earlier run in the output folder.
    pub force: bool,
}

/// The files `crr simulate` writes, and those `--plot` and `--animate` add (the animation's
/// index and GIF; its frames go with them): an earlier run's set is replaced whole (with
/// `--force`), never mixed with a new one.
const RESULT_FILES: [&str; 11] = [
    "animation/animation.pvd",
    "animation/animation.gif",
    "history.csv",
    "impacts.csv",
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

/// An output folder that already holds results is only written to with `force`.
fn check_out_dir(out: &Path, force: bool) -> Result<(), InputError> {
    refuse_earlier_results(out, force, &RESULT_FILES, &out.display().to_string())
}

/// Refuses an output folder that holds any of `files` from an earlier run unless `force`, or a
/// path that is not a folder; `label` names the folder in the message (e.g. `--out DIR`).
pub fn refuse_earlier_results(
    out: &Path,
    force: bool,
    files: &[&str],
    label: &str,
) -> Result<(), InputError> {
    if !out.exists() {
        return Ok(());
    }
    if !out.is_dir() {
        return Err(InputError::Argument(format!(
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
    Err(InputError::Argument(format!(
        "{label}: the folder holds the results of an earlier run ({}): pass --force to replace \
         them, or --out DIR for another folder",
        earlier.join(", ")
    )))
}

/// Everything a run needs, read and checked from the inputs.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The model file as read.
    pub file: ModelFile,
    /// The validated model.
    pub model: Model,
    /// The ground motion (model table plus command-line record).
    pub ground: GroundMotion,
    /// The consistent initial state.
    pub initial: InitialState,
    /// Simulation parameters.
    pub params: Parameters,
    /// Output folder.
    pub out: PathBuf,
}

/// The default duration: the ground motion's duration + 5 s when it ends, else 10 s.
pub fn default_duration(ground: &GroundMotion) -> f64 {
    let d = ground.duration();
    if d.is_finite() && d > 0.0 {
        d + 5.0
    } else {
        10.0
    }
}

/// Reads the model, the ground motion, the initial state and the parameters. Every failure is an
/// input error naming the file or item.
pub fn prepare(path: &Path, opts: &SimulateOptions) -> Result<Prepared, InputError> {
    let (file, model) = load_model(path)?;
    let base_dir = path.parent().unwrap_or(Path::new("."));
    let p = prepare_loaded(path, base_dir, file, model, opts, &[])?;
    check_out_dir(&p.out, opts.force)?;
    Ok(p)
}

/// [`prepare`] for a model already read (from a file, or given as text by an embedding program):
/// `path` names it in the errors, `base_dir` resolves the relative record files of its
/// `[ground_motion]`; `records` (component, record in m/s², factor) replace components after
/// those and `opts.record`, before the default duration is taken. The output folder is not
/// looked at (nothing is written here).
pub fn prepare_loaded(
    path: &Path,
    base_dir: &Path,
    file: ModelFile,
    model: Model,
    opts: &SimulateOptions,
    records: &[(Axis, crr_dynamics::ground_motion::Record, f64)],
) -> Result<Prepared, InputError> {
    let here = |msg: String| InputError::Argument(format!("{}: {msg}", path.display()));
    let mut ground = match &file.ground_motion {
        Some(spec) => GroundMotion::from_spec(spec, base_dir).map_err(|e| here(e.to_string()))?,
        None => GroundMotion::none(),
    };
    if let Some(r) = &opts.record {
        let record = read_record(&r.file, r.format, r.units)
            .map_err(|e| InputError::Argument(format!("--record: {e}")))?;
        ground = ground
            .with_record(r.component, record, r.scale)
            .map_err(|e| InputError::Argument(format!("--scale: {e}")))?;
    }
    for (axis, record, scale) in records {
        ground = ground
            .with_record(*axis, record.clone(), *scale)
            .map_err(|e| InputError::Argument(format!("ground motion: {e}")))?;
    }
    let initial_spec = file.initial.clone().unwrap_or_default();
    let initial = solve_initial(&model, &initial_spec).map_err(|e| here(e.to_string()))?;
    check_initial_state(&model, &initial).map_err(here)?;
    let analysis = file.analysis.clone().unwrap_or_default();
    let mut params =
        Parameters::from_analysis(&analysis, default_duration(&ground)).map_err(here)?;
    if let Some(d) = opts.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(InputError::Argument(format!(
                "--duration must be a positive number of seconds, got {d}"
            )));
        }
        params.duration = d;
    }
    let out = opts
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir(&file.name));
    Ok(Prepared {
        file,
        model,
        ground,
        initial,
        params,
        out,
    })
}

/// The outcome of a run: the trajectory and the error that stopped it early, if any.
pub struct Outcome {
    /// Results (complete or partial).
    pub trajectory: Trajectory,
    /// The error that interrupted the run.
    pub error: Option<SimulationError>,
}

/// Runs the simulation, printing a percentage on stderr when `progress`; the samples stay in
/// the trajectory.
pub fn run(p: &Prepared, progress: bool) -> Result<Outcome, SimulationError> {
    run_with_sink(p, progress, |_| Ok(()), false)
}

/// Runs the simulation, handing the samples to `sink` as they are computed (after every step)
/// when `stream` is set, so that memory stays flat however long the run; the trajectory then
/// holds no samples (its peaks and energy balance still cover all of them). A sink error stops
/// the run; it is returned as the run's error with what was computed until then.
pub fn run_with_sink(
    p: &Prepared,
    progress: bool,
    mut sink: impl FnMut(&Samples) -> std::io::Result<()>,
    stream: bool,
) -> Result<Outcome, SimulationError> {
    let mut sim = Simulation::new(&p.model, &p.ground, &p.initial, p.params.clone())?;
    let total = p.params.duration;
    let mut shown = -1i64;
    let mut flush = |sim: &mut Simulation| -> Result<(), SimulationError> {
        if stream {
            sink(&sim.drain_samples()).map_err(|e| {
                SimulationError::Parameter(format!("cannot write the history: {e}"))
            })?;
        }
        Ok(())
    };
    let error = loop {
        match sim.step() {
            Ok(StopReason::End(_)) | Ok(StopReason::Collapse(_)) => break flush(&mut sim).err(),
            Ok(_) => {}
            Err(e) => break flush(&mut sim).err().or(Some(e)),
        }
        if let Err(e) = flush(&mut sim) {
            break Some(e);
        }
        if progress {
            let pct = (100.0 * sim.time() / total).floor() as i64;
            if pct != shown {
                shown = pct;
                eprint!("\rcrr: simulating {:>3}% (t = {:.2} s)", pct, sim.time());
            }
        }
    };
    if progress {
        eprintln!("\rcrr: simulating 100% (t = {:.2} s)   ", sim.time());
    }
    Ok(Outcome {
        trajectory: sim.into_trajectory(),
        error,
    })
}

/// Slenderness α of a coordinate, when defined: for a hinge with two distinct pivot lines or a
/// rocking base tilt, atan(b/h) with b the half-distance between the pivot lines (perpendicular
/// to the axis) and h the height of the child's centre above the line midway between them,
/// measured normal to the joint face. None for a plain hinge (one pivot line).
pub fn coordinate_alpha(model: &Model, coordinate: usize) -> Option<f64> {
    let c = &model.coords[coordinate];
    let iface = &model.interfaces[c.interface];
    let com = model.bodies[iface.child].com;
    match &iface.kind {
        InterfaceKind::Hinge {
            axis,
            pivot_positive,
            pivot_negative,
        } => {
            let d = pivot_negative - pivot_positive;
            let d = d - axis * axis.dot(&d);
            let width = d.norm();
            if width < 1e-9 * model.size {
                return None;
            }
            let n = axis.cross(&d) / width;
            let mid = (pivot_negative + pivot_positive) / 2.0;
            let h = (com - mid).dot(&n);
            Some((width / 2.0).atan2(h))
        }
        InterfaceKind::RockingBase {
            corners,
            normal,
            e1,
            e2,
            ..
        } => {
            let centre: Vector3<f64> = corners.iter().sum::<Vector3<f64>>() / 4.0;
            // Tilt about e₁ pivots on edges parallel to e₁: half-extent along e₂, and vice versa.
            let across = if c.component == 0 { e2 } else { e1 };
            let extent = corners
                .iter()
                .map(|p| (p - centre).dot(across).abs())
                .fold(0.0, f64::max);
            let h = (com - centre).dot(normal);
            Some(extent.atan2(h))
        }
    }
}

fn num(x: f64) -> String {
    format!("{x:e}")
}

/// The header line of `history.csv`.
pub fn history_header(model: &Model) -> String {
    let mut s = String::from("t");
    for c in &model.coords {
        s.push(',');
        s.push_str(&c.name);
    }
    for c in &model.coords {
        s.push_str(&format!(",{}_rate", c.name));
    }
    s.push_str(",kinetic,potential,work_in,dissipated");
    for i in &model.interfaces {
        s.push_str(&format!(",{}_state", i.name));
    }
    s.push('\n');
    s
}

/// One line of `history.csv`.
pub fn history_row(model: &Model, x: &Sample) -> String {
    let mut s = String::with_capacity(24 * (2 * x.q.len() + 5) + 8 * model.interfaces.len());
    push_history_row(&mut s, model, x);
    s
}

/// Appends one line of `history.csv` to `s`, formatting in place (no string per value: writing
/// the history was a quarter of a short run's time).
pub fn push_history_row(s: &mut String, model: &Model, x: &Sample<'_>) {
    use std::fmt::Write;
    // Writing to a String cannot fail.
    let _ = write!(s, "{:e}", x.t);
    for v in x.q.iter().chain(x.qdot.iter()) {
        let _ = write!(s, ",{v:e}");
    }
    for v in [x.kinetic, x.potential, x.work_in, x.dissipated] {
        let _ = write!(s, ",{v:e}");
    }
    for i in &model.interfaces {
        s.push(',');
        for (k, slot) in i.slots.clone().enumerate() {
            if k > 0 {
                s.push('/');
            }
            s.push_str(x.states.get(slot).map_or("?", |st| st.code()));
        }
    }
    s.push('\n');
}

/// The text of `history.csv` for the samples a trajectory holds.
pub fn history_csv(model: &Model, t: &Trajectory) -> String {
    let mut s = history_header(model);
    for x in &t.samples {
        push_history_row(&mut s, model, &x);
    }
    s
}

/// What the streamed samples leave for the summary: how many were written, and the run's energy
/// scale (the largest T, |U|, |W| and D met).
#[derive(Clone, Copy, Debug, Default)]
pub struct SampleStats {
    /// Rows of history.csv.
    pub rows: usize,
    /// The largest of T, |U|, |W| and D over the samples (J).
    pub energy_scale: f64,
}

impl SampleStats {
    /// Counts `samples` in.
    pub fn add(&mut self, samples: &Samples) {
        self.rows += samples.len();
        for s in samples {
            let e = s
                .kinetic
                .max(s.potential.abs())
                .max(s.work_in.abs())
                .max(s.dissipated);
            self.energy_scale = self.energy_scale.max(e);
        }
    }
}

/// The text of `impacts.csv`.
pub fn impacts_csv(t: &Trajectory) -> String {
    let mut s = String::from("t,interfaces,rates_before,rates_after,energy_lost\n");
    let join = |v: &[f64]| v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(";");
    for i in &t.impacts {
        s.push_str(&format!(
            "{},{},{},{},{}\n",
            num(i.t),
            i.interfaces.join(";"),
            join(&i.rates_before),
            join(&i.rates_after),
            num(i.energy_lost)
        ));
    }
    s
}

fn method_name(a: &AnalysisSpec) -> &'static str {
    match a.method {
        crr_dynamics::MethodName::Dop853 => "dop853",
        crr_dynamics::MethodName::Dopri5 => "dopri5",
        crr_dynamics::MethodName::Rk4 => "rk4",
    }
}

/// A run's energy balance T + U − W + D − E(0) larger than this fraction of its energy scale
/// (the largest of T, |U|, |W| and D over the samples), and than the round-off 1e-9 W L, is a
/// warning.
pub const ENERGY_BALANCE_WARNING: f64 = 1e-3;

/// An RK4 step longer than this fraction of the structure's time scale √(L/g) (L the model size)
/// is a warning: rocking is resolved in steps far shorter than its quarter periods.
pub const RK4_STEP_WARNING: f64 = 0.05;

/// A simultaneity tolerance larger than this fraction of the smallest slenderness α is a warning.
pub const SIMULTANEITY_WARNING: f64 = 1e-2;

/// What a user must know before trusting the results (`warnings` in summary.json, also printed
/// on stderr by `crr simulate`).
fn warnings(
    p: &Prepared,
    t: &Trajectory,
    stats: &SampleStats,
    gains: &[&ImpactRecord],
) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(worst) = gains
        .iter()
        .min_by(|a, b| a.energy_lost.total_cmp(&b.energy_lost))
    {
        out.push(format!(
            "{} impact(s) raised the kinetic energy (the largest by {:.3e} J at t = {} s, {}); \
             the impact laws never do so for r ≤ 1: the impact map failed numerically",
            gains.len(),
            -worst.energy_lost,
            worst.t,
            worst.interfaces.join(", ")
        ));
    }
    let scale = stats.energy_scale;
    // Below 1e-9 W L (W the weight, L the model size) an error is round-off of the energies.
    let round_off = 1e-9 * p.model.total_mass() * p.model.gravity * p.model.size;
    if t.energy_balance_error > (ENERGY_BALANCE_WARNING * scale).max(round_off) {
        out.push(format!(
            "the energy balance is off by {:.3e} J, {:.2} % of the run's energy scale {:.3e} J \
             (more than {} %): tighten rtol/atol or shorten the step",
            t.energy_balance_error,
            100.0 * t.energy_balance_error / scale,
            scale,
            100.0 * ENERGY_BALANCE_WARNING
        ));
    }
    let analysis = p.file.analysis.clone().unwrap_or_default();
    if !matches!(analysis.method, crr_dynamics::MethodName::Rk4)
        && analysis.rtol > crr_dynamics::analysis::RTOL_WARNING
    {
        out.push(format!(
            "rtol = {} is loose: impacts, uplifts and loop closures are located to about that \
             relative precision; check the results with a smaller rtol (default 1e-10)",
            num(analysis.rtol)
        ));
    }
    if matches!(analysis.method, crr_dynamics::MethodName::Rk4) {
        let time_scale = (p.model.size / p.model.gravity).sqrt();
        if analysis.rk4_step > RK4_STEP_WARNING * time_scale {
            out.push(format!(
                "rk4_step = {} s is longer than {} of the structure's time scale √(L/g) = {:.3} s",
                num(analysis.rk4_step),
                RK4_STEP_WARNING,
                time_scale
            ));
        }
        if let Some(dt) = p.ground.record_sample_interval()
            && analysis.rk4_step > dt
        {
            out.push(format!(
                "rk4_step = {} s is longer than the record's sample interval {dt} s: the steps \
                 skip samples of the ground motion",
                num(analysis.rk4_step)
            ));
        }
    }
    let alpha_min = (0..p.model.dof())
        .filter_map(|k| coordinate_alpha(&p.model, k))
        .fold(f64::INFINITY, f64::min);
    if alpha_min.is_finite() && p.params.simultaneity > SIMULTANEITY_WARNING * alpha_min {
        out.push(format!(
            "simultaneity = {} rad is not small against the smallest slenderness α = {:.4} rad: \
             joints far from their seats are taken to impact together",
            num(p.params.simultaneity),
            alpha_min
        ));
    }
    if let Some(v) = &t.violation {
        let what = if v.kind == "tension" {
            format!(
                "would need tension (N = {:.4e} N): the bodies separate (flight)",
                v.normal
            )
        } else {
            format!(
                "needs friction |F_t|/N = {:.4} above μ: it slides",
                v.friction_demand
            )
        };
        out.push(format!(
            "the rigid-contact hypotheses fail at t = {} s: interface \"{}\" {what}; the results \
             after that time are outside crr's model",
            v.t, v.interface
        ));
    }
    out.extend(p.ground.record_warnings());
    out
}

/// The content of `summary.json`.
pub fn summary(
    model_path: &Path,
    p: &Prepared,
    opts: &SimulateOptions,
    t: &Trajectory,
    stats: &SampleStats,
    error: Option<&str>,
) -> Value {
    let coordinates: Vec<Value> = t
        .coordinates
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let alpha = coordinate_alpha(&p.model, k);
            json!({
                "name": name,
                "peak_abs": t.peak_abs[k],
                "alpha": alpha,
                "peak_over_alpha": alpha.map(|a| t.peak_abs[k] / a),
            })
        })
        .collect();
    let mut echo = p.file.clone();
    echo.gravity = p.model.gravity;
    let analysis = p.file.analysis.clone().unwrap_or_default();
    let pga = p.ground.pga();
    let duration = p.ground.duration();
    let initial = p.file.initial.clone().unwrap_or_default();
    let gains: Vec<&ImpactRecord> = t.impacts.iter().filter(|i| i.energy_gain).collect();
    json!({
        "crr_version": env!("CARGO_PKG_VERSION"),
        "completed": error.is_none(),
        "error": error,
        "model_file": model_path.display().to_string(),
        "model": echo,
        "record": opts.record.as_ref().map(|r| json!({
            "file": r.file.display().to_string(),
            "format": r.format.name(),
            "units": r.units.map(|u| u.name()),
            "component": r.component.name(),
            "scale": r.scale,
        })),
        "ground_motion": {
            "pga": [pga.x, pga.y, pga.z],
            "duration": if duration.is_finite() { json!(duration) } else { Value::Null },
        },
        "initial": {
            "spec": initial,
            "q": p.initial.q.as_slice(),
            "qdot": p.initial.qdot.as_slice(),
        },
        "solver": {
            "method": method_name(&analysis),
            "duration": p.params.duration,
            "output_interval": p.params.output_interval,
            "rtol": p.params.options.rtol,
            "atol": p.params.options.atol,
            "max_step": if p.params.options.h_max.is_finite() { json!(p.params.options.h_max) } else { Value::Null },
            "rk4_step": analysis.rk4_step,
            "seat_rate": p.params.seat_rate,
            "min_impact_interval": p.params.min_impact_interval,
            "simultaneity": p.params.simultaneity,
            "max_impacts": p.params.max_impacts,
            "collapse_drop": p.params.collapse_drop,
            "friction": p.params.friction,
        },
        "solver_stats": {
            "steps": t.solver_stats.steps,
            "accepted": t.solver_stats.accepted,
            "rejected": t.solver_stats.rejected,
            "rhs_evaluations": t.solver_stats.rhs_evals,
        },
        "end_time": t.end_time,
        "samples": stats.rows,
        "coordinates": coordinates,
        "impacts": t.impacts.len(),
        "energy_lost_at_impacts": t.impacts.iter().map(|i| i.energy_lost).sum::<f64>(),
        "impacts_with_energy_gain": gains.len(),
        "warnings": warnings(p, t, stats, &gains),
        "uplift_time": t.uplift_time,
        "collapse": {
            "collapsed": t.collapse.is_some(),
            "time": t.collapse.as_ref().map(|c| c.t),
            "body": t.collapse.as_ref().map(|c| c.body.clone()),
        },
        "energy_balance_error": t.energy_balance_error,
        "hypothesis_violation": t.violation.as_ref().map(|v| json!({
            "time": v.t,
            "interface": v.interface,
            "kind": v.kind,
            "normal_force": v.normal,
            "friction_demand": if v.friction_demand.is_finite() { json!(v.friction_demand) } else { Value::Null },
        })),
    })
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
    crate::animate::remove_animation(&dir.join(crate::animate::DEFAULT_DIR))?;
    for (tmp, dst) in temps {
        std::fs::rename(tmp, dst)?;
    }
    Ok(())
}

/// The hidden temporary name a result file is written to before it is renamed into place.
pub fn partial_name(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!(".{name}.partial"))
}

/// What `crr simulate` did.
pub enum SimulateResult {
    /// The run completed; the output folder.
    Done(PathBuf, Value),
    /// The run failed part-way; the partial results were written to the folder.
    Failed(PathBuf, String),
}

/// `crr simulate` end to end. Input problems are `Err`; a simulation failure is
/// `Ok(SimulateResult::Failed)` after writing what was computed.
pub fn simulate(path: &Path, opts: &SimulateOptions) -> Result<SimulateResult, InputError> {
    let p = prepare(path, opts)?;
    let progress = !opts.quiet && std::io::stderr().is_terminal();
    let output_error = |source| InputError::Output {
        dir: p.out.clone(),
        source,
    };
    // One writer per folder: another run writing here would rename these files away.
    let _lock = crate::folder_lock::FolderLock::acquire(&p.out)?;
    // history.csv is streamed to its temporary name while the run goes: memory stays flat in the
    // duration. It is renamed into place with the other files at the end.
    std::fs::create_dir_all(&p.out).map_err(output_error)?;
    let history_tmp = partial_name(&p.out, "history.csv");
    let mut history =
        std::io::BufWriter::new(std::fs::File::create(&history_tmp).map_err(output_error)?);
    history
        .write_all(history_header(&p.model).as_bytes())
        .map_err(output_error)?;
    let mut stats = SampleStats::default();
    let mut rows = String::new();
    let sink = |samples: &Samples| -> std::io::Result<()> {
        stats.add(samples);
        rows.clear();
        for x in samples {
            push_history_row(&mut rows, &p.model, &x);
        }
        history.write_all(rows.as_bytes())
    };
    let (trajectory, error) = match run_with_sink(&p, progress, sink, true) {
        Ok(o) => (o.trajectory, o.error.map(|e| e.to_string())),
        Err(e) => {
            // Nothing was integrated: an empty trajectory at t = 0.
            let t = Trajectory::empty(&p.model);
            (t, Some(e.to_string()))
        }
    };
    let file = history
        .into_inner()
        .map_err(|e| output_error(e.into_error()))?;
    file.sync_all().map_err(output_error)?;
    let sum = summary(path, &p, opts, &trajectory, &stats, error.as_deref());
    let files = [
        ("impacts.csv", impacts_csv(&trajectory)),
        (
            "summary.json",
            serde_json::to_string_pretty(&sum).expect("summary serialises") + "\n",
        ),
    ];
    write_outputs_with(&p.out, &["history.csv"], &files).map_err(output_error)?;
    Ok(match error {
        None => SimulateResult::Done(p.out, sum),
        Some(e) => SimulateResult::Failed(p.out, e),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(t: f64, lost: f64) -> ImpactRecord {
        ImpactRecord {
            t,
            interfaces: vec!["base".into()],
            slots: vec![0],
            rates_before: vec![-1.0],
            rates_after: vec![1.5],
            energy_lost: lost,
            energy_gain: true,
            seated: Vec::new(),
        }
    }

    #[test]
    fn a_record_given_as_samples_drives_the_run_and_sets_the_default_duration() {
        use crr_dynamics::ground_motion::Record;
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
        let (file, model) = load_model(&path).unwrap();
        let record = Record::from_samples(vec![0.0, 1.0, 2.0], vec![0.0, 3.0, 0.0]).unwrap();
        let base = path.parent().unwrap();
        let p = prepare_loaded(
            &path,
            base,
            file.clone(),
            model.clone(),
            &SimulateOptions::default(),
            &[(Axis::X, record, 2.0)],
        )
        .unwrap();
        assert_eq!(p.ground.pga().x, 6.0);
        assert_eq!(p.params.duration, 2.0 + 5.0);
        // Without records it is `prepare` without the output folder check.
        let q = prepare_loaded(&path, base, file, model, &SimulateOptions::default(), &[]).unwrap();
        let r = prepare(&path, &unit_test_options()).unwrap();
        assert_eq!(q.params.duration, r.params.duration);
        assert_eq!(q.initial.q, r.initial.q);
    }

    /// Default options with an output folder that holds no results: the default
    /// `results/single_block` may hold those of the README's command, which `prepare` refuses to
    /// replace.
    fn unit_test_options() -> SimulateOptions {
        SimulateOptions {
            out: Some(std::env::temp_dir().join("crr-simulate-unit-tests-no-results")),
            ..Default::default()
        }
    }

    #[test]
    fn an_energy_gain_is_a_warning_naming_the_worst_impact() {
        // No law of crr raises T for r ≤ 1, so the case is built by hand.
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
        let p = prepare(&path, &unit_test_options()).unwrap();
        let t = Trajectory::empty(&p.model);
        let stats = SampleStats::default();
        assert!(warnings(&p, &t, &stats, &[]).is_empty());
        let (a, b) = (record(0.5, -2.0), record(1.5, -7.0));
        let w = warnings(&p, &t, &stats, &[&a, &b]);
        assert_eq!(w.len(), 1);
        assert!(w[0].starts_with("2 impact(s) raised"), "{}", w[0]);
        assert!(w[0].contains("7.000e0 J at t = 1.5 s, base"), "{}", w[0]);
    }
}
