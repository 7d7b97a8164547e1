//! A study file expanded into its cases: the model read once, the records read once, and one
//! case per (pulse amplitude, pulse frequency) or (record, intensity level), in a fixed order
//! that gives every case a stable id (`c000000`, `c000001`, … in that order).

use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crr_dynamics::ground_motion::{
    Axis, ComponentSpec, GroundMotion, GroundMotionSpec, PulseSpec, Record, RickerSpec,
    STANDARD_GRAVITY, SignalSpec, read_record,
};
use crr_dynamics::{InitialState, equivalent_block, solve_initial};
use crr_impact::Parameters;
use crr_kinematics::Model;

use super::spec::{PulseKind, Start, StudySpec, Values};
use crate::InputError;
use crate::model_file::load_model;
use crate::simulate::default_duration;
use crate::size_sweep::{scale_structure, structure_height};

/// What drives one case.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// A pulse of amplitude a_p (m/s²) and period T_p = 2π/ω_p (s).
    Pulse {
        /// a_p (m/s²).
        amplitude: f64,
        /// T_p (s).
        period: f64,
        /// a_p/(g tan α), when the grid was given so.
        amplitude_ratio: Option<f64>,
        /// ω_p/p, when the grid was given so.
        frequency_ratio: Option<f64>,
    },
    /// Record `record` (index into [`Study::records`]) times `factor`, at intensity `level` (the
    /// target PGA in g, PGV in m/s, or the factor itself).
    Record {
        /// Index of the record.
        record: usize,
        /// Intensity level as given.
        level: f64,
        /// Factor on the record's accelerations (None when the record could not be read or has
        /// a zero intensity).
        factor: Option<f64>,
    },
}

/// One case of a study.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Position in the study's order.
    pub index: usize,
    /// Stable id: `c` and the index on six digits.
    pub id: String,
    /// Index of its model variant (scale factor) in [`Study::variants`].
    pub variant: usize,
    /// Its ground motion.
    pub motion: Motion,
}

/// The model at one scale factor of the study's size axis.
#[derive(Clone, Debug)]
pub struct Variant {
    /// Scale factor s (every length × s; 1 without a size axis).
    pub scale: f64,
    /// The model scaled by s.
    pub model: Model,
    /// Its initial state.
    pub initial: InitialState,
    /// λ and p_eq of its one-DOF mechanism (p_eq ∝ 1/√s, λ unchanged).
    pub lambda_p: Option<(f64, f64)>,
    /// Height of the scaled structure at rest (m), when defined.
    pub height: Option<f64>,
}

/// A record of the study, read once.
#[derive(Clone, Debug)]
pub struct StudyRecord {
    /// The file as named in the study.
    pub file: PathBuf,
    /// The record, or why it could not be read (its cases then fail with this message).
    pub record: Result<Record, String>,
}

/// The intensity measure of a records study.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntensityMeasure {
    /// Factors on the record.
    Factor,
    /// Peak ground acceleration, g.
    Pga,
    /// Peak ground velocity, m/s.
    Pgv,
}

impl IntensityMeasure {
    /// Column name of the level.
    pub fn name(self) -> &'static str {
        match self {
            IntensityMeasure::Factor => "factor",
            IntensityMeasure::Pga => "pga_g",
            IntensityMeasure::Pgv => "pgv_m_s",
        }
    }
}

