//! `crr._crr`: the Python extension of crr (PyO3). A thin layer over the library `crr`: models
//! read as the command line reads them, runs prepared and summarised by the same functions as
//! `crr simulate`, study cases expanded, run and written as rows of `cases.csv` by the functions
//! of `crr study`. The public, typed API is the pure-Python package `crr` around it
//! (`crr/__init__.py`); this module's signatures are in `crr/_crr.pyi`.
//!
//! Errors are raised as the classes of `crr._errors` with the command line's messages (what
//! `crr` prints after `crr: error: `). Simulations and studies run with the interpreter
//! detached (`Python::detach`, the GIL released), so that Python threads run them in parallel.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};

use crr::Error;
use crr::analysis::inspect;
use crr::analysis::study::{Case, StudySpec};
use crr::dynamics::ground_motion::{Axis, Record, RecordFormat, Units};
use crr::impact::{SlotState, Trajectory};
use crr::input::model_file::{ModelFile, build_model, load_model, parse_model_text};
use crr::kinematics::Model as Structure;
use crr::output::history::{history_csv, hops_csv, impacts_csv, opened_names, openings_csv};
use crr::output::study::folder::header;
use crr::output::study::{StudyOptions, case_rows_cancellable, cases_csv, run_study};
use crr::{ModelInput, RecordFile, RecordSamples, RunOptions};

/// An exception of `crr._errors` (`kind` is the class name) carrying `message`.
fn raise(py: Python<'_>, kind: &str, message: String) -> PyErr {
    let made = py
        .import("crr._errors")
        .and_then(|m| m.getattr(kind))
        .and_then(|cls| cls.call1((message.clone(),)));
    match made {
        Ok(exc) => PyErr::from_value(exc),
        Err(e) => e,
    }
}

/// An input error of the library as the Python exception of its kind: files that cannot be
/// read or written are `crr.FileError` (an `OSError`), everything else `crr.InputError` (a
/// `ValueError`).
fn input_error(py: Python<'_>, e: Error) -> PyErr {
    let message = e.to_string();
    let (file, source) = match &e {
        Error::Io { file, source } => (file, source),
        Error::NamedFile { file, source, .. } => (file, source),
        Error::Output { dir, source } => (dir, source),
        _ => return raise(py, "InputError", message),
    };
    // With the OS error number and the path, as OSError has them; a missing file is also a
    // FileNotFoundError.
    let kind = if source.kind() == std::io::ErrorKind::NotFound {
        "MissingFileError"
    } else {
        "FileError"
    };
    let made = py
        .import("crr._errors")
        .and_then(|m| m.getattr(kind))
        .and_then(|cls| cls.call1((message, source.raw_os_error(), file.clone())));
    match made {
        Ok(exc) => PyErr::from_value(exc),
        Err(e) => e,
    }
}

fn argument(py: Python<'_>, message: String) -> PyErr {
    raise(py, "InputError", message)
}

/// A model read and validated, with the name and folder its errors and relative record paths
/// refer to.
#[pyclass(name = "Model", module = "crr._crr", frozen)]
struct PyModel {
    label: PathBuf,
    base_dir: PathBuf,
    file: ModelFile,
    structure: Structure,
}

