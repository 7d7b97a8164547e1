//! `crr poincare`: Poincaré sections of a model under harmonic ground motion, and their sweeps
//! (bifurcation diagrams against the amplitude or the frequency, basins of initial conditions).
//! Documented in `docs/poincare.md`.
//!
//! **What is sampled.**
//! - *Stroboscopic section* (the default): the model under the harmonic ground acceleration
//!   a_g(t) = A sin(2πF t + φ) on one component (A in m/s², replacing the model's own ground
//!   motion) is sampled at t = kT, T = 1/F, exactly: the [`Simulation`] runs with
//!   `output_interval = T`, so its output samples are evaluated on the integrator's dense output
//!   at the floating-point times `(k as f64)·T`; the extra samples it records just before and
//!   after impacts (and at collapse) are left out by keeping only the samples whose time is
//!   bit-for-bit `(k as f64)·T` for the next k. The first M periods (the transient) are dropped;
//!   the N points k = M+1, …, M+N are kept.
//! - *Crossing section* (`--section COORD`, or `--amplitude 0`): the states where coordinate
//!   COORD crosses 0 from negative to positive. A rocking coordinate crosses 0 only at its impacts,
//!   so the point is the **post-impact** state of every impact of COORD whose rate is positive
//!   both before and after it (the angle goes on from the negative side to the positive one). The
//!   first M crossings are dropped, the next N kept.
//!
//! A section runs through the loop of every run ([`simulate_observed`]), whose observer drains
//! the samples after every step ([`Simulation::drain_samples`]) and clears the impact log, so
//! memory stays flat however many periods are run.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use crr_dynamics::ground_motion::{
    Axis, ComponentSpec, GroundMotion, STANDARD_GRAVITY, SignalSpec, SineSpec,
};
use crr_dynamics::{InitialSpec, InitialState, solve_initial};
use crr_impact::simulation::{
    Collapse, Parameters, Simulation, SimulationError, SlotState, StopReason, check_initial_state,
};
use crr_kinematics::Model;

use crate::Error;
use crate::analysis::simulation::{Cancel, Flow, simulate_observed};
use crate::input::model_file::{ModelFile, load_model};

/// Two section points are the same point when every angle differs by at most this fraction of the
/// largest |angle| of the section, and every rate by this fraction of the largest |rate| (used by
/// [`distinct_points`] and [`detect_period`]).
pub const SAME_POINT_TOLERANCE: f64 = 1e-6;

/// The longest period (in forcing cycles, or crossings) [`detect_period`] looks for.
pub const MAX_DETECTED_PERIOD: usize = 64;

/// The default time limit of a crossing section (s).
pub const DEFAULT_CROSSING_DURATION: f64 = 1000.0;

/// The harmonic ground acceleration a_g(t) = A sin(2πF t + φ) on one component.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Forcing {
    /// A (m/s², ≥ 0); 0 is no ground motion.
    pub amplitude: f64,
    /// F (Hz, > 0); T = 1/F.
    pub frequency: f64,
    /// φ (rad).
    pub phase: f64,
    /// The component driven.
    pub axis: Axis,
}

impl Forcing {
    /// The period T = 1/F (s), computed as the ground motion and the sampling compute it.
    pub fn period(&self) -> f64 {
        1.0 / self.frequency
    }

    /// The ground motion: the sine alone (no other component), or none when A = 0.
    pub fn ground_motion(&self) -> Result<GroundMotion, String> {
        if self.amplitude == 0.0 {
            return Ok(GroundMotion::none());
        }
        let sine = SineSpec {
            amplitude: self.amplitude,
            period: None,
            frequency: Some(self.frequency),
            phase: self.phase,
            cycles: None,
            start: 0.0,
        };
        GroundMotion::none()
            .with_component(
                self.axis,
                &ComponentSpec::new(SignalSpec::Sine(sine)),
                Path::new("."),
            )
            .map_err(|e| e.to_string())
    }
}

/// Which states make the section.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SectionKind {
    /// t = kT exactly.
    Stroboscopic,
    /// Post-impact states where this coordinate crosses 0 from negative to positive.
    Crossing(usize),
}

/// The settings of one section.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectionSettings {
    /// The ground motion.
    pub forcing: Forcing,
    /// What is sampled.
    pub kind: SectionKind,
    /// M: periods (stroboscopic) or crossings dropped first.
    pub transient: usize,
    /// N: points kept.
    pub points: usize,
    /// Time limit of a crossing section (s); a stroboscopic section runs (M + N)·T.
    pub max_time: f64,
}

/// One point of a section.
#[derive(Clone, Debug, PartialEq)]
pub struct SectionPoint {
    /// k: the forcing cycle (t = kT) or the crossing's number (1 = the first crossing).
    pub k: usize,
    /// Time (s).
    pub t: f64,
    /// q (rad).
    pub q: Vec<f64>,
    /// q̇ (rad/s).
    pub qdot: Vec<f64>,
    /// The state of every slot.
    pub states: Vec<SlotState>,
}

