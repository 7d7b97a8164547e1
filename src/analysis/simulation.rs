//! A simulation in memory, behind [`crate::run`]: a model and [`RunOptions`] become a
//! [`Prepared`] run (ground motion, consistent initial state, parameters), the event-driven
//! simulation runs it, and the results come back as a [`Run`] with a typed [`Summary`] and the
//! warnings a user must read before trusting them. Nothing here writes a file: `crr simulate`'s
//! results folder is [`crate::output::simulate`]'s.

use std::path::PathBuf;

use nalgebra::Vector3;

use crr_dynamics::ground_motion::{
    Axis, GroundMotion, GroundMotionError, GroundMotionSpec, Record, RecordFormat, Units,
    read_record,
};
use crr_dynamics::{AnalysisSpec, InitialSpec, InitialState, solve_initial};
use crr_impact::simulation::{
    ImpactRecord, Parameters, Samples, Simulation, SimulationError, SlotState, StopReason,
    Trajectory, check_initial_state,
};
use crr_kinematics::{InterfaceKind, Model};

use super::summary::{
    CollapseSummary, CoordinateSummary, GroundMotionSummary, HopsSummary, InitialSummary,
    RecordSummary, SolverSettings, SolverStats, Summary, ViolationSummary,
};
use crate::Error;
use crate::input::model_file::{ModelFile, ModelInput};

/// A record file that replaces one component of the ground motion (`crr simulate --record`).
#[derive(Clone, Debug)]
pub struct RecordFile {
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

/// A record in memory (accelerations in m/s²) that replaces one component.
#[derive(Clone, Debug)]
pub struct RecordSamples {
    /// The component it drives.
    pub component: Axis,
    /// The record.
    pub record: Record,
    /// Factor on the accelerations.
    pub scale: f64,
}

/// What a run changes from the model file: its tables, records and duration. The default runs
/// the file as written.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Replaces `[ground_motion]`.
    pub ground_motion: Option<GroundMotionSpec>,
    /// Replaces `[initial]`.
    pub initial: Option<InitialSpec>,
    /// Replaces `[analysis]`.
    pub analysis: Option<AnalysisSpec>,
    /// A record file replacing one component (after `[ground_motion]`).
    pub record_file: Option<RecordFile>,
    /// Records in memory replacing components (after the record file).
    pub records: Vec<RecordSamples>,
    /// Duration (s), replacing `[analysis].duration`; the default is the ground motion's
    /// duration + 5 s when it ends, else 10 s.
    pub duration: Option<f64>,
    /// Print the percentage done on stderr while running.
    pub progress: bool,
    /// A flag the run polls inside and after every step: once set, it stops with
    /// [`SimulationError::Cancelled`] within one integration step and keeps what it computed.
    pub cancel: Option<Cancel>,
    /// Most output samples a run keeps in memory (not streamed): the run stops with
    /// [`SimulationError::TooManySamples`] after the step that passes it (a step records at
    /// most 4 096 samples plus two per impact), keeping what it computed.
    pub max_samples: Option<usize>,
}

/// A request to stop a run, a check or a study ([`crr_dynamics::Cancel`]): a run stops within
/// one integration step of its current step ([`Simulation::set_interrupt`]), at a state of the
/// motion; the statics after the linear program under way.
pub use crr_dynamics::Cancel;

/// Everything a run needs, read and checked from the inputs.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The path (or label) that names the model.
    pub path: PathBuf,
    /// The model file as run (tables overridden).
    pub file: ModelFile,
    /// The validated model.
    pub model: Model,
    /// The ground motion (model table plus records).
    pub ground: GroundMotion,
    /// The consistent initial state.
    pub initial: InitialState,
    /// Simulation parameters.
    pub params: Parameters,
    /// The record file of the options, echoed in the summary.
    pub record_file: Option<RecordFile>,
    /// Print progress on stderr.
    pub progress: bool,
    /// The cancellation flag of the options.
    pub cancel: Option<Cancel>,
    /// The sample limit of the options.
    pub max_samples: Option<usize>,
}

/// The results of a run: complete, or partial with the reason it stopped.
#[derive(Debug)]
pub struct Run {
    /// The structure that ran (coordinate and interface names, mass properties).
    pub model: Model,
    /// The history (samples, also just before and after each impact), the impacts, the peaks.
    /// Its samples are empty when they were handed to a sink ([`run_streaming`]).
    pub trajectory: Trajectory,
    /// What `summary.json` holds, warnings included.
    pub summary: Summary,
    /// Why the run stopped early, typed (too many impacts, a solver failure, a sink that could
    /// not write, …); `summary.error` is its message.
    pub failure: Option<SimulationError>,
}

impl Run {
    /// The run reached its duration or a collapse without an error.
    pub fn completed(&self) -> bool {
        self.summary.completed
    }

    /// What a user must know before trusting the results.
    pub fn warnings(&self) -> &[String] {
        &self.summary.warnings
    }
}

/// Runs `model` with `options`: `crr::run`. Input problems are an [`Error`]; a simulation that
/// fails part-way is a [`Run`] whose summary gives the error, with what was computed until then.
pub fn run(model: &ModelInput, options: &RunOptions) -> Result<Run, Error> {
    let prepared = prepare(model, options)?;
    Ok(prepared.run())
}