#[pymethods]
impl PyModel {
    /// Reads a model file (TOML, or JSON when it ends in .json), as the command line does.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let (file, structure) = load_model(&path).map_err(|e| input_error(py, e))?;
        let base_dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        Ok(PyModel {
            label: path,
            base_dir,
            file,
            structure,
        })
    }

    /// The model of an assembly file (blocks only) as `crr assemble` writes it: its contacts
    /// found from the blocks' shapes, every bed (or, `all_contacts`, every contact) a rocking
    /// interface (hinges about y when `planar`), faces closer than `tolerance` (m) touching, the
    /// ground the plane z = `ground_level` (m) and the blocks the file names `fixed`; with
    /// `inscribed`, a face that is no rectangle rocks on the largest rectangle of its
    /// proportions inside it. Relative record files are read from the assembly's folder.
    /// Returns the model and the assembly's warnings (blocks a little farther apart than the
    /// tolerance, which are no contact).
    #[staticmethod]
    fn assemble(
        py: Python<'_>,
        path: PathBuf,
        planar: bool,
        all_contacts: bool,
        tolerance: f64,
        ground_level: f64,
        inscribed: bool,
    ) -> PyResult<(Self, Vec<String>)> {
        use crr::analysis::assemble::{AssemblyOptions, assemble, read_assembly};
        use crr::kinematics::assembly::ContactSet;
        let options = AssemblyOptions {
            planar,
            contacts: if all_contacts {
                ContactSet::All
            } else {
                ContactSet::Beds
            },
            tolerance,
            ground_level,
            inscribed,
        };
        let assembled = py
            .detach(|| read_assembly(&path).and_then(|file| assemble(&path, &file, &options)))
            .map_err(|e| input_error(py, e))?;
        let warnings = assembled
            .warnings
            .iter()
            .map(|w| format!("{}: {w}", path.display()))
            .collect();
        Ok((
            PyModel {
                label: path,
                base_dir: assembled.folder,
                file: assembled.file,
                structure: assembled.model,
            },
            warnings,
        ))
    }

    /// Parses a model given as text (JSON when `is_json`, else TOML); `label` names it in the
    /// errors, `base_dir` resolves its relative record files.
    #[staticmethod]
    fn parse(
        py: Python<'_>,
        text: &str,
        is_json: bool,
        label: PathBuf,
        base_dir: PathBuf,
    ) -> PyResult<Self> {
        let file = parse_model_text(&label, text, is_json).map_err(|e| input_error(py, e))?;
        let (file, structure) = build_model(&label, file).map_err(|e| input_error(py, e))?;
        Ok(PyModel {
            label,
            base_dir,
            file,
            structure,
        })
    }

    /// The path or label naming the model in messages.
    #[getter]
    fn label(&self) -> PathBuf {
        self.label.clone()
    }

    /// The folder relative record files are read from.
    #[getter]
    fn base_dir(&self) -> PathBuf {
        self.base_dir.clone()
    }

    /// The structure's name.
    #[getter]
    fn name(&self) -> String {
        self.file.name.clone()
    }

    /// Coordinate names, in the order of q.
    #[getter]
    fn coordinates(&self) -> Vec<String> {
        self.structure
            .coords
            .iter()
            .map(|c| c.name.clone())
            .collect()
    }

    /// Interface names, in the order of the state columns.
    #[getter]
    fn interfaces(&self) -> Vec<String> {
        self.structure
            .interfaces
            .iter()
            .map(|i| i.name.clone())
            .collect()
    }

    /// The model file as JSON (every table, defaults filled in).
    fn to_json(&self) -> String {
        serde_json::to_string(&self.file).expect("a model file serialises")
    }

    /// `crr check --json` of this model, with `--direction D…` (`directions`, each as the
    /// command line takes it), `--friction MU` and `--exhaustive-sets N`.
    #[pyo3(signature = (directions=None, friction=None, exhaustive_sets=None))]
    fn check_json(
        &self,
        py: Python<'_>,
        directions: Option<Vec<String>>,
        friction: Option<f64>,
        exhaustive_sets: Option<usize>,
    ) -> PyResult<String> {
        use crr::analysis::static_multiplier::{
            MultiplierOptions, check_friction, horizontal_directions, parse_direction,
        };
        let directions = match directions {
            None => horizontal_directions(),
            Some(list) if list.is_empty() => {
                return Err(argument(
                    py,
                    "direction: give at least one direction".into(),
                ));
            }
            Some(list) => list
                .iter()
                .map(|d| parse_direction(d))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| argument(py, format!("direction: {e}")))?,
        };
        if let Some(mu) = friction {
            check_friction(mu).map_err(|e| argument(py, format!("friction {e}")))?;
        }
        let mut asked = MultiplierOptions {
            friction,
            ..MultiplierOptions::default()
        };
        if let Some(n) = exhaustive_sets {
            asked.exhaustive_sets = n;
        }
        // Ctrl-C stops the check after the stage under way (one linear program of the statics,
        // or one factorisation of the mobility) and raises KeyboardInterrupt: a check has no
        // partial result to keep.
        let cancel = crr::Cancel::new();
        asked.cancel = Some(cancel.clone());
        match interruptible(py, &cancel, || {
            crr::analysis::check::check_with(&self.structure, &directions, &asked)
        }) {
            Ok(Ok(report)) => Ok(serde_json::to_string(&report).expect("the report serialises")),
            // Only a Ctrl-C sets the flag, and it comes back as the interrupt below.
            Ok(Err(interrupted)) => Err(PyRuntimeError::new_err(interrupted.to_string())),
            Err((interrupt, _)) => Err(interrupt),
        }
    }

    /// `crr poincare` of this model (nothing written): the options as the command line takes
    /// them, `amplitude` and the ranges as text (`"0.3g"`, `"1:3:21"`, `"T0:T1:N,W0:W1:M"`).
    /// Returns the data file's name (`poincare.csv`, `bifurcation.csv` or `basins.csv`), its
    /// text and the text of `poincare.json`. Ctrl-C stops the cases under way within one
    /// integration step and raises KeyboardInterrupt with those three texts, of the points
    /// computed until then, as its `poincare` attribute.
    #[pyo3(signature = (amplitude, frequency, component, phase, periods, transient, section, coordinate, duration, rest, amplitudes, frequencies, grid, jobs))]
    #[allow(clippy::too_many_arguments)]
    fn poincare(
        &self,
        py: Python<'_>,
        amplitude: &str,
        frequency: Option<f64>,
        component: &str,
        phase: f64,
        periods: usize,
        transient: usize,
        section: Option<String>,
        coordinate: Option<String>,
        duration: Option<f64>,
        rest: bool,
        amplitudes: Option<String>,
        frequencies: Option<String>,
        grid: Option<String>,
        jobs: Option<usize>,
    ) -> PyResult<(String, String, String)> {
        use crr::analysis::poincare::{
            PoincareOptions, compute_until, parse_acceleration, parse_sweep, prepare_model,
        };
        use crr::output::poincare::{data_file, summary};
        let error = |m: String| argument(py, keyword_names(&m));
        let amplitude = parse_acceleration(amplitude, "--amplitude").map_err(error)?;
        let axis: Axis = component
            .parse()
            .map_err(|e| error(format!("--component: {e}")))?;
        let sweep = parse_sweep(
            amplitudes.as_deref(),
            frequencies.as_deref(),
            grid.as_deref(),
        )
        .map_err(error)?;
        let opts = PoincareOptions {
            amplitude,
            frequency,
            phase,
            axis,
            periods,
            transient,
            section,
            coordinate,
            duration,
            rest,
            sweep,
            jobs,
            out: None,
            force: false,
            quiet: true,
        };
        let prepared = py
            .detach(|| {
                prepare_model(
                    &self.label,
                    self.file.clone(),
                    self.structure.clone(),
                    &opts,
                )
            })
            .map_err(|e| match e {
                Error::Argument(m) => error(m),
                e => input_error(py, e),
            })?;
        let texts = |computed: &crr::analysis::poincare::Computed| {
            let (name, text) = data_file(&prepared, computed);
            let json = summary(&self.label, &prepared, &opts, computed).to_json();
            (name.to_string(), text, json)
        };
        let cancel = crr::Cancel::new();
        match interruptible(py, &cancel, || {
            compute_until(&prepared, &opts, false, Some(&cancel))
        }) {
            Ok(Ok(computed)) => Ok(texts(&computed)),
            Ok(Err(e)) => Err(error(e)),
            Err((interrupt, partial)) => {
                if let Some(Ok(computed)) = partial {
                    interrupt.value(py).setattr("poincare", texts(&computed))?;
                }
                Err(interrupt)
            }
        }
    }

    /// `crr inspect --json` at q: `settings` as `--q NAME=VALUE` (others 0), or every
    /// coordinate's value in `q`.
    #[pyo3(signature = (settings=None, q=None))]
    fn inspect_json(
        &self,
        py: Python<'_>,
        settings: Option<Vec<String>>,
        q: Option<Vec<f64>>,
    ) -> PyResult<String> {
        let n = self.structure.dof();
        let q = match q {
            Some(v) => {
                if v.len() != n {
                    return Err(argument(
                        py,
                        format!("q has {} values, the model has {n} coordinate(s)", v.len()),
                    ));
                }
                if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                    return Err(argument(
                        py,
                        format!("q: {x} is not a finite number of radians"),
                    ));
                }
                nalgebra::DVector::from_vec(v)
            }
            None => inspect::configuration(&self.structure, &settings.unwrap_or_default())
                .map_err(|e| input_error(py, e))?,
        };
        let report = inspect::inspect(&self.structure, &q);
        Ok(serde_json::to_string(&report).expect("the report serialises"))
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(name={:?}, coordinates={:?}, source={:?})",
            self.file.name,
            self.coordinates(),
            self.label.display().to_string()
        )
    }
}