/// A computed section.
#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    /// The kept points, in time order.
    pub points: Vec<SectionPoint>,
    /// The collapse (overturning) that ended the section, if any.
    pub collapse: Option<Collapse>,
    /// Time reached (s).
    pub end_time: f64,
    /// Every slot seated at the end and, for a stroboscopic section, at every kept point (the
    /// structure at rest on its seats).
    pub at_rest: bool,
    /// The simulation error that stopped the run early, if any.
    pub error: Option<String>,
    /// The first failure of the rigid-contact hypotheses (a contact in tension: flight; or
    /// sliding when `[analysis].friction` is given), checked at the simulation's samples and
    /// impacts; the points after it are outside crr's model.
    pub violation: Option<crr_impact::monitor::Violation>,
}

/// The model's settings and the length of each run the section takes are input errors found
/// before any run (a run of 5e6 s failed as a run stopping early, with exit 1, blaming
/// `[analysis] duration`): the longest is (transient + periods)/F for a stroboscopic section and
/// `--duration` (or its default) for a crossing one, at most `LONGEST_DURATION` times the
/// structure's time scale √(L/g).
fn check_run_length(
    model: &Model,
    params: &Parameters,
    kind: SectionKind,
    section_time: f64,
    opts: &PoincareOptions,
) -> Result<(), String> {
    let mut settings = params.clone();
    settings.duration = 0.0;
    crr_impact::simulation::check_physical_bounds(model, &settings).map_err(|e| e.to_string())?;
    let (longest, what) = match kind {
        SectionKind::Stroboscopic => (section_time, "(transient + periods) / F"),
        _ => (
            opts.duration.unwrap_or(DEFAULT_CROSSING_DURATION),
            "--duration, or its default",
        ),
    };
    let time_scale = (model.size / model.gravity).sqrt();
    let bound = crr_impact::simulation::LONGEST_DURATION * time_scale;
    if longest.is_nan() || longest > bound {
        return Err(format!(
            "each run would last {longest:e} s ({what}): more than {:e} times the structure's \
             time scale √(L/g) = {time_scale:.4} s, beyond which an instant is located more \
             coarsely than the impacts' own spacing near rest; lower --periods, --transient or \
             --duration",
            crr_impact::simulation::LONGEST_DURATION
        ));
    }
    Ok(())
}

/// Runs one section of `model` from `initial`; `params` gives the solver settings (its duration
/// and output interval are replaced). Never panics on a failing run: the error is in
/// [`Section::error`] with the points computed until then.
pub fn run_section(
    model: &Model,
    initial: &InitialState,
    params: &Parameters,
    settings: &SectionSettings,
) -> Section {
    run_section_until(model, initial, params, settings, None)
}