/// A study ready to run.
#[derive(Clone, Debug)]
pub struct Study {
    /// The study file as read.
    pub spec: StudySpec,
    /// Its name.
    pub name: String,
    /// The model.
    pub model: Model,
    /// The model's initial state.
    pub initial: InitialState,
    /// Parameters from the model's `[analysis]` (the duration is set per case).
    pub params: Parameters,
    /// The driven axis.
    pub axis: Axis,
    /// Pulse kind (pulse studies).
    pub pulse_kind: Option<PulseKind>,
    /// The records (records studies).
    pub records: Vec<StudyRecord>,
    /// The intensity measure (records studies).
    pub intensity: IntensityMeasure,
    /// Activation multiplier λ (g tan α for a block is λg) and frequency parameter p_eq (rad/s)
    /// of the model's one-DOF mechanism, when it has one.
    pub lambda_p: Option<(f64, f64)>,
    /// Slenderness α_eq of the equivalent block of that mechanism (rad; size-free), when it has
    /// one: the study's products measure peak rotations in units of it.
    pub alpha_eq: Option<f64>,
    /// The model at each scale factor (one variant, s = 1, without `scales`).
    pub variants: Vec<Variant>,
    /// Whether the study has a size axis (`scales`): then `cases.csv` has the columns `scale`
    /// and `height_m`.
    pub sized: bool,
    /// The cases, in id order.
    pub cases: Vec<Case>,
}

/// Peak ground velocity of a record (m/s): the largest |∫a dt| by the trapezoid rule (the record
/// is linear between samples, so this is its velocity at the samples exactly).
pub fn peak_ground_velocity(record: &Record) -> f64 {
    let mut v: f64 = 0.0;
    let mut peak: f64 = 0.0;
    let times: Vec<f64> = record.times().collect();
    let a = record.accel();
    for i in 1..a.len() {
        v += 0.5 * (a[i] + a[i - 1]) * (times[i] - times[i - 1]);
        peak = peak.max(v.abs());
    }
    peak
}

fn bad(path: &Path, msg: String) -> InputError {
    InputError::Argument(format!("{}: {msg}", path.display()))
}