/// A finished (or failed) run: the trajectory and its summary.
#[pyclass(name = "Run", module = "crr._crr", frozen)]
struct PyRun {
    structure: Structure,
    trajectory: Trajectory,
    summary: String,
    error: Option<String>,
    /// `[analysis] hop_tolerance` of the run (m), for hops.csv.
    hop_tolerance: f64,
}

#[pymethods]
impl PyRun {
    /// Number of samples (rows of history.csv).
    #[getter]
    fn samples(&self) -> usize {
        self.trajectory.samples.len()
    }

    /// The numbers of history.csv as columns of native-endian f64 bytes, each written straight
    /// into its Python object: t, q (row-major, samples × dof), q̇ (the same), kinetic,
    /// potential, work_in, dissipated. numpy reads each without a copy.
    fn history_columns<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyBytes>>> {
        let s = &self.trajectory.samples;
        [
            s.times(),
            s.q(),
            s.qdot(),
            s.kinetic(),
            s.potential(),
            s.work_in(),
            s.dissipated(),
        ]
        .into_iter()
        .map(|column| {
            PyBytes::new_with(py, 8 * column.len(), |buf| {
                for (bytes, v) in buf.chunks_exact_mut(8).zip(column) {
                    bytes.copy_from_slice(&v.to_ne_bytes());
                }
                Ok(())
            })
        })
        .collect()
    }