/// [`run_section`] that `cancel` stops within one integration step: the section keeps the
/// points until then and its error says where it was interrupted (a section not yet started
/// when `cancel` was set does not start).
pub fn run_section_until(
    model: &Model,
    initial: &InitialState,
    params: &Parameters,
    settings: &SectionSettings,
    cancel: Option<&Cancel>,
) -> Section {
    let mut section = Section {
        points: Vec::new(),
        collapse: None,
        end_time: 0.0,
        at_rest: false,
        error: None,
        violation: None,
    };
    if cancel.is_some_and(Cancel::is_cancelled) {
        section.error = Some(NOT_STARTED.into());
        return section;
    }
    let ground = match settings.forcing.ground_motion() {
        Ok(g) => g,
        Err(e) => {
            section.error = Some(e);
            return section;
        }
    };
    let mut params = params.clone();
    let period = settings.forcing.period();
    let last_k = settings.transient + settings.points;
    match settings.kind {
        SectionKind::Stroboscopic => {
            params.output_interval = period;
            params.duration = last_k as f64 * period;
        }
        SectionKind::Crossing(_) => {
            params.duration = settings.max_time;
            // Samples are not used: as few as the streaming allows.
            params.output_interval = settings.max_time;
        }
    }
    let max_impacts = params.max_impacts;
    let mut next_k = 0usize;
    let mut crossings = 0usize;
    let mut impacts = 0usize;
    // The slot states after the last step (the section is at rest when all are seated).
    let mut last_states = Vec::new();
    let mut observe = |sim: &mut Simulation, result: &Result<StopReason, SimulationError>| {
        let samples = sim.drain_samples();
        if settings.kind == SectionKind::Stroboscopic {
            for s in &samples {
                // Only the samples at exactly (k as f64)·T: the impact and collapse samples
                // fall elsewhere (an impact exactly at kT gives its pre-impact sample first).
                if s.t == next_k as f64 * period {
                    if next_k > settings.transient {
                        section.points.push(SectionPoint {
                            k: next_k,
                            t: s.t,
                            q: s.q.to_vec(),
                            qdot: s.qdot.to_vec(),
                            states: s.states.to_vec(),
                        });
                    }
                    next_k += 1;
                }
            }
        }
        let terminal = match result {
            Ok(StopReason::End(_)) | Err(_) => true,
            Ok(StopReason::Collapse(c)) => {
                section.collapse = Some(c.clone());
                true
            }
            Ok(StopReason::Impact(i)) => {
                impacts += 1;
                if let SectionKind::Crossing(c) = settings.kind
                    && let Some(record) = sim.impacts.get(*i)
                    && let Some(j) = record.slots.iter().position(|&s| s == c)
                {
                    let qdot = sim.qdot();
                    let before = record.rates_before.get(j).copied().unwrap_or(0.0);
                    if before > 0.0 && qdot[c] > 0.0 {
                        crossings += 1;
                        if crossings > settings.transient {
                            section.points.push(SectionPoint {
                                k: crossings,
                                t: sim.time(),
                                q: sim.q().iter().copied().collect(),
                                qdot: qdot.iter().copied().collect(),
                                states: sim.states(),
                            });
                        }
                    }
                }
                false
            }
            Ok(_) => false,
        };
        // The log is not needed here: cleared so that memory stays flat.
        sim.impacts.clear();
        sim.peaks.clear();
        // The states are read only where the run ends (no allocation per step).
        if terminal {
            last_states = sim.states();
            return Flow::Continue;
        }
        if impacts > max_impacts {
            section.error = Some(format!(
                "more than {max_impacts} impacts: raise analysis.max_impacts or check the \
                 seating parameters"
            ));
            last_states = sim.states();
            return Flow::Stop;
        }
        if let SectionKind::Crossing(_) = settings.kind {
            if crossings >= last_k {
                last_states = sim.states();
                return Flow::Stop;
            }
            // Seated with no ground motion: nothing moves again.
            if ground.is_none() {
                let states = sim.states();
                if states.iter().all(|s| *s == SlotState::Seated) {
                    last_states = states;
                    return Flow::Stop;
                }
            }
        }
        Flow::Continue
    };
    let (trajectory, error) = match simulate_observed(
        model,
        &ground,
        initial,
        &params,
        false,
        cancel,
        &mut observe,
    ) {
        Ok(run) => run,
        Err(e) => {
            section.error = Some(e.to_string());
            return section;
        }
    };
    if let Some(e) = error {
        section.error = Some(e.to_string());
    }
    // A start beyond the point of no return is a collapse at t = 0 that `step` never reports.
    if section.collapse.is_none() {
        section.collapse = trajectory.collapse.clone();
    }
    section.violation = trajectory.violation.clone();
    section.end_time = trajectory.end_time;
    // At rest: seated at the end and, for a stroboscopic section, at every kept point (a forced
    // orbit with seated phases may end in one of them without being at rest).
    section.at_rest = last_states.iter().all(|s| *s == SlotState::Seated)
        && (settings.kind != SectionKind::Stroboscopic
            || section
                .points
                .iter()
                .all(|p| p.states.iter().all(|s| *s == SlotState::Seated)));
    section
}

/// The scales of a section: the largest |angle| and |rate| over its points (at least 1e-300).
fn scales(points: &[SectionPoint]) -> (f64, f64) {
    let mut a: f64 = 1e-300;
    let mut r: f64 = 1e-300;
    for p in points {
        a = p.q.iter().fold(a, |m, v| m.max(v.abs()));
        r = p.qdot.iter().fold(r, |m, v| m.max(v.abs()));
    }
    (a, r)
}

fn same(a: &SectionPoint, b: &SectionPoint, scales: (f64, f64), tol: f64) -> bool {
    a.q.iter()
        .zip(&b.q)
        .all(|(x, y)| (x - y).abs() <= tol * scales.0)
        && a.qdot
            .iter()
            .zip(&b.qdot)
            .all(|(x, y)| (x - y).abs() <= tol * scales.1)
}

/// The number of distinct points of a section: points whose every angle (rate) differs by at most
/// `tol` times the section's largest |angle| (|rate|) count once.
pub fn distinct_points(points: &[SectionPoint], tol: f64) -> usize {
    let s = scales(points);
    let mut reps: Vec<&SectionPoint> = Vec::new();
    for p in points {
        if !reps.iter().any(|r| same(r, p, s, tol)) {
            reps.push(p);
        }
    }
    reps.len()
}

/// The smallest P ≤ [`MAX_DETECTED_PERIOD`] such that every point equals the one P later (same
/// test as [`distinct_points`]), when the section has at least 2P points; None otherwise.
pub fn detect_period(points: &[SectionPoint], tol: f64) -> Option<usize> {
    let s = scales(points);
    (1..=MAX_DETECTED_PERIOD)
        .take_while(|p| 2 * p <= points.len())
        .find(|&p| (0..points.len() - p).all(|i| same(&points[i], &points[i + p], s, tol)))
}