impl Study {
    /// Reads the study file, its model and its records, and lists the cases. Errors name the
    /// study file and the key; a record that cannot be read is not an error here (its cases fail
    /// one by one).
    pub fn load(path: &Path) -> Result<Self, InputError> {
        let spec = StudySpec::read(path)?;
        let base = path.parent().unwrap_or(Path::new("."));
        let name = spec.name.clone().unwrap_or_else(|| {
            path.file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("study")
                .to_string()
        });
        let (file, model) = load_model(&base.join(&spec.model))?;
        let axis: Axis = spec
            .component
            .parse()
            .map_err(|e: String| bad(path, format!("component: {e}")))?;
        if axis == Axis::Z {
            return Err(bad(
                path,
                "component: the study drives a horizontal component, x or y".into(),
            ));
        }
        if let Some(d) = spec.duration
            && !(d.is_finite() && d > 0.0)
        {
            return Err(bad(
                path,
                format!("duration must be a positive number of seconds, got {d}"),
            ));
        }
        let initial_spec = match spec.start {
            Start::Rest => Default::default(),
            Start::Model => file.initial.clone().unwrap_or_default(),
        };
        let initial = solve_initial(&model, &initial_spec)
            .map_err(|e| bad(path, format!("model {}: {e}", spec.model.display())))?;
        let params = Parameters::from_analysis(&file.analysis.clone().unwrap_or_default(), 10.0)
            .map_err(|e| bad(path, format!("model {}: {e}", spec.model.display())))?;
        let mechanism = mechanism_scales(&model, axis);
        let lambda_p = mechanism.map(|m| (m.0, m.1));
        let alpha_eq = mechanism.map(|m| m.2).filter(|a| a.is_finite() && *a > 0.0);
        let structure = file.structure();
        let mut variants = Vec::new();
        let sized = spec.scales.is_some();
        match &spec.scales {
            None => variants.push(Variant {
                scale: 1.0,
                model: model.clone(),
                initial: initial.clone(),
                lambda_p,
                height: structure_height(&structure),
            }),
            Some(v) => {
                let scales = v.expand("scales").map_err(|e| bad(path, e))?;
                if let Some(s) = scales.iter().find(|s| **s <= 0.0) {
                    return Err(bad(path, format!("scales: a factor must be > 0, got {s}")));
                }
                for s in scales {
                    let scaled = scale_structure(&structure, s);
                    let m = Model::from_spec(&scaled)
                        .map_err(|e| bad(path, format!("scales: the model scaled by {s}: {e}")))?;
                    let init = solve_initial(&m, &initial_spec)
                        .map_err(|e| bad(path, format!("scales: the model scaled by {s}: {e}")))?;
                    variants.push(Variant {
                        scale: s,
                        lambda_p: mechanism_scales(&m, axis).map(|m| (m.0, m.1)),
                        height: structure_height(&scaled),
                        model: m,
                        initial: init,
                    });
                }
            }
        }
        let mut study = Study {
            spec: spec.clone(),
            name,
            model,
            initial,
            params,
            axis,
            pulse_kind: None,
            records: Vec::new(),
            intensity: IntensityMeasure::Factor,
            lambda_p,
            alpha_eq,
            variants,
            sized,
            cases: Vec::new(),
        };
        match (&spec.pulses, &spec.records) {
            (Some(_), Some(_)) | (None, None) => {
                return Err(bad(
                    path,
                    "give exactly one of [pulses] and [records]".into(),
                ));
            }
            (Some(p), None) => {
                if spec.intensity.is_some() {
                    return Err(bad(
                        path,
                        "[intensity] scales records; a pulse family sets its amplitudes in [pulses]"
                            .into(),
                    ));
                }
                study.pulse_kind = Some(p.kind);
                for v in 0..study.variants.len() {
                    let lp = study.variants[v].lambda_p;
                    let gravity = study.variants[v].model.gravity;
                    let (amplitudes, ratios_a) = pulse_axis(
                        path,
                        lp,
                        gravity,
                        &p.amplitudes,
                        &p.amplitude_ratios,
                        "pulses.amplitudes",
                        "pulses.amplitude_ratios",
                    )?;
                    let (periods, ratios_f) = pulse_axis(
                        path,
                        lp,
                        gravity,
                        &p.periods,
                        &p.frequency_ratios,
                        "pulses.periods",
                        "pulses.frequency_ratios",
                    )?;
                    if let Some(t) = periods.iter().find(|t| **t <= 0.0) {
                        return Err(bad(
                            path,
                            format!("pulses: a period must be > 0, got {t} s"),
                        ));
                    }
                    for (i, &a) in amplitudes.iter().enumerate() {
                        for (j, &t) in periods.iter().enumerate() {
                            study.push(
                                v,
                                Motion::Pulse {
                                    amplitude: a,
                                    period: t,
                                    amplitude_ratio: ratios_a.as_ref().map(|r| r[i]),
                                    frequency_ratio: ratios_f.as_ref().map(|r| r[j]),
                                },
                            );
                        }
                    }
                }
            }
            (None, Some(r)) => {
                let mut files: Vec<PathBuf> = r.files.clone();
                if let Some(folder) = &r.folder {
                    let ext = r.extension.clone().unwrap_or_else(|| "AT2".into());
                    let dir = base.join(folder);
                    let mut found: Vec<PathBuf> = std::fs::read_dir(&dir)
                        .map_err(|e| {
                            bad(path, format!("records.folder {}: {e}", folder.display()))
                        })?
                        .filter_map(|e| e.ok().map(|e| e.path()))
                        .filter(|p| {
                            p.extension()
                                .and_then(|x| x.to_str())
                                .is_some_and(|x| x.eq_ignore_ascii_case(&ext))
                        })
                        .filter_map(|p| p.file_name().map(|n| folder.join(n)))
                        .collect();
                    found.sort();
                    files.extend(found);
                }
                let seeds: Vec<u64> = match &r.synthetic {
                    None => Vec::new(),
                    Some(syn) => {
                        let v = syn
                            .seeds
                            .expand("records.synthetic.seeds")
                            .map_err(|e| bad(path, e))?;
                        let mut seeds = Vec::with_capacity(v.len());
                        for x in v {
                            if !(x >= 0.0 && x.fract() == 0.0 && x < 9.0e15) {
                                return Err(bad(
                                    path,
                                    format!(
                                        "records.synthetic.seeds: {x} is not a whole number from \
                                         0 to 9e15"
                                    ),
                                ));
                            }
                            seeds.push(x as u64);
                        }
                        seeds
                    }
                };
                if files.is_empty() && seeds.is_empty() {
                    return Err(bad(path, "records: no record files".into()));
                }
                if !files.is_empty() && r.format.is_none() {
                    return Err(bad(
                        path,
                        "records.format: give the format of the record files (peer-at2, csv, \
                         text)"
                            .into(),
                    ));
                }
                study.records = files
                    .iter()
                    .map(|f| StudyRecord {
                        file: f.clone(),
                        record: match r.format {
                            Some(format) => read_record(&base.join(f), format, r.units)
                                .map_err(|e| e.to_string()),
                            None => Err("no format".into()),
                        },
                    })
                    .collect();
                study.records.extend(seeds.iter().map(|&seed| StudyRecord {
                    file: PathBuf::from(format!("synthetic:{seed}")),
                    record: synthetic_record(seed),
                }));
                let (measure, levels) = match &spec.intensity {
                    None => (IntensityMeasure::Factor, vec![1.0]),
                    Some(i) => {
                        let given: Vec<(IntensityMeasure, &Values, &str)> = [
                            (IntensityMeasure::Factor, &i.factors, "intensity.factors"),
                            (IntensityMeasure::Pga, &i.pga, "intensity.pga"),
                            (IntensityMeasure::Pgv, &i.pgv, "intensity.pgv"),
                        ]
                        .into_iter()
                        .filter_map(|(m, v, k)| v.as_ref().map(|v| (m, v, k)))
                        .collect();
                        if given.len() != 1 {
                            return Err(bad(
                                path,
                                "[intensity]: give exactly one of factors, pga and pgv".into(),
                            ));
                        }
                        let (m, v, key) = given[0];
                        let levels = v.expand(key).map_err(|e| bad(path, e))?;
                        if let Some(x) = levels.iter().find(|x| **x < 0.0) {
                            return Err(bad(path, format!("{key}: {x} is negative")));
                        }
                        (m, levels)
                    }
                };
                study.intensity = measure;
                for v in 0..study.variants.len() {
                    for k in 0..study.records.len() {
                        for &level in &levels {
                            let factor = study.records[k].record.as_ref().ok().and_then(|rec| {
                                let im = match measure {
                                    IntensityMeasure::Factor => return Some(level),
                                    IntensityMeasure::Pga => rec.peak() / STANDARD_GRAVITY,
                                    IntensityMeasure::Pgv => peak_ground_velocity(rec),
                                };
                                (im > 0.0).then(|| level / im)
                            });
                            study.push(
                                v,
                                Motion::Record {
                                    record: k,
                                    level,
                                    factor,
                                },
                            );
                        }
                    }
                }
            }
        }
        Ok(study)
    }