    /// The state column of every interface per sample, as in history.csv (`seated`, `+`, `-`,
    /// slots joined by `/`), coded: the distinct labels, and for every sample and interface (row
    /// by row) the index of its label as native-endian u32 bytes. Python indexes the labels with
    /// them (one numpy operation) instead of building a string per sample.
    fn state_codes<'py>(&self, py: Python<'py>) -> PyResult<(Vec<String>, Bound<'py, PyBytes>)> {
        let interfaces = &self.structure.interfaces;
        let mut labels: Vec<String> = Vec::new();
        let mut by_label: HashMap<String, u32> = HashMap::new();
        // (interface, its slots' states as a base-4 number) → label index: a label is built once.
        let mut by_key: HashMap<(usize, u64), u32> = HashMap::new();
        let mut codes = Vec::with_capacity(self.samples() * interfaces.len());
        // Each interface's last key and code: states change only at events, so most samples
        // repeat the previous one's and skip the map.
        let mut last: Vec<Option<(u64, u32)>> = vec![None; interfaces.len()];
        for s in &self.trajectory.samples {
            for (i, iface) in interfaces.iter().enumerate() {
                let key = iface.slots.clone().fold(0u64, |key, k| {
                    let digit = match s.states.get(k) {
                        Some(SlotState::Seated) => 0,
                        Some(SlotState::Positive) => 1,
                        Some(SlotState::Negative) => 2,
                        Some(SlotState::Open) => 3,
                        None => 4,
                    };
                    key.wrapping_mul(5).wrapping_add(digit)
                });
                if let Some((k, code)) = last[i]
                    && k == key
                {
                    codes.push(code);
                    continue;
                }
                let code = *by_key.entry((i, key)).or_insert_with(|| {
                    let label = iface
                        .slots
                        .clone()
                        .map(|k| s.states.get(k).map_or("?", |st| st.code()))
                        .collect::<Vec<_>>()
                        .join("/");
                    *by_label.entry(label.clone()).or_insert_with(|| {
                        labels.push(label);
                        (labels.len() - 1) as u32
                    })
                });
                last[i] = Some((key, code));
                codes.push(code);
            }
        }
        let bytes = PyBytes::new_with(py, 4 * codes.len(), |buf| {
            for (chunk, c) in buf.chunks_exact_mut(4).zip(&codes) {
                chunk.copy_from_slice(&c.to_ne_bytes());
            }
            Ok(())
        })?;
        Ok((labels, bytes))
    }

    /// The impact log: one dict per impact (t in s, interfaces, rates before and after in
    /// rad/s, energy lost in J, the seated joints it opened).
    fn impacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for i in &self.trajectory.impacts {
            let d = PyDict::new(py);
            d.set_item("t", i.t)?;
            d.set_item("interfaces", i.interfaces.clone())?;
            d.set_item("rates_before", i.rates_before.clone())?;
            d.set_item("rates_after", i.rates_after.clone())?;
            d.set_item("energy_lost", i.energy_lost)?;
            d.set_item("opened", opened_names(&self.structure, &i.released))?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// summary.json as text.
    #[getter]
    fn summary_json(&self) -> String {
        self.summary.clone()
    }

    /// Why the run stopped early, if it did.
    #[getter]
    fn error(&self) -> Option<String> {
        self.error.clone()
    }

    /// The text of history.csv, as `crr simulate` writes it.
    fn history_csv(&self) -> String {
        history_csv(&self.structure, &self.trajectory)
    }

    /// The text of impacts.csv, as `crr simulate` writes it.
    fn impacts_csv(&self) -> String {
        impacts_csv(&self.structure, &self.trajectory)
    }

    /// The text of hops.csv, as `crr simulate` writes it: every pull at a pivot just after an
    /// impact, measured by the motion with that face released (the header alone when none).
    fn hops_csv(&self) -> String {
        hops_csv(&self.trajectory, self.hop_tolerance)
    }

    /// The text of openings.csv, as `crr simulate` writes it: the offset of every face open at
    /// a row of history.csv (the header alone when no face lifts off).
    fn openings_csv(&self) -> String {
        openings_csv(&self.structure, &self.trajectory)
    }
}