/// What happens to one case of a basins grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// At rest on its seats at the end of the run (every slot seated).
    Settles,
    /// Still moving at the end, without overturning.
    Orbits,
    /// Overturned (collapse).
    Overturns,
    /// The run or the initial state failed.
    Fails,
}

impl Outcome {
    /// The name written in basins.csv.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Settles => "settles",
            Outcome::Orbits => "orbits",
            Outcome::Overturns => "overturns",
            Outcome::Fails => "fails",
        }
    }

    /// The outcome of a section.
    pub fn of(section: &Section) -> Self {
        if section.collapse.is_some() {
            Outcome::Overturns
        } else if section.error.is_some() {
            Outcome::Fails
        } else if section.at_rest {
            Outcome::Settles
        } else {
            Outcome::Orbits
        }
    }
}

/// An evenly spaced range `start:end:count` (count ≥ 1; one value is `start`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// First value.
    pub start: f64,
    /// Last value.
    pub end: f64,
    /// Number of values.
    pub count: usize,
}

impl Range {
    /// The values, start + (end − start)·i/(count − 1).
    pub fn values(&self) -> Vec<f64> {
        if self.count == 1 {
            return vec![self.start];
        }
        (0..self.count)
            .map(|i| {
                if i + 1 == self.count {
                    self.end
                } else {
                    self.start + (self.end - self.start) * i as f64 / (self.count - 1) as f64
                }
            })
            .collect()
    }
}

/// Parses an acceleration in m/s², or in standard g (9.80665 m/s²) with a trailing `g`
/// (`0.3g`). Errors name `option`.
pub fn parse_acceleration(text: &str, option: &str) -> Result<f64, String> {
    let t = text.trim();
    let (number, factor) = match t.strip_suffix('g').or_else(|| t.strip_suffix('G')) {
        Some(n) => (n.trim(), STANDARD_GRAVITY),
        None => (t, 1.0),
    };
    let v: f64 = number.parse().map_err(|_| {
        format!("{option}: `{text}` is not a number (an acceleration in m/s², or in g as `0.3g`)")
    })?;
    let v = v * factor;
    if !v.is_finite() || v < 0.0 {
        return Err(format!(
            "{option} must be a finite acceleration ≥ 0 (m/s²), got {text}"
        ));
    }
    Ok(v)
}

/// Most points of one range (`--amplitudes`, `--frequencies`, each axis of `--grid`): each is a
/// whole run, and their results are held until written.
pub const MAX_RANGE_POINTS: usize = 100_000;

/// Most cases of a basins grid (angle points × rate points).
pub const MAX_GRID_CASES: usize = 1_000_000;

/// Most section points or transient periods (`--periods`, `--transient`): a run keeps every
/// section point.
pub const MAX_PERIODS: usize = 10_000_000;

/// The most section points a run keeps over all its cases (a sweep's cases × `--periods`).
pub const MAX_KEPT_POINTS: usize = 10_000_000;

/// Longest simulated time of one run, (transient + periods)/F (s).
pub const MAX_SECTION_TIME: f64 = 1e7;

/// Parses `start:end:count`, each endpoint with `value` (which names the option in its errors).
pub fn parse_range(
    text: &str,
    option: &str,
    value: impl Fn(&str) -> Result<f64, String>,
) -> Result<Range, String> {
    let parts: Vec<&str> = text.split(':').collect();
    let [a, b, n] = parts[..] else {
        return Err(format!(
            "{option} must be START:END:COUNT (e.g. 1:3:21), got `{text}`"
        ));
    };
    let count: usize = n.trim().parse().map_err(|_| {
        format!("{option}: the count `{n}` is not a whole number (START:END:COUNT)")
    })?;
    if count == 0 {
        return Err(format!(
            "{option}: the count must be at least 1, got 0 (START:END:COUNT)"
        ));
    }
    if count > MAX_RANGE_POINTS {
        return Err(format!(
            "{option}: the count {count} is more than {MAX_RANGE_POINTS} points (START:END:COUNT): \
             each point is a whole run"
        ));
    }
    Ok(Range {
        start: value(a)?,
        end: value(b)?,
        count,
    })
}

/// Parses a finite number; errors name `option`.
pub fn parse_finite(text: &str, option: &str) -> Result<f64, String> {
    let v: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("{option}: `{text}` is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{option} must be finite, got {text}"))
    }
}

/// Parses a frequency (Hz, finite, > 0); errors name `option`.
pub fn parse_frequency(text: &str, option: &str) -> Result<f64, String> {
    let v = parse_finite(text, option)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{option} must be a frequency > 0 (Hz), got {text}"))
    }
}