/// [`run`], handing the samples to `sink` after every step instead of keeping them, so that
/// memory stays flat however long the run (the trajectory's peaks and energy balance still cover
/// all of them). A sink error stops the run; the summary gives it.
pub fn run_streaming(
    model: &ModelInput,
    options: &RunOptions,
    sink: impl FnMut(&Samples) -> std::io::Result<()>,
) -> Result<Run, Error> {
    let prepared = prepare(model, options)?;
    Ok(prepared.run_streaming(sink))
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

/// Reads the ground motion, solves the initial state and sets the parameters. Every failure is
/// an [`Error`] naming the model or the item.
pub fn prepare(input: &ModelInput, options: &RunOptions) -> Result<Prepared, Error> {
    let path = &input.path;
    let here = |msg: String| Error::Argument(format!("{}: {msg}", path.display()));
    let mut file = input.file.clone();
    if let Some(g) = &options.ground_motion {
        file.ground_motion = Some(g.clone());
    }
    if let Some(i) = &options.initial {
        file.initial = Some(i.clone());
    }
    if let Some(a) = &options.analysis {
        file.analysis = Some(a.clone());
    }
    let ground = ground_motion(input, &file, options)?;
    let initial_spec = file.initial.clone().unwrap_or_default();
    let initial = solve_initial(&input.model, &initial_spec).map_err(|e| here(e.to_string()))?;
    check_initial_state(&input.model, &initial).map_err(here)?;
    let analysis = file.analysis.clone().unwrap_or_default();
    let mut params =
        Parameters::from_analysis(&analysis, default_duration(&ground)).map_err(here)?;
    if let Some(d) = options.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(Error::Argument(format!(
                "duration must be a positive number of seconds, got {d}"
            )));
        }
        params.duration = d;
    }
    // Settings that would change the physics are input errors, found before anything runs or
    // is written (not a failed run with partial results).
    crr_impact::simulation::check_physical_bounds(&input.model, &params)
        .map_err(|e| here(e.to_string()))?;
    if let Some(period) = ground.time_scale() {
        let structure = (input.model.size / input.model.gravity).sqrt();
        if period.is_nan() || period < SHORTEST_GROUND_PERIOD * structure {
            return Err(here(format!(
                "ground motion: its shortest time scale {period:e} s (a period, or 1/f of a \
                 Ricker wavelet) is below {SHORTEST_GROUND_PERIOD:e} of the structure's time \
                 scale √(L/g) = {structure:.4} s: no ground motion is that fast against a \
                 structure, and the uplift test samples each period {} times while joints are \
                 seated (a 1e9 Hz sine over 2 s would take hours)",
                crr_impact::simulation::SEATED_SAMPLES_PER_PERIOD
            )));
        }
    }
    let rows = (params.duration / params.output_interval).floor() + 1.0;
    if rows.is_nan() || rows > MAX_HISTORY_ROWS {
        return Err(here(format!(
            "output_interval = {} s over the duration {} s makes {rows:.3e} history rows, more \
             than {MAX_HISTORY_ROWS:e} (tens of gigabytes; 1e-300 s wrote 880 MB in 10 s and \
             would never end): raise output_interval",
            num(params.output_interval),
            params.duration
        )));
    }
    Ok(Prepared {
        path: path.clone(),
        file,
        model: input.model.clone(),
        ground,
        initial,
        params,
        record_file: options.record_file.clone(),
        progress: options.progress,
        cancel: options.cancel.clone(),
        max_samples: options.max_samples,
    })
}

/// The model's `[ground_motion]` with the record file, then the records in memory, replacing
/// components.
fn ground_motion(
    input: &ModelInput,
    file: &ModelFile,
    options: &RunOptions,
) -> Result<GroundMotion, Error> {
    let mut ground = match &file.ground_motion {
        Some(spec) => GroundMotion::from_spec(spec, &input.base_dir).map_err(|e| match e {
            // A record file the model names that cannot be read is a file error (Python:
            // crr.MissingFileError when it does not exist), named with the item.
            GroundMotionError::InComponent { context, error } => match *error {
                GroundMotionError::Io { path, error } => Error::NamedFile {
                    input: input.path.clone(),
                    item: context,
                    file: path.into(),
                    source: error,
                },
                other => Error::Argument(format!("{}: {context}: {other}", input.path.display())),
            },
            e => Error::Argument(format!("{}: {e}", input.path.display())),
        })?,
        None => GroundMotion::none(),
    };
    if let Some(r) = &options.record_file {
        let record = read_record(&r.file, r.format, r.units).map_err(|e| match e {
            // A file that cannot be read is a file error (Python: crr.FileError with errno).
            GroundMotionError::Io { error, .. } => Error::Io {
                file: r.file.clone(),
                source: error,
            },
            e => Error::Argument(format!("record file: {e}")),
        })?;
        ground = ground
            .with_record(r.component, record, r.scale)
            .map_err(|e| Error::Argument(format!("record scale: {e}")))?;
    }
    for r in &options.records {
        ground = ground
            .with_record(r.component, r.record.clone(), r.scale)
            .map_err(|e| Error::Argument(format!("ground motion: {e}")))?;
    }
    Ok(ground)
}

impl Prepared {
    /// The history's expected size: its rows (one per output interval, the impacts' two extra
    /// rows left out) and the bytes of `history.csv` they make.
    pub fn history_estimate(&self) -> (f64, f64) {
        let rows = (self.params.duration / self.params.output_interval).floor() + 1.0;
        (rows, rows * history_row_bytes(&self.model))
    }

    /// The warning to give before the run when its history will be larger than
    /// [`HISTORY_SIZE_WARNING`]: what makes it so and how to shrink it.
    pub fn history_size_warning(&self) -> Option<String> {
        let (rows, bytes) = self.history_estimate();
        (bytes > HISTORY_SIZE_WARNING).then(|| {
            format!(
                "the history will hold about {rows:.3e} rows ({:.1} GB): the duration {} s over \
                 output_interval = {} s; raise output_interval to shrink it",
                bytes / 1e9,
                self.params.duration,
                num(self.params.output_interval)
            )
        })
    }

    /// Runs the simulation and keeps the samples in the trajectory.
    pub fn run(&self) -> Run {
        self.run_with(|_| Ok(()), false)
    }