/// A record array: component, times (s), accelerations, their units (`g`, `m/s2`, `cm/s2`),
/// factor.
type ArrayRecord = (String, Vec<f64>, Vec<f64>, String, f64);
/// A record file as `--record FILE --format F --units U --component C --scale S`.
type FileRecord = (PathBuf, String, Option<String>, String, f64);

fn parse_axis(what: &str, axis: &str) -> Result<Axis, String> {
    axis.parse().map_err(|e: String| format!("{what}: {e}"))
}

/// Runs `model` as `crr simulate` does, with its tables replaced by the given JSON (ground
/// motion, initial state, analysis), a record file (as `--record`) and record arrays overriding
/// components, and `duration` (as `--duration`).
#[pyfunction]
#[pyo3(signature = (model, ground_motion=None, initial=None, analysis=None, record_file=None, records=Vec::new(), duration=None, max_samples=None, memory=None))]
fn simulate(
    py: Python<'_>,
    model: &PyModel,
    ground_motion: Option<String>,
    initial: Option<String>,
    analysis: Option<String>,
    record_file: Option<FileRecord>,
    records: Vec<ArrayRecord>,
    duration: Option<f64>,
    max_samples: Option<usize>,
    memory: Option<f64>,
) -> PyResult<PyRun> {
    let mut options = RunOptions::default();
    let table =
        |what: &str, e: serde_json::Error| format!("{}: {what}: {e}", model.label.display());
    if let Some(g) = ground_motion {
        options.ground_motion =
            Some(serde_json::from_str(&g).map_err(|e| argument(py, table("ground_motion", e)))?);
    }
    if let Some(i) = initial {
        options.initial =
            Some(serde_json::from_str(&i).map_err(|e| argument(py, table("initial", e)))?);
    }
    if let Some(a) = analysis {
        options.analysis =
            Some(serde_json::from_str(&a).map_err(|e| argument(py, table("analysis", e)))?);
    }
    options.record_file = match record_file {
        None => None,
        Some((path, format, units, component, scale)) => {
            let format: RecordFormat = format
                .parse()
                .map_err(|e| argument(py, format!("record format: {e}")))?;
            let units: Option<Units> = units
                .map(|u| {
                    u.parse()
                        .map_err(|e| argument(py, format!("record units: {e}")))
                })
                .transpose()?;
            let component =
                parse_axis("record component", &component).map_err(|e| argument(py, e))?;
            if !scale.is_finite() {
                return Err(argument(
                    py,
                    format!("record scale must be finite, got {scale}"),
                ));
            }
            Some(RecordFile {
                file: path,
                format,
                units,
                component,
                scale,
            })
        }
    };
    let mut arrays = Vec::with_capacity(records.len());
    for (component, t, a, units, scale) in records {
        let axis =
            parse_axis("ground motion component", &component).map_err(|e| argument(py, e))?;
        let units: Units = units
            .parse()
            .map_err(|e| argument(py, format!("ground motion units: {e}")))?;
        let a = a.into_iter().map(|x| units.to_si(x)).collect();
        let r = Record::from_samples(t, a)
            .map_err(|e| argument(py, format!("ground motion record: {e}")))?;
        arrays.push(RecordSamples {
            component: axis,
            record: r,
            scale,
        });
    }
    options.records = arrays;
    // Also checked in Python (crr.simulate), with the same wording: the argument is `duration`.
    if let Some(d) = duration
        && !(d.is_finite() && d > 0.0)
    {
        return Err(argument(
            py,
            format!("duration must be a positive number of seconds, got {d}"),
        ));
    }
    options.duration = duration;
    let input = ModelInput {
        path: model.label.clone(),
        base_dir: model.base_dir.clone(),
        file: model.file.clone(),
        model: model.structure.clone(),
    };
    let cancel = crr::Cancel::new();
    options.cancel = Some(cancel.clone());
    let to_py = |run: crr::Run| {
        PyRun {
            // The text `crr simulate` writes, so that Result.write writes the same bytes.
            summary: run.summary.to_json(),
            error: run.summary.error,
            hop_tolerance: run.summary.solver.hop_tolerance,
            structure: run.model,
            trajectory: run.trajectory,
        }
    };
    let prepared = py
        .detach(|| crr::analysis::simulation::prepare(&input, &options))
        .map_err(|e| input_error(py, e))?;
    let prepared = limit_samples(py, prepared, max_samples, memory)?;
    match interruptible(py, &cancel, move || Ok::<_, Error>(prepared.run())) {
        Ok(run) => run.map(to_py).map_err(|e| input_error(py, e)),
        Err((interrupt, partial)) => {
            // Ctrl-C: KeyboardInterrupt, with the partial run as its `run` attribute.
            if let Some(Ok(run)) = partial {
                interrupt
                    .value(py)
                    .setattr("run", Py::new(py, to_py(run))?)?;
            }
            Err(interrupt)
        }
    }
}