/// The sweep of `--amplitudes A0:A1:N` (m/s², or g as `0.1g`), `--frequencies F0:F1:N` (Hz) or
/// `--grid T0:T1:N,W0:W1:M` (rad × rad/s), at most one of them given; none: [`Sweep::None`].
/// Errors name the option.
pub fn parse_sweep(
    amplitudes: Option<&str>,
    frequencies: Option<&str>,
    grid: Option<&str>,
) -> Result<Sweep, String> {
    match (amplitudes, frequencies, grid) {
        (None, None, None) => Ok(Sweep::None),
        (Some(r), None, None) => Ok(Sweep::Amplitudes(parse_range(r, "--amplitudes", |v| {
            parse_acceleration(v, "--amplitudes")
        })?)),
        (None, Some(r), None) => Ok(Sweep::Frequencies(parse_range(r, "--frequencies", |v| {
            parse_frequency(v, "--frequencies")
        })?)),
        (None, None, Some(g)) => {
            let Some((angle, rate)) = g.split_once(',') else {
                return Err(format!(
                    "--grid must be T0:T1:N,W0:W1:M (angles in rad, rates in rad/s), got `{g}`"
                ));
            };
            Ok(Sweep::Grid {
                angle: parse_range(angle, "--grid (angles)", |v| {
                    parse_finite(v, "--grid (angles)")
                })?,
                rate: parse_range(rate, "--grid (rates)", |v| {
                    parse_finite(v, "--grid (rates)")
                })?,
            })
        }
        _ => {
            Err("give one of --amplitudes, --frequencies and --grid: a run sweeps one thing".into())
        }
    }
}

/// A sweep of cases.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sweep {
    /// One section.
    None,
    /// Sections for each amplitude (m/s²): a bifurcation diagram.
    Amplitudes(Range),
    /// Sections for each frequency (Hz): a bifurcation diagram.
    Frequencies(Range),
    /// Initial angle (rad) × initial rate (rad/s) of the chosen coordinate: basins.
    Grid {
        /// θ₀ values.
        angle: Range,
        /// θ̇₀ values.
        rate: Range,
    },
}

/// Options of `crr poincare`.
#[derive(Clone, Debug)]
pub struct PoincareOptions {
    /// Amplitude A (m/s²).
    pub amplitude: f64,
    /// Frequency F (Hz); required for a stroboscopic section.
    pub frequency: Option<f64>,
    /// Phase φ (rad).
    pub phase: f64,
    /// Ground component.
    pub axis: Axis,
    /// N.
    pub periods: usize,
    /// M.
    pub transient: usize,
    /// `--section COORD`: a crossing section of this coordinate.
    pub section: Option<String>,
    /// `--coordinate NAME`: the coordinate of the bifurcation diagram and of the basins grid
    /// (default the first).
    pub coordinate: Option<String>,
    /// Time limit of a crossing section (s).
    pub duration: Option<f64>,
    /// Start from rest instead of the model's `[initial]`.
    pub rest: bool,
    /// The sweep.
    pub sweep: Sweep,
    /// Worker threads of a sweep (None: rayon's default, one per core).
    pub jobs: Option<usize>,
    /// Output folder.
    pub out: Option<PathBuf>,
    /// Replace earlier results.
    pub force: bool,
    /// No progress.
    pub quiet: bool,
}

impl Default for PoincareOptions {
    fn default() -> Self {
        Self {
            amplitude: 0.0,
            frequency: None,
            phase: 0.0,
            axis: Axis::X,
            periods: 100,
            transient: 100,
            section: None,
            coordinate: None,
            duration: None,
            rest: false,
            sweep: Sweep::None,
            jobs: None,
            out: None,
            force: false,
            quiet: false,
        }
    }
}

/// A checked run of `crr poincare`: the model, its solver settings and the section settings.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// The model file as read.
    pub file: ModelFile,
    /// The model.
    pub model: Model,
    /// The initial state (the model's, or rest).
    pub initial: InitialState,
    /// The initial specification the basins grid starts from.
    pub initial_spec: InitialSpec,
    /// Solver settings from `[analysis]`.
    pub params: Parameters,
    /// The section's settings (a sweep changes A, F or the initial state).
    pub settings: SectionSettings,
    /// The coordinate of the bifurcation diagram and of the basins grid.
    pub coordinate: usize,
}

fn coordinate_index(model: &Model, name: &str, option: &str) -> Result<usize, Error> {
    model.coord_index(name).ok_or_else(|| {
        let names: Vec<&str> = model.coords.iter().map(|c| c.name.as_str()).collect();
        Error::Argument(format!(
            "{option}: no coordinate named \"{name}\"; coordinates are: {}",
            names.join(", ")
        ))
    })
}

/// Reads and checks everything before any run. Errors name the option or the file.
pub fn prepare(path: &Path, opts: &PoincareOptions) -> Result<Prepared, Error> {
    check_options(opts)?;
    let (file, model) = load_model(path)?;
    prepare_checked(path, file, model, opts)
}

/// [`prepare`] for a model already read (`file` and the `model` built from it), named `label`
/// in the errors: what Python's `Model.poincare` runs.
pub fn prepare_model(
    label: &Path,
    file: ModelFile,
    model: Model,
    opts: &PoincareOptions,
) -> Result<Prepared, Error> {
    check_options(opts)?;
    prepare_checked(label, file, model, opts)
}