    /// Runs the simulation, handing the samples to `sink` after every step (see
    /// [`run_streaming`]).
    pub fn run_streaming(&self, sink: impl FnMut(&Samples) -> std::io::Result<()>) -> Run {
        self.run_with(sink, true)
    }

    fn run_with(&self, mut sink: impl FnMut(&Samples) -> std::io::Result<()>, stream: bool) -> Run {
        let mut stats = SampleStats::watching_corners_of(&self.model);
        let mut counted = |samples: &Samples| {
            stats.add(samples);
            sink(samples)
        };
        let (trajectory, failure) = self.integrate(&mut counted, stream);
        if !stream {
            stats.add(&trajectory.samples);
        }
        let error = failure.as_ref().map(|e| e.to_string());
        let summary = self.summary(&trajectory, &stats, error.as_deref());
        Run {
            model: self.model.clone(),
            trajectory,
            summary,
            failure,
        }
    }

    /// Integrates to the end, a collapse or an error; the error as text, with the trajectory
    /// computed until then (empty at t = 0 when the simulation could not start).
    fn integrate(
        &self,
        sink: &mut dyn FnMut(&Samples) -> std::io::Result<()>,
        stream: bool,
    ) -> (Trajectory, Option<SimulationError>) {
        match self.simulate(sink, stream) {
            Ok((t, e)) => (t, e),
            Err(e) => (Trajectory::empty(&self.model), Some(e)),
        }
    }

    /// The event-driven simulation of this preparation ([`simulate`]).
    pub fn simulate(
        &self,
        sink: &mut dyn FnMut(&Samples) -> std::io::Result<()>,
        stream: bool,
    ) -> Result<(Trajectory, Option<SimulationError>), SimulationError> {
        simulate(
            &self.model,
            &self.ground,
            &self.initial,
            &self.params,
            sink,
            stream,
            self.progress,
            self.cancel.as_ref(),
            self.max_samples,
        )
    }
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

/// What the streamed samples leave for the summary: how many were written, and the run's energy
/// scale (the largest T, |U|, |W| and D met).
#[derive(Clone, Debug, Default)]
pub struct SampleStats {
    /// Rows of history.csv.
    pub rows: usize,
    /// The largest of T, |U|, |W| and D over the samples (J).
    pub energy_scale: f64,
    /// The rocking bases without twist watched for a sample on a corner
    /// ([`Self::watching_corners_of`]; none by default).
    pub corners: Vec<CornerWatch>,
    /// The last sample's angles and rates, and whether every slot was seated there.
    pub last: Option<LastSample>,
}

/// The state of the last sample a run wrote.
#[derive(Clone, Debug, Default)]
pub struct LastSample {
    /// Its time (s).
    pub t: f64,
    /// The angles (rad).
    pub q: Vec<f64>,
    /// The rates (rad/s).
    pub qdot: Vec<f64>,
    /// Whether every slot was seated.
    pub seated: bool,
}

/// One rocking base watched for a sample on a corner.
#[derive(Clone, Debug)]
pub struct CornerWatch {
    /// Its interface.
    pub interface: usize,
    /// Its first slot (`.1`; `.2` follows it).
    pub first_slot: usize,
    /// The first sample (s) at which both its tilts were turned.
    pub first_seen: Option<f64>,
}

impl SampleStats {
    /// Stats that also watch `model`'s rocking bases (not those that may twist) for a sample on
    /// a corner (both tilts turned), for the warning of docs/model-format.md, "Rocking bases: the
    /// order of the two tilts".
    pub fn watching_corners_of(model: &Model) -> Self {
        let corners = model
            .interfaces
            .iter()
            .enumerate()
            .filter(|(_, i)| matches!(i.kind, InterfaceKind::RockingBase { twist: false, .. }))
            .map(|(k, i)| CornerWatch {
                interface: k,
                first_slot: i.slots.start,
                first_seen: None,
            })
            .collect();
        SampleStats {
            corners,
            ..SampleStats::default()
        }
    }