/// Bytes a run keeps in memory per output sample, both copies counted: the engine's columns
/// (t, q, q̇ and four energies as f64, one byte per slot state; grown by doubling, so up to twice
/// that) and the history the Python `Result` copies once.
fn memory_per_sample(model: &Structure) -> f64 {
    let numbers = (5 + 2 * model.dof()) as f64 * 8.0 + model.slot_count as f64;
    3.0 * numbers
}

/// The sample limit of a run: `max_samples` when given; otherwise, when the memory `memory`
/// (bytes) the caller can give is known, what fits in 80 % of it, and a run whose output samples
/// alone would not fit is refused before it starts (crr.OutOfMemoryError, a MemoryError).
fn limit_samples(
    py: Python<'_>,
    mut prepared: crr::analysis::simulation::Prepared,
    max_samples: Option<usize>,
    memory: Option<f64>,
) -> PyResult<crr::analysis::simulation::Prepared> {
    if let Some(max) = max_samples {
        prepared.max_samples = Some(max);
        return Ok(prepared);
    }
    let Some(memory) = memory.filter(|m| m.is_finite() && *m > 0.0) else {
        return Ok(prepared);
    };
    let per_sample = memory_per_sample(&prepared.model);
    let fits = (0.8 * memory / per_sample).floor();
    let (rows, _) = prepared.history_estimate();
    if rows > fits {
        return Err(raise(
            py,
            "OutOfMemoryError",
            format!(
                "{}: the history would need about {:.1} GB in memory ({rows:.3e} samples: the \
                 duration {} s over output_interval = {} s), more than 80 % of the {:.1} GB this process \
                 can still take: raise output_interval, shorten the duration, or use `crr \
                 simulate`, which streams the history to a file",
                prepared.path.display(),
                rows * per_sample / 1e9,
                prepared.params.duration,
                prepared.params.output_interval,
                memory / 1e9
            ),
        ));
    }
    prepared.max_samples = Some(fits as usize);
    Ok(prepared)
}