/// The checks of the options that need no model.
fn check_options(opts: &PoincareOptions) -> Result<(), Error> {
    let arg = |m: String| Error::Argument(m);
    if matches!(opts.sweep, Sweep::Amplitudes(_)) && opts.amplitude != 0.0 {
        return Err(arg(
            "--amplitude and --amplitudes cannot be given together".into()
        ));
    }
    if !(opts.amplitude.is_finite() && opts.amplitude >= 0.0) {
        return Err(arg(format!(
            "--amplitude must be a finite acceleration ≥ 0 (m/s²), got {}",
            opts.amplitude
        )));
    }
    if let Some(f) = opts.frequency
        && !(f.is_finite() && f > 0.0)
    {
        return Err(arg(format!(
            "--frequency must be a frequency > 0 (Hz), got {f}"
        )));
    }
    if !opts.phase.is_finite() {
        return Err(arg(format!("--phase must be finite, got {}", opts.phase)));
    }
    if opts.periods == 0 {
        return Err(arg("--periods must be at least 1, got 0".into()));
    }
    for (name, value) in [("--periods", opts.periods), ("--transient", opts.transient)] {
        if value > MAX_PERIODS {
            return Err(arg(format!(
                "{name} must be at most {MAX_PERIODS}, got {value}: the run keeps every section point"
            )));
        }
    }
    if let Sweep::Grid { angle, rate } = &opts.sweep
        && angle.count.saturating_mul(rate.count) > MAX_GRID_CASES
    {
        return Err(arg(format!(
            "--grid asks for {} × {} cases, more than {MAX_GRID_CASES}",
            angle.count, rate.count
        )));
    }
    // Every case keeps its section's points until the end (about 240 bytes each for one
    // coordinate): the total is bounded, not only each section.
    let cases = match &opts.sweep {
        Sweep::None => 1,
        Sweep::Amplitudes(r) | Sweep::Frequencies(r) => r.count,
        Sweep::Grid { angle, rate } => angle.count.saturating_mul(rate.count),
    };
    if cases.saturating_mul(opts.periods) > MAX_KEPT_POINTS {
        return Err(arg(format!(
            "{cases} case(s) × --periods {} would keep {} section points, more than \
             {MAX_KEPT_POINTS} (about 240 bytes each): fewer cases or periods",
            opts.periods,
            cases.saturating_mul(opts.periods)
        )));
    }
    if opts.jobs == Some(0) {
        return Err(arg("--jobs must be at least 1, got 0".into()));
    }
    crate::analysis::check_max_jobs(opts.jobs)?;
    if let Some(d) = opts.duration
        && !(d.is_finite() && d > 0.0)
    {
        return Err(arg(format!(
            "--duration must be a positive number of seconds, got {d}"
        )));
    }
    match opts.sweep {
        Sweep::Amplitudes(r) if !(r.start >= 0.0 && r.end >= 0.0) => {
            return Err(arg(format!(
                "--amplitudes must be finite accelerations ≥ 0 (m/s²), got {}:{}",
                r.start, r.end
            )));
        }
        Sweep::Frequencies(r) if !(r.start > 0.0 && r.end > 0.0) => {
            return Err(arg(format!(
                "--frequencies must be frequencies > 0 (Hz), got {}:{}",
                r.start, r.end
            )));
        }
        _ => {}
    }
    Ok(())
}