    fn push(&mut self, variant: usize, motion: Motion) {
        let index = self.cases.len();
        self.cases.push(Case {
            index,
            id: format!("c{index:06}"),
            variant,
            motion,
        });
    }

    /// The ground motion of a case, or why it cannot be built.
    pub fn ground_motion(&self, case: &Case) -> Result<GroundMotion, String> {
        match &case.motion {
            Motion::Pulse {
                amplitude, period, ..
            } => {
                let kind = self.pulse_kind.expect("a pulse study has a kind");
                let signal = match kind {
                    PulseKind::OneSinePulse => SignalSpec::OneSinePulse(PulseSpec {
                        amplitude: *amplitude,
                        period: *period,
                        start: 0.0,
                    }),
                    PulseKind::OneCosinePulse => SignalSpec::OneCosinePulse(PulseSpec {
                        amplitude: *amplitude,
                        period: *period,
                        start: 0.0,
                    }),
                    PulseKind::Ricker => SignalSpec::Ricker(RickerSpec {
                        amplitude: *amplitude,
                        frequency: 1.0 / *period,
                        center: *period,
                    }),
                };
                let mut spec = GroundMotionSpec::default();
                let component = Some(ComponentSpec::new(signal));
                match self.axis {
                    Axis::Y => spec.y = component,
                    _ => spec.x = component,
                }
                GroundMotion::from_spec(&spec, Path::new(".")).map_err(|e| e.to_string())
            }
            Motion::Record { record, factor, .. } => {
                let r = &self.records[*record];
                let rec = r
                    .record
                    .as_ref()
                    .map_err(|e| format!("record {}: {e}", r.file.display()))?;
                let factor = factor.ok_or_else(|| {
                    format!(
                        "record {}: zero intensity, cannot be scaled to a level",
                        r.file.display()
                    )
                })?;
                GroundMotion::from_record(self.axis, rec.clone(), factor).map_err(|e| e.to_string())
            }
        }
    }