/// Runs `work` on a thread of its own, without the GIL, while this thread waits for its result
/// in slices of [`POLL`] and checks for signals between them: Ctrl-C sets `cancel` (the work
/// stops within one integration step) and, once the work has returned, comes back as the
/// `KeyboardInterrupt` with what the work returned. The result comes through a channel, so the
/// wait ends the moment it is sent (a wake-up by `unpark` before the thread had finished made
/// the waiter sleep another slice: docs/performance.md, "Python's wait for a run").
fn interruptible<T: Send>(
    py: Python<'_>,
    cancel: &crr::Cancel,
    work: impl FnOnce() -> T + Send,
) -> Result<T, (PyErr, Option<T>)> {
    use std::sync::mpsc::RecvTimeoutError;
    std::thread::scope(|scope| {
        let (sender, mut receiver) = std::sync::mpsc::channel();
        let worker = scope.spawn(move || {
            // The waiter holds the receiver until it has the result: the send cannot fail.
            let _ = sender.send(work());
        });
        let mut interrupt = None;
        let check = |interrupt: &mut Option<PyErr>| {
            if interrupt.is_none()
                && let Err(e) = py.check_signals()
            {
                cancel.cancel();
                *interrupt = Some(e);
            }
        };
        let result = loop {
            // The receiver goes into the detached closure and comes back (a `&Receiver` is not
            // `Send`).
            let (received, back) = py.detach(move || (receiver.recv_timeout(POLL), receiver));
            receiver = back;
            match received {
                Ok(result) => break Some(result),
                // The sender dropped without a send: the work panicked.
                Err(RecvTimeoutError::Disconnected) => break None,
                Err(RecvTimeoutError::Timeout) => check(&mut interrupt),
            }
        };
        // A Ctrl-C that came with the result still interrupts, and keeps the result.
        check(&mut interrupt);
        // Joined here, so that a panic comes back as no result (not as the scope's own panic).
        let _ = worker.join();
        match (interrupt, result) {
            (Some(e), result) => Err((e, result)),
            (None, Some(result)) => Ok(result),
            (None, None) => Err((PyRuntimeError::new_err("the run's thread panicked"), None)),
        }
    })
}

/// How often a run waiting in Python checks for signals (Ctrl-C): well under the 0.2 s a user
/// notices, and a negligible cost (a wake-up per slice).
const POLL: std::time::Duration = std::time::Duration::from_millis(20);

/// A study expanded into its cases.
#[pyclass(name = "Study", module = "crr._crr", frozen)]
struct PyStudy {
    label: PathBuf,
    study: crr::analysis::study::Study,
}

impl PyStudy {
    fn cases(&self, py: Python<'_>, ids: Option<Vec<String>>) -> PyResult<Vec<&Case>> {
        match ids {
            None => Ok(self.study.cases.iter().collect()),
            Some(ids) => ids
                .iter()
                .map(|id| {
                    case_index(id)
                        .and_then(|k| self.study.cases.get(k))
                        .filter(|c| &c.id == id)
                        .ok_or_else(|| {
                            argument(
                                py,
                                format!(
                                    "{}: no case {id:?} in this study ({} case(s), c000000 …)",
                                    self.label.display(),
                                    self.study.cases.len()
                                ),
                            )
                        })
                })
                .collect(),
        }
    }
}

fn case_index(id: &str) -> Option<usize> {
    id.strip_prefix('c')?.parse().ok()
}