    /// Counts `samples` in.
    pub fn add(&mut self, samples: &Samples) {
        self.rows += samples.len();
        let turned = |s: SlotState| matches!(s, SlotState::Positive | SlotState::Negative);
        for s in samples {
            let e = s
                .kinetic
                .max(s.potential.abs())
                .max(s.work_in.abs())
                .max(s.dissipated);
            self.energy_scale = self.energy_scale.max(e);
            for c in self.corners.iter_mut().filter(|c| c.first_seen.is_none()) {
                let k = c.first_slot;
                if s.states.len() > k + 1 && turned(s.states[k]) && turned(s.states[k + 1]) {
                    c.first_seen = Some(s.t);
                }
            }
        }
        if let Some(s) = samples.last() {
            let last = self.last.get_or_insert_with(LastSample::default);
            last.t = s.t;
            last.q.clear();
            last.q.extend_from_slice(s.q);
            last.qdot.clear();
            last.qdot.extend_from_slice(s.qdot);
            last.seated = s.states.iter().all(|st| *st == SlotState::Seated);
        }
    }
}

/// A run's energy balance T + U − W + D − E(0) larger than this fraction of its energy scale
/// (the largest of T, |U|, |W| and D over the samples), and than the round-off 1e-9 W L, is a
/// warning.
pub const ENERGY_BALANCE_WARNING: f64 = 1e-3;

/// The opening of the loops at acceleration level left by the closed-chain solves
/// ([`crr_impact::simulation::LoopResidual`]), in units of g, above which a run warns: the level
/// at which the contact program reads a contact's opening rate and force as a tie
/// (docs/simulation.md, Limitations, "Contacts at a threshold"). The bundled models' loops stay
/// at round-off (4.7e-14 m/s² or less; the temple 1.4e-11 m/s² until its monitor's first
/// violation); the temple with rigid seats under 0.8 of its record reaches 1.9e-5 m/s².
pub const LOOP_RESIDUAL_WARNING: f64 = 1e-6;

/// An RK4 step longer than this fraction of the structure's time scale √(L/g) (L the model size)
/// is a warning: rocking is resolved in steps far shorter than its quarter periods.
pub const RK4_STEP_WARNING: f64 = 0.05;

/// A simultaneity tolerance larger than this fraction of the smallest slenderness α is a warning.
pub const SIMULTANEITY_WARNING: f64 = 1e-2;

/// The shortest time scale a ground motion may have (a period, or 1/f of a Ricker wavelet), as
/// a fraction of the structure's √(L/g): earthquakes are slower than their structures' rocking
/// by far (the bundled block: √(L/g) = 0.3255 s, so at most 31 kHz). The seated uplift test
/// samples each period 32 times, and the run's duration is bounded by `LONGEST_DURATION`
/// √(L/g), so the tests a run can take are bounded too.
pub const SHORTEST_GROUND_PERIOD: f64 = 1e-4;

/// The most rows a run's history may have (one per output interval): beyond, the run is
/// refused before it starts, as a history of tens of gigabytes fills a disk and never ends.
pub const MAX_HISTORY_ROWS: f64 = 1e9;

/// A history expected to exceed this size (bytes of `history.csv`, or of memory held by a run
/// that keeps its samples: both are about the same) is a warning, given before the run starts.
pub const HISTORY_SIZE_WARNING: f64 = 1e9;

/// Bytes of one history row: t, q, q̇ and the four energies as `{:e}` (at most about 23
/// characters with the comma), and each interface's state (`seated`, `+`, `-`, one per slot).
fn history_row_bytes(model: &Model) -> f64 {
    let numbers = 1 + 2 * model.dof() + 4;
    (23 * numbers + 7 * model.slot_count + 1) as f64
}

/// What an observer of [`simulate_observed`] tells the loop after a step.
#[derive(Debug)]
pub enum Flow {
    /// Go on.
    Continue,
    /// Stop here: the run is complete as far as the observer is concerned.
    Stop,
    /// Stop with this error (a sink that cannot write).
    Fail(SimulationError),
}

/// The event-driven simulation of `model` under `ground` from `initial`, step by step to the end,
/// a collapse or an error: the one loop every run goes through (`crr::run`, `crr simulate`, the
/// cases of a study). The samples are drained into `sink` after every step when `stream` (a sink
/// error stops the run), else kept in the trajectory; a percentage goes to stderr when
/// `progress`; a set `cancel` flag stops the run within one integration step of the request,
/// inside the current step where it is long ([`SimulationError::Cancelled`]), and so do more
/// than `max_samples` samples kept in memory ([`SimulationError::TooManySamples`]). An error before the first step is `Err`; one later comes
/// back with the trajectory computed until then.
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    model: &Model,
    ground: &GroundMotion,
    initial: &InitialState,
    params: &Parameters,
    sink: &mut dyn FnMut(&Samples) -> std::io::Result<()>,
    stream: bool,
    progress: bool,
    cancel: Option<&Cancel>,
    max_samples: Option<usize>,
) -> Result<(Trajectory, Option<SimulationError>), SimulationError> {
    let mut drain = |sim: &mut Simulation, _: &Result<StopReason, SimulationError>| {
        let cancelled = cancel.is_some_and(Cancel::is_cancelled);
        if cancelled {
            sim.record_final_sample();
        }
        if !stream {
            return if cancelled {
                Flow::Fail(SimulationError::Cancelled { t: sim.time() })
            } else if let Some(max) = max_samples.filter(|&m| sim.samples.len() > m) {
                Flow::Fail(SimulationError::TooManySamples { max, t: sim.time() })
            } else {
                Flow::Continue
            };
        }
        if cancelled {
            // The samples of the last step go out before the run stops.
            if let Err(e) = sink(&sim.drain_samples()) {
                return Flow::Fail(SimulationError::Parameter(format!(
                    "cannot write the history: {e}"
                )));
            }
            return Flow::Fail(SimulationError::Cancelled { t: sim.time() });
        }
        match sink(&sim.drain_samples()) {
            Ok(()) => Flow::Continue,
            Err(e) => Flow::Fail(SimulationError::Parameter(format!(
                "cannot write the history: {e}"
            ))),
        }
    };
    simulate_observed(model, ground, initial, params, progress, cancel, &mut drain)
}