/// [`prepare`] after [`check_options`], with the model read.
fn prepare_checked(
    path: &Path,
    file: ModelFile,
    model: Model,
    opts: &PoincareOptions,
) -> Result<Prepared, Error> {
    let arg = |m: String| Error::Argument(m);
    let here = |m: String| Error::Argument(format!("{}: {m}", path.display()));
    let forced = opts.amplitude > 0.0
        || matches!(opts.sweep, Sweep::Amplitudes(r) if r.start > 0.0 || r.end > 0.0);
    if forced
        && let Some(why) =
            crate::analysis::simulation::component_along_the_hinges(&model, opts.axis)
    {
        return Err(here(format!("--component {}: {why}", opts.axis)));
    }
    if model.dof() == 0 {
        return Err(here(
            "the model has no coordinate: there is nothing to section".into(),
        ));
    }
    let crossing = match &opts.section {
        Some(name) => Some(coordinate_index(&model, name, "--section")?),
        None => None,
    };
    let sweeps_amplitude = matches!(opts.sweep, Sweep::Amplitudes(_));
    let unforced = opts.amplitude == 0.0 && !sweeps_amplitude;
    let kind = match crossing {
        Some(c) => SectionKind::Crossing(c),
        None if unforced => SectionKind::Crossing(0),
        None => SectionKind::Stroboscopic,
    };
    let sweeps_frequency = matches!(opts.sweep, Sweep::Frequencies(_));
    if sweeps_frequency && opts.amplitude == 0.0 {
        return Err(arg(
            "--frequencies needs --amplitude A > 0 (m/s²): without forcing the frequency plays \
             no part"
                .into(),
        ));
    }
    if opts.frequency.is_some() && sweeps_frequency {
        return Err(arg(
            "--frequency and --frequencies cannot be given together".into(),
        ));
    }
    let frequency = match (opts.frequency, opts.sweep) {
        (Some(f), _) => f,
        (None, Sweep::Frequencies(r)) => r.start,
        (None, _) if kind == SectionKind::Stroboscopic || !unforced => {
            return Err(arg(
                "--frequency F (Hz) is required: the section is taken at t = k/F".into(),
            ));
        }
        // Unforced: F plays no part.
        (None, _) => 1.0,
    };
    let lowest = match opts.sweep {
        Sweep::Frequencies(r) => r.start.min(r.end),
        _ => frequency,
    };
    let section_time = (opts.transient + opts.periods) as f64 / lowest;
    if kind == SectionKind::Stroboscopic
        && (section_time.is_nan() || section_time > MAX_SECTION_TIME)
    {
        return Err(arg(format!(
            "(transient + periods) / F = {section_time:e} s at F = {lowest:e} Hz: more than {MAX_SECTION_TIME:e} s \
             of simulated time per run; raise the frequency or lower --periods/--transient"
        )));
    }
    if opts.duration.is_some() && kind == SectionKind::Stroboscopic {
        return Err(arg(
            "--duration applies to a crossing section (--section COORD, or --amplitude 0) only: \
             a stroboscopic section runs (transient + periods) forcing periods"
                .into(),
        ));
    }
    let coordinate = match &opts.coordinate {
        Some(name) => coordinate_index(&model, name, "--coordinate")?,
        None => 0,
    };
    let initial_spec = if opts.rest {
        InitialSpec::default()
    } else {
        file.initial.clone().unwrap_or_default()
    };
    let initial = solve_initial(&model, &initial_spec).map_err(|e| here(e.to_string()))?;
    check_initial_state(&model, &initial).map_err(here)?;
    let analysis = file.analysis.clone().unwrap_or_default();
    let params = Parameters::from_analysis(&analysis, 1.0).map_err(here)?;
    check_run_length(&model, &params, kind, section_time, opts).map_err(here)?;
    let settings = SectionSettings {
        forcing: Forcing {
            amplitude: opts.amplitude,
            frequency,
            phase: opts.phase,
            axis: opts.axis,
        },
        kind,
        transient: opts.transient,
        points: opts.periods,
        max_time: opts.duration.unwrap_or(DEFAULT_CROSSING_DURATION),
    };
    Ok(Prepared {
        file,
        model,
        initial,
        initial_spec,
        params,
        settings,
        coordinate,
    })
}

/// Runs `run` on every case on a pool of `jobs` threads (None: one per core), in parallel, and
/// returns the results in the order of `cases`: each case is computed alone from its own inputs,
/// so the results do not depend on the number of threads. A count of the finished cases is shown
/// on stderr when `progress`.
pub fn run_cases<C: Sync, R: Send>(
    cases: &[C],
    jobs: Option<usize>,
    progress: bool,
    run: impl Fn(&C) -> R + Sync,
) -> Result<Vec<R>, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.unwrap_or(0))
        .build()
        .map_err(|e| format!("--jobs: cannot start the worker threads: {e}"))?;
    let done = AtomicUsize::new(0);
    let total = cases.len();
    let results = pool.install(|| {
        cases
            .par_iter()
            .map(|c| {
                let r = run(c);
                let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                if progress {
                    let width = 30;
                    let filled = width * d / total.max(1);
                    eprint!(
                        "\rcrr: [{}{}] {d}/{total} cases",
                        "#".repeat(filled),
                        "-".repeat(width - filled)
                    );
                }
                r
            })
            .collect()
    });
    if progress {
        eprintln!();
    }
    Ok(results)
}

/// The initial state with coordinate `k` at angle `angle` and rate `rate` (the others as in
/// `spec`).
pub fn initial_with(
    model: &Model,
    spec: &InitialSpec,
    k: usize,
    angle: f64,
    rate: f64,
) -> Result<InitialState, String> {
    let mut spec = spec.clone();
    let name = model.coords[k].name.clone();
    spec.angles.insert(name.clone(), angle);
    spec.rates.insert(name, rate);
    let initial = solve_initial(model, &spec).map_err(|e| e.to_string())?;
    check_initial_state(model, &initial)?;
    Ok(initial)
}

/// What one run of `crr poincare` computed.
#[derive(Clone, Debug)]
pub enum Computed {
    /// One section.
    Section(Section),
    /// A bifurcation sweep: the parameter value and the section of each case.
    Bifurcation {
        /// "amplitude" (m/s²) or "frequency" (Hz).
        parameter: &'static str,
        /// The cases.
        cases: Vec<(f64, Section)>,
    },
    /// A basins grid: (θ₀, θ̇₀) and the section of each case.
    Basins(Vec<(f64, f64, Section)>),
}