#[pymethods]
impl PyStudy {
    /// Reads a study file (TOML), its model and records, and lists the cases.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let study = py
            .detach(|| crr::analysis::study::Study::load(&path))
            .map_err(|e| input_error(py, e))?;
        Ok(PyStudy { label: path, study })
    }

    /// A study given as text (JSON when `is_json`, else TOML), as if it were the file `label`:
    /// its folder resolves the model and records, its stem is the default name.
    #[staticmethod]
    fn parse(py: Python<'_>, text: &str, is_json: bool, label: PathBuf) -> PyResult<Self> {
        let spec = if is_json {
            serde_json::from_str::<StudySpec>(text).map_err(|e| Error::Parse {
                file: label.clone(),
                message: e.to_string(),
            })
        } else {
            StudySpec::parse(&label, text)
        }
        .map_err(|e| input_error(py, e))?;
        let study = py
            .detach(|| crr::analysis::study::Study::from_spec(spec, &label))
            .map_err(|e| input_error(py, e))?;
        Ok(PyStudy { label, study })
    }

    /// The study's name (the output folder's default name).
    #[getter]
    fn name(&self) -> String {
        self.study.name.clone()
    }

    /// The path or label naming the study in messages.
    #[getter]
    fn label(&self) -> PathBuf {
        self.label.clone()
    }

    /// The case ids, in order.
    #[getter]
    fn case_ids(&self) -> Vec<String> {
        self.study.cases.iter().map(|c| c.id.clone()).collect()
    }

    /// What to know before trusting the results, found before any case runs (a `duration`
    /// that cuts motions short), as `crr study` warns.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.study
            .warnings
            .iter()
            .map(|w| format!("{}: {w}", self.label.display()))
            .collect()
    }

    /// The header line of cases.csv (without its newline).
    #[getter]
    fn header(&self) -> String {
        header(&self.study)
    }

    fn __len__(&self) -> usize {
        self.study.cases.len()
    }

    /// Runs the cases `ids` (all when None) on `jobs` threads and returns their rows of
    /// cases.csv (without newlines) in the order of `ids`.
    #[pyo3(signature = (ids=None, jobs=None))]
    fn run_rows(
        &self,
        py: Python<'_>,
        ids: Option<Vec<String>>,
        jobs: Option<usize>,
    ) -> PyResult<Vec<String>> {
        let cases = self.cases(py, ids)?;
        let cancel = crr::Cancel::new();
        let work = || case_rows_cancellable(&self.study, &cases, jobs, Some(&cancel));
        match interruptible(py, &cancel, work) {
            Ok(Ok(Some(rows))) => Ok(rows),
            Ok(Ok(None)) => Err(PyRuntimeError::new_err("the study was cancelled")),
            Ok(Err(e)) => Err(input_error(py, e)),
            Err((interrupt, _)) => Err(interrupt),
        }
    }

    /// The text of cases.csv from rows in any order (in case-id order, as `crr study` writes it).
    fn csv(&self, rows: Vec<String>) -> String {
        cases_csv(&header(&self.study), rows.iter().map(String::as_str))
    }

    /// `crr study FILE --out OUT --jobs JOBS [--quiet]`: runs (or resumes) the study into `out`
    /// (cases.csv, study.json) and returns (cases, skipped, ran, failed); `progress` shows the
    /// command line's progress line on stderr.
    #[pyo3(signature = (out, jobs=None, progress=false))]
    fn run_into(
        &self,
        py: Python<'_>,
        out: PathBuf,
        jobs: Option<usize>,
        progress: bool,
    ) -> PyResult<(usize, usize, usize, usize)> {
        if jobs == Some(0) {
            return Err(argument(py, "jobs must be at least 1".into()));
        }
        let cancel = crr::Cancel::new();
        let opts = StudyOptions {
            out,
            jobs,
            shard: crr::output::study::Shard::ALL,
            quiet: !progress,
            cancel: Some(cancel.clone()),
        };
        // Ctrl-C: the cases under way stop without a row, the folder keeps the others (running
        // into it again resumes), and KeyboardInterrupt is raised.
        match interruptible(py, &cancel, || run_study(&self.study, &self.label, &opts)) {
            Ok(Ok(o)) => Ok((o.cases, o.skipped, o.ran, o.failed)),
            Ok(Err(e)) => Err(input_error(py, e)),
            Err((interrupt, _)) => Err(interrupt),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "Study(name={:?}, cases={}, source={:?})",
            self.study.name,
            self.study.cases.len(),
            self.label.display().to_string()
        )
    }
}

/// A message of `crr poincare`'s checks with its options named as Python's keyword arguments
/// (`--periods must be at least 1` → `periods must be at least 1`).
fn keyword_names(message: &str) -> String {
    const OPTIONS: [&str; 12] = [
        "amplitude",
        "frequenc",
        "component",
        "phase",
        "periods",
        "transient",
        "section",
        "coordinate",
        "duration",
        "rest",
        "grid",
        "jobs",
    ];
    OPTIONS.iter().fold(message.to_string(), |m, name| {
        m.replace(&format!("--{name}"), name)
    })
}

/// The crr library's version.
const VERSION: &str = env!("CARGO_PKG_VERSION");

#[pymodule]
fn _crr(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModel>()?;
    m.add_class::<PyRun>()?;
    m.add_class::<PyStudy>()?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add("__version__", VERSION)?;
    m.add("ANALYSIS_KEYS", analysis_keys())?;
    Ok(())
}

/// The keys of the `[analysis]` table (every field of its spec serialises, defaults included):
/// the keyword arguments `crr.simulate` accepts besides its own.
fn analysis_keys() -> Vec<String> {
    let spec = serde_json::to_value(crr::dynamics::AnalysisSpec::default())
        .expect("the analysis spec serialises");
    spec.as_object()
        .expect("the analysis spec is a table")
        .keys()
        .cloned()
        .collect()
}