    /// Duration of a case: the study's, else the motion's duration + 5 s.
    pub fn duration(&self, ground: &GroundMotion) -> f64 {
        self.spec
            .duration
            .unwrap_or_else(|| default_duration(ground))
    }
}

/// The synthetic record of `seed` (`crate::synthetic::accelerogram_with_seed`, in m/s²).
pub fn synthetic_record(seed: u64) -> Result<Record, String> {
    let a: Vec<f64> = crate::synthetic::accelerogram_with_seed(seed)
        .into_iter()
        .map(|g| g * STANDARD_GRAVITY)
        .collect();
    Record::uniform(crate::synthetic::DT, a).map_err(|e| e.to_string())
}

/// One axis of the pulse grid: values in physical units, and the dimensionless ratios when given
/// so (converted with λg or p_eq of the case's model).
fn pulse_axis(
    path: &Path,
    lambda_p: Option<(f64, f64)>,
    gravity: f64,
    physical: &Option<Values>,
    ratio: &Option<Values>,
    physical_key: &str,
    ratio_key: &str,
) -> Result<(Vec<f64>, Option<Vec<f64>>), InputError> {
    match (physical, ratio) {
        (Some(v), None) => Ok((v.expand(physical_key).map_err(|e| bad(path, e))?, None)),
        (None, Some(r)) => {
            let ratios = r.expand(ratio_key).map_err(|e| bad(path, e))?;
            let Some((lambda, p)) = lambda_p else {
                return Err(bad(
                    path,
                    format!(
                        "{ratio_key}: the model has no one-DOF mechanism to take g tan α and p \
                         from; give {physical_key} instead"
                    ),
                ));
            };
            let values = if ratio_key.ends_with("amplitude_ratios") {
                ratios.iter().map(|r| r * lambda * gravity).collect()
            } else {
                ratios
                    .iter()
                    .map(|r| 2.0 * std::f64::consts::PI / (r * p))
                    .collect()
            };
            Ok((values, Some(ratios)))
        }
        _ => Err(bad(
            path,
            format!("give exactly one of {physical_key} and {ratio_key}"),
        )),
    }
}

/// λ, p_eq and α_eq of the model's one-DOF mechanism opening under the driven axis, if it has one.
fn mechanism_scales(model: &Model, axis: Axis) -> Option<(f64, f64, f64)> {
    let name = model.coords.first()?.name.clone();
    let opening = crr_dynamics::InitialSpec {
        angles: [(name, 0.01)].into_iter().collect(),
        rates: Default::default(),
    };
    let open = solve_initial(model, &opening).ok()?;
    let d = match axis {
        Axis::Y => Vector3::y(),
        _ => Vector3::x(),
    };
    let eq = equivalent_block(model, &open.pivots, 0, &d).ok()?;
    (eq.lambda.is_finite() && eq.p_squared > 0.0)
        .then(|| (eq.lambda, eq.p_squared.sqrt(), eq.alpha))
}