/// [`simulate`] with an observer called after every step with the simulation and the step's
/// result: it may drain the samples, read the impacts, and stop the run ([`Flow`]) — Poincaré
/// sections keep their points and stop after enough crossings this way. The run ends at its
/// duration, a collapse, an error, or when the observer says so; an observer's error comes
/// first. A set `cancel` also stops a step from inside, within one integration step of the
/// request ([`Simulation::set_interrupt`]), with [`SimulationError::Cancelled`].
pub fn simulate_observed(
    model: &Model,
    ground: &GroundMotion,
    initial: &InitialState,
    params: &Parameters,
    progress: bool,
    cancel: Option<&Cancel>,
    observe: &mut dyn FnMut(&mut Simulation, &Result<StopReason, SimulationError>) -> Flow,
) -> Result<(Trajectory, Option<SimulationError>), SimulationError> {
    let mut sim = Simulation::new(model, ground, initial, params.clone())?;
    sim.set_interrupt(cancel.cloned());
    let total = params.duration;
    let mut shown = -1i64;
    let error = loop {
        let result = sim.step();
        let flow = observe(&mut sim, &result);
        match (result, flow) {
            (_, Flow::Fail(e)) => break Some(e),
            (Ok(StopReason::End(_)) | Ok(StopReason::Collapse(_)), _) => break None,
            (Err(e), _) => break Some(e),
            (Ok(_), Flow::Stop) => break None,
            (Ok(_), Flow::Continue) => {}
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
    Ok((sim.into_trajectory(), error))
}

fn method_name(a: &AnalysisSpec) -> &'static str {
    match a.method {
        crr_dynamics::MethodName::Dop853 => "dop853",
        crr_dynamics::MethodName::Dopri5 => "dopri5",
        crr_dynamics::MethodName::Rk4 => "rk4",
    }
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

impl Prepared {
    /// The summary of `t`, a run of this preparation; `stats` counts its samples, `error` is what
    /// stopped it early.
    pub fn summary(&self, t: &Trajectory, stats: &SampleStats, error: Option<&str>) -> Summary {
        let coordinates = t
            .coordinates
            .iter()
            .enumerate()
            .map(|(k, name)| {
                let alpha = coordinate_alpha(&self.model, k);
                CoordinateSummary {
                    name: name.clone(),
                    peak_abs: t.peak_abs[k],
                    alpha,
                    peak_over_alpha: alpha.map(|a| t.peak_abs[k] / a),
                }
            })
            .collect();
        let mut echo = self.file.clone();
        echo.gravity = self.model.gravity;
        let analysis = self.file.analysis.clone().unwrap_or_default();
        let pga = self.ground.pga();
        let p = &self.params;
        let gains: Vec<&ImpactRecord> = t.impacts.iter().filter(|i| i.energy_gain).collect();
        Summary {
            crr_version: env!("CARGO_PKG_VERSION").to_string(),
            completed: error.is_none(),
            error: error.map(str::to_string),
            model_file: self.path.display().to_string(),
            model: echo,
            record: self.record_file.as_ref().map(|r| RecordSummary {
                file: r.file.display().to_string(),
                format: r.format.name().to_string(),
                units: r.units.map(|u| u.name().to_string()),
                component: r.component.name().to_string(),
                scale: r.scale,
            }),
            ground_motion: GroundMotionSummary {
                pga: [pga.x, pga.y, pga.z],
                duration: finite(self.ground.duration()),
            },
            initial: InitialSummary {
                spec: self.file.initial.clone().unwrap_or_default(),
                q: self.initial.q.as_slice().to_vec(),
                qdot: self.initial.qdot.as_slice().to_vec(),
            },
            solver: SolverSettings {
                method: method_name(&analysis).to_string(),
                duration: p.duration,
                output_interval: p.output_interval,
                rtol: p.options.rtol,
                atol: p.options.atol,
                max_step: finite(p.options.h_max),
                rk4_step: analysis.rk4_step,
                seat_rate: p.seat_rate,
                min_impact_interval: p.min_impact_interval,
                simultaneity: p.simultaneity,
                max_impacts: p.max_impacts,
                collapse_drop: p.collapse_drop,
                friction: p.friction,
                hold_seated_at_impacts: p.hold_seated_at_impacts,
                hop_tolerance: p.hop_tolerance,
                stop_at_violation: p.stop_at_violation,
            },
            solver_stats: SolverStats {
                steps: t.solver_stats.steps,
                accepted: t.solver_stats.accepted,
                rejected: t.solver_stats.rejected,
                rhs_evaluations: t.solver_stats.rhs_evals,
            },
            end_time: t.end_time,
            samples: stats.rows,
            coordinates,
            impacts: t.impacts.len(),
            energy_lost_at_impacts: t.impacts.iter().map(|i| i.energy_lost).sum::<f64>(),
            impacts_with_energy_gain: gains.len(),
            warnings: warnings(self, t, stats, &gains),
            uplift_time: t.uplift_time,
            collapse: CollapseSummary {
                collapsed: t.collapse.is_some(),
                time: t.collapse.as_ref().map(|c| c.t),
                body: t.collapse.as_ref().map(|c| c.body.clone()),
            },
            energy_balance_error: t.energy_balance_error,
            energy_at_snaps: t.energy_at_snaps,
            hypothesis_violation: t.violation.as_ref().map(|v| ViolationSummary {
                time: v.t,
                interface: v.interface.clone(),
                kind: v.kind.clone(),
                normal_force: v.normal,
                friction_demand: finite(v.friction_demand),
                hop: v.hop.as_deref().cloned(),
            }),
            hops: HopsSummary {
                count: t.hops.len(),
                beyond_tolerance: t.hops.iter().filter(|h| !h.within(p.hop_tolerance)).count(),
                largest_separation: t.hops.iter().map(|h| h.separation).reduce(f64::max),
                largest_pull: t.hops.iter().map(|h| h.largest_pull).reduce(f64::max),
            },
        }
    }
}

/// The words of a `tension` violation that is a pull just after an impact, measured by the
/// motion with the face released (docs/simulation.md, "Hops").
fn hop_words(h: &crr_impact::simulation::Hop, tolerance: f64) -> String {
    if !h.opens {
        ", although released the face would not open (its tangential force holds it down): no \
         answer without sliding"
            .to_string()
    } else if h.closed {
        format!(
            "; released, the face would open by at most {:.1e} m and the bodies depart from \
             crr's motion by at most {:.1e} m before it lands {:.2e} s later (a hop: \
             `[analysis] hop_tolerance`, {} m here, accepts hops up to a length)",
            h.separation,
            h.departure,
            h.end - h.start,
            num(tolerance)
        )
    } else {
        format!(
            "; released, the bodies are not shown to land (the face open by {:.1e} m, the \
             bodies {:.1e} m from crr's motion when the measure stopped: at the run's end, a \
             change of the dynamic chain, a departure past 1e-3 of the model's size or the \
             tolerance, or a gap closing while the chain still pulled)",
            h.separation, h.departure
        )
    }
}

/// The warning for a planar model (every interface a hinge about one common axis a,
/// [`Model::planar_axis`]) under a ground motion with a part along a: its hinges carry that part
/// bilaterally, so the run answers for the in-plane part only. Where one component acts along a
/// (a coordinate axis, as in every planar model the project bundles) the part's peak is that
/// component's |aₖ| PGAₖ, quoted as the peak; where several do, their peaks need not coincide and
/// Σₖ |aₖ| PGAₖ is quoted as a bound. None when the model is not planar or nothing acts along a.
fn out_of_plane_ground_motion(model: &Model, ground: &GroundMotion) -> Option<String> {
    let axis = model.planar_axis()?;
    let pga = ground.pga();
    let parts = axis.abs().component_mul(&pga);
    let along = parts.sum();
    // Below 1e-12 g the part is round-off of a turned axis.
    let negligible = 1e-12 * model.gravity;
    (along > negligible).then(|| {
        let acting = parts.iter().filter(|&&p| p > negligible).count();
        let peak = if acting == 1 { "peak" } else { "peak at most" };
        format!(
            "the ground motion has a part along the hinges' common axis ({:.3}, {:.3}, {:.3}) \
             ({peak} {:.3e} m/s², {:.3} g): the hinges of a planar model carry it \
             bilaterally, so this run answers for the motion in the plane normal to that axis \
             only; out-of-plane rocking, overturning or sliding is outside the model",
            axis.x,
            axis.y,
            axis.z,
            along,
            along / model.gravity
        )
    })
}

/// Why a planar model (every interface a hinge about one common axis a,
/// [`Model::planar_axis`]) cannot be driven along the ground-motion component `axis` alone: a
/// lies along it (within 1e-9 rad, as `crr check` answers nothing there), so its hinges carry
/// the whole load bilaterally and every run stays at rest, an answer about the model, not the
/// structure. `crr study` and `crr poincare` refuse such a component (a sweep or a map of "no
/// motion" would read as safety); `crr simulate`, whose record may have other components, warns
/// (its summary's warning on the part along the axis). None where `axis` has a part in the
/// plane of motion.
pub fn component_along_the_hinges(model: &Model, axis: Axis) -> Option<String> {
    let mut d = Vector3::zeros();
    d[axis.index()] = 1.0;
    let a = model.planar_axis()?;
    (crate::analysis::static_multiplier::out_of_plane(model, &d) == Some(1.0)).then(|| {
        format!(
            "the ground motion along {axis} lies along the hinges' common axis ({:.3}, {:.3}, \
             {:.3}) of this planar model, whose hinges carry it bilaterally: every run would \
             stay at rest, which says nothing of the structure (out-of-plane rocking, \
             overturning or sliding is outside a planar model); drive a component in its plane, \
             or model the structure in 3D with rocking bases",
            a.x + 0.0,
            a.y + 0.0,
            a.z + 0.0
        )
    })
}

/// The warning for hinges in a model that is not planar: a hinge is a line, which holds any
/// couple out of its plane and any force along its axis, so the run excludes tipping out of
/// the hinges' planes at those joints (`crr check` names them where λ uses that,
/// `hinges_out_of_plane`). None for a planar model or one without hinges.
fn hinges_in_three_dimensions(model: &Model) -> Option<String> {
    if model.planar_axis().is_some() {
        return None;
    }
    let hinges: Vec<&str> = model
        .interfaces
        .iter()
        .filter(|i| matches!(i.kind, InterfaceKind::Hinge { .. }))
        .map(|i| i.name.as_str())
        .collect();
    (!hinges.is_empty()).then(|| {
        format!(
            "the model is not planar but has hinges ({}): a hinge is a line that holds any \
             couple out of its plane and any force along its axis, so the run excludes tipping \
             out of the hinges' planes at those joints; model them as rocking bases where that \
             matters",
            hinges.join(", ")
        )
    })
}

fn num(x: f64) -> String {
    format!("{x:e}")
}

/// The rocking bases that rocked on a corner (both tilts turned) at some output sample, with the
/// first such time. Their two tilts are applied in series, `.1` about the edge corner 0 →
/// corner 1 and then `.2`, with no twist about the face normal: R(e₁, φ₁)R(e₂, φ₂) and
/// R(e₂, φ₂)R(e₁, φ₁) differ by a twist of order φ₁φ₂, so on a corner the motion depends at
/// second order on the corner a face's list starts from (a 0.4 × 0.6 × 2 m block under two
/// sines overturned with one order and rocked on with the other, both without a warning until
/// this one). A seat that may twist (`twist = true`) has no such constraint and is left out.
fn rocking_on_a_corner(model: &Model, stats: &SampleStats) -> Option<String> {
    let first: Vec<(f64, &str)> = stats
        .corners
        .iter()
        .filter_map(|c| Some((c.first_seen?, model.interfaces[c.interface].name.as_str())))
        .collect();
    let (t0, _) = *first.iter().min_by(|x, y| x.0.total_cmp(&y.0))?;
    let mut names: Vec<&str> = first.iter().map(|(_, n)| *n).collect();
    let more = names.len().saturating_sub(3);
    names.truncate(3);
    Some(format!(
        "from t = {} s (an output sample) {}{} rocked on a corner (both tilts turned): a \
         rocking base's two tilts turn in series, .1 about the edge from its corner 0 to corner \
         1 and then .2, with no twist about the face normal, and the two orders differ at second \
         order (φ₁φ₂) on a corner and in the rate at which a base leaves an edge for a corner, \
         so the motion depends on the corner the face's list starts from; near a threshold \
         (overturning, the timing of an impact) the response may change: run the model with the \
         corners listed from the next corner to see how much (docs/model-format.md, \
         \"Rocking bases: the order of the two tilts\")",
        num(t0),
        names.join(", "),
        if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        }
    ))
}

/// A run that ends before its ground motion does, without a collapse: the motion after its
/// duration is not simulated, so a collapse it would cause is not seen (a 20 s record run for
/// 5 s wrote `collapse: no` for a block that overturns at 6.9 s, with no warning). An endless
/// motion (a sine, a constant) has no end to reach: its run ends where the user says. A run
/// stopped earlier by an error says so in its error.
fn motion_cut_short(p: &Prepared, t: &Trajectory, stats: &SampleStats) -> Option<String> {
    let motion_end = p.ground.duration();
    let duration = p.params.duration;
    let reached = t.end_time >= duration * (1.0 - 1e-12);
    if !reached || t.collapse.is_some() {
        return None;
    }
    if !(motion_end.is_finite() && motion_end > duration) {
        return still_overturning_at_the_end(p, stats);
    }
    Some(format!(
        "the run ends at t = {duration} s, before its ground motion does (at t = {motion_end} \
         s): the motion after {duration} s is not simulated, so a collapse it would cause is \
         not seen and the run reads as not collapsed; leave the duration out (it is then the \
         motion's end + 5 s) or make it at least {motion_end} s"
    ))
}

/// A run that ends, without a collapse, with a coordinate past its joint's slenderness α
/// (`coordinate_alpha`: a block's atan(b/h)) and turning away from rest: the structure is still
/// on its way over when the run stops, so whether it collapses is not known (the bundled block
/// under one sine cycle of 5 m/s² and 1 s, run for 2 s, ended at θ = 1.57 α turning outward
/// and read "no collapse"; run on, it overturns at 2.156 s). A structure rocking within its α
/// at the end is not reported: this test does not decide that motion's outcome.
fn still_overturning_at_the_end(p: &Prepared, stats: &SampleStats) -> Option<String> {
    let last = stats.last.as_ref().filter(|l| !l.seated)?;
    let (k, ratio) = (0..p.model.dof())
        .filter_map(|k| {
            let alpha = coordinate_alpha(&p.model, k)?;
            let (q, w) = (*last.q.get(k)?, *last.qdot.get(k)?);
            (q.abs() > alpha && q * w > 0.0).then_some((k, q.abs() / alpha))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(format!(
        "the run ends at t = {} s with {} at {ratio:.3} times its joint's slenderness α \
         (atan(b/h), the overturning angle of a block on its base) and turning away from rest: \
         the structure is still on its way over, so whether it collapses is not known and the \
         run reads as not collapsed; run it longer (`--duration`)",
        last.t, p.model.coords[k].name
    ))
}

/// What a user must know before trusting the results (`warnings` in summary.json, also printed
/// on stderr by `crr simulate`).
fn warnings(
    p: &Prepared,
    t: &Trajectory,
    stats: &SampleStats,
    gains: &[&ImpactRecord],
) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(cut) = motion_cut_short(p, t, stats) {
        out.push(cut);
    }
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
    // The snaps against the losses over the part of the run inside the model (until the
    // monitor's first violation): past a flight the energies grow and would hide them.
    let x = &t.snaps_and_losses;
    let snap_floor = 1e-12 * p.model.total_mass() * p.model.gravity * p.model.size;
    if x.snaps > (crr_impact::simulation::SNAP_ENERGY_FRACTION * x.lost.abs()).max(snap_floor) {
        out.push(format!(
            "until t = {} s the snaps of joints to their seats moved {:.3e} J against {:.3e} J \
             dissipated by the impacts and the regularised Dirac forces (more than {} % of it): the motion is small against \
             `simultaneity` ({} rad, the angle within which joints impact and seat together), so \
             the energy booked as dissipated is partly the idealisation's; lower it",
            x.t,
            x.snaps,
            x.lost,
            100.0 * crr_impact::simulation::SNAP_ENERGY_FRACTION,
            num(p.params.simultaneity)
        ));
    }
    let loops = &t.loop_residual;
    if loops.largest > LOOP_RESIDUAL_WARNING * p.model.gravity {
        out.push(format!(
            "at t = {} s the closed-chain solve left the loops open at acceleration level by \
             {:.3e} m/s² ({:.1e} g; rows nearly dependent near a hyperstatic seat, taken as \
             dependent): contact decisions whose rates lie below that are within the solve's \
             error (docs/simulation.md, Limitations)",
            loops.t,
            loops.largest,
            loops.largest / p.model.gravity
        ));
    }
    if let Some(check) = &t.doubtful_check {
        out.push(format!(
            "at t = {} s the contact program found that {} open(s), and the closed-chain solve \
             that checks its releases, which left the loops open at acceleration level by \
             {:.3e} m/s² ({:.1e} g; rows nearly dependent near a hyperstatic seat, taken as \
             dependent), kept them seated: the decisions from then on rest on that solve's \
             word (docs/simulation.md, Limitations)",
            check.t,
            check.interfaces.join(", "),
            check.residual,
            check.residual / p.model.gravity
        ));
    }
    if let Some(held) = &t.held_on_search {
        let a = nalgebra::Vector3::from(held.load);
        let d = a / a.norm();
        out.push(format!(
            "at t = {} s the structure at rest was held under a ground acceleration of {:.4} m/s² \
             along ({:.3}, {:.3}, {:.3}) on a static multiplier that is not exhaustive: along \
             that direction it has more sets of joints that may open and slide than a run tries \
             ({} along an axis, {} along another direction), or a program of the pass over them \
             did not solve; the search found none below the load, but a lower mechanism may \
             exist and the structure may leave rest earlier (`crr check --direction {:.6},{:.6},{:.6}` tries up to {}; \
             docs/simulation.md, \"The exhaustive pass\")",
            held.t,
            a.norm(),
            d.x + 0.0,
            d.y + 0.0,
            d.z + 0.0,
            crr_impact::statics::REST_EXHAUSTIVE_SETS,
            crr_impact::statics::REST_DIRECTION_SETS,
            d.x + 0.0,
            d.y + 0.0,
            d.z + 0.0,
            crr_impact::statics::EXHAUSTIVE_SETS,
        ));
    }
    if let Some(corners) = rocking_on_a_corner(&p.model, stats) {
        out.push(corners);
    }
    if let Some(part) = out_of_plane_ground_motion(&p.model, &p.ground) {
        out.push(part);
    }
    if let Some(hinges) = hinges_in_three_dimensions(&p.model) {
        out.push(hinges);
    }
    if let Some(tilt) = crate::analysis::static_multiplier::gravity_along_axis_warning(&p.model) {
        out.push(tilt);
    }
    out.extend(crate::analysis::contact_geometry::contact_geometry_warnings(&p.model));
    out.extend(crate::analysis::contact_geometry::bodies_held_by_shear_alone(&p.model));
    out.extend(crate::analysis::body_sizes::bodies_too_large(&p.model));
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
                "would need tension (N = {:.4e} N): the bodies separate (flight){}",
                v.normal,
                v.hop
                    .as_ref()
                    .map(|h| hop_words(h, p.params.hop_tolerance))
                    .unwrap_or_default()
            )
        } else if v.kind == "outside_face" {
            format!(
                "is held seated with its contact's resultant outside its face (an edge of the \
                 face would pull with N = {:.4e} N): the joint should be rocking, which the \
                 engine's choice of the joints that open missed",
                v.normal
            )
        } else if v.kind == "impulse_tension" {
            format!(
                "would need tension in the impulse of a landing or of an impact (a normal \
                 impulse of {:.4e} N s at least): a contact held through it would leave its \
                 support (the bodies it holds would jump)",
                v.normal
            )
        } else if v.kind == "lift_off" {
            "is lifted off its support by the contact program, but the model without it drives \
             it back into its support, and with it closed no joint opens: crr finds no motion \
             that keeps every contact compressive (the program's own needs the face to slide \
             while it lifts)"
                .to_string()
        } else if v.kind == "sliding_unloaded" {
            "slides while keeping contact, carrying nothing, in a mechanism whose multiplier \
             the ground acceleration exceeds (found by the search for joints that open and \
             slide, `crr check`), and the motion without it presses its face (the face would \
             have to slide under compression, as between two equal blocks tipping together); \
             the CRR chain, whose joints do not slide, holds the structure at rest by shear \
             across it with no compression, which no friction gives: a real structure may move \
             from here (docs/simulation.md, \"Joints that open may slide\")"
                .to_string()
        } else {
            if v.friction_demand.is_finite() {
                format!(
                    "needs friction |F_t|/N = {:.4} above μ: it slides",
                    v.friction_demand
                )
            } else {
                "needs a friction coefficient above 1000, or holds only by a contact that \
                 carries nothing: it slides"
                    .to_string()
            }
        };
        out.push(format!(
            "the rigid-contact hypotheses fail at t = {} s: interface \"{}\" {what}; the results \
             after that time are outside crr's model",
            v.t, v.interface
        ));
    }
    out.extend(p.history_size_warning());
    out.extend(p.ground.record_warnings());
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

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
            released: Vec::new(),
        }
    }

    fn single_block() -> ModelInput {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/single_block.toml");
        ModelInput::read(path).unwrap()
    }

    #[test]
    fn a_record_given_as_samples_drives_the_run_and_sets_the_default_duration() {
        let model = single_block();
        let record = Record::from_samples(vec![0.0, 1.0, 2.0], vec![0.0, 3.0, 0.0]).unwrap();
        let options = RunOptions {
            records: vec![RecordSamples {
                component: Axis::X,
                record,
                scale: 2.0,
            }],
            ..Default::default()
        };
        let p = prepare(&model, &options).unwrap();
        // 3 m/s² peak × 2.
        assert_eq!(p.ground.pga().x, 6.0);
        // The record ends at 2 s: 5 s more.
        assert_eq!(p.params.duration, 2.0 + 5.0);
    }

    #[test]
    fn overrides_replace_the_tables_and_a_bad_duration_is_refused() {
        let model = single_block();
        let options = RunOptions {
            initial: Some(InitialSpec::default()),
            duration: Some(0.5),
            ..Default::default()
        };
        let p = prepare(&model, &options).unwrap();
        assert_eq!(p.params.duration, 0.5);
        assert_eq!(p.file.initial, Some(InitialSpec::default()));
        assert!(p.initial.q.iter().all(|q| *q == 0.0));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let options = RunOptions {
                duration: Some(bad),
                ..Default::default()
            };
            let e = prepare(&model, &options).unwrap_err().to_string();
            assert!(e.contains("duration must be a positive number"), "{e}");
        }
    }

    #[test]
    fn a_history_larger_than_the_limit_is_a_warning_before_the_run() {
        let mut p = prepare(&single_block(), &RunOptions::default()).unwrap();
        // 10 s at 0.01 s: 1 001 rows of about 0.3 kB: no warning.
        assert_eq!(p.history_estimate().0, 1001.0);
        assert!(p.history_size_warning().is_none());
        // output_interval = 1e-9 s: 1e10 rows, terabytes.
        p.params.output_interval = 1e-9;
        let w = p.history_size_warning().expect("a warning");
        assert!(
            w.contains("1.000e10 rows") && w.contains("output_interval = 1e-9 s"),
            "{w}"
        );
        let t = Trajectory::empty(&p.model);
        let all = warnings(&p, &t, &SampleStats::default(), &[]);
        assert!(all.contains(&w), "{all:?}");
    }

    #[test]
    fn an_energy_gain_is_a_warning_naming_the_worst_impact() {
        // No law of crr raises T for r ≤ 1, so the case is built by hand.
        let p = prepare(&single_block(), &RunOptions::default()).unwrap();
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