/// The error of a case that `cancel` stopped before it started ([`run_section_until`]).
pub const NOT_STARTED: &str = "interrupted before it started";

/// Runs what the options ask for (one section, or a sweep in parallel).
pub fn compute(p: &Prepared, opts: &PoincareOptions, progress: bool) -> Result<Computed, String> {
    compute_until(p, opts, progress, None)
}

/// [`compute`] that `cancel` stops: the cases under way stop within one integration step with
/// the points they have, the cases not started are not run (their error [`NOT_STARTED`]).
pub fn compute_until(
    p: &Prepared,
    opts: &PoincareOptions,
    progress: bool,
    cancel: Option<&Cancel>,
) -> Result<Computed, String> {
    let section = |initial: &InitialState, settings: &SectionSettings| {
        run_section_until(&p.model, initial, &p.params, settings, cancel)
    };
    Ok(match opts.sweep {
        Sweep::None => Computed::Section(section(&p.initial, &p.settings)),
        Sweep::Amplitudes(r) | Sweep::Frequencies(r) => {
            let amplitude = matches!(opts.sweep, Sweep::Amplitudes(_));
            let values = r.values();
            let sections = run_cases(&values, opts.jobs, progress, |&v| {
                let mut s = p.settings;
                if amplitude {
                    s.forcing.amplitude = v;
                } else {
                    s.forcing.frequency = v;
                }
                section(&p.initial, &s)
            })?;
            Computed::Bifurcation {
                parameter: if amplitude { "amplitude" } else { "frequency" },
                cases: values.into_iter().zip(sections).collect(),
            }
        }
        Sweep::Grid { angle, rate } => {
            let cases: Vec<(f64, f64)> = angle
                .values()
                .into_iter()
                .flat_map(|a| rate.values().into_iter().map(move |w| (a, w)))
                .collect();
            let sections = run_cases(&cases, opts.jobs, progress, |&(a, w)| {
                match initial_with(&p.model, &p.initial_spec, p.coordinate, a, w) {
                    Ok(initial) => section(&initial, &p.settings),
                    Err(e) => Section {
                        points: Vec::new(),
                        collapse: None,
                        end_time: 0.0,
                        at_rest: false,
                        error: Some(format!("initial state: {e}")),
                        violation: None,
                    },
                }
            })?;
            Computed::Basins(
                cases
                    .into_iter()
                    .zip(sections)
                    .map(|((a, w), s)| (a, w, s))
                    .collect(),
            )
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(k: usize, q: f64, r: f64) -> SectionPoint {
        SectionPoint {
            k,
            t: k as f64,
            q: vec![q],
            qdot: vec![r],
            states: vec![SlotState::Positive],
        }
    }

    #[test]
    fn a_period_two_sequence_has_two_distinct_points_and_period_two() {
        let pts: Vec<SectionPoint> = (0..10)
            .map(|k| {
                if k % 2 == 0 {
                    point(k, 0.1, 1.0)
                } else {
                    point(k, -0.05, 0.5)
                }
            })
            .collect();
        assert_eq!(distinct_points(&pts, SAME_POINT_TOLERANCE), 2);
        assert_eq!(detect_period(&pts, SAME_POINT_TOLERANCE), Some(2));
        // A change of 1e-3 of the scale in one point breaks the period.
        let mut broken = pts.clone();
        broken[7].q[0] += 1e-4;
        assert_eq!(detect_period(&broken, SAME_POINT_TOLERANCE), None);
        assert_eq!(distinct_points(&broken, SAME_POINT_TOLERANCE), 3);
    }

    #[test]
    fn ranges_include_both_ends_and_parse_errors_name_the_option() {
        let r = Range {
            start: 1.0,
            end: 2.0,
            count: 5,
        };
        assert_eq!(r.values(), vec![1.0, 1.25, 1.5, 1.75, 2.0]);
        let e = parse_range("1:2:0", "--amplitudes", |s| {
            parse_acceleration(s, "--amplitudes")
        })
        .unwrap_err();
        assert!(
            e.contains("--amplitudes") && e.contains("at least 1"),
            "{e}"
        );
        let e = parse_range("1:2", "--frequencies", |s| {
            parse_frequency(s, "--frequencies")
        })
        .unwrap_err();
        assert!(e.contains("--frequencies"), "{e}");
        let e = parse_frequency("0", "--frequencies").unwrap_err();
        assert!(e.contains("> 0"), "{e}");
        let e = parse_acceleration("-1", "--amplitude").unwrap_err();
        assert!(e.contains("≥ 0"), "{e}");
        assert!(parse_acceleration("nan", "--amplitude").is_err());
        // 1 g is the standard gravity of the record units.
        assert_eq!(parse_acceleration("0.5g", "--amplitude"), Ok(0.5 * 9.80665));
    }
}
